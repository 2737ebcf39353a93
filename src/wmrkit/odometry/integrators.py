"""Pose integration on SE(2): one step and whole trajectories, four schemes (papers 002 and 003; thesis (3.15)).

Every scheme advances a world pose ``(x, y, theta)`` by a *body increment* ``(dx, dy, dtheta)``: the twist of the
robot frame (thesis (3.15): ``^G p_dot = Rot_Z(theta) ^R p_dot``) integrated over one sample interval, which is what
wheel encoders measure. The schemes differ only in the heading along which the body displacement is rotated and
in a chord factor:

============  ========================  ==============  =======================================================
method        heading used              chord factor    source, order
============  ========================  ==============  =======================================================
``euler``     ``theta_k``               1               forward Euler; 003 (20) (translate, then rotate); 1st
``paper002``  ``theta_k + dtheta``      1               002 eq. (15) (new heading); 1st
``rk2``       ``theta_k + dtheta / 2``  1               midpoint / Runge-Kutta 2; 003 (26); 2nd
``exact``     ``theta_k + dtheta / 2``  sinc(dtheta/2)  constant twist, SE(2) exponential; 003 (21)-(25),
                                                        002 (11)-(12) corrected; exact for arcs and lines
============  ========================  ==============  =======================================================

The exact step is the chord form of the SE(2) exponential: ``Rot(h) sinc(h) = V(2h)`` with ``h = dtheta / 2``,
where ``V`` is the left Jacobian of SO(2); it has no ``1 - cos`` cancellation, so the straight-line limit
``dtheta -> 0`` loses no precision (papers-odometry.md A.3 [DERIVED]).

Every scheme has one implementation, a compiled kernel (:func:`._kernels.compose`, numba, loaded on first
use): :func:`step` is a trajectory of one increment, :func:`integrate_increments` one of N, and the pipeline's
fused pass (:func:`._kernels.odometry_chunk`) runs the same block steps.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_reals, as_vectors
from ..errors import ShapeError, WmrkitError

Method = Literal["exact", "rk2", "euler", "paper002"]
#: Integration schemes, best first.
METHODS: tuple[str, ...] = ("exact", "rk2", "euler", "paper002")
#: Fraction of the step's heading change at which the displacement is rotated, per method.
HEADING_FRACTION = {"exact": 0.5, "rk2": 0.5, "euler": 0.0, "paper002": 1.0}
#: Below this |h| the chord factor uses its series (error < h^6 / 5040 < 1e-25).
_SMALL = 1e-4


def check_method(method: str) -> str:
    """`method` if it is one of :data:`METHODS`, else :class:`WmrkitError` listing them."""
    if not isinstance(method, str) or method not in HEADING_FRACTION:  # a list raised "unhashable type"
        raise WmrkitError(f"unknown integration method '{method}' (methods: {', '.join(METHODS)})")
    return method


def sinc(h: ArrayLike) -> np.ndarray:
    """``sin(h) / h`` with the value 1 at 0, safe pattern (no division by zero on the branch not taken).

    ``(...) -> (...)``; chord factor of 003 eqs. (22)-(24): a chord is ``2 R sin(h) = arc * sinc(h)``, ``h = dtheta/2``.
    """
    h = np.asarray(h, dtype=float)
    small = np.abs(h) < _SMALL
    safe = np.where(small, 1.0, h)
    return np.where(small, 1.0 - h * h / 6.0, np.sin(safe) / safe)


def sinc_derivative(h: ArrayLike) -> np.ndarray:
    """``d/dh sinc(h) = (h cos h - sin h) / h^2``. ``(...) -> (...)``.

    For ``|h| < 1`` the closed form cancels, so its Taylor series ``h sum_k (-1)^k 2k h^(2k-2) / (2k+1)!`` (ten
    terms, error below 1e-16 relative) is used. Needed by the Jacobians of the exact step (003 eqs. (22)-(25)).
    """
    h = np.asarray(h, dtype=float)
    small = np.abs(h) < 1.0
    safe = np.where(small, 1.0, h)
    h2 = h * h
    series = np.zeros_like(h)
    for c in _SINC_D_COEFFS[::-1]:  # Horner in h^2
        series = series * h2 + c
    return np.where(small, h * series, (safe * np.cos(safe) - np.sin(safe)) / (safe * safe))


_SINC_D_COEFFS = tuple((-1) ** k * 2 * k / math.factorial(2 * k + 1) for k in range(1, 11))


def step(pose_world_robot: ArrayLike, increment_robot: ArrayLike, method: Method = "exact") -> np.ndarray:
    """One pose update by a body increment, papers 002 (15) / 003 (20), (25), (26); thesis (3.15).

    ``(..., 3), (..., 3) -> (..., 3)``. `pose_world_robot` is ``(x [m], y [m], theta [rad])`` in the world frame;
    `increment_robot` is ``(dx [m], dy [m], dtheta [rad])``, the body twist times the time step. `method` is one
    of :data:`METHODS` (module docstring).
    """
    check_method(method)
    pose = _finite(as_vectors(pose_world_robot, 3, "pose_world_robot"), "pose_world_robot")
    inc = _finite(as_vectors(increment_robot, 3, "increment_robot"), "increment_robot")
    check_batches(pose, "pose_world_robot", inc, "increment_robot")
    return compose_columns(pose, inc[..., 0, None], inc[..., 1, None], inc[..., 2, None], method)[..., 0, :]


def _finite(values: np.ndarray, name: str) -> np.ndarray:
    """`values`, or :class:`ShapeError` naming `name` when any is NaN or infinite (it went through as NaN poses)."""
    if not np.isfinite(values).all():
        raise ShapeError(f"{name}: expected finite numbers, got {values[~np.isfinite(values)].flat[0]}")
    return values


def check_batches(a: np.ndarray, a_name: str, b: np.ndarray, b_name: str) -> None:
    """Refuse arrays ``(..., 3)`` whose batch shapes (all but the last axis) do not broadcast, naming both (numpy's
    'shape mismatch' named neither)."""
    try:
        np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
    except ValueError:
        raise ShapeError(f"{a_name} {a.shape} and {b_name} {b.shape}: their batch shapes (all but the last axis) do "
                         "not broadcast") from None


def _twist_step(pose_world_robot: ArrayLike, twist_robot: ArrayLike, dt: ArrayLike, method: Method) -> np.ndarray:
    twist = _finite(as_vectors(twist_robot, 3, "twist_robot"), "twist_robot")
    dt = _finite(as_reals(dt, "dt"), "dt")[..., None]  # text ('0.1') was read as a number
    check_batches(twist, "twist_robot", dt, "dt")
    return step(pose_world_robot, twist * dt, method)


def integrate_exact(pose_world_robot: ArrayLike, twist_robot: ArrayLike, dt: ArrayLike) -> np.ndarray:
    """Exact SE(2) step for a body twist held constant over `dt` (003 eqs. 21-25; 002 eqs. 11-12 corrected).

    ``(..., 3), (..., 3), (...) -> (..., 3)``; poses ``(x [m], y [m], theta [rad])`` in the world frame, twist
    ``(vx [m/s], vy [m/s], omega [rad/s])`` in the robot frame, `dt` [s]. Not the same as Euler: the heading turns
    during the step.

    Examples
    --------
    >>> x, y, theta = integrate_exact([0, 0, 0], [0.1, 0, 0.04], 1.0)   # papers-odometry.md A.6 oracle
    >>> print(f"{x:.10f} {y:.10f} {theta:.2f}")
    0.0999733355 0.0019997333 0.04
    """
    return _twist_step(pose_world_robot, twist_robot, dt, "exact")


def integrate_rk2(pose_world_robot: ArrayLike, twist_robot: ArrayLike, dt: ArrayLike) -> np.ndarray:
    """Midpoint (Runge-Kutta 2) step, 003 eq. (26): heading ``theta + omega dt / 2``. Same shapes as exact."""
    return _twist_step(pose_world_robot, twist_robot, dt, "rk2")


def integrate_euler(pose_world_robot: ArrayLike, twist_robot: ArrayLike, dt: ArrayLike) -> np.ndarray:
    """Forward Euler step, 003 eq. (20): translate along the old heading, then rotate. Same shapes as exact."""
    return _twist_step(pose_world_robot, twist_robot, dt, "euler")


def integrate_paper002(pose_world_robot: ArrayLike, twist_robot: ArrayLike, dt: ArrayLike) -> np.ndarray:
    """Step of 002 eq. (15): translate along the *new* heading ``theta + omega dt``. Same shapes as exact."""
    return _twist_step(pose_world_robot, twist_robot, dt, "paper002")


def integrate_increments(
    pose_world_robot: ArrayLike,
    increments_robot: ArrayLike,
    method: Method = "exact",
    *,
    heading_world: ArrayLike | None = None,
) -> np.ndarray:
    """Compose a sequence of body increments into poses, vectorised (002 (15)/(22), 003 (20)-(26), thesis (3.15)).

    ``(..., 3), (..., N, 3) -> (..., N, 3)``: the pose after each increment (the start pose is not repeated).
    One compiled pass per row of the batch: the heading is a running sum, the world displacement of each step a
    rotation of its body displacement (times the chord factor for ``exact``), the positions running sums, in
    float64. Equal to applying :func:`step` N times.

    `heading_world` ``(..., N + 1)`` [rad], when given, is an external absolute heading (gyro, IMU, compass) at
    the start and end of every interval: it replaces the wheels' ``dtheta`` and the start pose's theta (the
    heading column of the result equals ``heading_world[..., 1:]``). It must be continuous (unwrapped).
    """
    check_method(method)
    pose0 = as_vectors(pose_world_robot, 3, "pose_world_robot")
    inc = as_reals(increments_robot, "increments_robot")  # the Python API reads no units: text was numpy's error
    if inc.ndim < 2 or inc.shape[-1] != 3:
        raise WmrkitError(f"increments_robot: expected shape (..., N, 3), got {inc.shape}")
    _finite(pose0, "pose_world_robot"), _finite(inc, "increments_robot")
    if heading_world is not None:
        _finite(as_reals(heading_world, "heading_world"), "heading_world")
    return compose_columns(pose0, inc[..., 0], inc[..., 1], inc[..., 2], method, heading_world=heading_world)


def compose_columns(pose_world_robot: ArrayLike, dx_robot: np.ndarray, dy_robot: np.ndarray | None,
                    dtheta: np.ndarray, method: Method = "exact", *,
                    heading_world: ArrayLike | None = None, out: np.ndarray | None = None) -> np.ndarray:
    """:func:`integrate_increments` on separate columns (the streaming hot path; 003 (20)-(26), 002 (15)).

    ``(..., 3), (..., N), (..., N) or None, (..., N) -> (..., N, 3)``; ``dy_robot=None`` means all zero (a
    differential drive). Same `heading_world` rule and kernel. `out` ``(..., N, 3)``, when given, receives the
    result.
    """
    from . import _kernels  # numba loads on first use

    pose = np.asarray(pose_world_robot, dtype=float)
    n = np.shape(dtheta)[-1]
    hw = None
    if heading_world is not None:
        hw = np.asarray(heading_world, dtype=float)
        if hw.shape[-1:] != (n + 1,):
            raise WmrkitError(f"heading_world: expected shape (..., {n + 1}) (one more than the increments), "
                              f"got {hw.shape}")
    shapes = [np.shape(a)[:-1] for a in (dx_robot, dy_robot, dtheta, hw) if a is not None]
    batch = np.broadcast_shapes(pose.shape[:-1], *shapes)
    rows = math.prod(batch)

    def matrix(a: ArrayLike | None, width: int) -> np.ndarray:  # (rows, width); a view unless broadcast
        if a is None:
            return np.empty((rows, 0))
        return np.broadcast_to(np.asarray(a, dtype=float), (*batch, width)).reshape(rows, width)

    result = np.empty((*batch, n, 3)) if out is None else out
    flat = result.reshape(rows, n, 3)  # a view of `out` when it is contiguous, else a copy written back
    dx = matrix(dx_robot, n)
    _kernels.compose(matrix(pose, 3), dx, matrix(dy_robot, n), dx if hw is not None else matrix(dtheta, n),
                     matrix(hw, n + 1), HEADING_FRACTION[method], method == "exact", flat)
    if not np.may_share_memory(flat, result):
        result[...] = flat.reshape(result.shape)
    return result
