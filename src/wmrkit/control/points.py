"""What the position loop controls (§8.2-8.4): the full pose, or the (x, y) of a point for reduced mobility.

A robot with fixed wheels (types 2 and 4) can only take twists in the null space of its fixed wheels' lateral rows
(8.14). With one independent fixed axle that space has dimension 2, so two pose components are controlled: the
(x, y) of a point ``P`` off the fixed axle (the thesis's R origin ahead of the axle, §8.6 and §9.2). The twist that
gives ``P`` a wanted velocity is solved in that space, which is the general solution of the constraint cases
(8.14)-(8.16) (case B: ``omega`` dictated by ``v``), not the unwritten ``f_k`` of (8.17)-(8.20).
Robots without fixed wheels (types 1, 3, 5) control the full pose ``(x, y, theta)``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors, readonly
from ..errors import WmrkitError
from ..kinematics.wheel_ik import wheel_commands
from ..limits import MAX_SIZE
from ..robot import Robot, check_robot
from ..wheels import heading_from_beta

if TYPE_CHECKING:
    from .coupled_point import CoupledSteering

__all__ = ["ControlError", "ControlPoint", "StoppedRun", "control_point", "point_pose", "robot_reach",
           "twist_for_velocity"]


class ControlError(WmrkitError, ValueError):
    """A robot, reference or option the controller cannot use (one line, names the cause)."""


class StoppedRun(ControlError):
    """A closed loop that stopped at time ``t`` [s] (it diverged, or a wheel lifted off): :func:`.track.track`
    names the Table 8.1 jump of the reference before it, if any."""

    def __init__(self, message: str, t: float = math.nan) -> None:
        self.t = t
        super().__init__(message)


def check_delay(delay: int) -> None:
    """A measurement delay is a whole number of samples >= 0."""
    if isinstance(delay, bool) or not isinstance(delay, int | np.integer) or delay < 0:
        raise ControlError(f"delay: expected a number of samples >= 0, got {delay!r}")


@dataclass(frozen=True, eq=False)
class ControlPoint:
    """What is controlled and how twists are formed (eq=False: array fields, read-only).

    ``reduced``: True when only ``(x, y)`` of ``point`` ``(2,)`` [m, robot frame] are controlled. ``basis``
    ``(3, m)``: orthonormal basis of the admissible twists (null space of the fixed wheels' lateral rows (8.14));
    ``m = 3`` without fixed wheels. ``forward`` [rad]: the rolling direction of the fixed wheels in the robot frame
    (0 without fixed wheels), used by the geometric trackers. ``axle_point`` ``(2,)``: the foot of the
    perpendicular from ``point`` to the fixed axle (the origin without fixed wheels). ``skid``: the fixed wheels
    have parallel but distinct axles (skid steering, degenerate in Table 5.1): turning makes them slip, and the
    admissible space is that of the linear part of their rows. ``gain`` ``(3, 2)`` (reduced): the twist that gives
    the point a unit velocity along each robot axis (None with ``coupled``). ``coupled``: a robot without fixed
    wheels whose gears or linkages leave one steering degree of freedom (:mod:`.coupled_point`): reduced, its
    twist solved on the coupled headings' admissible twists; ``forward`` and ``axle_point`` of its virtual axle.
    """

    robot: Robot
    reduced: bool
    point: np.ndarray
    basis: np.ndarray
    forward: float
    axle_point: np.ndarray
    skid: bool = False
    gain: np.ndarray | None = None  # (3, 2): twist = gain @ (point velocity in R), reduced only
    coupled: CoupledSteering | None = None  # one steering degree of freedom left by couplings, no fixed wheel

    @property
    def n_controlled(self) -> int:
        """Number of pose references: 2 (reduced) or 3 (full), the maneuverability of ch. 8."""
        return 2 if self.reduced else 3


def fixed_lateral_rows(robot: Robot) -> np.ndarray:
    """The fixed wheels' lateral rows (8.14), ``(n_fixed, 3)``: lateral slip = rows @ twist_robot."""
    c = wheel_commands(robot, np.eye(3))
    fixed = [i for i, w in enumerate(robot.wheels) if w.type == "fixed"]
    return np.asarray(c.slip[:, fixed]).T.copy()


@functools.lru_cache(maxsize=128)
def _cached(robot: Robot, point: tuple[float, float] | None, reduced: bool | None) -> ControlPoint:
    rows = fixed_lateral_rows(robot)
    skid = False
    if len(rows) and np.linalg.matrix_rank(rows, tol=1e-9) > 1 and np.linalg.matrix_rank(rows[:, :2], tol=1e-9) == 1:
        rows, skid = np.column_stack([rows[:, :2], np.zeros(len(rows))]), True  # skid steering: turning slips
    _, s, vt = np.linalg.svd(rows if len(rows) else np.zeros((1, 3)))
    scale = max(1.0, float(np.max(np.abs(rows))) if len(rows) else 1.0)
    rank = int(np.sum(s > 1e-9 * scale)) if len(rows) else 0
    basis = vt[rank:].T  # (3, 3 - rank)
    if rank == 0 and reduced is not False:
        from .coupled_point import coupled_steering

        coupled = coupled_steering(robot, None if point is None else np.asarray(point, dtype=float))
        if coupled is not None:
            return ControlPoint(robot, True, coupled.point, readonly(np.ascontiguousarray(basis)), coupled.forward,
                                coupled.axle_point, coupled=coupled)
    fixed = [w for w in robot.wheels if w.type == "fixed"]
    forward = float(heading_from_beta(fixed[0].beta)) if fixed else 0.0
    if math.cos(forward) < -1e-9 or (abs(math.cos(forward)) <= 1e-9 and math.sin(forward) < 0):
        forward = float(np.angle(np.exp(1j * (forward + math.pi))))  # ahead = towards +x (thesis robots: +y)
    is_reduced = rank > 0 if reduced is None else reduced
    if is_reduced and rank != 1:
        what = "no fixed wheels" if rank == 0 else f"fixed wheels whose axles leave {3 - rank} degree(s) of mobility"
        raise ControlError(f"robot '{robot.name}' has {what}: reduced (x, y) references need exactly one fixed axle "
                           "(types 2 and 4)")
    if not is_reduced and rank:
        raise ControlError(f"robot '{robot.name}' has fixed wheels: only (x, y) of a point can be controlled "
                           "(reduced references, types 2 and 4)")
    if point is None:
        p = np.zeros(2)
        if is_reduced and abs(_gain_det(basis, p)) < 1e-9:
            # at the robot's scale, not a fixed length (a 0.1 m floor put a 0.5 mm robot's point 200 of its sizes ahead)
            p = robot_reach(robot) * np.array([math.cos(forward), math.sin(forward)])
    else:
        p = np.asarray(point, dtype=float)
    if is_reduced and abs(_gain_det(basis, p)) < 1e-9:
        raise ControlError(f"control point ({p[0]:g}, {p[1]:g}) m of robot '{robot.name}' lies on its fixed axle: "
                           "its velocity cannot be assigned (choose a point ahead of the axle)")
    foot = np.zeros(2)
    if rank:  # a rotation about q is admissible iff (c, s, k) . (q_y, -q_x, 1) = 0: the axle line n . q = -k
        c, s_, k = vt[0] / np.linalg.norm(vt[0, :2])
        normal = np.array([-s_, c])
        foot = p - normal * (normal @ p + k)
    gain = basis @ np.linalg.inv(_point_map(p) @ basis) if is_reduced else None
    return ControlPoint(robot, is_reduced, readonly(p.copy()), readonly(np.ascontiguousarray(basis)), forward,
                        readonly(foot), skid, None if gain is None else readonly(gain))


def robot_reach(robot: Robot) -> float:
    """The robot's size [m]: its largest wheel distance from the origin (its largest wheel radius when every wheel is
    at the origin)."""
    return max(w.l for w in robot.wheels) or max(w.r for w in robot.wheels)


def _gain_det(basis: np.ndarray, p: np.ndarray) -> float:
    m = _point_map(p) @ basis
    return float(np.linalg.det(m)) if m.shape == (2, 2) else 1.0


def _point_map(p: np.ndarray) -> np.ndarray:
    """``(2, 3)``: velocity of the body point `p` in the robot frame from a twist (rigid body)."""
    return np.array([[1.0, 0.0, -p[1]], [0.0, 1.0, p[0]]])


def control_point(robot: Robot, point: ArrayLike | None = None, *, reduced: bool | None = None) -> ControlPoint:
    """What the loop controls for `robot` (§8.2): full pose, or ``(x, y)`` of `point` [m, robot frame].

    `reduced`: None picks it from the robot (fixed wheels, or steering couplings that leave one steering degree of
    freedom without them, :mod:`.coupled_point` -> reduced; False keeps the full pose of the latter). Default point:
    the robot origin, or when the origin lies on the fixed axle, a point ahead of it at the robot's largest wheel
    distance (its largest wheel radius when every wheel is at the origin); a coupled robot's, that distance ahead of
    its virtual axle.
    """
    check_robot(robot)  # before the cache: a dict is no key
    key = None if point is None else tuple(float(v) for v in as_vectors(point, 2, "point"))
    if key is not None and not all(abs(v) <= MAX_SIZE for v in key):  # NaN included
        raise ControlError(f"point: expected finite coordinates within {MAX_SIZE:g} m of the robot origin, got {key}")
    return _cached(robot, key, reduced)


def point_pose(cp: ControlPoint, pose_world_robot: ArrayLike) -> np.ndarray:
    """World pose of the controlled point ``(x_P, y_P, theta)``. ``(..., 3) -> (..., 3)``."""
    pose = as_vectors(pose_world_robot, 3, "pose_world_robot")
    c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
    px, py = cp.point
    return np.stack([pose[..., 0] + c * px - s * py, pose[..., 1] + s * px + c * py, pose[..., 2]], axis=-1)


def twist_for_velocity(cp: ControlPoint, pose_world_robot: ArrayLike, velocity_world: ArrayLike) -> np.ndarray:
    """Body twist realising a wanted world velocity of the controlled coordinates. ``(3,), (n,) -> (3,)``.

    Full: ``velocity_world`` = ``(x_dot, y_dot, omega)`` of R, rotated into R (3.15). Reduced: ``(x_dot, y_dot)``
    of the point (``n = 2``, or 3 with the last ignored), solved in the admissible twist space (8.14)-(8.16).
    """
    th = float(pose_world_robot[2])
    v0, v1 = float(velocity_world[0]), float(velocity_world[1])
    c, s = math.cos(th), math.sin(th)
    vr0, vr1 = c * v0 + s * v1, -s * v0 + c * v1
    if not cp.reduced:
        return np.array([vr0, vr1, float(velocity_world[2])])
    if cp.coupled is not None:
        return cp.coupled.twist(np.array([vr0, vr1]))
    return cp.gain[:, 0] * vr0 + cp.gain[:, 1] * vr1
