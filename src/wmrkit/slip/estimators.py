"""Slip-aware odometry estimators for a log stream: WLS (7.52) and the Kalman filters FK1/FK2 (7.68)-(7.75).

:func:`estimator` builds what ``wmrkit odometry --method wls|fk1|fk2`` runs. WLS is an
:class:`~wmrkit.odometry.model.OdometryModel` (:func:`.weights.wls_model`), run by the odometry pipeline itself.
A filter is a :class:`KalmanEstimator`: chunks of the log in, the filter state carried from chunk to chunk, the
filtered twists composed into poses with the chosen scheme, the same :class:`~wmrkit.odometry.pipeline.OdometrySummary`
out (the slip indicator is the norm of the measurement residual times the step [m]).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from ..errors import WmrkitError
from ..odometry.integrators import Method, check_method, integrate_increments
from ..odometry.logs import JointLog, LogError
from ..odometry.model import OdometryModel
from ..odometry.pipeline import OdometrySummary, check_poses, start_pose
from ..odometry.trajectories import Trajectory
from ..robot import Robot
from .kalman import (
    FILTERS,
    ILL_CONDITIONED,
    PERIOD_INTERVALS,
    KalmanModel,
    KalmanNoise,
    _filter,
    check_log,
    kalman_model,
    nominal_period,
)
from .weights import SlipWeights, wls_model

ESTIMATORS = ("wls", *FILTERS)
#: A filter's given nominal sample period more than this times the log's is said (:meth:`KalmanEstimator.
#: period_warning`): the log's steps then all round to one period (n = 1 below 1.5 T).
PERIOD_MISMATCH = 2.0


@dataclass(frozen=True, eq=False)
class KalmanEstimator:
    """A velocity filter over a stream of log chunks (module docstring)."""

    model: KalmanModel
    name: str = "fk2"
    # the nominal period of the log last run (its first intervals' median, :func:`.kalman.nominal_period`)
    _seen: dict = field(init=False, default_factory=dict, compare=False, repr=False)

    @property
    def joints(self) -> tuple[str, ...]:
        """The log columns read."""
        return self.model.odometry.joints

    @property
    def robot(self) -> Robot:
        """The robot."""
        return self.model.odometry.robot

    def conditioning_warning(self) -> str | None:
        """The line saying that, at a steering configuration met so far, the filter's kept rows barely fixed the
        twist (:attr:`~.kalman.KalmanModel.worst_conditioning` above :data:`~.kalman.ILL_CONDITIONED`): its answer
        there is its prediction; None when they fixed it everywhere."""
        worst = self.model.worst_conditioning
        if worst is None or worst[0] <= ILL_CONDITIONED:
            return None
        om = self.model.odometry
        beta = dict(zip((om.robot.steer_names[i] for i in om.steer_index), worst[1], strict=True))
        heading = om.robot.with_beta_angles(beta).heading
        where = ", ".join(f"{n} {math.degrees(heading[om.robot.steer_names.index(n)]):.4g} deg" for n in beta)
        fix = ("do not fix the twist" if math.isinf(worst[0]) else
               f"barely fix the twist (condition number {worst[0]:.3g} > {ILL_CONDITIONED:g})")
        at = f"at a steering heading of the log ({where}) " if beta else ""  # a robot that does not steer: everywhere
        return (f"{self.name}: {at}its measurement rows {fix}: there the filter carries its prediction and the "
                f"trajectory can be far off{'; use --method fk2 or wls' if self.name == 'fk1' else ''}")

    def period_warning(self) -> str | None:
        """The line saying that the nominal sample period T given the filter (:attr:`~.kalman.KalmanNoise.period`)
        is more than :data:`PERIOD_MISMATCH` times the log's (the median of its first intervals): every step
        shorter than 1.5 T counts one period of ``Q``, so each of the log's steps gets about T / (its period) times
        the process noise it spans; None when no period was given or it is within that factor."""
        given, log = self.model.period, self._seen.get("period")
        if given is None or log is None or given <= PERIOD_MISMATCH * log:
            return None
        return (f"{self.name}: the nominal sample period of the process noise, {given:g} s, is {given / log:.3g} times "
                f"the log's ({log:g} s, the median of its first {PERIOD_INTERVALS} intervals): every step counts "
                f"as one period (n = 1), about {given / log:.3g} times the process noise it spans")

    def notes(self) -> list[str]:
        """The warning lines of the last run: :meth:`conditioning_warning`, :meth:`period_warning`."""
        return [line for line in (self.conditioning_warning(), self.period_warning()) if line]

    def _checked(self, chunks: Iterable[JointLog]) -> Iterator[JointLog]:
        """The non-empty chunks, with the filter's columns, each checked (:func:`.kalman.check_log`)."""
        prev = None
        for raw in chunks:
            chunk = raw if raw.joints == self.joints else raw.select(self.joints)
            if len(chunk):
                check_log(chunk, prev, self.name)
                yield chunk
                prev = chunk

    def run(self, chunks: Iterable[JointLog], *, method: Method = "exact", pose0: ArrayLike = (0.0, 0.0, 0.0),
            sinks: Sequence[Callable[[Trajectory], object]] = ()) -> OdometrySummary:
        """Filter and integrate every chunk; each sink gets each :class:`Trajectory` chunk."""
        check_method(method)
        pose = start_pose(pose0)
        prev: JointLog | None = None
        x = p = None
        n_total, t0, t1, dist, rot, max_slip, sq, max_dt = 0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        period, checked = _first_period(self._checked(chunks))
        self._seen["period"] = period
        period = period if self.model.period is None else self.model.period
        for chunk in checked:
            if prev is None:
                t0 = float(chunk.time[0])
                first = Trajectory(chunk.time[:1], pose[None].copy(), np.zeros(1))
                for sink in sinks:
                    sink(first)
                n_total = 1
            else:
                chunk = JointLog(np.concatenate([prev.time[-1:], chunk.time]), chunk.joints,
                                 np.vstack([prev.positions[-1:], chunk.positions]), source=chunk.source)
            if len(chunk) >= 2:
                run = _filter(self.model, chunk, x, p, period)
                x, p = run.twist[-1], run.covariance
                with np.errstate(over="ignore", invalid="ignore"):  # an overflow is named by check_poses
                    poses = integrate_increments(pose, run.increments, method)
                check_poses(chunk.slice(1, len(chunk)), poses)  # a gap of 1e9 s turned the twist 5.7e8 rad
                for sink in sinks:
                    sink(Trajectory(chunk.time[1:], poses, run.slip))
                n = len(run.slip)
                n_total += n
                dist += float(np.sum(np.hypot(run.increments[:, 0], run.increments[:, 1])))
                rot += float(np.sum(np.abs(run.increments[:, 2])))
                max_slip, sq = max(max_slip, float(run.slip.max())), sq + float(run.slip @ run.slip)
                max_dt = max(max_dt, float(np.max(np.diff(chunk.time))))
                pose = poses[-1]
            t1 = float(chunk.time[-1])
            prev = chunk.slice(len(chunk) - 1, len(chunk))
        if prev is None:
            raise LogError("the log has no samples")
        rms = math.sqrt(sq / (n_total - 1)) if n_total > 1 else 0.0
        return OdometrySummary(self.robot.name, self.name, n_total, t0, t1, tuple(float(v) for v in pose),
                               dist, rot, max_slip, rms, max_dt)


def _first_period(chunks: Iterator[JointLog]) -> tuple[float | None, Iterator[JointLog]]:
    """The log's nominal sample period (:func:`.kalman.nominal_period`, None for fewer than two samples), read
    ahead over as many `chunks` as its first :data:`.kalman.PERIOD_INTERVALS` intervals take (so that it does not
    depend on where the stream is cut), and all the chunks again."""
    ahead, times, count = [], [], 0
    for chunk in chunks:
        ahead.append(chunk)
        times.append(chunk.time[:PERIOD_INTERVALS + 1 - count])
        count += len(times[-1])
        if count > PERIOD_INTERVALS:
            break
    return (nominal_period(np.concatenate(times)) if count >= 2 else None), itertools.chain(ahead, chunks)


@dataclass(frozen=True)
class EstimatorSpec:
    """What :func:`estimator` builds a slip-aware estimator from, and the `scheme` integrating its twists: a plain
    value (``wmrkit batch odometry`` sends it to its workers, which build one estimator per log, so that a filter's
    :meth:`KalmanEstimator.conditioning_warning` is that log's)."""

    name: str
    scheme: Method = "exact"
    sensed: tuple[str, ...] | None = None
    weights: SlipWeights | None = None
    noise: KalmanNoise | None = None
    thesis_double_q: bool = False

    @property
    def label(self) -> str:
        """The method as ``wmrkit odometry`` names it in its summary: ``fk2 (exact)``."""
        return f"{self.name} ({self.scheme})"

    def build(self, robot: Robot) -> OdometryModel | KalmanEstimator:
        """A new estimator of `robot` (:func:`estimator`)."""
        return estimator(robot, self.name, sensed=self.sensed, weights=self.weights, noise=self.noise,
                         thesis_double_q=self.thesis_double_q)


def estimator(robot: Robot, name: str, *, sensed: Sequence[str] | None = None, weights: SlipWeights | None = None,
              noise: KalmanNoise | None = None, thesis_double_q: bool = False) -> OdometryModel | KalmanEstimator:
    """The estimator `name` (``wls``, ``fk1``, ``fk2``) of `robot`: WLS with friction coefficients `weights`, a
    filter with `noise` (defaults: unit coefficients, unit noise). Sensed joints that never report a turn the
    robot's described ones report are refused (:func:`check_slip_sensing`)."""
    if sensed is not None and name in ESTIMATORS:
        check_slip_sensing(robot, sensed)
    if name == "wls":
        return wls_model(robot, weights, sensed)
    if name in FILTERS:
        return KalmanEstimator(kalman_model(robot, name, noise, sensed, thesis_double_q=thesis_double_q), name)
    raise WmrkitError(f"estimator must be one of {', '.join(ESTIMATORS)}, got '{name}'")


#: Steering offsets [rad] from the described angles at which a steering model's twist maps are taken (a sensed
#: steering angle moves the twist: the forklift's one drive wheel and steering report its turn).
STEERING_PROBES = (0.0, 0.3, -0.3, 0.7)


def check_slip_sensing(robot: Robot, sensed: Sequence[str]) -> None:
    """Refuse `sensed` joints whose twist maps (over steering configurations, :data:`STEERING_PROBES`) hold the turn
    rate at 0 whatever the log, where the robot's described sensors report it: the no-slip rows alone then fix it,
    which a slip-aware estimator exists to relax. A skid steer read by one side's wheels: its lateral rows fix the
    turn rate at 0, so a turning run was driven straight with no word (plain odometry refuses sensors that do not
    determine the no-slip motion; this is the same refusal for the motion with slip). Only the turn: a sideways speed
    held at 0 depends on the origin (a car's rear wheels alone hold it at 0 at their axle, as the no-slip model does),
    and sensors that tie the turn to others (the forklift's drive wheels alone; one of them with its steering) report
    it. :class:`~wmrkit.odometry.model.SensingError`."""
    from ..odometry.model import SensingError, odometry_model

    def turns(joints) -> bool:
        """Whether the model of `joints` maps some rates to a turn."""
        model = odometry_model(robot, joints)
        if model.constant:
            maps = np.asarray(model.solution)[None]
        else:
            maps = model.configuration_maps(robot.beta[model.steer_index] + np.array(STEERING_PROBES)[:, None])[0]
            maps = np.asarray(maps.arrays[0])
        if not maps.size:
            return False
        return bool(np.abs(maps[:, 2]).max() > 1e-9 * np.abs(maps[:, :3]).max())

    if not turns(sensed) and turns(robot.sensed):
        raise SensingError(f"the sensed joints of robot '{robot.name}' ({', '.join(sensed) or 'none'}) do not "
                           "determine its motion with slip: they never report a turn (the no-slip rows hold omega at "
                           f"0 whatever the log), which its described sensors ({', '.join(robot.sensed)}) report (a "
                           "skid steer read by one side's wheels drives straight)")
