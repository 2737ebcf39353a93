"""Batch odometry over a fleet's logs: every log through :func:`wmrkit.odometry.files.odometry_file`, in parallel.

One row per log (:data:`SUMMARY_SCHEMA`, Parquet): the final pose as columns ``x, y, theta``, duration, path
length, closure error for closed paths, slip statistics, warnings, whether the log is consistent (as ``wmrkit
odometry`` says), the error when the log failed. A log that fails is recorded with its error and the batch goes on;
a rerun with the same output skips logs already done (an error row is retried) and redoes a log whose trajectory
file is missing.

The serial engine and the workers run the same function, :func:`process_log`, on the same :class:`LogJob`s: a
path (the worker reads the file itself; only a summary row comes back) and the odometry model, built once for
the batch. The logs go out to the workers in tasks of up to 64 (:func:`~.engine.chunk_spans`).
"""

from __future__ import annotations

import glob
import hashlib
import math
import os
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..odometry.logs import LogFormat
from ..robot import Robot
from .engine import BatchError, Engine, TaskFailure, engine
from .parquet import RowSink, check_table, parts_dir, read_rows, stored_text

if TYPE_CHECKING:
    from ..odometry.diagnostics import Diagnosis, ImuCheck
    from ..odometry.model import OdometryModel
    from ..odometry.pipeline import OdometrySummary
    from ..slip.estimators import EstimatorSpec
    from ..slip.kalman import KalmanNoise
    from ..slip.weights import SlipWeights

#: Columns of the batch-odometry table (name, type and unit, :data:`.parquet.Schema`).
SUMMARY_SCHEMA = (
    ("log", "string"), ("robot", "string"), ("method", "string"), ("samples", "int64"),
    ("start_time", "float64 s"), ("duration", "float64 s"), ("x", "float64 m"), ("y", "float64 m"),
    ("theta", "float64 rad"), ("path_length", "float64 m"), ("rotation", "float64 rad"),
    ("closure_error", "float64 m"), ("closure_heading", "float64 rad"), ("max_slip", "float64 m"),
    ("rms_slip", "float64 m"), ("max_dt", "float64 s"), ("warnings", "string"), ("consistent", "bool"),
    ("error", "string"), ("trajectory", "string"), ("wall_time", "float64 s"), ("settings", "string"),
    ("imu", "string"), ("imu_mount", "string"),
)
#: Columns a table must have to be a batch-odometry table at all (an older one lacks some others: it is redone).
KEY_COLUMNS = ("log", "robot", "method", "error", "trajectory")
#: Version of what a row holds, in its settings digest: a row of an older version is redone (2: odometry's
#: diagnostic lines in ``warnings``; 3: ``consistent``, which part files of a version-2 run lack; 4: a bag's IMU
#: check in ``warnings`` and ``consistent``, its topic in ``imu``; 5: a named IMU that cannot be used is the log's
#: error, no longer a warning; 6: the IMU's line says when the IMU looks upside down or in deg/s; 7: the IMU's
#: mounting in ``imu_mount``, a filter's conditioning line in ``warnings``).
ROW_VERSION = 7
#: Suffixes of single-file logs found in a folder (CSV joint logs, ROS 2 bag files).
LOG_SUFFIXES = (".csv", ".db3", ".mcap")


@dataclass(frozen=True)
class LogJob:
    """What one task does: odometry of the log at ``path`` with the options of :func:`batch_odometry`."""

    path: str
    robot: Robot
    method: str = "exact"
    trajectory: str | None = None
    closed: bool = False
    slip_warning: float | None = None  # an absolute slip threshold [m per interval] besides odometry's rule
    options: Mapping[str, Any] = field(default_factory=dict)  # more keyword arguments of odometry_file
    model: Any = None  # the odometry model, built once per batch (else per log, from options' sensed/weights)
    header: Mapping[str, Any] | None = None  # without options["fmt"]: a CSV log's format from its header and these
    imu: str | None = None  # a bag's Imu topic checking its heading, named (else the bag's only one, found)
    imu_mount: tuple[float, float, float] | None = None  # the IMU's (roll, pitch, yaw) [rad], over /tf_static's
    imu_mount_option: str = "imu_mount="  # the door's name of imu_mount, in the row's imu_mount and its lines
    estimator: EstimatorSpec | None = None  # a slip-aware estimator, built per log (method: its scheme)


@dataclass(frozen=True)
class FleetResult:
    """A batch: ``rows`` (one mapping per log, input order, :data:`SUMMARY_SCHEMA`), how many were ``skipped``
    (done by an earlier run) and how many ``failed``."""

    rows: tuple[Mapping[str, Any], ...]
    skipped: int
    failed: int

    @property
    def inconsistent(self) -> tuple[str, ...]:
        """The logs done whose diagnostics say inconsistent (``consistent`` false: ``wmrkit odometry``'s verdict)."""
        return tuple(r["log"] for r in self.rows if r["consistent"] is False and not r["error"])

    def to_dict(self) -> dict:
        """JSON-ready summary of the batch."""
        return {"logs": len(self.rows), "skipped": self.skipped, "failed": self.failed,
                "inconsistent": len(self.inconsistent), "inconsistent_logs": list(self.inconsistent),
                "errors": {r["log"]: r["error"] for r in self.rows if r["error"]}}


def check_paths(paths: object, what: str = "logs") -> None:
    """Refuse one path given where a sequence of them is expected: a string was read as the paths of its
    characters ('l: no such file or folder'), a :class:`~pathlib.Path` raised TypeError."""
    if isinstance(paths, str | os.PathLike):
        raise BatchError(f"{what}: expected a sequence of files, globs or folders, got the single path "
                         f"'{os.fspath(paths)}' (write ['{os.fspath(paths)}'])")


def expand_logs(patterns: Sequence[str | os.PathLike[str]]) -> list[str]:
    """Log paths from files, globs and folders (in order, each once). A folder holding a ROS 2 bag
    (``metadata.yaml``) is one log; another folder gives its CSV/bag files and bag sub-folders, sorted."""
    check_paths(patterns)
    out: list[str] = []
    for pattern in map(os.fspath, patterns):
        matches = sorted(glob.glob(pattern)) if glob.has_magic(pattern) else [pattern]
        if not matches:
            raise BatchError(f"{pattern}: no file matches")
        for m in matches:
            p = Path(m)
            if not p.exists():
                raise BatchError(f"{m}: " + ("a symbolic link to nothing (its target is missing, or a loop of links)"
                                             if p.is_symlink() else "no such file or folder"))  # ls lists a link
            if not (p.is_file() or p.is_dir()):  # a FIFO: reading it waited for a writer forever
                raise BatchError(f"{m}: not a regular file or folder (a FIFO, socket or device)")
            if p.is_dir() and not (p / "metadata.yaml").exists():
                found = [os.fspath(c) for c in sorted(p.iterdir())
                         if (c.is_file() and c.suffix.lower() in LOG_SUFFIXES)
                         or (c.is_dir() and (c / "metadata.yaml").exists())]
                if not found:  # else an empty batch "succeeded" with exit 0
                    raise BatchError(f"{m}: no logs in the folder (CSV, .db3 or .mcap files, or ROS 2 bag folders)")
                out.extend(found)
            else:
                out.append(m)
    # one log given twice (logs/a.csv and ./logs/a.csv) is run once: twice, both runs wrote one trajectory file
    first: dict[str, str] = {}
    for m in out:
        first.setdefault(os.path.normcase(os.path.abspath(m)), m)
    return list(first.values())


def process_log(job: LogJob) -> dict[str, Any]:
    """Odometry of one log to its summary row; never raises (an error becomes the row's ``error``)."""
    from ..odometry.files import is_bag, odometry_file
    from ..odometry.header import header_format
    from ..odometry.model import odometry_model
    from ..slip.estimators import KalmanEstimator

    row: dict[str, Any] = {name: None for name, _ in SUMMARY_SCHEMA}
    row.update(log=job.path, robot=job.robot.name, method=job.estimator.label if job.estimator else job.method,
               trajectory=job.trajectory)
    t0 = time.perf_counter()
    unread = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            options = dict(job.options)
            model = job.model or odometry_model(job.robot, options.get("sensed"), weights=options.get("weights"))
            if job.header is not None and not is_bag(job.path):  # each log says its units (odometry's rule)
                options["fmt"] = header_format(job.path, job.robot.name, model.joints, **job.header)
            check, unread = _imu_check(job, model)  # made here, in the worker: only the row goes back
            estimator = job.estimator.build(job.robot) if job.estimator else None
            s = odometry_file(job.robot, job.path, method=job.method, out=job.trajectory, model=estimator or model,
                              sinks=[check] if check else (), check=check.judge if check else None, **options)
            diagnosis = _diagnose(job, s, model, options)
            filtered = estimator.notes() if isinstance(estimator, KalmanEstimator) else []
        except Exception as err:  # what was said before it failed stays said (wmrkit odometry says it too)
            if unread and " ".join(unread.split()).startswith(_message(err)):  # the bag itself unreadable: said once,
                unread = None  # as wmrkit odometry says it (its IMU's note repeated the error, the name twice)
            said = [" ".join(str(w.message).split()) for w in caught] + ([unread] if unread else [])
            row.update(error=_message(err), trajectory=None, warnings="; ".join(said) or None,
                       wall_time=time.perf_counter() - t0)
            return row
    x, y, theta = s.final_pose
    # a filter's notes (its rows barely fixing the twist at a steering heading of this log, its period), then the
    # diagnosis, in wmrkit odometry's order
    notes = [" ".join(str(w.message).split()) for w in caught] + filtered + list(diagnosis.warnings)
    imu = check.topic if check and check.checked else None
    if check and check.mounting.note:  # the given mounting and the bag's /tf_static disagree
        notes.append(check.mounting.note)
    if line := check.line if check else unread:  # after diagnose's lines, as wmrkit odometry says them
        notes.append(line)
    if job.slip_warning is not None and s.max_slip > job.slip_warning:
        notes.append(f"slip indicator up to {s.max_slip:.3g} m per interval (threshold {job.slip_warning:g} m)")
    if s.samples < 2:
        notes.append("a single sample: no motion")
    row.update(samples=s.samples, start_time=s.start_time, duration=s.end_time - s.start_time, x=x, y=y, theta=theta,
               path_length=s.path_length, rotation=s.rotation, max_slip=s.max_slip, rms_slip=s.rms_slip,
               max_dt=s.max_dt, warnings="; ".join(notes) or None, imu=imu,
               imu_mount=check.mounting.source if imu else None,
               consistent=diagnosis.consistent and not (imu and check.line), wall_time=time.perf_counter() - t0)
    if job.closed:  # the run ends where it started (the start pose is the origin)
        row.update(closure_error=math.hypot(x, y), closure_heading=float(np.angle(np.exp(1j * theta))))
    return row


def _imu_check(job: LogJob, model: OdometryModel) -> tuple[ImuCheck | None, str | None]:
    """``wmrkit odometry``'s IMU check of a bag's run (:func:`~wmrkit.odometry.diagnostics.imu_check`): on the
    batch's `job.imu` topic, else the bag's only ``Imu`` topic, judging the run of `model` (named as that command
    names it, but by this door's option: "weighted no-slip (weights=)" when its rows are weighted, which only
    :func:`batch_odometry`'s `weights` does, ``wmrkit batch odometry`` having no ``--weight``); ``(None, None)`` for
    a CSV log or a bag without one, ``(None, the line saying none is checked)`` for a bag with several and no
    `job.imu`. As in that command, a named IMU that cannot be used (not in the bag, not an ``Imu``, unreadable, or
    its stamps missing the run's: raised by the check after the run) is a :class:`~wmrkit.odometry.logs.LogError`,
    the log's error; one found by itself is ``(None, the line saying the log is not checked against it)``."""
    from ..odometry.bags import imu_topic
    from ..odometry.diagnostics import imu_check, odometry_name
    from ..odometry.files import is_bag
    from ..odometry.logs import LogError

    if not is_bag(job.path):
        return None, None
    named = job.imu is not None
    try:
        topic, note = imu_topic(job.path, job.imu)
    except LogError as err:
        if named:
            raise
        return None, f"{err} (the odometry is not checked against it)"
    if topic is None:  # several Imu topics (a warning, as wmrkit odometry's), or none (nothing to say)
        return None, note
    what = odometry_name(job.estimator.name if job.estimator else None,
                         "weights=" if np.any(np.asarray(model.row_weights) != 1.0) else None)
    return imu_check(job.path, topic, what, named=named, mount=job.imu_mount,
                     mount_option=job.imu_mount_option)


def _diagnose(job: LogJob, s: OdometrySummary, model: OdometryModel, options: Mapping[str, Any]) -> Diagnosis:
    """``wmrkit odometry``'s diagnostics of the log's run `s` (:func:`~wmrkit.odometry.diagnostics.diagnose`: slip per
    wheel, external heading, gears, steering steps), over its first samples, read only when a check needs them."""
    from ..odometry.diagnostics import diagnose
    from ..odometry.files import first_samples

    reading = {k: options[k] for k in ("fmt", "topic", "joint_names") if k in options}
    filtered = job.estimator.name if job.estimator and job.estimator.name != "wls" else None
    return diagnose(s, model, lambda: first_samples(job.robot, job.path, model.joints, **reading), options.get("fmt"),
                    filtered=filtered)


def batch_odometry(robot: Robot, logs: Sequence[str | os.PathLike[str]], *, runner: Engine | None = None,
                   method: str = "exact", out: str | os.PathLike[str] | None = None,
                   trajectories: str | os.PathLike[str] | None = None, trajectory_format: str = "tum",
                   closed: bool = False, resume: bool = True, progress: bool = False, slip_warning: float | None = None,
                   fmt: LogFormat | None = None, header: Mapping[str, Any] | None = None,
                   topic: str = "/joint_states", joint_names: Mapping[str, str] | None = None,
                   sensed: Sequence[str] | None = None, weights: Mapping[str, float] | None = None,
                   imu: str | None = None, imu_mount: Sequence[float] | None = None,
                   imu_mount_option: str = "imu_mount=", scheme: str | None = None,
                   slip_weights: SlipWeights | None = None, noise: KalmanNoise | None = None,
                   thesis_double_q: bool = False) -> FleetResult:
    """Odometry of every log in `logs` (files, globs, folders; :func:`expand_logs`) on `runner` (default: a
    serial engine); the table is written to `out` (Parquet) and each trajectory to `trajectories`/``NAME.EXT`` (the
    folder made when missing).

    `closed`: every run ends at its start (the closure error is reported). `fmt` (CSV layout), `topic` and
    `joint_names` (bags), `sensed` and `weights` go to :func:`~wmrkit.odometry.files.odometry_file`. Without
    `fmt`, each CSV log is read as its header says (units in brackets, :func:`~wmrkit.odometry.header.header_format`
    with the settings `header`, e.g. ``{"time_unit": "ms"}``), as ``wmrkit odometry`` reads one.
    With `resume`, rows of `out` (and of its part files) without error are kept and their logs skipped.
    Each row's ``warnings`` are ``wmrkit odometry``'s lines for its log (:mod:`wmrkit.odometry.diagnostics`), and
    with `slip_warning` [m] a note where the slip indicator exceeds it; its ``consistent`` is that command's verdict.
    A bag's IMU checks its heading as there: the `imu` topic, else the bag's only ``Imu`` topic; its ``imu`` column
    says the topic checked. An IMU found by itself that cannot be used is a warning line; a named `imu` that a bag
    lacks or that cannot be used is that log's error (the other logs run), as ``wmrkit odometry --imu`` refuses it.
    `imu_mount` ``(roll, pitch, yaw)`` [rad]: the IMU's mounting, over each bag's ``/tf_static`` (its ``imu_mount``
    column says where each row's came from, `imu_mount_option` naming this one).

    `method` ``wls``, ``fk1`` or ``fk2``: the slip-aware estimators of ``wmrkit odometry --method`` (thesis §7.4-7.5),
    WLS with the friction coefficients `slip_weights`, a filter with `noise` (and `thesis_double_q`), their twists
    integrated by `scheme` (default exact; rows say ``fk2 (exact)``); each log gets its own estimator.
    """
    from ..odometry.files import is_bag
    from ..odometry.model import odometry_model

    spec = _estimator_spec(robot, method, scheme, sensed, weights, slip_weights, noise, thesis_double_q)
    label = spec.label if spec else method  # each row's method
    if slip_warning is not None and not (isinstance(slip_warning, int | float) and math.isfinite(slip_warning)
                                         and slip_warning >= 0):
        raise BatchError(f"slip_warning must be a finite length >= 0 m, got {slip_warning!r}")  # NaN: never warned
    model = odometry_model(robot, sensed, weights=weights)  # once: the same for every log (a bad --sensed fails here)
    options = {"topic": topic, "joint_names": joint_names}
    if fmt is not None:
        options["fmt"] = fmt
        if header:
            raise BatchError("batch odometry: give fmt (a whole CSV layout) or header settings, not both")
    header = None if fmt is not None else dict(header or {})
    paths = expand_logs(logs)
    if not paths:
        raise BatchError("batch odometry: no logs given")
    if imu is not None and not any(is_bag(p) for p in paths):  # it would be ignored
        raise BatchError(f"--imu {imu} applies to ROS 2 bags; none of the {len(paths)} logs is one")
    if imu_mount is not None:
        from ..odometry.imu_mount import quaternion_rpy

        quaternion_rpy(imu_mount, imu_mount_option.rstrip("="))  # three finite angles, else refused by that name
        imu_mount = tuple(float(a) for a in imu_mount)
        if not any(is_bag(p) for p in paths):  # it would be ignored
            raise BatchError(f"{imu_mount_option.rstrip('=')} applies to the IMU of ROS 2 bags; none of the "
                             f"{len(paths)} logs is one")
    if out is not None and not Path(out).absolute().parent.is_dir():
        raise BatchError(f"--out {os.fspath(out)}: the folder {Path(out).absolute().parent} does not exist")
    if out is not None and Path(out).is_dir():  # else refused only when the table is written, after the work
        raise BatchError(f"--out {os.fspath(out)}: a folder, not a file")
    if out is not None and parts_dir(out).exists() and not parts_dir(out).is_dir():  # else it failed after the work
        raise BatchError(f"--out {os.fspath(out)}: {parts_dir(out)} is a file; the batch keeps its part files (resume "
                         "points) in a folder of that name")
    if trajectories is not None:  # made with its parents when missing, as every output folder of the CLI
        try:
            Path(trajectories).mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise BatchError(f"--trajectories {os.fspath(trajectories)}: cannot make the folder "
                             f"({err.strerror or err})") from None
    if trajectory_format not in ("csv", "tum"):
        raise BatchError(f"trajectory format must be csv or tum, got '{trajectory_format}'")
    targets = _trajectory_names(paths, trajectories, trajectory_format)
    batch = _fingerprint(robot, method, closed, slip_warning, options, header, sensed, weights, imu, ROW_VERSION,
                         imu_mount, spec)
    settings = {p: _fingerprint(batch, _stat(p)) for p in paths}
    # an existing --out must be a table of this command (it is replaced at the end), even without resuming
    current = check_table(out, SUMMARY_SCHEMA, KEY_COLUMNS) if out is not None and Path(out).is_file() else True
    done = _done(out, robot, label, targets, settings) if resume and out is not None and current else {}
    jobs = [LogJob(p, robot, spec.scheme if spec else method, targets[p], closed, slip_warning, options, model, header,
                   imu, imu_mount, imu_mount_option, spec) for p in paths if p not in done]
    sink = RowSink(out, SUMMARY_SCHEMA)
    rows: dict[str, Mapping[str, Any]] = dict(done)
    own = runner is None
    runner = engine(workers=0) if runner is None else runner
    try:
        chunk = max(1, min(64, len(jobs) // (4 * runner.workers)))  # up to 64 logs per task, fewer at the end
        for index, row in runner.as_completed(process_log, jobs, progress=progress, desc="logs", chunk=chunk):
            if isinstance(row, TaskFailure):  # the worker died more often than the scheduler allows
                row = {name: None for name, _ in SUMMARY_SCHEMA} | {"log": jobs[index].path, "robot": robot.name,
                                                                     "method": label, "error": str(row)}
            row = dict(row) | {"settings": settings[row["log"]]}
            rows[row["log"]] = row
            sink.add(row)
    finally:
        if own:
            runner.close()
        sink.flush()
    ordered = tuple(rows[p] for p in paths)
    sink.finish(ordered)
    return FleetResult(ordered, len(done), sum(1 for r in ordered if r["error"]))


def _estimator_spec(robot: Robot, method: str, scheme: str | None, sensed: Sequence[str] | None,
                    weights: Mapping[str, float] | None, slip_weights: SlipWeights | None, noise: KalmanNoise | None,
                    thesis_double_q: bool) -> EstimatorSpec | None:
    """The slip-aware estimator of :func:`batch_odometry`'s `method` (built once here: a bad one fails before any
    log), None for a no-slip scheme; an option the method does not use is refused (it would be ignored)."""
    from ..odometry.integrators import METHODS, check_method
    from ..slip.estimators import ESTIMATORS, EstimatorSpec

    uses = {"scheme": ESTIMATORS, "slip_weights": ("wls",), "noise": ("fk1", "fk2"), "thesis_double_q": ("fk1", "fk2"),
            "weights": METHODS}
    for name, value in (("scheme", scheme), ("slip_weights", slip_weights), ("noise", noise),
                        ("thesis_double_q", thesis_double_q), ("weights", weights)):
        if value and method not in uses[name]:
            where = "the no-slip methods" if name == "weights" else f"method {' or '.join(uses[name])}"
            raise BatchError(f"{name}= applies to {where}, not to method {method} (it would be ignored)")
    if method not in ESTIMATORS:
        check_method(method)  # type: ignore[arg-type]
        return None
    check_method(scheme or "exact")  # type: ignore[arg-type]
    spec = EstimatorSpec(method, scheme or "exact", None if sensed is None else tuple(sensed), slip_weights, noise,
                         thesis_double_q)  # type: ignore[arg-type]
    spec.build(robot)
    return spec


def _done(out, robot: Robot, method: str, targets: Mapping[str, str | None],
          settings: Mapping[str, str]) -> dict[str, Mapping[str, Any]]:
    """Rows of an earlier run that need no redoing: same log, robot and method, made with the same settings
    (robot description, options, log file: ``settings``), no error, trajectory present."""
    keep: dict[str, Mapping[str, Any]] = {}
    logs = {stored_text(p): p for p in targets}  # the table holds a name that is not UTF-8 as escapes
    for row in read_rows(out):
        p = logs.get(row.get("log"))
        if p is None or row.get("robot") != robot.name or row.get("method") != method:
            continue
        if row.get("settings") != settings[p]:  # another geometry of the same name, --closed, --sensed, a new log
            keep.pop(p, None)
            continue
        want = targets[p]
        if row.get("error") or (want is not None and (row.get("trajectory") != stored_text(want)
                                                      or not Path(want).exists())):
            keep.pop(p, None)
            continue
        keep[p] = row | {"log": p, "trajectory": want}
    return keep


def _fingerprint(*parts: Any) -> str:
    """A short digest of `parts` (their ``repr``; mappings sorted by key)."""
    def canonical(x: Any) -> Any:
        if isinstance(x, Mapping):
            return sorted((str(k), canonical(v)) for k, v in x.items())
        if isinstance(x, Robot):
            from ..description import robot_to_dict

            return canonical(robot_to_dict(x, thesis=True))
        if isinstance(x, list | tuple):
            return [canonical(v) for v in x]
        return x

    return hashlib.sha1(repr(canonical(list(parts))).encode()).hexdigest()[:16]


def _stat(path: str) -> tuple:
    """Size and modification time of a log file, or of every file of a bag folder (a changed log is redone)."""
    p = Path(path)
    files = sorted(f for f in p.rglob("*") if f.is_file()) if p.is_dir() else [p]
    return tuple((os.fspath(f.relative_to(p)) if p.is_dir() else "", f.stat().st_size, f.stat().st_mtime_ns)
                 for f in files)


def _trajectory_names(paths: Sequence[str], folder, fmt: str) -> dict[str, str | None]:
    """``folder/STEM.EXT`` per log; stems shared by several logs get a short hash of the path."""
    if folder is None:
        return dict.fromkeys(paths)
    stems = [Path(p).stem for p in paths]
    out = {}
    for p, stem in zip(paths, stems, strict=True):
        if stems.count(stem) > 1:
            stem = f"{stem}-{hashlib.sha1(os.fsencode(os.path.abspath(p))).hexdigest()[:8]}"  # a name not UTF-8 too
        out[p] = os.fspath(Path(folder) / f"{stem}.{fmt}")
    return out


def _message(err: BaseException) -> str:
    from ..errors import WmrkitError

    text = " ".join(str(err).split()) or type(err).__name__
    return text if isinstance(err, WmrkitError) else f"{type(err).__name__}: {text}"
