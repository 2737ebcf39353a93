"""Odometry over a log, streaming: chunks of joint samples in, poses (slip, covariance) out, bounded memory.

Per chunk: the sensed direct model (:mod:`.model`) gives body increments between consecutive samples, the chosen
scheme (:mod:`.integrators`) composes them from the pose carried over from the previous chunk, and the
covariance (:mod:`.covariance`) is propagated from the carried covariance. The last sample of each chunk is kept
to difference against the next, so the result does not depend on the chunk size (to round-off). Increments,
composition, slip and path sums are one compiled pass over the chunk (:func:`._kernels.odometry_chunk`) that
differences the joint positions itself; for a steering robot (:func:`._kernels.steered_chunk`) it also takes the
steering angles at mid-interval and finds their maps among those the model keeps (computed once per
configuration, :meth:`.model.OdometryModel.configuration_maps`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_reals, as_vectors
from ..errors import WmrkitError
from ..limits import MAX_COORDINATE, check_chunk_size
from ..robot import Robot
from ..units import MAX_ANGLE, MAX_TURNS
from .covariance import CrowleyNoise, JointNoise, NoiseError, check_covariance, propagate_checked
from .integrators import HEADING_FRACTION, Method, check_method
from .logs import JointLog, LogError, check_time
from .model import ModelIncrements, OdometryModel, kernel_maps, odometry_model, wrap_angle
from .trajectories import Trajectory

Noise = CrowleyNoise | JointNoise


@dataclass(frozen=True, slots=True)
class OdometrySummary:
    """What a run produced: final pose ``(x [m], y [m], theta [rad])``, sample count, time span [s], path length
    [m] and accumulated rotation [rad] (sums of ``|body displacement|`` and ``|dtheta|``), the largest and RMS
    slip indicator per interval [m], the longest time step [s], and the final covariance when computed."""

    robot: str
    method: str
    samples: int
    start_time: float
    end_time: float
    final_pose: tuple[float, float, float]
    path_length: float
    rotation: float
    max_slip: float
    rms_slip: float
    max_dt: float
    final_covariance: tuple[tuple[float, ...], ...] | None = None

    def __post_init__(self) -> None:
        """Inputs are checked finite and bounded, so a result that is not is an overflow inside wmrkit: refused
        here (one line from the CLI), never printed as NaN (null in JSON) with success."""
        values = (*self.final_pose, self.path_length, self.rotation, self.max_slip, self.rms_slip,
                  *(v for row in self.final_covariance or () for v in row))
        if not all(math.isfinite(v) for v in values):
            raise WmrkitError(f"odometry ({self.method}) of robot '{self.robot}': the result is not finite (final "
                              f"pose {list(self.final_pose)}, path length {self.path_length}): a numerical overflow in "
                              "wmrkit; please report it with the log")

    def to_dict(self) -> dict:
        """JSON-ready mapping; ``final_pose`` is the final pose ``[x, y, theta]`` (the key of every run's last pose,
        as ``wmrkit simulate``'s; docs/limits.md, JSON answers)."""
        return {"robot": self.robot, "method": self.method, "final_pose": list(self.final_pose),
                "samples": self.samples, "start_time": self.start_time, "end_time": self.end_time,
                "path_length": self.path_length, "rotation": self.rotation, "max_slip": self.max_slip,
                "rms_slip": self.rms_slip, "max_dt": self.max_dt,
                "covariance": None if self.final_covariance is None else [list(r) for r in self.final_covariance]}


def run_odometry(model: OdometryModel, chunks: Iterable[JointLog], *, method: Method = "exact",
                 pose0: ArrayLike = (0.0, 0.0, 0.0), noise: Noise | None = None,
                 initial_covariance: ArrayLike | None = None,
                 sinks: Sequence[Callable[[Trajectory], object]] = (),
                 out: Trajectory | None = None) -> OdometrySummary:
    """Integrate a stream of log chunks; every sink is called with each :class:`Trajectory` chunk (002 (22)).

    `pose0` is the pose at the first sample. With an external heading in the log, the heading's *changes* are
    used: ``theta = pose0[2] + heading - heading[0]``. `noise` (Crowley's model of 003 (17) generalised, or
    per-joint noise through the robot's kinematics) turns on covariance propagation from `initial_covariance`.
    `out`, a trajectory of preallocated arrays as long as the whole log, is filled in place (no copies).
    """
    check_method(method)
    pose = start_pose(pose0)
    _check_inputs(noise, initial_covariance)
    cov = None if noise is None else (np.zeros((3, 3)) if initial_covariance is None
                                      else np.array(initial_covariance, dtype=float))
    prev: JointLog | None = None
    heading0 = 0.0
    stats = _Stats()
    reach, turn = MAX_COORDINATE - np.abs(pose[:2]).max(), MAX_ANGLE - abs(pose[2])  # path and rotation in bounds
    row = 0  # index of the chunk's first sample in `out`
    for raw in chunks:
        chunk = raw if raw.joints == model.joints else raw.select(model.joints)
        if len(chunk) == 0:
            continue
        if prev is None:
            check_chunk(chunk, None)
            heading0 = 0.0 if chunk.heading_world is None else float(chunk.heading_world[0]) - pose[2]
            stats.start(chunk.time[0])
            first = Trajectory(chunk.time[:1], pose[None].copy(), np.zeros(1), None if cov is None else cov[None])
            for sink in sinks:
                sink(first)
            if out is not None:
                _fill(out, first, 0)
            prev, chunk, row = chunk.slice(0, 1), chunk.slice(1, len(chunk)), 1
            if len(chunk) == 0:
                continue
        n = len(chunk)
        # without covariance the kernel differences the positions (and finds each interval's steering maps); the
        # path length is then finite exactly when the positions are (checked below: one read of them). Steering
        # angles are checked first: the configuration lookup needs numbers.
        fused = cov is None
        max_dt = check_chunk(chunk, prev, positions=not (fused and model.constant))
        inc = None if fused else model.from_positions(chunk.positions, previous=prev.positions[-1])
        heading = None
        if chunk.heading_world is not None:
            if prev.heading_world is None:
                raise LogError(f"{chunk.where(0)}: external heading starts in the middle of the log")
            heading = np.concatenate([prev.heading_world[-1:], chunk.heading_world]) - heading0
        poses = np.empty((n, 3)) if out is None else out.poses[row:row + n]
        slip = np.zeros(n) if out is None else out.slip[row:row + n]
        sums = _compose_chunk(model, chunk.positions, prev.positions[-1], inc, pose, heading, method, poses, slip)
        if fused and not math.isfinite(sums[0]):  # a non-finite position makes every body increment NaN or inf
            check_finite(chunk)
        if not (all(map(math.isfinite, sums)) and np.isfinite(poses[-1]).all()):
            _overflow(chunk, poses)
        if (stats.dist + sums[0] > reach or stats.rot + sums[1] > turn  # cheap bounds of the poses; then scan them
                or abs(poses[-1, 2]) > MAX_ANGLE):
            _beyond(chunk, poses)
        covs = None
        if cov is not None:
            dx, dy, dth = (np.zeros(n) if c is None else c for c in (inc.column(0), inc.column(1), inc.column(2)))
            steps = np.stack([dx, dy, dth if heading is None else np.diff(heading)], axis=-1)
            q = _increment_covariance(noise, inc, steps)
            with np.errstate(over="ignore", invalid="ignore"):  # an overflow is reported below, located
                covs = propagate_checked(np.vstack([pose[None], poses]), steps, q, method, cov)
            cov = covs[-1]
            if not np.isfinite(cov).all():
                _overflow(chunk, covs.reshape(n, 9), "covariance")
        result = Trajectory(chunk.time, poses, slip, covs)
        for sink in sinks:
            sink(result)
        if out is not None and covs is not None:
            out.covariance[row:row + n] = covs
        row += n
        stats.add(n, max_dt, float(chunk.time[-1]), sums)
        pose, prev = poses[-1].copy(), chunk.slice(n - 1, n)
    if prev is None:
        raise LogError("the log has no samples")
    return stats.summary(model.robot.name, method, pose, cov)


def odometry(robot: Robot | OdometryModel, log: JointLog, *, method: Method = "exact",
             pose0: ArrayLike = (0.0, 0.0, 0.0), noise: Noise | None = None,
             initial_covariance: ArrayLike | None = None, chunk_size: int = 1 << 16) -> Trajectory:
    """The trajectory of `robot` over an in-memory `log` (see :func:`run_odometry`): one pose per sample.

    `robot` may be an :class:`OdometryModel` to choose the sensed joints (default: ``robot.sensed``).
    """
    check_chunk_size(chunk_size, LogError)
    if not isinstance(log, JointLog):  # a path or an array raised AttributeError or TypeError
        raise LogError(f"log: expected a JointLog (read_csv(path, joints, robot=robot), JointLog.from_headings), "
                       f"got {type(log).__name__} {log!r:.60}")
    model = robot if isinstance(robot, OdometryModel) else odometry_model(robot)
    n = len(log)
    # slip from calloc: robots without redundant sensors leave it untouched (no page is written)
    out = Trajectory(log.time, np.empty((n, 3)), np.zeros(n), None if noise is None else np.empty((n, 3, 3)))
    chunks = (log.slice(i, i + chunk_size) for i in range(0, max(n, 1), chunk_size))
    run_odometry(model, chunks, method=method, pose0=pose0, noise=noise, initial_covariance=initial_covariance,
                 out=out)
    return out


def final_poses(model: OdometryModel, log: JointLog, positions: np.ndarray, *,
                method: Method = "exact") -> np.ndarray:
    """Final poses ``(R, 3)`` of :func:`odometry` from pose (0, 0, 0) over `log`'s time with each of `positions`
    ``(R, N, n)`` (joints in ``model.joints`` order) in place of the log's own: many runs of one log (Monte Carlo)
    without the per-call work of :func:`odometry` (one compiled pass per run, the time checked once)."""
    check_method(method)
    if log.heading_world is not None:  # odometry() would take theta from it; the runs here have none
        raise LogError(f"{log.source}: an external heading (heading_world) is not used by final_poses; give the log "
                       "without it")
    log = log if log.joints == model.joints else log.select(model.joints)
    positions = as_reals(positions, "positions")  # a list of runs, as JointLog takes its positions
    n = len(log)
    if positions.ndim != 3 or positions.shape[1:] != log.positions.shape or n < 2:
        raise LogError(f"positions: expected (runs, {n}, {len(log.joints)}) of a log of at least 2 samples, got "
                       f"{positions.shape}")
    runs = positions.shape[0]
    check_chunk(log.slice(0, 1), None, positions=False)
    check_chunk(log.slice(1, n), log.slice(0, 1), positions=False)
    steer = _steer_columns(log)
    poses, slip, out, origin = np.empty((n - 1, 3)), np.zeros(n - 1), np.empty((runs, 3)), np.zeros(3)
    run = lambda k: JointLog(log.time, log.joints, positions[k], None, f"{log.source} (run {k})")  # noqa: E731
    for k in range(runs):  # the slow paths name the first bad value, as run_odometry's
        q = positions[k]
        if not (model.constant or (np.isfinite(q.sum()) and np.abs(q[:, steer]).max(initial=0.0) <= MAX_ANGLE)):
            check_finite(run(k))  # the configuration lookup needs numbers
        sums = _compose_chunk(model, q[1:], q[0], None, origin, None, method, poses, slip)
        if not (all(map(math.isfinite, sums)) and np.isfinite(poses[-1]).all()):
            check_finite(run(k))
            _overflow(run(k).slice(1, n), poses)
        if sums[0] > MAX_COORDINATE or sums[1] > MAX_ANGLE or abs(poses[-1, 2]) > MAX_ANGLE:  # cheap bounds first
            _beyond(run(k).slice(1, n), poses)
        out[k] = poses[-1]
    return out


def join(parts: Sequence[Trajectory]) -> Trajectory:
    """Trajectory chunks joined in order."""
    cov = None if parts[0].covariance is None else np.concatenate([p.covariance for p in parts])
    return Trajectory(np.concatenate([p.time for p in parts]), np.concatenate([p.poses for p in parts]),
                      np.concatenate([p.slip for p in parts]), cov)


class Decimator:
    """A sink keeping at most about `max_points` poses of a stream (every k-th, k doubling as needed), and the last."""

    def __init__(self, max_points: int = 100_000) -> None:
        self.max_points, self.stride, self._seen = max_points, 1, 0
        self._time: list[np.ndarray] = []
        self._poses: list[np.ndarray] = []
        self._last: tuple[np.ndarray, np.ndarray] | None = None

    def __call__(self, chunk: Trajectory) -> None:
        """Take the poses of `chunk` that fall on the stride."""
        idx = np.flatnonzero((np.arange(self._seen, self._seen + len(chunk)) % self.stride) == 0)
        self._seen += len(chunk)
        if len(chunk):
            self._last = (chunk.time[-1:], chunk.poses[-1:])
        self._time.append(chunk.time[idx])
        self._poses.append(chunk.poses[idx])
        if sum(map(len, self._time)) > self.max_points:
            t, p = np.concatenate(self._time), np.concatenate(self._poses)
            keep = np.arange(len(t)) % 2 == 0  # kept samples are multiples of the stride: keep every other
            self._time, self._poses, self.stride = [t[keep]], [p[keep]], self.stride * 2

    def result(self) -> tuple[np.ndarray, np.ndarray]:
        """Times ``(M,)`` and poses ``(M, 3)`` kept, the stream's last pose included (the end a plot marks)."""
        last = [] if self._last is None or (self._seen - 1) % self.stride == 0 else [self._last]
        return (np.concatenate([*self._time, *(t for t, _ in last)]),
                np.concatenate([*self._poses, *(p for _, p in last)]))


def _compose_chunk(model: OdometryModel, positions: np.ndarray, before: np.ndarray, inc: ModelIncrements | None,
                   pose: np.ndarray, heading: np.ndarray | None, method: Method, poses: np.ndarray,
                   slip: np.ndarray) -> tuple[float, float, float, float]:
    """Poses and slip of a chunk into `poses` ``(N, 3)`` and `slip` ``(N,)``, fused in one compiled pass over the
    samples (joint increments, the sensed model's maps (4.11), the scheme's composition); the chunk's path sums
    ``(distance, rotation, max slip, sum of slip^2)``. Without `inc` (a constant model), the joint increments are
    the differences of `positions` ``(N, n)`` from `before` ``(n,)``, taken in the kernel."""
    from . import _kernels  # numba loads on first use

    if inc is None and not model.constant:
        return _steered_chunk(model, positions, before, pose, heading, method, poses, slip)
    if inc is None:
        maps, residual, index = kernel_maps(model.solution, model.residual_map)
        rates, first = positions, np.asarray(before, dtype=float)
    else:
        (maps, residual, index), rates, first = inc.kernel_maps(), inc.rate_increments, np.empty(0)
    return _kernels.odometry_chunk(np.asarray(rates, dtype=float), first, maps, residual, index, pose,
                                   np.empty(0) if heading is None else heading, HEADING_FRACTION[method],
                                   method == "exact", poses, slip)


def _steered_chunk(model: OdometryModel, positions: np.ndarray, before: np.ndarray, pose: np.ndarray,
                   heading: np.ndarray | None, method: Method, poses: np.ndarray,
                   slip: np.ndarray) -> tuple[float, float, float, float]:
    """:func:`_compose_chunk` of a steering robot in one compiled pass (:func:`._kernels.steered_chunk`), with the
    maps of the configurations met so far; a pass that meets new ones stops, their maps are added, it resumes."""
    from . import _kernels  # numba loads on first use

    positions, before = np.asarray(positions, dtype=float), np.asarray(before, dtype=float)
    rate_cols, steer_cols = model.columns
    state = np.array([pose[0], pose[1], pose[2] if heading is None else heading[0], 0.0, 0.0, 0.0, 0.0])
    missing = np.empty((len(positions), len(steer_cols)))
    maps, start = model.configuration_maps()[0], 0
    while True:
        start, count = _kernels.steered_chunk(positions, before, rate_cols, steer_cols, start, maps.keys, maps.ids,
                                              maps.arrays[0][:, :3], maps.arrays[2],
                                              np.empty(0) if heading is None else heading, HEADING_FRACTION[method],
                                              method == "exact", state, poses, slip, missing)
        if count == 0:
            return state[3], state[4], state[5], state[6]
        maps, bad = model.configuration_maps(np.unique(missing[:count], axis=0))
        if len(bad):
            d = wrap_angle(np.diff(np.vstack([before[steer_cols], positions[:, steer_cols]]), axis=0))
            raise model.undetermined(np.vstack([before[steer_cols], positions[:-1, steer_cols]]) + 0.5 * d, bad)


def _increment_covariance(noise: Noise, inc: ModelIncrements, steps: np.ndarray) -> np.ndarray:
    if isinstance(noise, CrowleyNoise):
        return noise.increment_covariance(steps)
    return np.broadcast_to(noise.increment_covariance(inc.twist_map, inc.rate_increments), (len(steps), 3, 3))


def _fill(out: Trajectory, chunk: Trajectory, row: int) -> None:
    stop = row + len(chunk)
    out.poses[row:stop] = chunk.poses
    out.slip[row:stop] = chunk.slip
    if out.covariance is not None:
        out.covariance[row:stop] = chunk.covariance


def check_chunk(chunk: JointLog, prev: JointLog | None, *, positions: bool = True) -> float:
    """Refuse non-finite values and time that does not increase; the longest time step (from `prev`'s last
    sample, 0 without steps). `positions=False` leaves the joint positions to the caller."""
    from . import _kernels  # numba loads on first use

    t = np.asarray(chunk.time, dtype=float)
    bad, largest = _kernels.time_steps(t, np.empty(0) if prev is None else np.asarray(prev.time[-1:], dtype=float))
    ok = bool((not positions or np.isfinite(chunk.positions.sum())) and np.isfinite(t[0]) and np.isfinite(t[-1])
              and bad == 0)
    if chunk.heading_world is not None:
        ok = ok and bool(np.isfinite(chunk.heading_world.sum()))
    steer = _steer_columns(chunk)
    if steer and positions:
        ok = ok and bool(np.abs(chunk.positions[:, steer]).max(initial=0.0) <= MAX_ANGLE)
    if not ok:  # the slow path finds and names the first bad value
        check_finite(chunk)
        check_time(chunk, t, None if prev is None else float(prev.time[-1]), None)
    return largest


def check_start_pose(pose: np.ndarray, name: str = "pose0") -> None:
    """Refuse a start pose ``(3,)`` that is not finite or lies beyond :data:`MAX_COORDINATE`, naming it `name` (the
    CLI's ``--pose``)."""
    if not np.isfinite(pose).all():
        raise LogError(f"{name}: must be finite, got {pose.tolist()}")
    if np.abs(pose[:2]).max() > MAX_COORDINATE:
        raise LogError(f"{name}: a position beyond {MAX_COORDINATE:g} m, got {pose[:2].tolist()}")


def start_pose(pose0: ArrayLike) -> np.ndarray:
    """`pose0` as one pose ``(3,)`` (a copy), refused as :func:`check_start_pose` refuses it."""
    pose = as_vectors(pose0, 3, "pose0").copy()
    if pose.shape != (3,):
        raise LogError(f"pose0: expected one pose (3,), got {pose.shape}")
    check_start_pose(pose)
    return pose


def _check_inputs(noise: Noise | None, initial_covariance: ArrayLike | None) -> None:
    """Refuse a noise that is no noise model, and a bad initial covariance or one without a noise model (noise
    models check their coefficients when made)."""
    if noise is not None and not isinstance(noise, CrowleyNoise | JointNoise):
        raise NoiseError(f"noise: expected a CrowleyNoise or JointNoise instance, got {noise!r}")
    if initial_covariance is not None:
        if noise is None:
            raise NoiseError("initial_covariance: needs a noise model (noise=...); without one no covariance is "
                             "propagated and it would be ignored")
        check_covariance(initial_covariance, "initial_covariance")


def check_poses(chunk: JointLog, poses: np.ndarray) -> None:
    """Refuse poses ``(N, 3)`` of the rows of `chunk` that are not finite or lie beyond :data:`MAX_COORDINATE` or
    :data:`MAX_ANGLE`, naming the first such row (the bounds of :func:`run_odometry`, for other integrators: the
    Kalman filters')."""
    if not np.isfinite(poses).all():
        _overflow(chunk, poses)
    _beyond(chunk, poses)


def _overflow(chunk: JointLog, values: np.ndarray, what: str = "pose") -> None:
    """Name the first row whose `values` ``(N, ...)`` are not finite: the log's numbers overflow the integration."""
    bad = ~np.isfinite(values.reshape(len(values), -1)).all(axis=1)
    i = int(np.argmax(bad)) if bad.any() else len(values) - 1
    raise LogError(f"{chunk.where(i)}: the {what} overflows here (values too large for floating point: an "
                   "implausible log)")


def _beyond(chunk: JointLog, poses: np.ndarray) -> None:
    """Name the first row of `chunk` whose pose is beyond :data:`MAX_COORDINATE` or :data:`MAX_ANGLE` (finite, but
    no pose: a heading of 1e149 rad has no direction), if any."""
    bad = (np.abs(poses[:, :2]) > MAX_COORDINATE).any(axis=1) | (np.abs(poses[:, 2]) > MAX_ANGLE)
    if bad.any():
        i = int(np.argmax(bad))
        raise LogError(f"{chunk.where(i)}: the pose {poses[i].tolist()} is beyond {MAX_COORDINATE:g} m or "
                       f"{MAX_TURNS:g} turns here: an implausible log (a unit or time column misread?)")


def check_finite(log: JointLog) -> None:
    """Raise :class:`LogError` at the first time, joint position or heading of `log` that is not a finite number."""
    for name, values in (("time", log.time[:, None]), ("joint", log.positions)):
        bad = ~np.isfinite(values)
        if bad.any():
            i, c = (int(x) for x in np.argwhere(bad)[0])
            what = "time" if name == "time" else log.joints[c]
            raise LogError(f"{log.where(i)}: {what}: value {float(values[i, c])!r} is not a finite number")
    if log.heading_world is not None and not np.all(np.isfinite(log.heading_world)):
        i = int(np.flatnonzero(~np.isfinite(log.heading_world))[0])
        raise LogError(f"{log.where(i)}: heading: value {float(log.heading_world[i])!r} is not a finite number")
    steer = _steer_columns(log)
    far = np.abs(log.positions[:, steer]) > MAX_ANGLE
    if far.any():  # finite, but no angle to steer by: its sine and cosine are round-off
        i, c = (int(x) for x in np.argwhere(far)[0])
        raise LogError(f"{log.where(i)}: {log.joints[steer[c]]}: steering angle {float(log.positions[i, steer[c]])!r} "
                       f"rad is more than {MAX_TURNS:g} turns")


def _steer_columns(log: JointLog) -> list[int]:
    return [c for c, joint in enumerate(log.joints) if joint.endswith(".steer")]


class _Stats:
    def __init__(self) -> None:
        self.n, self.t0, self.t1, self.dist, self.rot, self.max_slip, self.sq_slip, self.max_dt = (0, 0.0, 0.0, 0.0,
                                                                                                   0.0, 0.0, 0.0, 0.0)

    def start(self, t0: float) -> None:
        self.n, self.t0, self.t1 = 1, float(t0), float(t0)

    def add(self, n: int, max_dt: float, t_last: float, sums: tuple[float, float, float, float]) -> None:
        """Account for `n` more intervals, their longest step and their path sums (:func:`_compose_chunk`)."""
        distance, rotation, max_slip, sq_slip = sums
        self.n += n
        self.t1 = t_last
        self.dist, self.rot, self.sq_slip = self.dist + distance, self.rot + rotation, self.sq_slip + sq_slip
        self.max_slip, self.max_dt = max(self.max_slip, max_slip), max(self.max_dt, max_dt)

    def summary(self, robot: str, method: str, pose: np.ndarray, cov: np.ndarray | None) -> OdometrySummary:
        rms = float(np.sqrt(self.sq_slip / (self.n - 1))) if self.n > 1 else 0.0
        final_cov = None if cov is None else tuple(tuple(float(v) for v in row) for row in cov)
        return OdometrySummary(robot, method, self.n, self.t0, self.t1, tuple(float(v) for v in pose),
                               self.dist, self.rot, self.max_slip, rms, self.max_dt, final_cov)
