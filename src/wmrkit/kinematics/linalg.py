"""Linear algebra of chapter 4, batched: numeric rank, the projector Delta (4.17), least squares (4.11)/(4.15).

The tolerance policy (one for the three methods of chapter 4, actuation, sensing and the analysis): rank
decisions are made on *nondimensional* matrices, those of :func:`nondimensional` (the robot with every length
divided by its :func:`characteristic_length`), with the one tolerance of :func:`matrix_rank`. Dividing the
lengths by ``L`` maps the velocities ``(vx, vy, omega, rates)`` to ``(vx / L, vy / L, omega, rates)``
(:func:`velocity_scale`), a diagonal change of variables that keeps every rank, null space and assignable set,
so the decisions do not depend on the robot's scale (a micrometre robot and a kilometre one get the same
answers). ``L`` is the wheels' spread about their centroid, and a decision that takes the whole twist is made
on the twist of the centroid (:func:`centred`), so neither depends on where the robot frame is. The robot's
three sizes, each with its purpose, are documented in ``docs/limits.md`` (the physical envelope): ``L``,
:func:`reach` (lengths from the origin) and :func:`robot_size` (a default length at the origin). Descriptions
keep radii and offsets at least ``MIN_RATIO`` of the reach, so at least half that of ``L``, far above the
tolerance.
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import lapack

from .._shapes import matvec

if TYPE_CHECKING:
    from ..robot import Robot

#: Resolution [rad] at which steering headings are given: a heading printed or typed to 4 decimals of a degree is off
#: by at most 5e-5 deg = 8.7e-7 rad (``wmrkit ik`` prints 32.5807 deg for 32.58070741 deg).
HEADING_RESOLUTION = 1e-6

#: Relative tolerance on singular values for numeric rank: a singular value at or below ``RANK_RTOL * max(s_max, 1)``
#: counts as 0 (:func:`rank_cutoff`). Tied to :data:`HEADING_RESOLUTION`: headings off a consistent configuration
#: by ``h`` [rad] move the least singular value of a nondimensional constraint matrix by at most about
#: ``0.3 h s_max`` (random robots aimed at random ICRs; 0.08 for the Ackermann car), so headings given to that
#: resolution keep the configuration's rank, while headings 0.01 rad off the law move it by 4e-4 of that at least
#: (1e-6 s_max or more); radii and offsets, at least ``limits.MIN_RATIO / 2`` of ``L`` (5e-5), stay far above it.
RANK_RTOL = HEADING_RESOLUTION


def matrix_rank(m: ArrayLike, *, rtol: float = RANK_RTOL) -> np.ndarray:
    """Numeric rank by SVD, ``(..., r, c) -> (...)`` int; singular values at or below :func:`rank_cutoff` count as 0.

    The one rank rule of the chapter-4 and chapter-5 decisions (mobility, assignable sets, models, actuation,
    sensing, classification, ICR), made on nondimensional matrices. The scale floor is 1: a matrix of tiny but
    meaningful entries (lengths in km) keeps its rank; an all-zero matrix has rank 0.
    """
    m = np.asarray(m, dtype=float)
    if m.shape[-1] == 0 or m.shape[-2] == 0:
        return np.zeros(m.shape[:-2], dtype=int)
    s = np.linalg.svd(m, compute_uv=False)
    return np.sum(s > rank_cutoff(s, rtol), axis=-1)


def rank_cutoff(s: np.ndarray, rtol: float = RANK_RTOL) -> np.ndarray:
    """The singular value at and below which :func:`matrix_rank` counts one as 0, ``(..., n) -> (..., 1)``: `s` the
    singular values (descending); ``rtol * max(s_max, 1)`` (:data:`RANK_RTOL`, relative to the matrix's scale).
    The one rank tolerance, shared by the least squares of :func:`solve_assigned` given an `rtol` and the pruned
    walk of :mod:`.search`."""
    return rtol * np.maximum(s[..., :1], 1.0)


def unit_columns(t: ArrayLike) -> np.ndarray:
    """`t` ``(..., n, c)`` with each nonzero column scaled to norm 1. For the variables of a coupling's channel
    (``q_j = k_j u``, ratios from 1e-6 to 1e6, ``wmrkit.couplings``) in a rank decision: a change of each channel's
    unit, which keeps every rank, so a channel of ratios 1e6 neither hides the other columns below the cut-off,
    relative to the largest singular value (:func:`rank_cutoff`), nor falls below it itself."""
    t = np.asarray(t, dtype=float)
    norms = np.linalg.norm(t, axis=-2, keepdims=True)
    return t / np.where(norms > 0, norms, 1.0)


def nullity(robot: Robot, a: ArrayLike) -> np.ndarray:
    """``k - rank A`` of `robot`'s nondimensional slip matrix `a` ``(..., R, k)`` (3.22, with a gear's rows or not):
    the mobility m (4.3), ``(...)`` int. The rank is :func:`matrix_rank`'s on the twist of the wheels' centroid
    (:func:`centred`), the same in every frame: the one m of the mobility, the assignable sets and models, the
    actuation and sensing analyses and their minimal sets."""
    a = np.asarray(a, dtype=float)
    return a.shape[-1] - matrix_rank(centred(robot, a))


def free_columns(m: ArrayLike, *, rtol: float = RANK_RTOL) -> np.ndarray:
    """Which columns of one matrix ``(r, c)`` its null space moves, ``(c,)`` bool: the unknowns that ``m x = b``
    leaves undetermined (all False at full column rank). Rank as :func:`matrix_rank` decides it."""
    m = np.asarray(m, dtype=float)
    rank = int(matrix_rank(m, rtol=rtol))
    if rank == m.shape[-1]:
        return np.zeros(m.shape[-1], dtype=bool)
    null = np.linalg.svd(m)[2][rank:]
    return np.abs(null).max(axis=0) > 1e-9


#: Wheel fields that are lengths [m] (scaled by :func:`nondimensional`).
LENGTH_FIELDS = ("l", "d", "r", "r_r", "b")


def characteristic_length(robot: Robot) -> float:
    """The robot's size ``L`` [m], the unit of every rank decision: the largest distance of a wheel's mount point
    from the wheels' centroid (:func:`centroid`), or of a wheel length (radius, roller radius, offset, half-width)
    if larger (one wheel, or all at one point).

    It does not depend on where the robot frame is (a rigid change of frame keeps it), so neither do the decisions
    made in it (:func:`centred`). Positive for any robot with a length; 1 m for a robot of no length at all.
    """
    return _characteristic_length(robot)


@functools.lru_cache(maxsize=256)
def _characteristic_length(robot: Robot) -> float:
    c = np.array(centroid(robot))
    spread = max((float(np.hypot(*(np.array(w.position) - c))) for w in robot.wheels), default=0.0)
    own = max((abs(float(getattr(w, f))) for w in robot.wheels for f in LENGTH_FIELDS if f != "l"), default=0.0)
    size = max(spread, own)
    return size if 0.0 < size < np.inf else 1.0


def centroid(robot: Robot) -> tuple[float, float]:
    """The mean of the wheels' mount points in the robot frame [m]: the origin rank decisions are made at."""
    return _centroid(robot)


@functools.lru_cache(maxsize=256)
def _centroid(robot: Robot) -> tuple[float, float]:
    x, y = np.mean([w.position for w in robot.wheels], axis=0) if robot.wheels else (0.0, 0.0)
    return float(x), float(y)


def centred(robot: Robot, m: ArrayLike, *, metres: bool = False) -> np.ndarray:
    """`m` ``(..., r, c >= 3)``, rows acting on the twist ``(vx, vy, omega)`` of the robot's origin in its first
    three columns, acting on the twist of the wheels' :func:`centroid` instead: the matrix rank decisions that take
    the whole twist are made on, the same however the robot frame is placed and turned (a turn of the frame turns
    ``(vx, vy)``, which keeps every singular value). `m` in the velocities of :func:`nondimensional`, or with
    `metres`, in `robot`'s (the omega column then divided by :func:`characteristic_length`, e.g. the lines of
    :mod:`wmrkit.analysis.lines`). Its ranks are those of `m`: the change of twist is invertible.
    """
    m = np.array(m, dtype=float)
    size = characteristic_length(robot)
    cx, cy = centroid(robot)
    if metres:
        m[..., 2] /= size
    # the twist at c: (vx - omega cy, vy + omega cx, omega); a row g acts on it as g T^-1
    m[..., 2] += (cy * m[..., 0] - cx * m[..., 1]) / size
    return m


def centred_twist(robot: Robot, twist: ArrayLike) -> np.ndarray:
    """Twists ``(..., 3)`` of the robot's origin in the velocities of :func:`nondimensional` as the twists of the
    wheels' :func:`centroid` (the same units): what the matrices of :func:`centred` act on."""
    t = np.array(twist, dtype=float)
    cx, cy = centroid(robot)
    size = characteristic_length(robot)
    t[..., 0] -= t[..., 2] * cy / size
    t[..., 1] += t[..., 2] * cx / size
    return t


def reach(robot: Robot) -> float:
    """The robot's largest length measured from its origin [m]: a wheel's distance from the origin, or a radius,
    roller radius, offset or half-width if larger (1 m for a robot of no length at all). It moves with the origin:
    the unit of what is defined at the origin (the twist of the condition number, :func:`robot_size`), never of a
    rank decision (:func:`characteristic_length`)."""
    return _reach(robot)


@functools.lru_cache(maxsize=256)
def _reach(robot: Robot) -> float:
    size = max((abs(float(getattr(w, f))) for w in robot.wheels for f in LENGTH_FIELDS), default=0.0)
    return size if 0.0 < size < np.inf else 1.0


#: Least :func:`robot_size` as a fraction of the robot's :func:`reach`: wheels all mounted at the origin still
#: make a robot of some size, and the default lengths scale with the robot at every size.
SIZE_FRACTION = 0.1


def robot_size(robot: Robot) -> float:
    """RMS distance of the wheels' mount points from the robot origin [m], at least :data:`SIZE_FRACTION` of its
    :func:`reach`: the default length that weighs a turn rate about the origin against speeds (``omega`` times it)."""
    rms = float(np.sqrt(np.mean([w.l**2 for w in robot.wheels])))
    return max(rms, SIZE_FRACTION * reach(robot))


@functools.lru_cache(maxsize=256)
def nondimensional(robot: Robot) -> Robot:
    """`robot` with every length divided by :func:`characteristic_length`: the robot rank decisions are made on.

    Its slip matrix and Jacobian form are those of `robot` in the velocities of :func:`velocity_scale` (same
    ranks, null spaces, assignable sets and tree verdicts), with entries of order 1 at any scale.
    """
    size = characteristic_length(robot)
    if size == 1.0:
        return robot
    wheels = tuple(replace(w, **{f: getattr(w, f) / size for f in LENGTH_FIELDS}) for w in robot.wheels)
    return replace(robot, wheels=wheels)


@functools.lru_cache(maxsize=256)
def centred_robot(robot: Robot) -> Robot:
    """:func:`nondimensional` described from the wheels' :func:`centroid` (same axes): the robot whose Jacobian form
    (3.20) the decisions that take the whole twist are made on, the same in every frame (the Jacobian form moves
    with the origin through its wheels' ``l`` and ``alpha``, not by a change of the twist alone). Its twist is
    :func:`centred_twist`'s."""
    unit = nondimensional(robot)
    cx, cy = centroid(unit)
    wheels = []
    for w in unit.wheels:
        x, y = w.position
        wheels.append(replace(w, l=math.hypot(x - cx, y - cy), alpha=math.atan2(y - cy, x - cx)))
    return replace(unit, wheels=tuple(wheels))


def velocity_scale(robot: Robot) -> np.ndarray:
    """Factors from the velocities ``q_dot`` of `robot` to those of :func:`nondimensional` ``(k,)``: ``1 / L`` for
    ``vx`` and ``vy``, 1 for ``omega`` and the wheel rates (angular)."""
    out = np.ones(len(robot.velocity_names))
    out[:2] = 1.0 / characteristic_length(robot)
    return out


def delta_projector(m: ArrayLike) -> np.ndarray:
    """Delta(M) of eq. (4.17): ``M pinv(M) - I`` (minus the projector onto col(M)^perp); ``-I`` for empty M.

    ``(..., r, c) -> (..., r, r)``. ``Delta(M) @ y = 0`` iff ``y`` is in the column space of M (4.18).
    """
    m = np.asarray(m, dtype=float)
    eye = np.eye(m.shape[-2])
    if m.shape[-1] == 0:
        return np.broadcast_to(-eye, (*m.shape[:-2], *eye.shape)).copy()
    return m @ np.linalg.pinv(m) - eye


def solve_assigned(a: ArrayLike, assigned: ArrayLike, q_assigned: ArrayLike,
                   name: str = "q_assigned", *, rtol: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Ranks-method solution (4.9)-(4.11): the velocities not assigned, by least squares, and the residual.

    ``a``: ``(..., R, k)`` slip matrix (3.22); ``assigned``: column indices (n_a,); ``q_assigned``:
    ``(..., n_a)``. Returns ``(q_dot, residual)``: the full velocity vector ``(..., k)`` (assigned entries
    copied in) and ``a @ q_dot`` ``(..., R)``, zero when the assignment is consistent with no slip; its norm is
    the slip indicator of (4.11)/(4.82). Uses the pseudo-inverse, so a non-assignable set returns the
    minimum-norm solution rather than failing: check assignability with ``matrix_rank`` (4.10). `name` names
    ``q_assigned`` when its batch shape does not broadcast with ``a``'s. With `rtol` (on a nondimensional matrix:
    :func:`robot_solve`, :func:`~.ranks.ranks_solution`) the pseudo-inverse drops the singular values
    :func:`matrix_rank` counts as 0 with that `rtol` (:func:`rank_cutoff`), so a direction the rank tests call
    undetermined is not solved from round-off; without, only those numpy's least squares drops (``eps``), the
    answer for a matrix in any units.
    """
    a = np.asarray(a, dtype=float)
    assigned = np.asarray(assigned, dtype=int)
    q_assigned = np.asarray(q_assigned, dtype=float)
    free_mask = np.ones(a.shape[-1], dtype=bool)
    free_mask[assigned] = False
    free = np.flatnonzero(free_mask)  # (np.setdiff1d costs ~20 us, a quarter of a small solve)
    a_na, a_a = a[..., free], a[..., assigned]
    one = a.ndim == 2 and len(free) and len(assigned) and q_assigned.size
    if one and rtol is None:  # one matrix: LAPACK least squares on every right-hand side at once; same minimum-norm
        rhs = -(a_a @ q_assigned.reshape(-1, len(assigned)).T)  # solution, ~1.7x faster (an empty batch takes the
        q_na = _min_norm_lstsq(a_na, rhs).T.reshape(*q_assigned.shape[:-1], len(free))  # general path: LAPACK
        # refuses zero right-hand sides)
    elif one:
        rhs = -(a_a @ q_assigned.reshape(-1, len(assigned)).T)
        q_na = (_pinv(a_na, rtol) @ rhs).T.reshape(*q_assigned.shape[:-1], len(free))
    else:
        rhs = -matvec(a_a, q_assigned, name)[..., None]
        q_na = ((np.linalg.pinv(a_na) if rtol is None else _pinv(a_na, rtol)) @ rhs)[..., 0]
    batch = np.broadcast_shapes(q_na.shape[:-1], q_assigned.shape[:-1])
    q = np.empty((*batch, a.shape[-1]))
    q[..., free] = q_na
    q[..., assigned] = q_assigned
    return q, (a @ q[..., None])[..., 0]


def geared_solve(a: ArrayLike, couplings: tuple, names: tuple[str, ...], assigned: ArrayLike, q_assigned: ArrayLike,
                 name: str = "q_assigned", *, rtol: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solve_assigned` with the robot's ``gear`` couplings held: the joints a gear turns with assigned ones
    filled (:func:`wmrkit.couplings.gear_fill`), and a gear with no assigned joint one unknown, its turn
    (:func:`wmrkit.couplings.gear_free`). `names`: the columns of `a`. Without a gear, :func:`solve_assigned`
    (`rtol` as there)."""
    from ..couplings import gear_unknowns

    assigned = tuple(int(c) for c in np.asarray(assigned, dtype=int).reshape(-1))
    if not any(c.kind == "gear" for c in couplings):
        return solve_assigned(a, assigned, q_assigned, name, rtol=rtol)
    a = np.asarray(a, dtype=float)
    free, given = gear_unknowns(couplings, names, assigned)  # q = free @ p + given @ q_assigned
    p = free.shape[1]
    x, residual = solve_assigned(np.concatenate([a @ free, a @ given], axis=-1), np.arange(p, p + len(assigned)),
                                 q_assigned, name, rtol=rtol)
    return x[..., :p] @ free.T + x[..., p:] @ given.T, residual


def decision_matrix(robot: Robot, a: ArrayLike, assigned: tuple[int, ...]) -> tuple[np.ndarray, bool]:
    """`robot`'s slip matrix `a` ``(..., R, k)`` (3.22) in the velocities of :func:`nondimensional` (row units
    ``1 / L``), and of the wheels' :func:`centroid` (:func:`centred`) when no twist component is among the
    `assigned` columns: the matrix the rank decisions and the least squares of :func:`robot_solve` and
    ``twist_is_determined`` are made on, the same at any scale and, for a whole unknown twist, in any frame.
    Returns it and whether it was centred."""
    unit = np.asarray(a, dtype=float) / (velocity_scale(robot) * characteristic_length(robot))
    whole = not any(c < 3 for c in assigned)
    return (centred(robot, unit) if whole else unit), whole


def robot_solve(robot: Robot, a: ArrayLike, assigned: ArrayLike, q_assigned: ArrayLike,
                name: str = "q_assigned") -> tuple[np.ndarray, np.ndarray]:
    """:func:`geared_solve` of `robot`'s slip matrix `a` ``(..., R, k)`` made on its :func:`decision_matrix`, the
    answer back in `robot`'s velocities: ``(q_dot (..., k), residual (..., R) [m/s])``. Its rank decisions are those
    of ``twist_is_determined`` (one tolerance, :func:`rank_cutoff`), whatever the robot's scale and frame."""
    assigned = tuple(int(c) for c in np.asarray(assigned, dtype=int).reshape(-1))
    unit, whole = decision_matrix(robot, a, assigned)
    scale, size = velocity_scale(robot), characteristic_length(robot)
    q, residual = geared_solve(unit, robot.couplings, robot.velocity_names, assigned,
                               np.asarray(q_assigned, dtype=float) * scale[list(assigned)], name, rtol=RANK_RTOL)
    if whole:  # the centroid's twist back to the origin's (the inverse of centred_twist)
        cx, cy = centroid(robot)
        q[..., 0] += q[..., 2] * cy / size
        q[..., 1] -= q[..., 2] * cx / size
    return q / scale, residual * size


def geared_twist_determined(a: np.ndarray, couplings: tuple, names: tuple[str, ...],
                            assigned: tuple[int, ...]) -> np.ndarray:
    """Whether the `assigned` columns of `a` ``(..., R, k)`` (the twist first) fix the twist, gears held
    (:func:`geared_solve`): ``rank(A T) = n_twist_free + rank(A T_rest)`` (4.10), ``T`` the unknown directions,
    ``T_rest`` those of the joints. ``(...)`` bool."""
    from ..couplings import gear_free

    free = gear_free(couplings, names, assigned)[0]
    twist = np.abs(free[:3]).sum(axis=0) > 0
    a_free = a @ free
    return matrix_rank(a_free) == int(twist.sum()) + matrix_rank(a_free[..., ~twist])


def coupled_constraints(robot: Robot, beta: np.ndarray) -> np.ndarray:
    """The no-slip constraint matrix (3.22) of `robot` at `beta` with one more row per direction a ``gear`` coupling
    holds at zero (its joints turn together, ``q_j = ratio_j * u``): its null space is the motions the mechanism
    allows, ``(..., 3E + n_g, k)``. Without a gear, the matrix (3.22) itself."""
    from ..couplings import coupled_columns

    a = robot.constraint_matrix(beta)
    if not any(c.kind == "gear" for c in robot.couplings):
        return a
    rows = coupled_columns(robot.couplings, robot.velocity_names, ())[3].T  # (n_g, k): across each gear's ratios
    return np.concatenate([a, np.broadcast_to(rows, (*a.shape[:-2], *rows.shape))], axis=-2)


def rref(m: ArrayLike, *, rtol: float = RANK_RTOL) -> tuple[np.ndarray, np.ndarray]:
    """Reduced row-echelon form by Gauss-Jordan elimination with partial pivoting, batched (thesis §4.2, 4.6).

    ``(..., r, c) -> ((..., r, c), (..., c) bool)``: the RREF and which columns hold a pivot. Pivots are taken
    left to right, so the free (non-pivot) columns are the right-most set of columns that can act as the
    mobility vector of (4.2): put the variables to assign last and read ``q_na = -R[:g, free] @ q_a``.
    A pivot candidate below ``rtol * max(|m|_max, 1)`` counts as zero (as in :func:`matrix_rank`).
    """
    m = np.asarray(m, dtype=float)
    n_rows, n_cols = m.shape[-2:]
    out = m.reshape(-1, n_rows, n_cols).copy()
    n_batch = out.shape[0]
    scale = np.maximum(np.abs(out).max(axis=(1, 2), initial=0.0), 1.0)
    tol = rtol * scale
    next_row = np.zeros(n_batch, dtype=int)
    pivots = np.zeros((n_batch, n_cols), dtype=bool)
    batch, rows = np.arange(n_batch), np.arange(n_rows)
    for j in range(n_cols):  # a loop over columns (a handful), never over the batch
        col = np.where(rows >= next_row[:, None], np.abs(out[:, :, j]), -1.0)
        p = np.argmax(col, axis=1) if n_rows else np.zeros(n_batch, dtype=int)
        ok = (next_row < n_rows) & (col[batch, p] > tol) if n_rows else np.zeros(n_batch, dtype=bool)
        if not ok.any():
            continue
        b, src, dst = batch[ok], p[ok], next_row[ok]
        pivot_rows = out[b, src].copy()
        out[b, src] = out[b, dst]
        pivot_rows /= pivot_rows[:, j : j + 1]
        factors = out[b, :, j].copy()
        factors[np.arange(len(b)), dst] = 0.0
        out[b] -= factors[:, :, None] * pivot_rows[:, None, :]
        out[b, dst] = pivot_rows
        out[b, :, j] = 0.0
        out[b, dst, j] = 1.0
        pivots[b, j] = True
        next_row[b] += 1
    return out.reshape(m.shape), pivots.reshape(*m.shape[:-2], n_cols)


def _pinv(a: np.ndarray, rtol: float) -> np.ndarray:
    """Pseudo-inverse ``(..., r, c) -> (..., c, r)`` dropping the singular values at or below :func:`rank_cutoff`."""
    if a.shape[-1] == 0 or a.shape[-2] == 0:
        return np.zeros((*a.shape[:-2], a.shape[-1], a.shape[-2]))
    u, s, vt = np.linalg.svd(a, full_matrices=False)
    keep = s > rank_cutoff(s, rtol)
    inverse = np.divide(1.0, s, out=np.zeros_like(s), where=keep)
    return np.swapaxes(vt, -1, -2) @ (inverse[..., None] * np.swapaxes(u, -1, -2))


def _min_norm_lstsq(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Minimum-norm least-squares solution of ``a x = b`` for one matrix, ``(r, c), (r, p) -> (c, p)``.

    LAPACK ``dgelsy`` (complete orthogonal factorisation with column pivoting): the same solution as
    ``numpy.linalg.lstsq`` with numpy's default cutoff, and about twice as fast on the small matrices of a robot.
    """
    rows, cols = a.shape
    rcond = np.finfo(float).eps * max(rows, cols)
    rhs = np.zeros((max(rows, cols), b.shape[1]), order="F")
    rhs[:rows] = b
    lwork = _gelsy_lwork(rows, cols, b.shape[1])
    _, x, _, _, info = lapack.dgelsy(a, rhs, np.zeros(cols, dtype=np.int32), rcond, lwork=lwork)
    if info != 0:  # pragma: no cover - LAPACK argument errors are bugs
        raise RuntimeError(f"dgelsy failed with info = {info}")
    return x[:cols]


@functools.cache
def _gelsy_lwork(rows: int, cols: int, nrhs: int) -> int:
    return int(lapack.dgelsy_lwork(rows, cols, nrhs, np.finfo(float).eps)[0])
