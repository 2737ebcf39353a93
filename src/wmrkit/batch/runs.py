"""Runs of a fleet calibration read from log files: each log with its reference trajectory (found by the log's
name in a folder) or as a closed path (:func:`load_runs`, on the engine). :mod:`wmrkit.batch.calibrate` fits them
(and re-exports these functions, their first home)."""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..odometry.calibration import CalibrationRun
from ..robot import Robot, check_robot
from .engine import BatchError, Engine, engine


def load_run(robot: Robot, path: str, *, reference: str | os.PathLike[str] | None = None, closed: bool = False,
             options: Mapping[str, Any] | None = None) -> CalibrationRun:
    """A :class:`CalibrationRun` from a log file: with `reference` (a TUM or trajectory-CSV file) its poses at
    the log's samples with equal times (within 1 us), the run starting at the first of them (in the reference's
    frame); with `closed`, the final pose is the start (origin).
    `options`: ``sensed``; ``topic`` and ``joint_names`` (bags); ``fmt`` (a CSV layout), else ``header`` (settings
    of :func:`~wmrkit.odometry.header.header_format`: each CSV log is read as its header says)."""
    from ..odometry.files import is_bag
    from ..odometry.header import header_format
    from ..odometry.logs import LogError, concatenate, load_csv
    from ..odometry.model import odometry_model
    from ..odometry.trajectories import read_trajectory_csv, read_tum

    options = dict(options or {})
    joints = odometry_model(robot, options.get("sensed")).joints
    if is_bag(path):
        from ..odometry.bags import read_joint_states

        log = concatenate(list(read_joint_states(path, joints, topic=options.get("topic", "/joint_states"),
                                                 names=options.get("joint_names"), robot=robot)))
    else:
        fmt = options.get("fmt") or header_format(path, robot.name, joints, **options.get("header", {}))
        log = load_csv(path, joints, fmt, robot=robot)
    if closed:
        return CalibrationRun.closed_path(log)
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
    if len(near) < 2:  # its only pose is where the run starts: nothing to fit
        raise LogError(f"{ref}: {len(near)} pose: a reference needs two or more poses within the log")
    # the run starts at the first reference pose: a reference may start after the log, in its own frame (motion
    # capture), and the log's start pose is then unknown (taken as the origin, it biased the fit), as in
    # wmrkit.slip.calibration.calibrate_slip
    first = int(near.min())
    return CalibrationRun(log.slice(first, len(log)), poses, near - first)


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
              closed: bool = False, runner: Engine | None = None, options: Mapping[str, Any] | None = None,
              progress: bool = False) -> list[CalibrationRun]:
    """Runs of many logs, read on the engine (the first bad log raises its error; a tqdm bar with `progress`)."""
    check_robot(robot, BatchError)
    from ..odometry.model import odometry_model
    from .fleet import check_paths

    check_paths(paths, "paths")
    if (reference_dir is None) == (not closed):
        raise BatchError("give reference trajectories (a folder) or closed paths, one of the two")
    odometry_model(robot, (options or {}).get("sensed"))  # sensed joints that cannot work: theirs, not the 1st log's
    refs = [None if closed else find_reference(p, reference_dir) for p in paths]
    owner: dict[str, str] = {}  # a reference is one run's truth: two logs of one name (robot1/run.csv, robot2/...)
    for p, r in zip(paths, refs, strict=True):
        if r is not None and owner.setdefault(os.path.realpath(r), p) != p:
            raise BatchError(f"{p}: its reference {r} is also that of {owner[os.path.realpath(r)]} (a log's reference "
                             "is DIR/NAME.tum by the log's name): give the logs names of their own")
    own = runner is None
    runner = engine(workers=0) if runner is None else runner
    try:
        out = runner.map(_load, [(robot, p, r, closed, dict(options or {})) for p, r in zip(paths, refs, strict=True)],
                         errors="return", progress=progress, desc="logs")
    finally:
        if own:
            runner.close()
    for p, run in zip(paths, out, strict=True):
        if not isinstance(run, CalibrationRun):
            raise BatchError(f"{p}: {run}" if p not in str(run) else str(run))
    return out


def copies(runs: Sequence[CalibrationRun]) -> list[tuple[int, int]]:
    """``(k, first)`` for each run `k` whose samples (times and joint positions) equal those of an earlier run
    `first`: a copy of one log, or a link to it, under another name."""
    seen: dict[str, int] = {}
    found = []
    for k, run in enumerate(runs):
        digest = hashlib.sha1(np.ascontiguousarray(run.log.time).tobytes()
                              + np.ascontiguousarray(run.log.positions).tobytes()).hexdigest()
        if (first := seen.setdefault(digest, k)) != k:
            found.append((k, first))
    return found


def copy_warning(logs: Sequence[str], k: int, first: int, counted: str = "noise is counted twice") -> str:
    """The warning naming run `k` as a copy of run `first` (`logs`: the runs' names), what of it is `counted`."""
    return (f"{logs[k]}: the same samples as {logs[first]} (a copy of one log, or a link to it): its {counted} and "
            "the intervals are too narrow; give each log once")


def repeated_runs(problem, residuals: np.ndarray) -> tuple[str, ...]:
    """A warning per run whose samples equal an earlier run's (:func:`copies`) when its residuals at the fit exceed
    round-off: one run's noise counted as two runs' (3 of 6 runs copied narrowed an interval by 36 %). Runs that
    fit exactly (noise-free, simulated) change nothing however often they are given, and are not named. `problem`:
    the fleet's ``CalibrationProblem``."""
    from .consistency import ROUNDOFF, names, travel

    logs = names(problem.runs)
    parts = np.split(np.asarray(residuals, dtype=float), np.cumsum(problem.sizes())[:-1])
    return tuple(copy_warning(logs, k, first) for k, first in copies(problem.runs)
                 if np.sqrt(np.mean(parts[k] ** 2)) > ROUNDOFF * travel(problem.robot, problem.runs[k]))
