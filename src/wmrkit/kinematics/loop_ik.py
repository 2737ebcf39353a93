"""The inverse kinematics of one twist for a loop calling it thousands of times (the continuous control loop):
:func:`~wmrkit.kinematics.wheel_ik.wheel_commands`' numbers without its other outputs and argument checks, in
arrays (:func:`checked_rates`) or plain floats (:func:`checked_steering_config`, :func:`checked_castor_rates`)."""

from __future__ import annotations

import numpy as np

from ..limits import MAX_QUERY_RATE
from ..robot import Robot
from ..units import MAX_ANGLE
from . import _ik_fast, gear_check
from .linkage_check import _plan as linkage_plan
from .wheel_ik import SLIP_TOL, SPEED_TOL, _rates, wheel_commands


def checked_rates(robot: Robot, twist: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`wheel_commands`' ``rates``, ``beta`` and ``spin`` for one twist ``(3,)`` at steering `beta`
    ``(n_steer,)`` (float arrays), the same numbers without its other outputs (slip, headings, ranges, gears) and
    the checks of its arguments' types and shapes: for a loop calling it thousands of times (the continuous
    control loop). A twist or an angle that :func:`wheel_commands` refuses is refused by it (same error)."""
    if not _queryable(twist, beta):
        c = wheel_commands(robot, twist, beta)  # raises; kept should its bounds ever differ
        return c.rates, c.beta, c.spin
    rates, config, _, spin = _rates(robot, _ik_fast.plan(robot), twist, beta, (), SPEED_TOL, SLIP_TOL)
    return rates, config, spin


def checked_steering_config(robot: Robot, twist: np.ndarray, beta: np.ndarray) -> list[float]:
    """:func:`checked_rates`' steering configuration alone (thesis angles, ``(n_steer,)``), in plain floats
    (:func:`_ik_fast.steering_one`): the same numbers, refusing what it refuses."""
    if not _queryable(twist, beta):
        return checked_rates(robot, twist, beta)[1].tolist()  # raises
    vx, vy, w = twist.tolist()
    gears = gear_check.steer_gears(robot)
    links = linkage_plan(robot) if any(c.kind == "linkage" for c in robot.couplings) or gears.table.coupling else None
    return _ik_fast.steering_one(_ik_fast.plan(robot), vx, vy, w, beta.tolist(), SPEED_TOL, SLIP_TOL, links, gears)


def checked_castor_rates(robot: Robot, twist: np.ndarray, beta: np.ndarray, elements: list[int]) -> list[float]:
    """:func:`checked_rates`' steering rates (8.24) of the castor-like `elements` (indices into the IK plan's
    elements) in plain floats (:func:`_ik_fast.castor_rates_one`): the same numbers, refusing what it refuses."""
    if not _queryable(twist, beta):
        checked_rates(robot, twist, beta)  # raises
    vx, vy, w = twist.tolist()
    return _ik_fast.castor_rates_one(_ik_fast.plan(robot), vx, vy, w, beta.tolist(), elements)


def _queryable(twist: np.ndarray, beta: np.ndarray) -> bool:
    """Whether :func:`wheel_commands` takes `twist` and steering `beta` (finite, within its bounds)."""
    return bool((np.abs(twist) <= MAX_QUERY_RATE).all() and (np.abs(beta) <= MAX_ANGLE).all())  # NaN included
