"""Trajectories: poses over time with the slip indicator and covariance; CSV and TUM files, written in chunks.

TUM is the format trajectory-evaluation tools (``evo``, the TUM RGB-D benchmark scripts) read: one line per pose,
``timestamp tx ty tz qx qy qz qw``, space separated; a planar pose has ``tz = 0`` and the quaternion of a rotation
``theta`` about z, ``(0, 0, sin(theta/2), cos(theta/2))``.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterator
from dataclasses import dataclass
from typing import IO, Literal, NoReturn

import numpy as np

from .._numbers import number_problem
from ..limits import MAX_COORDINATE, check_table_size
from .logs import LogError

TrajectoryFormat = Literal["csv", "tum"]
#: Covariance entries written to CSV, in this order (upper triangle of the (x, y, theta) covariance).
COV_COLUMNS = ("cov_xx", "cov_xy", "cov_xtheta", "cov_yy", "cov_ytheta", "cov_thetatheta")
_TRIU = np.triu_indices(3)


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class Trajectory:
    """Poses at sample times: ``time`` ``(N,)`` [s], ``poses`` ``(N, 3)`` ``(x [m], y [m], theta [rad])`` in the
    world frame (theta continuous, not wrapped); ``slip`` ``(N,)`` [m], the residual norm of the interval ending
    at each sample (0 at the first); ``covariance`` ``(N, 3, 3)`` or None.
    """

    time: np.ndarray
    poses: np.ndarray
    slip: np.ndarray
    covariance: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.time)

    @property
    def final_pose(self) -> np.ndarray:
        """The last pose ``(3,)``."""
        return self.poses[-1]


def quaternion_z(theta: np.ndarray) -> np.ndarray:
    """Unit quaternion ``(qx, qy, qz, qw)`` of a rotation `theta` [rad] about z. ``(...) -> (..., 4)``."""
    theta = np.asarray(theta, dtype=float)
    z = np.zeros_like(theta)
    return np.stack([z, z, np.sin(theta / 2), np.cos(theta / 2)], axis=-1)


def yaw_of_quaternion(q: np.ndarray) -> np.ndarray:
    """Yaw [rad] of quaternions ``(qx, qy, qz, qw)`` (ZYX convention), of any nonzero finite norm: the homogeneous
    form ``atan2(2 (w z + x y), w^2 + x^2 - y^2 - z^2)`` after scaling by the largest component (the unit form's
    ``1 - 2 (y^2 + z^2)`` is wrong for a quaternion that is not normalised). ``(..., 4) -> (...)``."""
    q = np.asarray(q, dtype=float)
    scale = np.max(np.abs(q), axis=-1, keepdims=True)
    x, y, z, w = np.moveaxis(q / np.where(scale > 0, scale, 1.0), -1, 0)
    return np.arctan2(2 * (w * z + x * y), (w * w + x * x) - (y * y + z * z))


class TrajectoryWriter:
    """Writes a trajectory to a CSV (``time,x,y,theta,slip[,cov_...]``) or TUM file chunk by chunk.

    Use as a context manager; ``write`` appends a :class:`Trajectory` chunk.
    """

    def __init__(self, path: str | os.PathLike[str], fmt: TrajectoryFormat, *, covariance: bool = False) -> None:
        if fmt not in ("csv", "tum"):
            raise LogError(f"unknown trajectory format '{fmt}' (formats: csv, tum)")
        self.path, self.fmt, self.covariance = os.fspath(path), fmt, covariance
        try:
            self._f: IO[str] = open(self.path, "w", encoding="utf-8", newline="")
        except OSError as err:
            raise LogError(f"{self.path}: cannot write: {err.strerror}") from None
        if fmt == "csv":
            self._f.write(",".join(("time", "x", "y", "theta", "slip", *(COV_COLUMNS if covariance else ()))) + "\n")
        else:
            self._f.write("# timestamp tx ty tz qx qy qz qw\n")

    def write(self, chunk: Trajectory) -> None:
        """Append the poses of `chunk`."""
        if self.fmt == "csv":
            cols = [chunk.time[:, None], chunk.poses, chunk.slip[:, None]]
            if self.covariance:
                cols.append(chunk.covariance[:, _TRIU[0], _TRIU[1]])
            values, row = np.hstack(cols), "%.9f," + ",".join(["%.12g"] * (4 + 6 * self.covariance)) + "\n"
        else:
            z = np.zeros((len(chunk), 1))
            values = np.hstack([chunk.time[:, None], chunk.poses[:, :2], z, quaternion_z(chunk.poses[:, 2])])
            row = "%.9f " + " ".join(["%.12g"] * 7) + "\n"
        values = values + 0.0  # no "-0" (a start pose given as -0, its quaternion's sin(-0 / 2))
        self._f.write((row * len(values)) % tuple(values.ravel().tolist()))  # one formatting call per chunk

    def close(self) -> None:
        """Close the file."""
        self._f.close()

    def __enter__(self) -> TrajectoryWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def write_trajectory(path: str | os.PathLike[str], trajectory: Trajectory, fmt: TrajectoryFormat) -> None:
    """Write a whole trajectory as CSV or TUM (see :class:`TrajectoryWriter`)."""
    with TrajectoryWriter(path, fmt, covariance=trajectory.covariance is not None) as w:
        w.write(trajectory)


#: The columns of a TUM file, as messages name them.
TUM_COLUMNS = ("timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw")


def read_tum(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray]:
    """A TUM file's times ``(N,)`` [s] and planar poses ``(N, 3)`` (yaw from the quaternion, z ignored)."""
    data = _load_table(path, TUM_COLUMNS, comments="#")
    if data.shape[1] != 8:
        raise LogError(f"{os.fspath(path)}: a TUM file has 8 columns, got {data.shape[1]}")
    _check_samples(path, data[:, 0], data[:, 1:4], 0, "#")
    _check_finite(path, data[:, 4:8], "the quaternion", 0, "#")
    scale = np.max(np.abs(data[:, 4:8]), axis=1)  # the norm as scale * |q / scale|: |q|^2 overflows beyond 1e154
    zero = scale < 1e-6 / np.linalg.norm(data[:, 4:8] / np.where(scale > 0, scale, 1.0)[:, None], axis=1).clip(1.0)
    if np.any(zero):
        raise LogError(f"{_line_of(path, int(np.argmax(zero)), 0, '#')}: the quaternion is (almost) zero")
    return data[:, 0], np.column_stack([data[:, 1], data[:, 2], np.unwrap(yaw_of_quaternion(data[:, 4:8]))])


def _load_table(path: str | os.PathLike[str], columns: tuple[str, ...], *, delimiter: str | None = None,
                skiprows: int = 0, comments: str | None = None) -> np.ndarray:
    """``np.loadtxt`` of a trajectory file (`columns` name its fields in messages) with at least one row of finite
    numbers; a field that is none (:func:`wmrkit._numbers.number_problem`) is named with its line, in one line."""
    import warnings

    check_table_size(path, LogError, "trajectory")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data": refused below
            data = np.loadtxt(path, ndmin=2, delimiter=delimiter, skiprows=skiprows, comments=comments,
                              encoding="utf-8-sig")  # -sig: a byte-order mark is not part of the first number
    except (OSError, UnicodeDecodeError) as err:
        reason = getattr(err, "strerror", None) or str(err).splitlines()[0]
        raise LogError(f"{os.fspath(path)}: cannot read the trajectory ({reason})") from None
    except ValueError:
        data = None
    if data is None or not np.isfinite(data).all():  # error path: name the field ('nan', '1e400' read as inf)
        _refuse_field(path, columns, delimiter, skiprows, comments)
    if data.size == 0:
        raise LogError(f"{os.fspath(path)}: no poses in the file")
    return data


def _refuse_field(path: str | os.PathLike[str], columns: tuple[str, ...], delimiter: str | None, skiprows: int,
                  comments: str | None) -> NoReturn:
    """Raise a :class:`LogError` naming the line and the column of the first field of the table at `path` that is
    not a finite number, or the first row of another field count (the file is at most ``MAX_TABLE_SIZE``)."""
    width = len(columns) if delimiter else None  # a CSV has its header's fields; read_tum counts a TUM file's
    for k, text in _data_lines(path, skiprows, comments):
        fields = text.split(delimiter)
        width = len(fields) if width is None else width
        if len(fields) != width:
            raise LogError(f"{os.fspath(path)}:{k}: expected {width} fields, got {len(fields)}")
        for c, field in enumerate(fields):
            problem = number_problem(field)
            if problem is not None:
                name = columns[c] if c < len(columns) else f"field {c + 1}"
                raise LogError(f"{os.fspath(path)}:{k}: column '{name}': {problem}")
    raise LogError(f"{os.fspath(path)}: cannot read the trajectory")  # pragma: no cover (loadtxt's reasons above)


def _data_lines(path: str | os.PathLike[str], skiprows: int, comments: str | None) -> Iterator[tuple[int, str]]:
    """``(line number (1-based), text without its comment)`` of the data lines of the table at `path` as
    :func:`_load_table` reads them: `skiprows` header lines, blank and `comments` lines skipped (error paths only)."""
    with open(path, encoding="utf-8-sig", newline="") as f:
        lines = f.read().splitlines()
    for k, text in enumerate(lines[skiprows:], start=skiprows + 1):
        data = text.partition(comments)[0] if comments else text
        if data.strip():
            yield k, data


def _line_of(path: str | os.PathLike[str], row: int, skiprows: int, comments: str | None) -> str:
    """``FILE:LINE`` of the data `row` (0-based) of the table at `path` (:func:`_data_lines`)."""
    return f"{os.fspath(path)}:{next(itertools.islice(_data_lines(path, skiprows, comments), row, None))[0]}"


def _check_samples(path: str | os.PathLike[str], t: np.ndarray, position: np.ndarray, skiprows: int,
                   comments: str | None) -> None:
    """Times finite and strictly increasing, positions finite within :data:`wmrkit.limits.MAX_COORDINATE`; else a
    :class:`LogError` naming the file and line (`skiprows`, `comments` as :func:`_load_table`'s)."""
    _check_finite(path, np.column_stack([t, position]), "times and positions", skiprows, comments)
    if np.abs(position).max() > MAX_COORDINATE:
        row = int(np.argmax(np.abs(position).max(axis=1)))
        raise LogError(f"{_line_of(path, row, skiprows, comments)}: a coordinate beyond {MAX_COORDINATE:g} m")
    if np.any(np.diff(t) <= 0):
        k = int(np.argmax(np.diff(t) <= 0))
        raise LogError(f"{_line_of(path, k + 1, skiprows, comments)}: time {float(t[k + 1])!r} s does not increase "
                       f"(after {float(t[k])!r} s)")


def _check_finite(path: str | os.PathLike[str], values: np.ndarray, what: str, skiprows: int,
                  comments: str | None) -> None:
    """Every row of `values` ``(N, k)`` finite, or a :class:`LogError` naming the file and line and `what`."""
    finite = np.isfinite(values).all(axis=1)
    if not finite.all():
        raise LogError(f"{_line_of(path, int(np.argmin(finite)), skiprows, comments)}: {what} must be finite numbers")


def read_trajectory_csv(path: str | os.PathLike[str]) -> Trajectory:
    """A trajectory CSV written by :class:`TrajectoryWriter` (covariance restored when present)."""
    check_table_size(path, LogError, "trajectory")  # before opening: a FIFO's open waits for a writer
    try:
        with open(path, encoding="utf-8-sig") as f:
            header = f.readline().strip().split(",")
    except (OSError, UnicodeDecodeError) as err:
        raise LogError(f"{os.fspath(path)}: cannot read the trajectory ({getattr(err, 'strerror', None) or err})") \
            from None
    if header[:5] != ["time", "x", "y", "theta", "slip"] or header[5:] not in ([], list(COV_COLUMNS)):
        raise LogError(f"{os.fspath(path)}:1: expected the columns time,x,y,theta,slip (and the covariance's "
                       f"{','.join(COV_COLUMNS)}), got {','.join(header)}")
    data = _load_table(path, tuple(header), delimiter=",", skiprows=1)
    if data.shape[1] != len(header):
        raise LogError(f"{os.fspath(path)}: {data.shape[1]} values per row under a header of {len(header)} columns")
    _check_samples(path, data[:, 0], data[:, 1:3], 1, None)
    _check_finite(path, data[:, 3:], "theta, slip and the covariance", 1, None)
    cov = None
    if len(header) > 5:
        cov = np.zeros((len(data), 3, 3))
        cov[:, _TRIU[0], _TRIU[1]] = data[:, 5:]
        cov = cov + np.swapaxes(np.triu(cov, 1), -1, -2)
    return Trajectory(data[:, 0], data[:, 1:4], data[:, 4], cov)
