"""Closed-form eigenvalues of batched symmetric 2x2 and 3x3 matrices (elementwise numpy, no LAPACK loop).

Used by the maps over millions of configurations; the eigenvalues feed condition numbers
``sqrt(lambda_max / lambda_min)`` of Gram matrices ``H^T H`` (5.28). Absolute accuracy is about
``eps * lambda_max``, so condition numbers are accurate while ``kappa^2 << 1 / eps``.
"""

from __future__ import annotations

import numpy as np


def gram(h: np.ndarray) -> np.ndarray:
    """``H^T H`` for ``(..., r, c) -> (..., c, c)``, summed elementwise over the (few) rows."""
    return np.einsum("...rc,...rd->...cd", h, h)


def eigvalsh2(g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues ``(small, large)`` of symmetric ``(..., 2, 2)`` matrices."""
    return eigvalsh2_entries(g[..., 0, 0], g[..., 0, 1], g[..., 1, 1])


def eigvalsh2_entries(a: np.ndarray, b: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues ``(small, large)`` of ``[[a, b], [b, d]]``, elementwise."""
    mean, half = (a + d) / 2, np.hypot((a - d) / 2, b)
    return mean - half, mean + half


def eigvalsh3(g: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eigenvalues ``(small, middle, large)`` of symmetric ``(..., 3, 3)`` matrices (trigonometric method)."""
    return eigvalsh3_entries(g[..., 0, 0], g[..., 1, 1], g[..., 2, 2], g[..., 0, 1], g[..., 0, 2], g[..., 1, 2])


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


def condition_from_gram(g: np.ndarray) -> np.ndarray:
    """``sigma_max / sigma_min`` of H from ``G = H^T H`` ``(..., c, c)``, c in 1..3; ``inf`` where singular."""
    c = g.shape[-1]
    if c == 0:
        return np.full(g.shape[:-2], np.nan)
    if c == 1:
        small = large = g[..., 0, 0]
    elif c == 2:
        small, large = eigvalsh2(g)
    elif c == 3 and g[..., 0, 0].size > 4096:  # closed form for big batches, LAPACK (more accurate) otherwise
        small, _, large = eigvalsh3(g)
    else:
        w = np.linalg.eigvalsh(g)
        small, large = w[..., 0], w[..., -1]
    tiny = np.maximum(small, 0.0) <= 1e-14 * np.maximum(large, 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.sqrt(large / np.where(tiny, 1.0, small))
    return np.where(tiny, np.inf, out)
