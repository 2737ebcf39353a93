"""Steering angles at the log doors: files speak headings, :class:`~.logs.JointLog` holds the thesis's β.

A steering joint in a log file (a CSV ``WHEEL.steer`` column in radians, degrees or absolute encoder counts, the
position of a ROS 2 ``JointState`` steering joint) is the wheel's **heading**: its rolling direction, 0 when it
rolls straight ahead along +x, counter-clockwise positive (ros2_control's steering controllers, swerve modules,
WPILib; ``docs/conventions.md``). The odometry model reads the thesis's β (straight ahead = 90 deg for δ = 0), the
convention of the equations, so every reader converts once, here, with the robot's own conversion
(:meth:`wmrkit.robot.Robot.beta_of_heading`, i.e. :func:`wmrkit.wheels.beta_from_heading` with each wheel's δ),
and every writer converts back. Files written in β by older wmrkit versions say so in their header
(``steer.steer [deg:beta]``, :mod:`.header`) and are read as they are.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np

from ..errors import WmrkitError
from ..robot import Robot

#: Conventions of a log's steering columns: the users' heading (default) or the thesis's β (legacy files).
CONVENTIONS = ("heading", "beta")


class SteeringError(WmrkitError, ValueError):
    """Steering columns that cannot be converted (no robot given, a column for a wheel that does not steer)."""


def steer_columns(joints: Sequence[str]) -> list[int]:
    """Positions of the steering joints (``WHEEL.steer``) in `joints`."""
    return [k for k, j in enumerate(joints) if j.endswith(".steer")]


def check_robot(joints: Sequence[str], robot: Robot | None, source: str) -> None:
    """Refuse heading columns without the robot whose wheels' δ convert them (:class:`SteeringError`)."""
    cols = steer_columns(joints)
    if cols and robot is None:
        raise SteeringError(f"{source}: steering joints ({', '.join(joints[k] for k in cols)}) are headings "
                            "(0 = rolling straight ahead); converting them needs the robot: pass robot=")


#: How far a logged heading may pass its wheel's ``steer_range`` [rad] (encoder offset, overshoot at the stops).
RANGE_MARGIN = np.radians(3.0)


def check_steer_range(robot: Robot | None, joints: Sequence[str], headings: np.ndarray,
                      where: Callable[[int], str]) -> None:
    """Refuse a logged heading [rad] beyond its wheel's described ``steer_range`` by more than
    :data:`RANGE_MARGIN` (:class:`SteeringError` located by ``where(row)``): inconsistent data, often degrees read
    as radians (said so when the value is past half a turn and, in degrees, within the range). `headings`
    ``(N, len(joints))``; wheels without a ``steer_range`` are not checked (a multi-turn swerve module may count
    past a turn)."""
    if robot is None:
        return
    for k in steer_columns(joints):
        wheel = joints[k].rpartition(".")[0]
        rng = robot.wheel(wheel).steer_range if wheel in robot.steer_names else None  # else: convert_steering's
        if rng is None:
            continue
        col = headings[:, k]
        bad = np.flatnonzero((col < rng[0] - RANGE_MARGIN) | (col > rng[1] + RANGE_MARGIN))
        if bad.size:
            i, value = int(bad[0]), float(col[bad[0]])
            hint = ("; degrees read as radians? (CSV logs: --steer degrees)"
                    if abs(value) > np.pi and rng[0] <= np.radians(value) <= rng[1] else "")
            raise SteeringError(f"{where(i)}: {joints[k]}: heading {value:.6g} rad ({np.degrees(value):.6g} deg) "
                                f"outside the wheel's steer_range [{np.degrees(rng[0]):.6g}, "
                                f"{np.degrees(rng[1]):.6g}] deg{hint}")


def convert_steering(robot: Robot | None, joints: Sequence[str], positions: np.ndarray, *,
                     to: Literal["beta", "heading"], source: str = "<log>") -> np.ndarray:
    """`positions` ``(N, len(joints))`` with the steering columns converted: headings to β (``to="beta"``, the
    readers) or β to headings (``to="heading"``, the writers: in (-pi, pi] at the first sample, then continuous
    over the samples, as a continuous ROS joint counts past 180 deg). Other columns and a log without steering
    joints are returned as they are. The one conversion of the log doors."""
    cols = steer_columns(joints)
    if not cols:
        return positions
    check_robot(joints, robot, source)
    names = robot.steer_names
    try:
        idx = [names.index(joints[k].rpartition(".")[0]) for k in cols]
    except ValueError:
        bad = next(joints[k] for k in cols if joints[k].rpartition(".")[0] not in names)
        raise SteeringError(f"{source}: joint '{bad}': robot '{robot.name}' has no steering wheel of that name "
                            f"(steering wheels: {', '.join(names) or 'none'})") from None
    p = np.asarray(positions, dtype=float)
    full = np.empty((len(p), len(names)))
    full[:] = robot.heading if to == "beta" else robot.beta  # wheels the log lacks: as described (unused)
    full[:, idx] = p[:, cols]
    converted = robot.beta_of_heading(full) if to == "beta" else robot.heading_of_beta(full)
    out = p.copy()
    out[:, cols] = converted[:, idx] if to == "beta" else np.unwrap(converted[:, idx], axis=0)
    return out
