"""Odometry over a log, streaming: chunks of joint samples in, poses (slip, covariance) out, bounded memory.

Per chunk: the sensed direct model (:mod:`.model`) gives body increments between consecutive samples, the chosen
scheme (:mod:`.integrators`) composes them from the pose carried over from the previous chunk, and the
covariance (:mod:`.covariance`) is propagated from the carried covariance. The last sample of each chunk is kept
to difference against the next, so the result does not depend on the chunk size (to round-off).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_vectors
from ..robot import Robot
from .covariance import CrowleyNoise, JointNoise, propagate_covariance
from .integrators import Method, check_method, integrate_increments
from .logs import JointLog, LogError, check_time
from .model import ModelIncrements, OdometryModel, odometry_model
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
    distance: float
    rotation: float
    max_slip: float
    rms_slip: float
    max_dt: float
    final_covariance: tuple[tuple[float, ...], ...] | None = None

    def to_dict(self) -> dict:
        """JSON-ready mapping; ``pose`` is the final pose ``[x, y, theta]``."""
        return {"robot": self.robot, "method": self.method, "pose": list(self.final_pose), "samples": self.samples,
                "start_time": self.start_time, "end_time": self.end_time, "distance": self.distance,
                "rotation": self.rotation, "max_slip": self.max_slip, "rms_slip": self.rms_slip,
                "max_dt": self.max_dt,
                "covariance": None if self.final_covariance is None else [list(r) for r in self.final_covariance]}


def run_odometry(model: OdometryModel, chunks: Iterable[JointLog], *, method: Method = "exact",
                 pose0: ArrayLike = (0.0, 0.0, 0.0), noise: Noise | None = None,
                 initial_covariance: ArrayLike | None = None,
                 sinks: Sequence[Callable[[Trajectory], object]] = ()) -> OdometrySummary:
    """Integrate a stream of log chunks; every sink is called with each :class:`Trajectory` chunk (002 (22)).

    `pose0` is the pose at the first sample. With an external heading in the log, the heading's *changes* are
    used: ``theta = pose0[2] + heading - heading[0]``. `noise` (Crowley's model of 003 (17) generalised, or
    per-joint noise through the robot's kinematics) turns on covariance propagation from `initial_covariance`.
    """
    check_method(method)
    pose = as_vectors(pose0, 3, "pose0").copy()
    if pose.shape != (3,):
        raise LogError(f"pose0: expected one pose (3,), got {pose.shape}")
    cov = None if noise is None else (np.zeros((3, 3)) if initial_covariance is None
                                      else np.array(initial_covariance, dtype=float))
    prev: JointLog | None = None
    heading0 = 0.0
    stats = _Stats()
    for raw in chunks:
        chunk = raw.select(model.joints)
        if len(chunk) == 0:
            continue
        check_time(chunk, chunk.time, None if prev is None else float(prev.time[-1]), None)
        _check_finite(chunk)
        if prev is None:
            heading0 = 0.0 if chunk.heading_world is None else float(chunk.heading_world[0]) - pose[2]
            stats.start(chunk.time[0])
            first = Trajectory(chunk.time[:1], pose[None].copy(), np.zeros(1), None if cov is None else cov[None])
            for sink in sinks:
                sink(first)
            prev, chunk = chunk.slice(0, 1), chunk.slice(1, len(chunk))
            if len(chunk) == 0:
                continue
        positions = np.vstack([prev.positions[-1:], chunk.positions])
        inc = model.from_positions(positions)
        heading = None
        if chunk.heading_world is not None:
            if prev.heading_world is None:
                raise LogError(f"{chunk.where(0)}: external heading starts in the middle of the log")
            heading = np.concatenate([prev.heading_world[-1:], chunk.heading_world]) - heading0
        steps = inc.increments_robot if heading is None else _with_heading(inc, heading)
        poses = integrate_increments(pose, steps, method, heading_world=heading)
        covs = None
        if cov is not None:
            q = _increment_covariance(noise, inc, steps)
            covs = propagate_covariance(np.vstack([pose[None], poses]), steps, q, method, initial=cov)
            cov = covs[-1]
        out = Trajectory(chunk.time, poses, inc.slip, covs)
        for sink in sinks:
            sink(out)
        stats.add(np.concatenate([prev.time[-1:], chunk.time]), steps, inc.slip)
        pose, prev = poses[-1].copy(), chunk.slice(len(chunk) - 1, len(chunk))
    if prev is None:
        raise LogError("the log has no samples")
    return stats.summary(model.robot.name, method, pose, cov)


def odometry(robot: Robot | OdometryModel, log: JointLog, *, method: Method = "exact",
             pose0: ArrayLike = (0.0, 0.0, 0.0), noise: Noise | None = None,
             initial_covariance: ArrayLike | None = None, chunk_size: int = 1 << 16) -> Trajectory:
    """The trajectory of `robot` over an in-memory `log` (see :func:`run_odometry`): one pose per sample.

    `robot` may be an :class:`OdometryModel` to choose the sensed joints (default: ``robot.sensed``).
    """
    model = robot if isinstance(robot, OdometryModel) else odometry_model(robot)
    parts: list[Trajectory] = []
    chunks = (log.slice(i, i + chunk_size) for i in range(0, max(len(log), 1), chunk_size))
    run_odometry(model, chunks, method=method, pose0=pose0, noise=noise, initial_covariance=initial_covariance,
                 sinks=[parts.append])
    return join(parts)


def join(parts: Sequence[Trajectory]) -> Trajectory:
    """Trajectory chunks joined in order."""
    cov = None if parts[0].covariance is None else np.concatenate([p.covariance for p in parts])
    return Trajectory(np.concatenate([p.time for p in parts]), np.concatenate([p.poses for p in parts]),
                      np.concatenate([p.slip for p in parts]), cov)


class Decimator:
    """A sink keeping at most about `max_points` poses of a stream (every k-th, k doubling as needed)."""

    def __init__(self, max_points: int = 100_000) -> None:
        self.max_points, self.stride, self._seen = max_points, 1, 0
        self._time: list[np.ndarray] = []
        self._poses: list[np.ndarray] = []

    def __call__(self, chunk: Trajectory) -> None:
        """Take the poses of `chunk` that fall on the stride."""
        idx = np.flatnonzero((np.arange(self._seen, self._seen + len(chunk)) % self.stride) == 0)
        self._seen += len(chunk)
        self._time.append(chunk.time[idx])
        self._poses.append(chunk.poses[idx])
        if sum(map(len, self._time)) > self.max_points:
            t, p = np.concatenate(self._time), np.concatenate(self._poses)
            keep = np.arange(len(t)) % 2 == 0  # kept samples are multiples of the stride: keep every other
            self._time, self._poses, self.stride = [t[keep]], [p[keep]], self.stride * 2

    def result(self) -> tuple[np.ndarray, np.ndarray]:
        """Times ``(M,)`` and poses ``(M, 3)`` kept."""
        return np.concatenate(self._time), np.concatenate(self._poses)


def _with_heading(inc: ModelIncrements, heading: np.ndarray) -> np.ndarray:
    steps = inc.increments_robot.copy()
    steps[:, 2] = np.diff(heading)
    return steps


def _increment_covariance(noise: Noise, inc: ModelIncrements, steps: np.ndarray) -> np.ndarray:
    if isinstance(noise, CrowleyNoise):
        return noise.increment_covariance(steps)
    return np.broadcast_to(noise.increment_covariance(inc.twist_map, inc.rate_increments), (len(steps), 3, 3))


def _check_finite(log: JointLog) -> None:
    for name, values in (("time", log.time[:, None]), ("joint", log.positions)):
        bad = ~np.isfinite(values)
        if bad.any():
            i, c = (int(x) for x in np.argwhere(bad)[0])
            what = "time" if name == "time" else log.joints[c]
            raise LogError(f"{log.where(i)}: {what}: value {float(values[i, c])!r} is not a finite number")
    if log.heading_world is not None and not np.all(np.isfinite(log.heading_world)):
        i = int(np.flatnonzero(~np.isfinite(log.heading_world))[0])
        raise LogError(f"{log.where(i)}: heading: value {float(log.heading_world[i])!r} is not a finite number")


class _Stats:
    def __init__(self) -> None:
        self.n, self.t0, self.t1, self.dist, self.rot, self.max_slip, self.sq_slip, self.max_dt = (0, 0.0, 0.0, 0.0,
                                                                                                   0.0, 0.0, 0.0, 0.0)

    def start(self, t0: float) -> None:
        self.n, self.t0, self.t1 = 1, float(t0), float(t0)

    def add(self, time: np.ndarray, steps: np.ndarray, slip: np.ndarray) -> None:
        self.n += len(steps)
        self.t1 = float(time[-1])
        self.dist += float(np.hypot(steps[:, 0], steps[:, 1]).sum())
        self.rot += float(np.abs(steps[:, 2]).sum())
        self.max_slip = max(self.max_slip, float(slip.max()))
        self.sq_slip += float(np.dot(slip, slip))
        self.max_dt = max(self.max_dt, float(np.diff(time).max()))

    def summary(self, robot: str, method: str, pose: np.ndarray, cov: np.ndarray | None) -> OdometrySummary:
        rms = float(np.sqrt(self.sq_slip / (self.n - 1))) if self.n > 1 else 0.0
        final_cov = None if cov is None else tuple(tuple(float(v) for v in row) for row in cov)
        return OdometrySummary(robot, method, self.n, self.t0, self.t1, tuple(float(v) for v in pose),
                               self.dist, self.rot, self.max_slip, rms, self.max_dt, final_cov)
