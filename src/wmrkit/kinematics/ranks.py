"""Ranks method (thesis §4.3, eqs. 4.9-4.11) on a slip matrix ``A`` (3.22), batched over configurations.

Moving the assigned velocities to the right-hand side gives ``A_na q_na = -A_a q_a`` (4.9). A set is
assignable iff deleting its columns keeps the rank, ``rank A_na = rank A`` (4.10), with as many members as the
mobility; the solution is the least-squares one (4.11), exact (zero residual) for an assignable set.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .linalg import RANK_RTOL, matrix_rank, solve_assigned


def ranks_assignable(a: ArrayLike, subsets: ArrayLike, *, whole: ArrayLike | None = None,
                     rank_a: ArrayLike | None = None) -> np.ndarray:
    """Assignability test (4.10) of many sets at once: ``(..., R, k), (S, n_a) -> (S, ...)`` bool.

    True where ``rank A_na = rank A`` and ``n_a = k - rank A`` (a set of the size of the mobility). `whole`: `a` on
    the twist of the wheels' centroid (``linalg.centred``), whose columns a set assigning no twist component takes
    for ``A_na`` (the same rank: a change of the unknowns), and `rank_a` ``(...)`` the rank of ``A`` the mobility
    was read from (``linalg.nullity``): the sets then have exactly the mobility's size, whatever side of the cut-off
    a least singular value near it falls on in the other matrix.
    """
    a = np.asarray(a, dtype=float)
    subsets = np.asarray(subsets, dtype=int)
    k, n_a = a.shape[-1], subsets.shape[-1]
    keep = np.array([np.setdiff1d(np.arange(k), s) for s in subsets], dtype=int).reshape(len(subsets), k - n_a)
    a_na = np.moveaxis(a[..., keep], -2, 0)  # (..., R, S, k - n_a) -> (S, ..., R, k - n_a)
    inner = ~np.isin(subsets, (0, 1, 2)).any(axis=-1)  # (S,): no twist component assigned
    if whole is not None and inner.any():
        a_na[inner] = np.moveaxis(np.asarray(whole, dtype=float)[..., keep[inner]], -2, 0)
    rank_a = matrix_rank(a) if rank_a is None else np.asarray(rank_a)
    return (matrix_rank(a_na) == rank_a) & (k - rank_a == n_a)


def ranks_solution(a: ArrayLike, assigned: ArrayLike) -> np.ndarray:
    """The matrix of the kinematic solution (4.11), ``q_na = -(A_na^T A_na)^-1 A_na^T A_a q_a``.

    ``(..., R, k), (n_a,) -> (..., k - n_a, n_a)``, rows in ascending column order. Computed with
    :func:`~wmrkit.kinematics.linalg.solve_assigned` (pseudo-inverse, the rank tolerance of :func:`ranks_assignable`),
    one unit assigned vector per column.
    """
    a = np.asarray(a, dtype=float)
    assigned = np.asarray(assigned, dtype=int).reshape(-1)
    free = np.setdiff1d(np.arange(a.shape[-1]), assigned)
    q, _ = solve_assigned(a[..., None, :, :], assigned, np.eye(len(assigned)), rtol=RANK_RTOL)  # (..., n_a, k)
    return np.swapaxes(q[..., free], -1, -2)
