"""The forklift of thesis §8.6: its closed-form IK (8.46)-(8.51) in the thesis's frame, and its set-ups.

Thesis frame: R at the fork tips, **Y forward, X to the right**; the fixed axle ``e`` behind R, the steered wheel
``l3`` behind; thesis signs (a forward roll is a negative spin) and the thesis's beta (0 = straight ahead for this
wheel, whose axle is along X). wmrkit's catalog ``forklift`` is the same truck in REP-103 (x forward, y left): its
headings are the thesis's ``beta_3`` (straight ahead = 0 in both), its spins the negated thesis spins, and a world
pose maps as ``theta_ours = theta_thesis + pi/2`` with the same world frame. :func:`from_thesis_pose` converts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors
from ..robot import Robot, check_robot
from .actuators import ActuatorLoop, LowLevelLoops

__all__ = ["ForkliftIK", "forklift_ik", "forklift_real_loops", "from_thesis_pose", "with_steer_range"]


@dataclass(frozen=True, eq=False)
class ForkliftIK:
    """(8.47)-(8.51), each ``(...)``: ``omega`` [rad/s], fixed-wheel spins ``phi1``, ``phi2`` and steered-wheel spin
    ``phi3`` [rad/s] (thesis signs), steering ``beta3`` [rad] (thesis angle, 0 straight ahead)."""

    omega: np.ndarray
    phi1: np.ndarray
    phi2: np.ndarray
    beta3: np.ndarray
    phi3: np.ndarray


def forklift_ik(velocity_world: ArrayLike, theta: ArrayLike, *, l12: float = 0.45, l3: float = 2.35, e: float = 1.0,
                r: float = 0.23, quadrants: int = 4) -> ForkliftIK:
    """The thesis's forklift IK, eqs. (8.47)-(8.51), in the thesis frame. ``(..., 2), (...) -> ForkliftIK``.

    `velocity_world` ``(G v_x, G v_y)`` [m/s] of R, `theta` [rad] (thesis). ``quadrants=4``: ``beta3 = atan2``
    and ``phi3 <= 0`` (8.50); ``quadrants=2``: ``beta3`` in (-90, 90] deg and ``phi3`` times ``sign(R v_y)`` (8.51).
    """
    v = as_vectors(velocity_world, 2, "velocity_world")
    th = np.asarray(theta, dtype=float)
    c, s = np.cos(th), np.sin(th)
    rvx = v[..., 0] * c + v[..., 1] * s  # R v_x (8.47)
    rvy = -v[..., 0] * s + v[..., 1] * c
    omega = -rvx / e
    phi1 = -(rvy - (l12 / e) * rvx) / r
    phi2 = -(rvy + (l12 / e) * rvx) / r
    k = (l3 - e) / e
    mag = np.hypot(k * rvx, rvy) / r  # no overflow of the squares for large velocities
    if quadrants == 4:
        beta3, phi3 = np.arctan2(k * rvx, rvy), -mag  # (8.49) in four quadrants, (8.50)
    elif quadrants == 2:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # a quotient beyond 1e308: arctan(+-inf)
            beta3 = np.where(rvy == 0, np.copysign(math.pi / 2, k * rvx), np.arctan(k * rvx / rvy))
        beta3 = np.where(beta3 <= -math.pi / 2, beta3 + math.pi, beta3)
        # (8.51) = -sign(R v_y) * mag; written as the rolling row (8.11) at beta3, which also holds at R v_y = 0
        phi3 = -(-np.sin(beta3) * rvx + np.cos(beta3) * rvy + l3 * np.cos(beta3 + math.pi / 2) * omega) / r
    else:
        raise ValueError(f"quadrants must be 2 or 4, got {quadrants}")
    return ForkliftIK(omega, phi1, phi2, beta3, phi3)


def from_thesis_pose(pose_thesis: ArrayLike) -> np.ndarray:
    """A thesis §8.6 pose (Y forward) as a wmrkit pose of the catalog forklift (x forward). ``(..., 3) -> (..., 3)``."""
    p = np.array(as_vectors(pose_thesis, 3, "pose_thesis"), dtype=float)
    p[..., 2] += math.pi / 2
    return p


def with_steer_range(robot: Robot, wheel: str, lo: float, hi: float) -> Robot:
    """The robot with wheel `wheel`'s steering range set to headings ``[lo, hi]`` [rad] (the forklift: +-90 deg)."""
    check_robot(robot)
    w = robot.wheel(wheel)
    return replace(robot, wheels=tuple(replace(x, steer_range=(float(lo), float(hi))) if x is w else x
                                       for x in robot.wheels))


def forklift_real_loops(steer_settling: float = 1.5, traction_settling: float = 3.5,
                        traction_overshoot: float = 0.15) -> LowLevelLoops:
    """The real forklift's uncoupled loops (§8.6.3): steering first order, 1.5 s; traction (the steered wheel's
    speed, joint ``steer.spin``) second order, 3.5 s, 15 % overshoot."""
    return LowLevelLoops(("steer.steer", "steer.spin"),
                         (ActuatorLoop(steer_settling), ActuatorLoop(traction_settling, traction_overshoot)))
