"""The diagnostics of an odometry run over a log: the warning lines ``wmrkit odometry`` prints and ``wmrkit batch
odometry`` puts in each log's row, composed once, here.

After the run, its summary and the log's first samples (:func:`~.files.first_samples`, CSV or bag, read only when a
check needs them) are judged: the sensed joints contradicting each other (slip, naming each wheel's slip), an
external heading column contradicting the wheels' turns (CSV logs), joints breaking a description's ``gear``
coupling, and a steering angle stepping within one sample interval (:func:`~.steering.steering_step_warning`).
A bag's IMU checks the heading of the trajectory the run outputs, sampled during the run (:class:`ImuCheck`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..analysis.singularity import robot_size
from ..couplings import GEAR_BREACH_RTOL, gear_breaches
from .imu_mount import ImuMounting
from .logs import JointLog, LogError, LogFormat
from .model import OdometryModel, wheel_slip
from .pipeline import OdometrySummary
from .steering import steering_step_warning
from .trajectories import Trajectory

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
#: The IMU check compares the turns of the wheels' heading and the IMU's yaw over the run and over windows this long
#: [s], half a window apart (a turn of a few seconds, its start and end in one window; a gyro's drift small within).
IMU_WINDOW = 10.0
#: Most window ends the IMU check samples: a run whose IMU spans longer than this many half windows (58 days) is
#: sampled at that many, its windows longer, so that two samples far apart in time cannot make it hold more.
MAX_IMU_WINDOWS = 1_000_000
#: Turns within this fraction of the larger agree: a MEMS gyro's scale factor is within 3 % (MPU-6050: +-3 %;
#: BMI088: +-1 %), a calibrated odometry's heading within a few % (wheel radii, track); a slipping skid steer's
#: wheels turn 1.5-3 times the robot (ROS's wheel_separation_multiplier), 33-67 % apart.
IMU_TURN_RTOL = 0.1
#: ... within this many radians: a fused orientation's noise and jitter (about 1 deg, read twice) and the
#: interpolation of both at a window's ends.
IMU_TURN_ATOL = 0.05
#: ... plus this drift rate [rad/s] times the span (0.29 deg/s): the bias left in a consumer MEMS gyro after its
#: start-up calibration (0.01-0.1 deg/s, temperature drift) several times over; a run without turning stays within.
IMU_DRIFT = 0.005

#: The IMU's yaw over these scales (keys) agreeing with the odometry's heading (:func:`imu_warning`'s rule) is said to
#: be the IMU's frame or units (values): an IMU mounted upside down (z down) or in a NED frame reads the opposite yaw
#: rate; one publishing deg/s (sensor_msgs/Imu: rad/s) reads 180/pi = 57.3 times the rate. Over large turns the
#: check's 10 % lets the IMU turn 0.9 to 1.11 times the scale (-0.9 to -1.11; 51.6 to 63.7); its 0.05 rad and drift
#: widen that over small ones.
IMU_FRAME_SCALES = {
    -1.0: "the IMU's yaw rate is the opposite of the odometry's: is the IMU mounted upside down, or its frame not "
          "REP-103 (z down, NED)? (Else the odometry turns the wrong way: the description's left and right swapped?)",
    180 / math.pi: "the IMU's yaw turns 57.3 times the odometry's: does the IMU publish deg/s? (sensor_msgs/Imu's "
                   "angular_velocity is in rad/s)",
    -180 / math.pi: "the IMU's yaw turns -57.3 times the odometry's: does the IMU publish deg/s (sensor_msgs/Imu's "
                    "angular_velocity is in rad/s), and is it mounted upside down, or its frame not REP-103?",
}
#: ... only when the odometry turns at least this much [rad] over the run or a window (29 deg: 5 times the check's
#: 0.05 rad + 10 s of drift), so that a run without turning, the IMU's drift and noise all it reads, is not said to be
#: upside down or in deg/s.
IMU_FRAME_MIN_TURN = 0.5


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
    said = [slip_warning(summary, lambda: wheel_slip(model, first().positions), filtered=filtered,
                         length=robot_size(model.robot))]
    if fmt is not None and (fmt.heading_column or fmt.gyro_column):
        said.append(heading_warning(fmt, model, first()))
    said += gear_warnings(model, first)
    lines = [line for line in said if line]
    step = steering_step_warning(model, first()) if model.steer_joints else None
    return Diagnosis(not lines, (*lines, *([step] if step else [])))


def slip_warning(s: OdometrySummary, wheel_slips: Callable[[], dict[str, float]], *,
                 filtered: str | None = None, length: float = 0.0) -> str | None:
    """The line when the slip indicator exceeds the tolerance (:data:`LOG_SLIP_RTOL` of the mean motion per
    interval: the path length plus the rotation at `length` [m], the wheels' distance from the origin, so that a
    turn on the spot has its wheels' motion, not none), naming the wheels that slip most (`wheel_slips()`, RMS per
    wheel of the no-slip model); None within it. A slip indicator as large as the motion itself means units, signs
    or the description are wrong. A Kalman filter's indicator (`filtered`: its name) is its residual, which also
    holds its lag behind the measurements: where the no-slip model's own slips stay within the tolerance, the line
    says the log changes faster than the filter expects, not that the joints contradict each other."""
    motion = (s.path_length + s.rotation * length) / max(s.samples - 1, 1)
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
    for b in gear_breaches(couplings, model.joints, steps, GEAR_BREACH_RTOL, GEAR_MIN_TURN):
        turns = ", ".join(f"{model.joints[i]} {steps[:, i].sum():.4g} rad" for i in b.given)
        lines.append(f"{b.head} over the first {len(log)} samples ({turns}; {b.spread:.0%} apart interval by "
                     "interval): the log is not of this robot, or its description's gear is wrong")
    return lines


def imu_step(imu_time: np.ndarray) -> float:
    """The spacing [s] of the IMU check's window ends for an IMU read at `imu_time` (increasing): half
    :data:`IMU_WINDOW`, or longer when the IMU spans more than :data:`MAX_IMU_WINDOWS` of them."""
    return max(IMU_WINDOW / 2, float(imu_time[-1] - imu_time[0]) / MAX_IMU_WINDOWS)


def imu_warning(grid: np.ndarray, heading: np.ndarray, imu: np.ndarray, topic: str,
                what: str = "no-slip") -> str | None:
    """The line when the `what` odometry's heading and the IMU's yaw (both at the `grid` times of :class:`ImuCheck`)
    turn apart, over the run or over one window, by more than :data:`IMU_TURN_ATOL` + :data:`IMU_DRIFT` times its
    span + :data:`IMU_TURN_RTOL` times the larger turn; else None. The line gives both turns over the run and over
    the worst window, and says why: the IMU's frame or units when its yaw divided by a scale of
    :data:`IMU_FRAME_SCALES` agrees with the heading by that rule and the odometry turns :data:`IMU_FRAME_MIN_TURN`
    somewhere, else the odometry (slip, the description)."""
    n = len(grid)
    i, j = np.r_[0, np.arange(n - 2)], np.r_[n - 1, np.arange(2, n)]  # the run, then each window
    a = heading[j] - heading[i]
    span = grid[j] - grid[i]

    def excess(scale: float) -> np.ndarray:
        b = (imu[j] - imu[i]) / scale
        return np.abs(a - b) / (IMU_TURN_ATOL + IMU_DRIFT * span + IMU_TURN_RTOL * np.maximum(np.abs(a), np.abs(b)))

    apart = excess(1.0)
    worst = int(np.argmax(apart))
    if apart[worst] <= 1.0:
        return None
    why = next((said for scale, said in IMU_FRAME_SCALES.items() if np.max(excess(scale)) <= 1.0),
               None) if np.max(np.abs(a)) >= IMU_FRAME_MIN_TURN else None
    w, k = i[worst], j[worst]
    window = (f"; from {grid[w] - grid[0]:.4g} s to {grid[k] - grid[0]:.4g} s into the run the {what} odometry "
              f"turned {heading[k] - heading[w]:.4g} rad and the IMU {imu[k] - imu[w]:.4g} rad" if worst else "")
    return (f"the {what} odometry's heading contradicts the IMU on {topic}: over the run the {what} odometry turned "
            f"{heading[-1] - heading[0]:.4g} rad and the IMU {imu[-1] - imu[0]:.4g} rad{window} (beyond "
            f"{IMU_TURN_ATOL:g} rad + {IMU_DRIFT:g} rad/s of gyro drift + {IMU_TURN_RTOL:.0%} of the turn): "
            + (why or "the wheels slip (a skid steer turning?), or the description's track or wheel radii are wrong"))


def odometry_name(estimator: str | None, weighted_by: str | None) -> str:
    """How the IMU check's warning names the odometry it judges: the slip-aware `estimator` (``wls``, ``fk1``,
    ``fk2``), else the no-slip model, weighted by the door's option `weighted_by` (``--weight`` of ``wmrkit
    odometry``, ``weights=`` of :func:`wmrkit.batch.batch_odometry`) or not weighted (None)."""
    return estimator or (f"weighted no-slip ({weighted_by})" if weighted_by else "no-slip")


class ImuCheck:
    """The IMU check of one run of a bag (:func:`imu_warning`) on the trajectory the run outputs, whatever its
    estimator: a sink of its chunks (:func:`~.files.odometry_file`'s `sinks`) keeping their heading only at the
    times the check reads (every half :data:`IMU_WINDOW` from the run's first sample, the IMU's first and last
    stamps, the run's last sample), so the log is read once and memory stays small; then :meth:`judge`.

    The IMU's `time` and `yaw` (:func:`~.bag_imu.read_imu`, on `topic` of the bag at `path`) are read before the
    run; `what` names the odometry judged in the warning (``no-slip``, ``wls``...). `named`: the user chose the IMU,
    so stamps missing the run's are an error, not a warning. `mounting`: the IMU's, and where it came from
    (:class:`~.imu_mount.ImuMounting`), for the answer to say.
    """

    def __init__(self, path: str, topic: str, time: np.ndarray, yaw: np.ndarray, what: str, *,
                 named: bool, mounting: ImuMounting | None = None) -> None:
        self.path, self.topic, self.what, self.named, self.mounting = path, topic, what, named, mounting
        self.imu = (np.asarray(time, dtype=float), np.asarray(yaw, dtype=float))
        self._start = self._last = None  # the run's first time; its latest (time, heading)
        self._step = imu_step(self.imu[0])
        self._next = 0  # k of the next grid time, start + k step
        self._times: list[np.ndarray] = []
        self._headings: list[np.ndarray] = []
        #: After :meth:`judge`: the warning line (or None), and whether the IMU checked the run.
        self.line: str | None = None
        self.checked = False

    def __call__(self, chunk: Trajectory) -> None:
        """Keep the heading of a trajectory `chunk` (they follow each other) at the check's times within it."""
        t, h = chunk.time, chunk.poses[:, 2]
        if not len(t):
            return
        if self._last is None:
            self._start = float(t[0])
            lo = math.nextafter(self._start, -math.inf)
        else:  # continued from the previous chunk's last sample
            lo = self._last[0]
            t, h = np.concatenate([[lo], t]), np.concatenate([[self._last[1]], h])
        hi, step, (imu_lo, imu_hi) = float(t[-1]), self._step, (self.imu[0][0], self.imu[0][-1])
        first = max(self._next, math.ceil((imu_lo - self._start) / step))  # none before the IMU's first stamp
        k = np.arange(first, math.floor((min(hi, imu_hi) - self._start) / step) + 2)
        grid = self._start + step * k
        keep = (grid <= hi) & (grid <= imu_hi)
        grid = grid[keep]
        if len(grid):
            self._next = int(k[keep][-1]) + 1
        at = np.concatenate([grid, [x for x in (self.imu[0][0], self.imu[0][-1]) if lo < x <= hi]])
        self._times.append(at)
        self._headings.append(np.interp(at, t, h))
        self._last = (hi, float(h[-1]))

    def judge(self) -> None:
        """Judge the run fed so far (at least one sample): sets :attr:`line` and :attr:`checked`. An IMU whose stamps
        miss the run's is a :class:`~.logs.LogError` when `named`, else a line saying it is not checked."""
        assert self._last is not None, "ImuCheck.judge: no sample fed"  # a run without samples is an error itself
        if self._last[0] <= self._start:  # one sample: no turn
            self.checked = True
            return
        time, yaw = self.imu
        err = None
        if time[-1] <= self._start or time[0] >= self._last[0]:
            err = LogError(f"{self.path}: {self.topic}: the IMU's stamps ({time[0]:.9g} to {time[-1]:.9g} s) miss the "
                           f"joint states' ({self._start:.9g} to {self._last[0]:.9g} s): another clock?")
        elif time[-1] <= time[0]:  # one stamp: no turn to compare ("consistent" over nothing)
            at = f"1 IMU message (at {time[0]:.9g} s)" if len(time) == 1 else \
                f"{len(time)} IMU messages, all at {time[0]:.9g} s"
            err = LogError(f"{self.path}: {self.topic}: {at}: too few to measure a turn")
        if err is not None:
            if self.named:
                raise err
            self.line = f"{err} (the odometry is not checked against it)"
            return
        # the window ends: the times kept where both have samples (the run's ends or the IMU's, start + k step)
        at = np.concatenate([*self._times, [self._last[0]]])
        grid, first = np.unique(at, return_index=True)
        within = (grid >= time[0]) & (grid <= time[-1])
        heading = np.concatenate([*self._headings, [self._last[1]]])[first][within]
        self.line = imu_warning(grid[within], heading, np.interp(grid[within], time, yaw), self.topic, self.what)
        self.checked = True


def imu_check(path: str, topic: str, what: str, *, named: bool, mount: ArrayLike | None = None,
              mount_option: str = "mount=") -> tuple[ImuCheck | None, str | None]:
    """The :class:`ImuCheck` of the IMU on `topic` of the bag at `path`, read now (before the run), and None; an IMU
    that cannot be read is a :class:`~.logs.LogError` when `named`, else ``(None, the line saying it is not
    checked)``. `mount`: the IMU's ``(roll, pitch, yaw)`` [rad] on the robot, overriding the bag's ``/tf_static``
    (:func:`~.bag_imu.read_imu_yaw`; `mount_option` names it in the check's :class:`~.imu_mount.ImuMounting`)."""
    from .bag_imu import read_imu_mounted

    try:
        time, yaw, mounting = read_imu_mounted(path, topic, mount=mount, option=mount_option)
        return ImuCheck(path, topic, time, yaw, what, named=named, mounting=mounting), None
    except LogError as err:
        if named:
            raise
        return None, f"{err} (the odometry is not checked against it)"
