"""One control tick in a single call (issue item 4): position law (8.2)/(8.53), admissible twist, per-wheel IK.

For a controller that runs once per sample: scalars in, caller-owned arrays out, nothing allocated per call. The
law and the point-velocity map are a few scalar operations in Python; the per-wheel IK is the robot's compiled
kernel of :func:`wmrkit.kinematics.realtime.realtime`. The numbers are those of :func:`.loop.law_controller` followed
by :func:`~wmrkit.kinematics.wheel_ik.wheel_commands` (tested).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..robot import Robot
from .laws import PositionLaw
from .points import ControlError, control_point

__all__ = ["ControlTick", "control_tick"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, eq=False)
class ControlTick:
    """A compiled control tick for one robot and law (build with :func:`control_tick`; eq=False: array fields).

    ``tick(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, heading, twist_out, rates_out,
    heading_out) -> bool``: pose and reference (world frame, the reference's velocity in G), current headings
    ``(n_steer,)``; writes the body twist ``(3,)``, the joint rates ``(n_rates,)`` (``robot.rate_names``) and the new
    headings ``(n_steer,)``; returns whether the twist is feasible. Reduced robots ignore ``theta_ref`` and
    ``omega_ref`` (their heading is the zero dynamics). One compiled call: the law, the point-velocity map and the
    robot's per-wheel IK kernel.
    """

    robot: Robot
    reduced: bool
    point: tuple[float, float]
    gain_matrix: tuple[float, ...]  # row-major (3, 2) of ControlPoint.gain, reduced only
    a: tuple[float, float, float]
    gate: float
    tick: Any


def control_tick(robot: Robot, law: PositionLaw | None = None, point: ArrayLike | None = None) -> ControlTick:
    """Compile the single-call tick of `robot` for `law` (``"p"``, gated or not; default P with a = 1 s^-1)."""
    from ..kinematics.realtime import realtime

    law = law or PositionLaw.uniform("p", 1.0)
    if law.kind != "p":
        raise ControlError(f"control_tick: only the P + feedforward law (8.2)/(8.53), got '{law.kind}'")
    cp = control_point(robot, point)
    gain = tuple(float(v) for v in np.asarray(cp.gain).ravel()) if cp.reduced else (0.0,) * 6
    px, py = float(cp.point[0]), float(cp.point[1])
    gate = math.inf if law.gate is None else float(law.gate)
    kernel = _tick_kernel(realtime(robot).ik, bool(cp.reduced), px, py, gain, tuple(float(v) for v in law.a), gate)
    return ControlTick(robot, cp.reduced, (px, py), gain if cp.reduced else (), law.a, gate, kernel)


def _tick_kernel(ik, reduced: bool, px: float, py: float, g: tuple[float, ...], a: tuple[float, float, float],
                 gate: float):
    """The tick of law (8.2)/(8.53) at the point ``(px, py)`` compiled around the robot's IK kernel `ik`."""
    import numba

    g0, g1, g2, g3, g4, g5 = g
    ax, ay, at = a
    gate2 = gate * gate

    @numba.njit(cache=False)
    def tick(x, y, theta, x_ref, y_ref, theta_ref, vx_ref, vy_ref, omega_ref, heading, twist_out, rates_out,
             heading_out):
        c, s = math.cos(theta), math.sin(theta)
        ex = x_ref - (x + c * px - s * py)
        ey = y_ref - (y + s * px + c * py)
        ff = 1.0 if ex * ex + ey * ey <= gate2 else 0.0
        gx, gy = ff * vx_ref + ax * ex, ff * vy_ref + ay * ey
        rx, ry = c * gx + s * gy, -s * gx + c * gy  # (3.15) inverse: the point's velocity in R
        if reduced:
            vx, vy, w = g0 * rx + g1 * ry, g2 * rx + g3 * ry, g4 * rx + g5 * ry
        else:
            et = theta_ref - theta
            et = et - TWO_PI * math.floor((et + math.pi) / TWO_PI)
            vx, vy, w = rx, ry, ff * omega_ref + at * et
        twist_out[0], twist_out[1], twist_out[2] = vx, vy, w
        return ik(vx, vy, w, heading, rates_out, heading_out)

    return tick
