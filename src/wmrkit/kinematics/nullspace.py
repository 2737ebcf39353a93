"""Null-space method (thesis §4.2, eqs. 4.1-4.8) on a slip matrix ``A`` (3.22), batched over configurations.

No slip is ``A q_dot = 0`` (4.1), so ``q_dot = B eta`` with B a basis of N(A) (4.2) and ``m = k - rank A``
(4.3). A set of m velocities can be *assigned* (chosen freely) iff its rows ``B_a`` of B are invertible; the
others follow as ``q_na = B_na B_a^-1 q_a`` (4.4)-(4.5). The Gauss-Jordan variant (4.6) orders the columns
with the set last and reads the same matrix off the reduced row-echelon form. These kernels take ``A`` and
column indices; :mod:`wmrkit.kinematics.models` names the velocities.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import ArrayLike

from .linalg import matrix_rank, rref


def _split(k: int, assigned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    assigned = np.asarray(assigned, dtype=int).reshape(-1)
    return np.setdiff1d(np.arange(k), assigned), assigned


def null_space_basis(a: ArrayLike, m: int) -> np.ndarray:
    """An orthonormal basis of N(A) (4.2) for configurations where ``rank A = k - m``: ``(..., R, k) -> (..., k, m)``.

    The last m right singular vectors; where the rank is higher they are not null vectors (check the rank).
    """
    a = np.asarray(a, dtype=float)
    k = a.shape[-1]
    if m == 0:
        return np.zeros((*a.shape[:-2], k, 0))
    rows = a.shape[-2]
    if rows < k:  # pad so that the SVD returns all k right singular vectors
        a = np.concatenate([a, np.zeros((*a.shape[:-2], k - rows, k))], axis=-2)
    _, _, vh = np.linalg.svd(a)
    return np.swapaxes(vh[..., k - m:, :], -1, -2)


def null_space_solution(a: ArrayLike, assigned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Assigned-velocity solution by the null-space method, eqs. (4.4)-(4.5).

    ``a``: ``(..., R, k)``; ``assigned``: column indices ``(n_a,)``. Returns ``(matrix, ok)``: ``matrix``
    ``(..., k - n_a, n_a)`` maps the assigned velocities to the others (ascending column order), and ``ok``
    ``(...)`` bool says where the set is assignable: ``dim N(A) = n_a`` and ``det B_a != 0``. Where ``ok`` is
    False the matrix is meaningless.
    """
    a = np.asarray(a, dtype=float)
    free, assigned = _split(a.shape[-1], assigned)
    m = len(assigned)
    basis = null_space_basis(a, m)
    b_a, b_na = basis[..., assigned, :], basis[..., free, :]
    ok = (matrix_rank(a) == a.shape[-1] - m) & (matrix_rank(b_a) == m)
    safe = np.where(ok[..., None, None], b_a, np.eye(m))
    return b_na @ np.linalg.inv(safe), ok


def rref_solution(a: ArrayLike, assigned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Assigned-velocity solution by Gauss-Jordan elimination, eq. (4.6): the set is placed last.

    Same signature and result as :func:`null_space_solution`. The set is assignable iff the RREF of the
    reordered A has its pivots exactly in the first ``k - n_a`` columns; then ``q_na = -R[:g, g:] q_a``.
    """
    a = np.asarray(a, dtype=float)
    free, assigned = _split(a.shape[-1], assigned)
    g = len(free)
    reduced, pivots = rref(a[..., np.concatenate([free, assigned])])
    ok = pivots[..., :g].all(axis=-1) & ~pivots[..., g:].any(axis=-1)
    return -reduced[..., :g, g:], ok


def rref_free_columns(a: ArrayLike, order: ArrayLike) -> np.ndarray:
    """Which velocities the RREF takes as the mobility vector when the columns are ordered as `order` (4.6).

    ``(..., R, k) -> (..., k)`` bool, in the original column order. With the wanted set last, a
    non-assignable set is replaced by the feasible set closest to the end of the order.
    """
    a = np.asarray(a, dtype=float)
    order = np.asarray(order, dtype=int)
    _, pivots = rref(a[..., order])
    free = np.empty_like(pivots)
    free[..., order] = ~pivots
    return free


def enumerate_subsets(k: int, m: int) -> np.ndarray:
    """All ``C(k, m)`` sets of m column indices of k, eq. (4.8): ``(C(k, m), m)`` int, lexicographic."""
    out = np.array(list(itertools.combinations(range(k), m)), dtype=int).reshape(math.comb(k, m), m)
    return out


def null_space_assignable(a: ArrayLike, subsets: ArrayLike) -> np.ndarray:
    """Assignability of many sets at once by the null-space test (4.5): ``(..., R, k), (S, m) -> (S, ...)`` bool.

    Each set must have ``m = dim N(A)`` members and an invertible ``B_a`` (4.8 enumerates all of them).
    """
    a = np.asarray(a, dtype=float)
    subsets = np.asarray(subsets, dtype=int)
    m = subsets.shape[-1]
    basis = null_space_basis(a, m)  # (..., k, m)
    b_a = np.moveaxis(basis[..., subsets, :], -3, 0)  # (S, ..., m, m)
    return (matrix_rank(a) == a.shape[-1] - m) & (matrix_rank(b_a) == m)
