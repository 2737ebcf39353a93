"""Shape contracts of batched functions: batch axes lead, core axes trail."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .errors import ShapeError


def as_vectors(x: ArrayLike, n: int, name: str) -> np.ndarray:
    """Return `x` as a float array of shape ``(..., n)``, or raise :class:`ShapeError` naming `name`."""
    a = np.asarray(x, dtype=float)
    if a.shape[-1:] != (n,):
        raise ShapeError(f"{name}: expected shape (..., {n}), got {a.shape}")
    return a


def readonly(a: np.ndarray) -> np.ndarray:
    """Mark `a` read-only and return it (values handed out are never written into)."""
    a.setflags(write=False)
    return a
