"""Odometry from a log file to trajectory files, streaming with a progress bar (what ``wmrkit odometry`` calls).

Inputs: CSV logs (:mod:`.logs`) or ROS 2 bags (a bag directory, or a ``.db3``/``.mcap`` file; :mod:`.bags`).
Outputs chosen by ``out_format`` or the extension of ``out``: ``.csv`` (time, pose, slip, covariance), ``.tum``
or ``.txt`` (TUM), anything else a new ROS 2 bag of ``nav_msgs/msg/Odometry``; a run that fails removes the output
it began (so does a failing ``check``, e.g. a named IMU's). A plot keeps a decimated copy of the trajectory, so
memory stays bounded for any log length. Steering joints in either file are headings (0 = rolling straight ahead;
:mod:`.steering`), converted to β with `robot`'s wheels by the readers.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Literal

from numpy.typing import ArrayLike

from ..limits import same_file
from ..robot import Robot
from .bags import OdometryBagWriter, bag_message_count, read_joint_states
from .integrators import Method, check_method
from .logs import JointLog, LogError, LogFormat, read_csv
from .model import OdometryModel, odometry_model
from .pipeline import Decimator, Noise, OdometrySummary, run_odometry
from .trajectories import Trajectory, TrajectoryWriter

OutFormat = Literal["csv", "tum", "bag"]
DEFAULT_FORMAT = LogFormat()


def is_bag(path: str | os.PathLike[str]) -> bool:
    """Whether `path` names a ROS 2 bag (a directory, or a ``.db3`` / ``.mcap`` file)."""
    p = Path(path)
    return p.is_dir() or p.suffix.lower() in (".db3", ".mcap")


def out_format_of(path: str | os.PathLike[str]) -> OutFormat:
    """Output format implied by a file name: ``.csv`` -> csv, ``.tum``/``.txt`` -> tum, no suffix -> a ROS 2 bag (a
    folder); any other suffix is refused (:class:`LogError`): ``traj.json`` was written as a bag, a folder of that
    name, where the user meant a file (give the format to write one)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        return "csv"
    if suffix in (".tum", ".txt"):
        return "tum"
    if suffix:
        raise LogError(f"{os.fspath(path)}: no trajectory format has the suffix '{Path(path).suffix}' (.csv, .tum or "
                       ".txt; a ROS 2 bag is a folder, named without a suffix); give the format (--format) to write "
                       "it anyway")
    return "bag"


def _remove(path: str | os.PathLike[str]) -> None:
    """Delete an output file, or a bag (a directory), that this run created."""
    if Path(path).is_dir():
        shutil.rmtree(path, ignore_errors=True)
    else:
        Path(path).unlink(missing_ok=True)


def _check_not_the_log(log_path: str | os.PathLike[str], outputs: Mapping[str, object]) -> None:
    """Refuse an output that is the log itself: opening it for writing would empty the log before it is read."""
    for what, path in outputs.items():
        if path is not None and same_file(log_path, path):  # type: ignore[arg-type]
            raise LogError(f"{os.fspath(log_path)}: the {what} file is the log itself (writing it would destroy the "
                           "log); choose another file")


#: Samples of a log the diagnostics after a run read (the per-wheel slip, the external heading against the wheels,
#: the gears, the steering steps): its first ones.
FIRST_SAMPLES = 20_000


def first_samples(robot: Robot, log_path: str | os.PathLike[str], joints: Sequence[str], *,
                  fmt: LogFormat = DEFAULT_FORMAT, topic: str = "/joint_states",
                  joint_names: Mapping[str, str] | None = None, count: int = FIRST_SAMPLES) -> JointLog:
    """The first `count` samples of `joints` in a CSV log (read with `fmt`) or a ROS 2 bag (`topic`, `joint_names`),
    steering in β, as :func:`odometry_file` reads them."""
    if is_bag(log_path):
        chunks = read_joint_states(log_path, joints, robot=robot, topic=topic, names=joint_names, chunk_size=count)
    else:
        chunks = read_csv(log_path, joints, fmt, robot=robot, chunk_size=count)
    try:
        return next(chunks)
    finally:
        chunks.close()  # the file (a bag's reader) closed now, not when collected


def odometry_file(robot: Robot, log_path: str | os.PathLike[str], *, fmt: LogFormat = DEFAULT_FORMAT,
                  method: Method = "exact", pose0: ArrayLike = (0.0, 0.0, 0.0), sensed: Sequence[str] | None = None,
                  noise: Noise | None = None, out: str | os.PathLike[str] | None = None,
                  out_format: OutFormat | None = None, plot: str | os.PathLike[str] | None = None,
                  progress: bool = False, chunk_size: int = 1 << 16, topic: str = "/joint_states",
                  joint_names: Mapping[str, str] | None = None,
                  weights: Mapping[str, float] | None = None, model=None,
                  sinks: Sequence[Callable[[Trajectory], object]] = (),
                  check: Callable[[], object] | None = None, label: str | None = None) -> OdometrySummary:
    """Run odometry over the log at `log_path` and write the requested outputs (module docstring).

    `fmt` describes a CSV log; `topic` and `joint_names` (ROS name -> robot joint) a bag. `sensed` and `weights`
    go to :func:`~.model.odometry_model`. `progress` shows a tqdm bar on stderr. Returns the run's
    :class:`~.pipeline.OdometrySummary`. `model`, when given, replaces that model: an ``OdometryModel`` (e.g.
    WLS, :func:`wmrkit.slip.weights.wls_model`) or an estimator with ``joints`` and ``run(chunks, method=,
    pose0=, sinks=)`` (the Kalman filters of :mod:`wmrkit.slip.estimators`). `sinks` get every chunk of the
    trajectory too (after the outputs), e.g. :class:`~.diagnostics.ImuCheck`; ``check()``, called after the run,
    fails it like an error of the run (the output removed, no plot) when it raises. `label` names the odometry in
    the plot's legend (default `method`, the integration scheme: a Kalman filter's plot said only ``exact``).
    """
    from tqdm import tqdm

    check_method(method)
    model = odometry_model(robot, sensed, weights=weights) if model is None else model
    if not Path(log_path).exists():
        raise LogError(f"{os.fspath(log_path)}: no such file")
    bag = is_bag(log_path)
    if bag and fmt != LogFormat():
        raise LogError(f"{os.fspath(log_path)}: CSV options (columns, counts, heading...) do not apply to a bag")
    total, unit = ((bag_message_count(log_path, topic), "msg") if bag
                   else (os.path.getsize(log_path), "B"))
    _check_not_the_log(log_path, {"output": out, "plot": plot})
    if out is not None and plot is not None and same_file(out, plot):
        raise LogError(f"{os.fspath(out)}: the output and the plot are one file (the plot would replace the "
                       "trajectory); choose two files")
    out_fmt = None if out is None else (out_format or out_format_of(out))
    if out_fmt not in (None, "csv", "tum", "bag"):
        raise LogError(f"unknown output format '{out_fmt}' (formats: csv, tum, bag)")
    with tqdm(total=total, unit=unit, unit_scale=True, disable=not progress, leave=False) as bar:
        if bag:
            chunks = read_joint_states(log_path, model.joints, robot=robot, topic=topic, names=joint_names,
                                       chunk_size=chunk_size, progress=bar.update)
        else:
            chunks = read_csv(log_path, model.joints, fmt, robot=robot, chunk_size=chunk_size, progress=bar.update)
        extra, sinks, writer = sinks, [], None
        if out_fmt == "bag":
            writer = OdometryBagWriter(out)
        elif out_fmt is not None:
            writer = TrajectoryWriter(out, out_fmt, covariance=noise is not None)
        if writer is not None:
            sinks.append(writer.write)
        decimated = Decimator() if plot is not None else None
        if decimated is not None:
            sinks.append(decimated)
        sinks += extra
        done = False
        try:
            summary = (run_odometry(model, chunks, method=method, pose0=pose0, noise=noise, sinks=sinks)
                       if isinstance(model, OdometryModel) else model.run(chunks, method=method, pose0=pose0,
                                                                          sinks=sinks))
            if check is not None:
                check()
            done = True
        finally:
            if writer is not None:
                writer.close()
                if not done:  # a failed run leaves no partial trajectory that would read as its result
                    _remove(out)
    if decimated is not None:
        from .plot import save_trajectory_plot

        _time, poses = decimated.result()
        save_trajectory_plot(plot, {f"{robot.name} ({label or method})": poses})
    return summary
