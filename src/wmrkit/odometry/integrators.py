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
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors
from ..errors import WmrkitError

Method = Literal["exact", "rk2", "euler", "paper002"]
#: Integration schemes, best first.
METHODS: tuple[str, ...] = ("exact", "rk2", "euler", "paper002")
#: Fraction of the step's heading change at which the displacement is rotated, per method.
HEADING_FRACTION = {"exact": 0.5, "rk2": 0.5, "euler": 0.0, "paper002": 1.0}
#: Below this |h| the chord factor uses its series (error < h^6 / 5040 < 1e-25).
_SMALL = 1e-4


def check_method(method: str) -> str:
    """`method` if it is one of :data:`METHODS`, else :class:`WmrkitError` listing them."""
    if method not in HEADING_FRACTION:
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
    pose = as_vectors(pose_world_robot, 3, "pose_world_robot")
    inc = as_vectors(increment_robot, 3, "increment_robot")
    dth = inc[..., 2]
    head = pose[..., 2] + HEADING_FRACTION[method] * dth
    f = sinc(dth / 2) if method == "exact" else 1.0
    c, s = np.cos(head) * f, np.sin(head) * f
    return np.stack(
        [pose[..., 0] + c * inc[..., 0] - s * inc[..., 1], pose[..., 1] + s * inc[..., 0] + c * inc[..., 1],
         pose[..., 2] + dth], axis=-1)


def _twist_step(pose_world_robot: ArrayLike, twist_robot: ArrayLike, dt: ArrayLike, method: Method) -> np.ndarray:
    twist = as_vectors(twist_robot, 3, "twist_robot")
    return step(pose_world_robot, twist * np.asarray(dt, dtype=float)[..., None], method)


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
    The heading is a cumulative sum, the world displacement of each step a rotation of its body displacement
    (times the chord factor for ``exact``), and the positions a cumulative sum: no Python loop, float64
    accumulation. Equal to applying :func:`step` N times (to round-off).

    `heading_world` ``(..., N + 1)`` [rad], when given, is an external absolute heading (gyro, IMU, compass) at
    the start and end of every interval: it replaces the wheels' ``dtheta`` and the start pose's theta (the
    heading column of the result equals ``heading_world[..., 1:]``). It must be continuous (unwrapped).
    """
    check_method(method)
    pose0 = as_vectors(pose_world_robot, 3, "pose_world_robot")
    inc = np.asarray(increments_robot, dtype=float)
    if inc.ndim < 2 or inc.shape[-1] != 3:
        raise WmrkitError(f"increments_robot: expected shape (..., N, 3), got {inc.shape}")
    dy = inc[..., 1] if np.any(inc[..., 1]) else None
    return compose_columns(pose0, inc[..., 0], dy, inc[..., 2], method, heading_world=heading_world)


#: Samples per block of :func:`compose_columns`: its temporaries stay in the CPU cache.
BLOCK = 4096


def compose_columns(pose_world_robot: np.ndarray, dx_robot: np.ndarray, dy_robot: np.ndarray | None,
                    dtheta: np.ndarray, method: Method = "exact", *,
                    heading_world: ArrayLike | None = None, out: np.ndarray | None = None) -> np.ndarray:
    """:func:`integrate_increments` on separate columns (the streaming hot path; 003 (20)-(26), 002 (15)).

    ``(..., 3), (..., N), (..., N) or None, (..., N) -> (..., N, 3)``; ``dy_robot=None`` means all zero (a
    differential drive), which saves work. Same `heading_world` rule. Works in blocks of :data:`BLOCK` samples
    with preallocated scratch arrays, carrying the pose from block to block; `out` ``(..., N, 3)``, when given,
    receives the result.
    """
    pose = np.asarray(pose_world_robot, dtype=float)
    hw = None
    if heading_world is not None:
        hw = np.asarray(heading_world, dtype=float)
        if hw.shape[-1:] != (dtheta.shape[-1] + 1,):
            raise WmrkitError(f"heading_world: expected shape (..., {dtheta.shape[-1] + 1}) (one more than the "
                              f"increments), got {hw.shape}")
        dtheta = np.diff(hw, axis=-1)
    shape = np.broadcast_shapes((*pose.shape[:-1], 1), dx_robot.shape, dtheta.shape,
                                () if dy_robot is None else dy_robot.shape)
    n = shape[-1]
    out = np.empty((*shape, 3)) if out is None else out
    z0 = pose[..., 0, None] + 1j * pose[..., 1, None]  # positions as complex numbers: one cumulative sum
    th0 = pose[..., 2, None].copy() if hw is None else hw[..., :1]
    frac, exact = HEADING_FRACTION[method], method == "exact"
    b = min(BLOCK, n)
    th, head, c, s, f = (np.empty((*shape[:-1], b)) for _ in range(5))
    zc = np.empty((*shape[:-1], b), dtype=complex)
    for start in range(0, n, BLOCK):
        stop = min(start + BLOCK, n)
        m = stop - start
        th_, head_, c_, s_, f_, z_ = th[..., :m], head[..., :m], c[..., :m], s[..., :m], f[..., :m], zc[..., :m]
        dth = dtheta[..., start:stop]
        if hw is None:
            np.cumsum(np.broadcast_to(dth, th_.shape), axis=-1, out=th_)
            th_ += th0
        else:
            th_[...] = hw[..., start + 1:stop + 1]
        if frac == 0.0:
            np.subtract(th_, dth, out=head_)
        elif frac == 1.0:
            head_[...] = th_
        else:
            np.multiply(dth, 0.5, out=f_)  # h
            np.subtract(th_, f_, out=head_)
        np.cos(head_, out=c_)
        np.sin(head_, out=s_)
        wx = dx_robot[..., start:stop]
        wy = None if dy_robot is None else dy_robot[..., start:stop]
        if exact:
            _chord_factor(f_, head_)
            wx = wx * head_
            wy = None if wy is None else wy * head_
        np.multiply(c_, wx, out=z_.real)
        np.multiply(s_, wx, out=z_.imag)
        if wy is not None:
            z_.real -= s_ * wy
            z_.imag += c_ * wy
        np.cumsum(z_, axis=-1, out=z_)
        z_ += z0
        out[..., start:stop, 0] = z_.real
        out[..., start:stop, 1] = z_.imag
        out[..., start:stop, 2] = th_
        z0, th0 = z_[..., -1:].copy(), th_[..., -1:].copy()
    return out


def _chord_factor(h: np.ndarray, out: np.ndarray) -> None:
    """``sin(h) / h`` into `out`, 1 at 0: the series ``1 - h^2/6 + h^4/120`` when every ``|h| < 0.01`` (next term
    below 2e-16 relative), else sine and division where ``h != 0`` (the safe pattern)."""
    if h.size and np.max(np.abs(h)) < 0.01:
        np.multiply(h, h, out=out)
        h2 = out.copy()
        out *= 1.0 / 120.0
        out -= 1.0 / 6.0
        out *= h2
        out += 1.0
        return
    np.sin(h, out=out)
    np.divide(out, h, out=out, where=h != 0)
    if not np.all(h):
        out[h == 0] = 1.0
