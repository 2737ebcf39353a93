"""Shape contracts of batched functions: batch axes lead, core axes trail."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .errors import ShapeError


def finite_number(value: object) -> bool:
    """Whether `value` is one finite real number (Python, NumPy scalar); False for NaN, infinities, text, None."""
    try:
        return math.isfinite(value)  # type: ignore[arg-type]
    except TypeError:
        return False


def as_vectors(x: ArrayLike, n: int, name: str) -> np.ndarray:
    """Return `x` as a float array of shape ``(..., n)``, or raise :class:`ShapeError` naming `name`."""
    a = np.asarray(x, dtype=float)
    if a.shape[-1:] != (n,):
        raise ShapeError(f"{name}: expected shape (..., {n}), got {a.shape}")
    return a


def as_angles(x: ArrayLike, n: int, name: str) -> np.ndarray:
    """:func:`as_vectors` for angles [rad]: also raise :class:`ShapeError` naming `name` for NaN, infinities and
    angles beyond :data:`wmrkit.units.MAX_ANGLE` (1e6 turns), whose sine and cosine are round-off."""
    from .units import MAX_ANGLE, MAX_TURNS

    a = as_vectors(x, n, name)
    bad = ~(np.abs(a) <= MAX_ANGLE)  # NaN included
    if bad.any():
        value = float(a[np.unravel_index(int(np.argmax(bad)), a.shape)])
        raise ShapeError(f"{name}: angles must be finite numbers of at most {MAX_TURNS:g} turns [rad], got {value!r}")
    return a


def readonly(a: np.ndarray) -> np.ndarray:
    """Mark `a` read-only and return it (values handed out are never written into)."""
    a.setflags(write=False)
    return a
