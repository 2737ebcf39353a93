"""Angles compared on the circle: pi and -pi are one angle, and sets of angles have no order."""

from __future__ import annotations

import numpy as np


def circular_gap(a, b) -> np.ndarray:
    """Distance on the circle between every pair ``a[i]``, ``b[j]`` [rad], shape ``(len(a), len(b))``."""
    a, b = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
    return np.abs(np.angle(np.exp(1j * (a[:, None] - b[None, :]))))


def same_angles(a, b, tol: float = 1e-7) -> bool:
    """`a` and `b` are the same set of angles (each within `tol` of one of the other, equal counts)."""
    gap = circular_gap(a, b)
    if gap.shape[0] != gap.shape[1]:
        return False
    return gap.size == 0 or bool(np.all(gap.min(axis=1) < tol) and np.all(gap.min(axis=0) < tol))


def assert_same_angles(got, want, tol: float = 1e-7) -> None:
    """Assert `got` and `want` are the same set of angles on the circle."""
    assert same_angles(got, want, tol), (np.asarray(got), np.asarray(want))
