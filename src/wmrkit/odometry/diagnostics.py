"""The diagnostics of an odometry run over a log: the warning lines ``wmrkit odometry`` prints and ``wmrkit batch
odometry`` puts in each log's row, composed once, here.

After the run, its summary and the log's first samples (:func:`~.files.first_samples`, CSV or bag, read only when a
check needs them) are judged: the sensed joints contradicting each other (slip, naming each wheel's slip), an
external heading column contradicting the wheels' turns (CSV logs), joints breaking a description's ``gear``
coupling, and a steering angle stepping within one sample interval (:func:`~.steering.steering_step_warning`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..couplings import gear_breaches
from .logs import JointLog, LogFormat
from .model import OdometryModel, wheel_slip
from .pipeline import OdometrySummary
from .steering import steering_step_warning

#: Slip tolerance of a log: an RMS slip indicator above this fraction of the mean motion per interval means the
#: sensed joints contradict each other (the same rule as ``wmrkit fk``, FK_SLIP_RTOL).
LOG_SLIP_RTOL = 0.02
#: An external heading (heading or gyro column) contradicts the wheels when its turns over the first samples differ
#: from theirs by more than this fraction of the larger, interval by interval. Turns k times apart (same sign) are
#: 1 - 1/k apart: a gyro in deg/s read as rad/s is 0.98 apart, a clockwise (NED) yaw 1 or more; a skid steer, whose
#: wheels turn up to 2-3 times the robot (ROS's wheel_separation_multiplier 1.5-2), is 0.67 apart at the most.
HEADING_RTOL = 0.8
#: Least turning [rad] of the wheels or the external heading over the first samples for that comparison.
HEADING_MIN_TURN = 0.1
#: Least turning [rad] of a gear's u over the first samples for its check (couplings.gear_breaches).
GEAR_MIN_TURN = 0.1


@dataclass(frozen=True)
class Diagnosis:
    """What the checks found: whether the log's data are ``consistent`` (a steering step, a matter of the sampling,
    leaves it as it is) and the ``warnings``, one line each, in the order said."""

    consistent: bool
    warnings: tuple[str, ...]


def diagnose(summary: OdometrySummary, model: OdometryModel, read: Callable[[], JointLog],
             fmt: LogFormat | None = None, *, filtered: str | None = None) -> Diagnosis:
    """Every check of the run `summary` of a log, with the no-slip `model` (its robot's gears, its sensed joints) over
    the log's first samples, ``read()`` at most once and only when a check needs them. `fmt`: a CSV log's layout (its
    external heading is checked), None for a bag. `filtered`: the Kalman filter that ran (fk1, fk2), whose slip
    indicator is its residual (:func:`slip_warning`)."""
    first = functools.cache(read)
    said = [slip_warning(summary, lambda: wheel_slip(model, first().positions), filtered=filtered)]
    if fmt is not None and (fmt.heading_column or fmt.gyro_column):
        said.append(heading_warning(fmt, model, first()))
    said += gear_warnings(model, first)
    lines = [line for line in said if line]
    step = steering_step_warning(model, first()) if model.steer_joints else None
    return Diagnosis(not lines, (*lines, *([step] if step else [])))


def slip_warning(s: OdometrySummary, wheel_slips: Callable[[], dict[str, float]], *,
                 filtered: str | None = None) -> str | None:
    """The line when the slip indicator exceeds the tolerance (:data:`LOG_SLIP_RTOL` of the mean motion per
    interval), naming the wheels that slip most (`wheel_slips()`, RMS per wheel of the no-slip model); None within
    it. A slip indicator as large as the motion itself means units, signs or the description are wrong. A Kalman
    filter's indicator (`filtered`: its name) is its residual, which also holds its lag behind the measurements:
    where the no-slip model's own slips stay within the tolerance, the line says the log changes faster than the
    filter expects, not that the joints contradict each other."""
    motion = s.path_length / max(s.samples - 1, 1)
    tolerance = LOG_SLIP_RTOL * motion + 1e-9
    if s.rms_slip <= tolerance:
        return None
    slips = wheel_slips()
    if filtered and float(np.sqrt(sum(v * v for v in slips.values()))) <= tolerance:
        return (f"the {filtered} filter's residual (slip indicator rms {s.rms_slip:.3g} m per interval, max "
                f"{s.max_slip:.3g} m, against {motion:.3g} m of motion) shows a log that changes faster than its "
                "process noise allows: a glitch in a reading, slip, or a process noise too small (--kf-noise); the "
                "sensed joints themselves agree")
    what = ("larger than the motion itself: check the columns' units (counts? degrees?), signs and the robot "
            "description" if s.rms_slip > motion else "beyond measurement noise: wheels slip, or units or signs "
            "are wrong")
    named = ", ".join(f"{name} {value:.3g} m" for name, value in sorted(slips.items(), key=lambda kv: -kv[1]))
    named = f" (slip per wheel: {named})" if named else ""
    return (f"the sensed joints contradict each other: slip indicator rms {s.rms_slip:.3g} m per interval (max "
            f"{s.max_slip:.3g} m) against {motion:.3g} m of motion per interval{named}, {what}")


def heading_warning(fmt: LogFormat, model: OdometryModel, first: JointLog) -> str | None:
    """The line when the external heading's turns contradict the wheels' over the `first` samples of a CSV log
    (:data:`HEADING_RTOL`; a bag has no external heading: JointState only), else None. Its changes replace the
    wheels' dtheta, so a heading in other units or of the other sign gave a wrong trajectory with "consistent":
    true."""
    wheels = model.from_positions(first.positions).column(2)
    external = np.diff(first.heading_world)
    wheels = np.zeros_like(external) if wheels is None else wheels
    scale = float(np.maximum(np.abs(wheels), np.abs(external)).sum())
    off = float(np.abs(external - wheels).sum())
    if scale < HEADING_MIN_TURN or off <= HEADING_RTOL * scale:
        return None
    column, unit = (fmt.heading_column, "deg") if fmt.heading_column else (fmt.gyro_column, "deg/s")
    return (f"the external heading (column '{column}') turns {external.sum():.4g} rad over the first {len(first)} "
            f"samples where the wheels turn {wheels.sum():.4g} rad ({off:.3g} rad apart interval by interval): its "
            f"units (deg or deg/s? write them in the header: '{column} [{unit}]') or its sign (clockwise?) are "
            "probably wrong")


def gear_warnings(model: OdometryModel, first: Callable[[], JointLog]) -> list[str]:
    """One line per ``gear`` coupling of the model's robot whose logged joints do not turn together at its ratios over
    the `first()` samples of the log (:func:`wmrkit.couplings.gear_breaches`; read only when the robot has a gear).
    Odometry reads each joint on its own: a log breaking the gear (another robot's, or a wrong description) was
    integrated as a turn with "consistent": true."""
    couplings = model.robot.couplings
    if not any(c.kind == "gear" for c in couplings):
        return []
    log = first()
    steps = np.diff(log.positions, axis=0)
    lines = []
    for b in gear_breaches(couplings, model.joints, steps, GEAR_MIN_TURN):
        turns = ", ".join(f"{model.joints[i]} {steps[:, i].sum():.4g} rad" for i in b.given)
        lines.append(f"{b.head} over the first {len(log)} samples ({turns}; {b.spread:.0%} apart interval by "
                     "interval): the log is not of this robot, or its description's gear is wrong")
    return lines
