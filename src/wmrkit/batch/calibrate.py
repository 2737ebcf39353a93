"""Fleet calibration: wheel radii and track fitted jointly from many logs, with confidence intervals.

The model is that of :mod:`wmrkit.odometry.calibration` (parameters are groups of ``WHEEL.FIELD`` names; lengths
scaled by ``1 + p``, angles offset by ``p``; :func:`~wmrkit.odometry.calibration.apply_parameters`). Here the
residuals of the runs are computed on the engine (runs split into one task per worker), so a fit over weeks of
logs uses the cluster, and the result carries confidence intervals:

- ``ci="jacobian"``: from the least-squares Jacobian at the solution (first order), with the covariance
  clustered by run (the "sandwich" estimator): errors along one trajectory accumulate, so its residuals are
  correlated and the textbook ``s^2 (J^T J)^-1`` is far too narrow (tested); runs are independent;
- ``ci="bootstrap"``: runs resampled with replacement, one refit per replicate (a task each), percentile
  intervals; needs no linearity and captures run-to-run variation (e.g. floors, loads).

Hook for slip weights: ``run_weights(run) -> (M,)`` multiplies the residuals of each referenced sample (e.g.
down-weights samples where a slip detector fires); the slip package plugs in there. Default: uniform.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..odometry.calibration import CalibrationRun, Parameter, apply_parameters
from ..robot import Robot
from .engine import BatchError, Engine, engine

RunWeights = Callable[[CalibrationRun], np.ndarray]


@dataclass(frozen=True)
class FleetCalibration:
    """A fleet fit: the calibrated ``robot``; per parameter ``estimate`` ``p`` and its ``interval`` ``(low,
    high)``; per wheel field ``values``: ``(name, nominal, fitted, low, high)`` [m or rad] at confidence
    ``level``; residual RMS before and after; ``runs``, ``residuals`` counts; ``ci`` the interval method."""

    robot: Robot
    parameters: tuple[tuple[str, ...], ...]
    estimate: tuple[float, ...]
    interval: tuple[tuple[float, float], ...]
    values: tuple[tuple[str, float, float, float, float], ...]
    rms_before: float
    rms_after: float
    runs: int
    residuals: int
    ci: str
    level: float
    success: bool

    def value(self, name: str) -> tuple[float, float, float]:
        """``(fitted, low, high)`` of the wheel field `name`."""
        for n, _, v, lo, hi in self.values:
            if n == name:
                return v, lo, hi
        raise BatchError(f"'{name}' was not calibrated (calibrated: {', '.join(v[0] for v in self.values)})")

    def to_dict(self) -> dict:
        """JSON-ready mapping."""
        return {"robot": self.robot.name, "ci": self.ci, "level": self.level, "runs": self.runs,
                "residuals": self.residuals, "rms_before": self.rms_before, "rms_after": self.rms_after,
                "success": self.success,
                "parameters": [{"group": list(g), "p": p, "low": lo, "high": hi}
                               for g, p, (lo, hi) in zip(self.parameters, self.estimate, self.interval, strict=True)],
                "values": [{"field": n, "nominal": a, "fitted": v, "low": lo, "high": hi}
                           for n, a, v, lo, hi in self.values]}


@dataclass(frozen=True)
class _Task:
    robot: Robot
    parameters: tuple[Parameter, ...]
    runs: tuple[CalibrationRun, ...]
    method: str
    heading_weight: float
    sensed: tuple[str, ...] | None
    weights: Mapping[str, float] | None
    run_weights: RunWeights | None


def run_residuals(task: _Task, p: np.ndarray) -> np.ndarray:
    """Residuals of `task`'s runs at parameters `p` (those of :func:`wmrkit.odometry.calibration.calibrate`:
    ``x, y`` error [m] and ``heading_weight`` times the wrapped heading error per referenced sample), each
    sample's three scaled by the run weight."""
    from ..odometry.model import odometry_model, wrap_angle
    from ..odometry.pipeline import odometry

    model = odometry_model(apply_parameters(task.robot, task.parameters, p), task.sensed, weights=task.weights)
    out = []
    for run in task.runs:
        poses = odometry(model, run.log, method=task.method, pose0=run.start()).poses[run.samples()]
        err = poses - np.asarray(run.reference, dtype=float).reshape(-1, 3)
        err[:, 2] = task.heading_weight * wrap_angle(err[:, 2])
        if task.run_weights is not None:
            err *= np.asarray(task.run_weights(run), dtype=float).reshape(-1, 1)
        out.append(err.ravel())
    return np.concatenate(out) if out else np.zeros(0)


def _residuals_of(args: tuple[_Task, np.ndarray]) -> np.ndarray:
    return run_residuals(*args)


def _fit(n: int, residuals: Callable[[np.ndarray], np.ndarray]):
    from scipy.optimize import least_squares

    return least_squares(residuals, np.zeros(n), method="lm", x_scale=1e-2, xtol=1e-14, ftol=1e-14)


def _refit(task: _Task) -> np.ndarray:
    """A bootstrap replicate: the fit over `task`'s runs, in one process."""
    return _fit(len(task.parameters), lambda p: run_residuals(task, p)).x


def fleet_calibrate(robot: Robot, runs: Sequence[CalibrationRun], parameters: Sequence[Parameter], *,
                    runner: Engine | None = None, ci: str = "jacobian", level: float = 0.95, n_boot: int = 200,
                    seed: int = 0, method: str = "exact", heading_weight: float = 1.0,
                    sensed: Sequence[str] | None = None, weights: Mapping[str, float] | None = None,
                    run_weights: RunWeights | None = None, progress: bool = False) -> FleetCalibration:
    """Fit `parameters` of `robot` to all `runs` at once (module docstring); intervals at `level`."""
    if not runs:
        raise BatchError("calibrate: no runs")
    if ci not in ("jacobian", "bootstrap"):
        raise BatchError(f"ci must be 'jacobian' or 'bootstrap', got '{ci}'")
    if not 0 < level < 1:
        raise BatchError(f"confidence level must be in (0, 1), got {level}")
    params = tuple(parameters)
    apply_parameters(robot, params, np.zeros(len(params)))  # names checked here, in the caller's process
    own = runner is None
    runner = engine(workers=0) if runner is None else runner
    try:
        make = lambda rs: _Task(robot, params, tuple(rs), method, heading_weight,  # noqa: E731
                                None if sensed is None else tuple(sensed), weights, run_weights)
        k = max(min(runner.workers, len(runs)), 1)
        tasks = [make(runs[i::k]) for i in range(k)]
        order = np.argsort(np.concatenate([np.arange(len(runs))[i::k] for i in range(k)]), kind="stable")

        def residuals(p: np.ndarray) -> np.ndarray:
            parts = runner.map(_residuals_of, [(t, p) for t in tasks])
            per_run = [r.reshape(-1, 3) for t, part in zip(tasks, parts, strict=True)
                       for r in np.split(part, np.cumsum([3 * len(run.samples()) for run in t.runs])[:-1])]
            return np.concatenate([per_run[i].ravel() for i in order])

        r0 = residuals(np.zeros(len(params)))
        m, n = r0.size, len(params)
        if m <= n:
            raise BatchError(f"calibrate: {m} residuals cannot fix {n} parameters with an interval; add runs")
        fit = _fit(n, residuals)
        if ci == "jacobian":
            lo, hi = _sandwich_interval(fit, [3 * len(run.samples()) for run in runs], level)
        else:
            rng = np.random.default_rng(seed)
            picks = [rng.integers(0, len(runs), len(runs)) for _ in range(n_boot)]
            reps = np.array(runner.map(_refit, [make([runs[i] for i in pick]) for pick in picks],
                                       progress=progress, desc="bootstrap"))
            lo, hi = np.quantile(reps, 0.5 - level / 2, axis=0), np.quantile(reps, 0.5 + level / 2, axis=0)
    finally:
        if own:
            runner.close()
    return _result(robot, params, fit, lo, hi, r0, len(runs), ci, level)


def _sandwich_interval(fit, sizes: Sequence[int], level: float) -> tuple[np.ndarray, np.ndarray]:
    """Interval from the least-squares Jacobian with the run-clustered ("sandwich") covariance
    ``(J^T J)^-1 (sum_g J_g^T r_g r_g^T J_g) (J^T J)^-1 G / (G - 1)``: the errors along one trajectory accumulate
    (they are correlated), runs are independent; Student's t with ``G - 1`` degrees of freedom."""
    from scipy import stats

    g = len(sizes)
    if g < 2:
        raise BatchError("calibrate: a confidence interval needs at least two runs")
    jtj = fit.jac.T @ fit.jac
    if np.linalg.cond(jtj) > 1e14:
        raise BatchError("calibrate: the runs cannot tell these parameters apart (singular Jacobian); add runs "
                         "of other shapes or fit fewer parameters")
    bread = np.linalg.inv(jtj)
    scores = np.array([fit.jac[a:b].T @ fit.fun[a:b] for a, b in zip(np.cumsum([0, *sizes[:-1]]), np.cumsum(sizes),
                                                                         strict=True)])
    cov = bread @ (scores.T @ scores) @ bread * g / (g - 1)
    half = float(stats.t.ppf(0.5 + level / 2, g - 1)) * np.sqrt(np.diag(cov))
    return fit.x - half, fit.x + half


def _result(robot: Robot, params, fit, lo, hi, r0, n_runs: int, ci: str, level: float) -> FleetCalibration:
    calibrated = apply_parameters(robot, params, fit.x)
    values = []
    for k, group in enumerate(params):
        at_lo = apply_parameters(robot, params, np.where(np.arange(len(params)) == k, lo[k], fit.x))
        at_hi = apply_parameters(robot, params, np.where(np.arange(len(params)) == k, hi[k], fit.x))
        for signed in (group,) if isinstance(group, str) else group:
            name = signed.lstrip("-")
            wheel, _, fld = name.partition(".")
            ends = sorted((float(getattr(at_lo.wheel(wheel), fld)), float(getattr(at_hi.wheel(wheel), fld))))
            values.append((name, float(getattr(robot.wheel(wheel), fld)), float(getattr(calibrated.wheel(wheel), fld)),
                           *ends))
    rms = lambda r: float(np.sqrt(np.mean(r * r)))  # noqa: E731
    groups = tuple((g,) if isinstance(g, str) else tuple(g) for g in params)
    return FleetCalibration(calibrated, groups, tuple(map(float, fit.x)),
                            tuple((float(a), float(b)) for a, b in zip(lo, hi, strict=True)), tuple(values),
                            rms(r0), rms(fit.fun), n_runs, int(r0.size), ci, level, bool(fit.success))


def default_parameters(robot: Robot, *, closed: bool) -> list[Parameter]:
    """Radii of the wheels with a sensed spin and the common scale of the wheel placement (``l``: the track of
    a differential drive); with only closed paths, the radius *ratio* of two such wheels instead of both radii
    (a closed path returns to its start at any scale)."""
    spun = [j.partition(".")[0] for j in robot.sensed if j.endswith(".spin")]
    placed = tuple(f"{w.name}.l" for w in robot.wheels if w.l > 0 and w.name in spun)
    if closed:
        if len(spun) != 2:
            raise BatchError(f"closed paths: give the parameters (--param) for robot '{robot.name}' "
                             f"(the default, the radius ratio, needs two spin encoders; it has {len(spun)})")
        return [(f"{spun[0]}.r", f"-{spun[1]}.r"), placed]
    return [f"{w}.r" for w in spun] + ([placed] if placed else [])


def load_run(robot: Robot, path: str, *, reference: str | os.PathLike[str] | None = None, closed: bool = False,
             options: Mapping[str, Any] | None = None) -> CalibrationRun:
    """A :class:`CalibrationRun` from a log file: with `reference` (a TUM or trajectory-CSV file) its poses at
    the log's samples with equal times (within 1 us); with `closed`, the final pose is the start (origin)."""
    from ..odometry.files import is_bag
    from ..odometry.logs import LogError, concatenate, load_csv
    from ..odometry.model import odometry_model
    from ..odometry.trajectories import read_trajectory_csv, read_tum

    options = dict(options or {})
    joints = odometry_model(robot, options.get("sensed")).joints
    if is_bag(path):
        from ..odometry.bags import read_joint_states

        log = concatenate(list(read_joint_states(path, joints, topic=options.get("topic", "/joint_states"),
                                                 names=options.get("joint_names"))))
    else:
        log = load_csv(path, joints, options["fmt"]) if "fmt" in options else load_csv(path, joints)
    if closed:
        return CalibrationRun(log, np.zeros((1, 3)), np.array([len(log) - 1]), (0.0, 0.0, 0.0))
    if reference is None:
        raise BatchError(f"{path}: needs a reference trajectory or --closed")
    ref = os.fspath(reference)
    if Path(ref).suffix.lower() == ".csv":
        traj = read_trajectory_csv(ref)
        t, poses = traj.time, traj.poses
    else:
        t, poses = read_tum(ref)
    idx = np.clip(np.searchsorted(log.time, t), 0, len(log) - 1)
    near = np.where(np.abs(log.time[np.maximum(idx - 1, 0)] - t) < np.abs(log.time[idx] - t), np.maximum(idx - 1, 0),
                    idx)
    bad = np.abs(log.time[near] - t) > 1e-6
    if bad.any():
        raise LogError(f"{ref}: reference time {float(t[np.flatnonzero(bad)[0]])!r} s is not a sample time of {path}")
    return CalibrationRun(log, poses, near)


def find_reference(log_path: str, folder: str | os.PathLike[str]) -> str:
    """The reference of a log in `folder`: ``STEM.tum``, ``STEM.txt`` or ``STEM.csv``."""
    stem = Path(log_path).stem
    for ext in (".tum", ".txt", ".csv"):
        candidate = Path(folder) / f"{stem}{ext}"
        if candidate.exists():
            return os.fspath(candidate)
    raise BatchError(f"{log_path}: no reference {stem}.tum/.txt/.csv in {os.fspath(folder)}")


def _load(args: tuple) -> CalibrationRun:
    return load_run(*args[:2], reference=args[2], closed=args[3], options=args[4])


def load_runs(robot: Robot, paths: Sequence[str], *, reference_dir: str | os.PathLike[str] | None = None,
              closed: bool = False, runner: Engine | None = None,
              options: Mapping[str, Any] | None = None) -> list[CalibrationRun]:
    """Runs of many logs, read on the engine (the first bad log raises its error)."""
    if (reference_dir is None) == (not closed):
        raise BatchError("give reference trajectories (a folder) or closed paths, one of the two")
    refs = [None if closed else find_reference(p, reference_dir) for p in paths]
    own = runner is None
    runner = engine(workers=0) if runner is None else runner
    try:
        out = runner.map(_load, [(robot, p, r, closed, dict(options or {})) for p, r in zip(paths, refs, strict=True)],
                         errors="return")
    finally:
        if own:
            runner.close()
    for p, run in zip(paths, out, strict=True):
        if not isinstance(run, CalibrationRun):
            raise BatchError(f"{p}: {run}" if p not in str(run) else str(run))
    return out

