"""The tightest turns a car-like robot drives within its steering stops, and whether a built-in reference turns
tighter (``wmrkit track`` and ``wmrkit feasibility`` warn: Table 8.1 judges a reference's continuity only, and a
circle of 1 m was 'feasible: yes' for the catalog car, which turns on 3.993 m at least)."""

from __future__ import annotations

import math

from numpy.typing import ArrayLike

from ..errors import WmrkitError
from ..robot import Robot
from .references import TIGHTEST_TURN

__all__ = ["min_turning_radius", "point_turning_radius", "tight_turn"]


def min_turning_radius(robot: Robot) -> float:
    """The radius [m] of the tightest circle the rear axle's midpoint of a car-like `robot` drives within its
    steering wheels' ``steer_range`` (:func:`wmrkit.parking.problem.curvature_limit`); 0 for any other robot, or
    one whose ranges do not limit it."""
    from ..parking.problem import curvature_limit

    try:
        return 1.0 / curvature_limit(robot)
    except (WmrkitError, ZeroDivisionError):  # not car-like; or it cannot roll straight ahead
        return 0.0


def point_turning_radius(robot: Robot, point: ArrayLike) -> float:
    """The radius [m] of the tightest circle `point` ``(x, y)`` [m, robot frame] of a car-like `robot` drives
    within its steering stops (0 as :func:`min_turning_radius`): on a circle every point turns about the ICR, on the
    rear axle's line (the car drives along x) at least :func:`min_turning_radius` from the axle's midpoint, so a
    point ``d`` ahead of that midpoint turns on ``hypot(d, R)`` at least (the catalog car's tracked point, 2.809 m
    ahead: 4.882 m)."""
    turning = min_turning_radius(robot)
    if turning <= 0:
        return 0.0
    rear = [w for w in robot.wheels if w.type == "fixed"]
    mx = sum(w.l * math.cos(w.alpha) for w in rear) / len(rear)
    my = sum(w.l * math.sin(w.alpha) for w in rear) / len(rear)
    px, py = (float(c) for c in point)  # type: ignore[union-attr]
    return min(math.hypot(px - mx, py - my - side * turning) for side in (1.0, -1.0))


def tight_turn(robot: Robot, name: str, size: float | None, point: ArrayLike, whose: str) -> str | None:
    """The words of a warning when built-in reference `name` of `size` [m] turns tighter than `point` (`whose`:
    what it is, e.g. 'the tracked point') of `robot` can (:func:`point_turning_radius`), else None (a robot whose
    steering does not limit its turns, a file, a shape of straight legs: :data:`.references.TIGHTEST_TURN`)."""
    if size is None or name not in TIGHTEST_TURN:
        return None
    tightest, radius = TIGHTEST_TURN[name] * size, point_turning_radius(robot, point)
    if not tightest < radius:
        return None
    turning = min_turning_radius(robot)
    limit = (f"the robot's minimum turning radius is {turning:.4g} m (of its rear axle's midpoint, at its steering "
             "stops)")
    if radius > turning * (1 + 1e-9):
        limit = f"{whose} turns on {radius:.4g} m at least; {limit}"
    return f"the reference turns on {tightest:.4g} m at its tightest, tighter than the robot can drive: {limit}"
