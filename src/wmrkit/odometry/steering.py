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

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from ..errors import WmrkitError
from ..robot import Robot

if TYPE_CHECKING:
    from .logs import JointLog
    from .model import OdometryModel

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
    past a turn). Every wheel's headings are checked against the limit of every heading
    (:func:`wmrkit.wheels.heading_limit`: the conversion refused them later, naming neither log nor row)."""
    from ..wheels import heading_limit

    if robot is None:
        return
    for k in steer_columns(joints):
        wheel = joints[k].rpartition(".")[0]
        if wheel not in robot.steer_names:  # convert_steering's
            continue
        col, limit = headings[:, k], heading_limit(robot.wheel(wheel).delta)
        far = np.flatnonzero(np.abs(col) > limit)
        if far.size:
            raise SteeringError(f"{where(int(far[0]))}: {joints[k]}: heading {float(col[far[0]]):.6g} rad is beyond "
                                f"+-{limit:.10g} rad, where the thesis's beta (heading - delta + 90 deg) of one sign "
                                "reaches the limit of every angle, 1e+06 turns (no angle to steer by)")
        rng = robot.wheel(wheel).steer_range
        if rng is None:
            continue
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


#: The share of a wheel's travel its no-slip rows may miss and still agree with rolling: the slip tolerance of a
#: log (``wmrkit odometry``'s consistency rule, 2 % of the motion per interval), here for one wheel and interval.
STEP_RTOL = 0.02


#: A step is a change in one interval whose larger part its neighbours do not explain: at least twice theirs.
STEP_SHARE = 0.5


@dataclass(frozen=True, slots=True)
class SteeringStep:
    """The largest steering step of one sensed joint (:func:`steering_steps`): `interval` k lies between samples k
    and k + 1; `step` [rad] its wrapped change, `excess` [rad] how much it exceeds the neighbouring intervals'
    changes, `travel` [m] its wheel's travel there, `bound` [m] how far that travel can be off its direction,
    ``2 travel sin(|step| / 4)``; `count`: the joint's intervals found so."""

    joint: str
    interval: int
    step: float
    excess: float
    travel: float
    bound: float
    count: int


def steering_steps(model: OdometryModel, positions: np.ndarray) -> list[SteeringStep]:
    """Sensed steering angles that step within one interval while their wheel rolls, over joint positions ``(N + 1,
    len(model.joints))`` (β) of an :class:`~.model.OdometryModel`: one :class:`SteeringStep` per joint that has one.

    The no-slip rows take each interval's steering at mid-interval, which is second order while the angle changes
    smoothly (docs/odometry.md). A change the samples cannot place, made at any instant of the interval, puts the
    wheel's travel ``s`` there up to ``2 s sin(|step| / 4)`` off its direction (all of it at the angle before the
    step, or after). A smooth steering changes in an interval by about as much as in its neighbours (their
    difference is second order in the sample period; a quantised encoder adds one count, a glitch in one reading
    two opposite changes of one size), so the part of a change that is a step is its `excess` over the neighbours'
    larger change. A joint is reported where that part is at least :data:`STEP_SHARE` of the change (a step, not a
    turn that speeds up) and puts more than :data:`STEP_RTOL` of the interval's travel, and of the wheel's mean
    travel per interval, off its direction.
    The travel is the displacement of the wheel's steering axis by the no-slip body increment (0 when the wheel
    steers at rest)."""
    from .model import wrap_angle

    p = np.asarray(positions, dtype=float)
    if not model.steer_joints or len(p) < 3:  # a step needs a neighbouring interval to compare with
        return []
    inc = model.from_positions(p).increments_robot  # (N, 3)
    found = []
    for joint in model.steer_joints:
        x, y = model.robot.wheel(joint.rpartition(".")[0]).position
        travel = np.hypot(inc[:, 0] - inc[:, 2] * y, inc[:, 1] + inc[:, 2] * x)
        step = wrap_angle(np.diff(p[:, model.joints.index(joint)]))  # as the model wraps it
        size = np.abs(step)
        around = np.maximum(np.append(-np.inf, size[:-1]), np.append(size[1:], -np.inf))
        excess = np.maximum(size - around, 0.0)
        off = 2 * travel * np.sin(excess / 4)
        hit = np.flatnonzero((excess >= STEP_SHARE * size) & (off > STEP_RTOL * travel)
                             & (off > STEP_RTOL * travel.mean()))
        if hit.size:
            bound = 2 * travel * np.sin(size / 4)
            k = int(hit[np.argmax(bound[hit])])
            found.append(SteeringStep(joint, k, float(step[k]), float(excess[k]), float(travel[k]), float(bound[k]),
                                      int(hit.size)))
    return found


def steering_step_warning(model: OdometryModel, log: JointLog) -> str | None:
    """One line naming the largest steering step of `log` (joint positions in β, :func:`steering_steps`), its
    interval's times, its wheel's travel and bound and the other joints that step; None when no joint steps. The
    warning of ``wmrkit odometry`` and ``wmrkit batch odometry`` over a log's first samples (CSV or bag)."""
    steps = sorted(steering_steps(model, log.positions), key=lambda s: -s.bound)
    if not steps:
        return None
    s = steps[0]
    t0, t1 = log.time[s.interval], log.time[s.interval + 1]
    more = f"; {s.count} such steps over the first {len(log)} samples" if s.count > 1 else ""
    others = f" (also {', '.join(o.joint for o in steps[1:])})" if len(steps) > 1 else ""
    return (f"{s.joint} steps {math.degrees(s.step):+.4g} deg within one interval (t = {t0:.6g} to {t1:.6g} s; the "
            f"intervals around it change it by {math.degrees(abs(s.step) - s.excess):.3g} deg at most) while the "
            f"wheel travels {s.travel:.3g} m: up to {s.bound:.3g} m of that travel off its direction{more}{others}; "
            "the odometry assumes the angle changes uniformly within an interval: log faster")
