"""Closed-form eigenvalues of symmetric 2x2 and 3x3 matrices given by their entries (elementwise numpy arrays).

Used by the maps over millions of configurations; the eigenvalues feed condition numbers
``sqrt(lambda_max / lambda_min)`` of Gram matrices ``H^T H`` (5.28). Absolute accuracy is about
``eps * lambda_max`` (``sqrt(eps)`` relative for repeated eigenvalues), so condition numbers are accurate while
``kappa^2 << 1 / eps``.
"""

from __future__ import annotations

import numpy as np


def eigvalsh2_entries(a: np.ndarray, b: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues ``(small, large)`` of ``[[a, b], [b, d]]``, elementwise."""
    mean, half = (a + d) / 2, np.hypot((a - d) / 2, b)
    return mean - half, mean + half


def eigvalsh3_entries(a11, a22, a33, a12, a13, a23) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eigenvalues ``(small, middle, large)`` of the symmetric matrix with these entries, elementwise."""
    q = (a11 + a22 + a33) / 3
    b11, b22, b33 = a11 - q, a22 - q, a33 - q
    p2 = b11 * b11 + b22 * b22 + b33 * b33 + 2 * (a12 * a12 + a13 * a13 + a23 * a23)
    p = np.sqrt(p2 / 6)
    safe = np.where(p > 0, p, 1.0)
    det = (b11 * (b22 * b33 - a23 * a23) - a12 * (a12 * b33 - a23 * a13) + a13 * (a12 * a23 - b22 * a13))
    r = np.clip(det / (2 * safe**3), -1.0, 1.0)
    phi = np.arccos(r) / 3
    large = q + 2 * p * np.cos(phi)
    small = q + 2 * p * np.cos(phi + 2 * np.pi / 3)
    middle = 3 * q - large - small
    return small, middle, large
