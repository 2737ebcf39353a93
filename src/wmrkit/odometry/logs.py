"""Joint logs: samples of sensed joints over time, read from CSV in bounded memory, validated, written back.

A log holds one row per sample: ``time`` [s] and, per sensed joint ``WHEEL.spin`` / ``WHEEL.steer``, the
cumulative wheel angle / the steering **heading** [rad] (the wheel's rolling direction, 0 = straight ahead, as a
ROS 2 steering joint reads; :mod:`.steering`). :class:`LogFormat` describes other CSV layouts: other column
names, a time unit, encoder counts (with counter wrap-around), joint velocities, steering in degrees or in the
thesis's β (files of older wmrkit versions), an external heading (absolute yaw, or a gyro rate that is
integrated). Every reader turns them into the same :class:`JointLog` chunks, whose steering columns hold β.

Bad input is refused with a one-line :class:`LogError` naming the file, the line and the column: missing columns,
columns naming wheels the robot lacks, non-numeric or NaN values, time that repeats (a zero time step is
rejected, never divided by) or goes backwards, and steps longer than ``LogFormat.max_gap`` when given. Gaps
are otherwise integrated as one step: exact for the wheel travel (angles are cumulative), with the path shape
inside the gap approximated by a constant twist. Every row's field count is checked (vectorised), bytes that are
not UTF-8 and control characters are refused, a last line without its line end is reported as a truncated
file, and a spin joint turning faster than ``LogFormat.max_rate`` between two samples is reported as an
implausible jump (an encoder glitch, a wrong counter width or resolution) with its line. What parsing cannot
see (a truncated last line that still ends in a newline and holds plausible numbers) is listed in
``docs/limits.md``.
"""

from __future__ import annotations

import difflib
import numbers
import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Literal

import numpy as np

from .._shapes import as_names, as_reals, finite_number
from ..errors import WmrkitError
from ..limits import check_chunk_size, regular_file_problem
from ..units import UNITS
from ._text import check_lines, did_you_mean, encoded, parse_rows, read_lines, short
from .encoders import AbsoluteEncoder, Encoder, EncoderError, IncrementalEncoder
from .header import SPIN_MODES, bare_heading_problem, header_names, travel_radii
from .log_writer import write_csv, write_log  # noqa: F401  (re-exported: their home before)
from .steering import CONVENTIONS, check_robot, check_steer_range, convert_steering

if TYPE_CHECKING:
    from ..robot import Robot

#: Seconds per unit of the time column (the ASCII ones of the time units, :data:`wmrkit.units.UNITS`).
TIME_UNITS = {u: UNITS["time"][u] for u in ("s", "ms", "us", "ns")}

#: Default largest plausible spin rate of a wheel [rad/s] (about 95,000 rpm): faster is an encoder glitch.
MAX_RATE = 1e4
#: Largest cumulative spin angle of a log [rad], 2**42 (7e11 turns: 1400 years at 100 rad/s): beyond it float64
#: rounds an angle by 1 mrad or more, and angles of 1e17 rad (16 rad apart) turned a calibration into noise.
MAX_SPIN_ANGLE = 2.0**42

#: Longest header line read [characters]: a longer first line is not a CSV log (e.g. a binary file).
MAX_HEADER = 1 << 16


class LogError(WmrkitError, ValueError):
    """A log that cannot be read as the robot's sensor record; the message names file, line and column."""


@dataclass(frozen=True, eq=False)  # eq=False: array fields
class JointLog:
    """Samples of sensed joints: ``time`` ``(N,)`` [s], ``positions`` ``(N, n)`` [rad] named by ``joints``.

    Spin columns are cumulative wheel angles, steer columns the thesis's **β** (the model's convention: straight
    ahead is pi/2 for δ = 0). Joint data in the users' convention (ROS 2, WPILib: steering 0 = rolling straight
    ahead) comes in through :meth:`from_headings` and goes out through :meth:`heading_positions`; the log
    readers and writers do both. ``heading_world`` ``(N,)`` [rad] is an optional external yaw (continuous).
    ``source`` and ``first_line`` locate errors (``first_line``: the file line of row 0, or None when rows are not
    lines; ``first_index`` is then the sample number of row 0).
    """

    time: np.ndarray
    joints: tuple[str, ...]
    positions: np.ndarray
    heading_world: np.ndarray | None = None
    source: str = "<log>"
    first_line: int | None = None
    first_index: int = 0

    def __post_init__(self) -> None:
        joint_names(self.joints, self.source)  # tuple("left.spin") read nine joints 'l', 'e', ...
        for name in ("time", "positions", "heading_world"):  # lists given in Python: the methods need float arrays
            if (value := getattr(self, name)) is not None and not (isinstance(value, np.ndarray)
                                                                   and value.dtype == float):
                object.__setattr__(self, name, as_reals(value, f"{self.source}: {name}"))
        n = len(self.time) if np.ndim(self.time) else -1  # a number raised "len() of unsized object"
        if np.ndim(self.time) != 1 or np.shape(self.positions) != (n, len(self.joints)):
            raise LogError(f"{self.source}: expected time (N,) and positions (N, {len(self.joints)}), got "
                           f"{np.shape(self.time)} and {np.shape(self.positions)}")
        if self.heading_world is not None and np.shape(self.heading_world) != (n,):
            raise LogError(f"{self.source}: heading_world: expected shape ({n},), got {np.shape(self.heading_world)}")

    def __len__(self) -> int:
        return len(self.time)

    @classmethod
    def from_headings(cls, robot: Robot, time: np.ndarray, joints: Sequence[str], positions: np.ndarray,
                      heading_world: np.ndarray | None = None, source: str = "<log>") -> JointLog:
        """A log from joint data whose steering columns are headings (0 = rolling straight ahead, CCW; ROS 2
        ``JointState``, WPILib), converted to β with `robot`'s wheels (:func:`.steering.convert_steering`)."""
        log = cls(time, joints if isinstance(joints, str) else tuple(joints), positions, heading_world, source)
        check_steer_range(robot, log.joints, log.positions, log.where)  # shapes checked: the headings as given
        return replace(log, positions=convert_steering(robot, log.joints, log.positions, to="beta", source=source))

    def heading_positions(self, robot: Robot) -> np.ndarray:
        """``positions`` ``(N, n)`` with the steering columns as headings [rad] (what files hold; in (-pi, pi] at
        the first sample, continuous after it)."""
        return convert_steering(robot, self.joints, self.positions, to="heading", source=self.source)

    def where(self, row: int) -> str:
        """Location of `row` for messages: ``file:line`` or ``source: sample i``."""
        if self.first_line is not None:
            return f"{self.source}:{self.first_line + row}"
        return f"{self.source}: sample {self.first_index + row}"

    def select(self, joints: Sequence[str]) -> JointLog:
        """The same log with the columns `joints` in that order; :class:`LogError` names any joint missing."""
        missing = [j for j in joints if j not in self.joints]
        if missing:
            raise LogError(f"{self.source}: no samples of joint {_quoted(missing)} (the log has: "
                           f"{', '.join(self.joints) or 'none'})")
        idx = [self.joints.index(j) for j in joints]
        return JointLog(self.time, tuple(joints), self.positions[:, idx], self.heading_world, self.source,
                        self.first_line, self.first_index)

    def slice(self, start: int, stop: int) -> JointLog:
        """Rows ``start:stop`` (locations kept right)."""
        h = None if self.heading_world is None else self.heading_world[start:stop]
        return JointLog(self.time[start:stop], self.joints, self.positions[start:stop], h, self.source,
                        None if self.first_line is None else self.first_line + start, self.first_index + start)


@dataclass(frozen=True, slots=True)
class LogFormat:
    """How joints are stored in a CSV log; the defaults read ``time`` [s] and ``WHEEL.spin``/``WHEEL.steer`` [rad].

    ``columns``: ``(joint, column)`` pairs renaming columns. ``spin``: ``"angle"`` (cumulative, rad), ``"counts"``
    (incremental encoder, see ``encoders``), ``"velocity"`` (rad/s, integrated by the trapezoidal rule), ``"distance"``
    or ``"speed"`` (the wheel's travel [m] or speed [m/s], divided by its radius; the robot is needed). ``steer``:
    ``"angle"`` (rad), ``"degrees"`` or ``"counts"`` (absolute encoder readings). ``steer_convention``: ``"heading"``
    (0 = rolling straight ahead, the default) or ``"beta"`` (the thesis's angle, files of older wmrkit versions;
    header ``[deg:beta]``). ``encoders``: ``(joint, encoder)`` pairs for counts. ``heading_column``: absolute heading
    [rad] (IMU yaw; unwrapped here) replacing the wheels' heading; ``gyro_column``: yaw rate [rad/s] instead
    (integrated from 0); ``external_degrees``: that column is in deg (deg/s; a header's ``[deg]``). ``spin_scale``:
    radians in one unit of the spin columns in angle or velocity mode (pi/180 for a header's deg). ``max_gap``: longest
    time step accepted [s] (None: any). ``time_unit``: one of :data:`TIME_UNITS`. ``max_rate``: largest
    plausible spin rate [rad/s] between two samples (None: any); a faster step is refused as an encoder jump.
    """

    time_column: str = "time"
    time_unit: str = "s"
    columns: tuple[tuple[str, str], ...] = ()
    spin: Literal["angle", "counts", "velocity", "distance", "speed"] = "angle"
    steer: Literal["angle", "degrees", "counts"] = "angle"
    encoders: tuple[tuple[str, Encoder], ...] = field(default=())
    heading_column: str | None = None
    gyro_column: str | None = None
    max_gap: float | None = None
    delimiter: str = ","
    max_rate: float | None = MAX_RATE
    steer_convention: Literal["heading", "beta"] = "heading"
    external_degrees: bool = False
    spin_scale: float = 1.0

    def __post_init__(self) -> None:
        for name, kind, example in (("columns", str, "'enc_l'"),
                                    ("encoders", Encoder, "IncrementalEncoder(1024)")):
            value = getattr(self, name)
            pairs = tuple(value.items()) if isinstance(value, Mapping) else value  # a dict reads as its pairs
            if isinstance(pairs, str) or not isinstance(pairs, Iterable) or not all(  # a number: a bare TypeError
                    isinstance(p, tuple | list) and len(p) == 2 and isinstance(p[0], str) and isinstance(p[1], kind)
                    for p in pairs):
                raise LogError(f"LogFormat.{name}: expected (joint, {name[:-1]}) pairs, e.g. (('left.spin', "
                               f"{example}),), got {value!r}")
            object.__setattr__(self, name, tuple(tuple(p) for p in pairs))
        for name in ("max_gap", "max_rate"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, numbers.Real) and not isinstance(value, bool)):
                raise LogError(f"LogFormat.{name}: expected a number or None, got {value!r}")
        if not isinstance(self.time_unit, str) or self.time_unit not in TIME_UNITS:  # a list: "unhashable type"
            raise LogError(f"unknown time unit '{self.time_unit}' (units: {', '.join(TIME_UNITS)})")
        if self.spin not in SPIN_MODES or self.steer not in ("angle", "degrees", "counts"):
            raise LogError(f"spin must be one of {', '.join(SPIN_MODES)} and steer angle, degrees or counts; got "
                           f"{self.spin}, {self.steer}")
        if self.steer_convention not in CONVENTIONS:
            raise LogError(f"steer_convention must be heading or beta, got {self.steer_convention!r}")
        if self.heading_column is not None and self.gyro_column is not None:
            raise LogError("give a heading column or a gyro column, not both")
        if not isinstance(self.external_degrees, bool):
            raise LogError(f"LogFormat.external_degrees: expected True or False, got {self.external_degrees!r}")
        scale = self.spin_scale
        if (isinstance(scale, bool) or not (finite_number(scale) and scale > 0)
                or (scale != 1 and self.spin not in ("angle", "velocity"))):
            raise LogError(f"LogFormat.spin_scale: a number > 0 for spins in angle or velocity mode, got "
                           f"{self.spin_scale!r} ({self.spin})")
        if self.max_gap is not None and not self.max_gap > 0:
            raise LogError(f"max_gap must be > 0 s, got {self.max_gap}")
        if self.max_rate is not None and not self.max_rate > 0:
            raise LogError(f"max_rate must be > 0 rad/s, got {self.max_rate}")
        if len(self.delimiter) != 1 or self.delimiter.isspace() or self.delimiter in ".-+eE0123456789":
            raise LogError(f"the delimiter must be one character that cannot be part of a number, got "
                           f"{self.delimiter!r}")

    def column_of(self, joint: str) -> str:
        """The CSV column holding `joint`."""
        return dict(self.columns).get(joint, joint)

    def encoder_of(self, joint: str, source: str) -> Encoder:
        """The encoder of `joint` (counts formats), or :class:`LogError`."""
        enc = dict(self.encoders).get(joint)
        steer = joint.endswith(".steer")
        want = AbsoluteEncoder if steer else IncrementalEncoder
        if not isinstance(enc, want):
            raise LogError(f"{source}: joint '{joint}' is logged as counts but has no {want.__name__} "
                           "(give the counts per revolution / the steering resolution)")
        return enc


class Decoder:
    """Turns raw rows of one log into :class:`JointLog` chunks, carrying state across chunks (counts, rates).

    Steering columns are decoded to angles (radians, degrees or encoder counts) in the file's convention, then
    headings are converted to β with `robot` (:mod:`.steering`; required when the log has steering joints).
    """

    def __init__(self, joints: Sequence[str], fmt: LogFormat, source: str, robot: Robot | None = None) -> None:
        self.joints, self.fmt, self.source, self.robot = joint_names(joints, source), fmt, source, robot
        if fmt.steer_convention == "heading":
            check_robot(self.joints, robot, source)
        self._radii = travel_radii(self.joints, fmt.spin, robot, source, fmt.spin_scale)  # m, m/s, deg: into rad
        self._last: np.ndarray | None = None  # last raw row (time, joints, heading)
        self._positions: np.ndarray | None = None  # last decoded positions
        self._heading = 0.0

    def decode(self, raw: np.ndarray, first_line: int | None, first_index: int) -> JointLog:
        """Rows ``(time, joint columns..., [heading or gyro])`` in file units to a validated chunk."""
        fmt, n_j = self.fmt, len(self.joints)
        probe = JointLog(raw[:, 0], self.joints, raw[:, 1:1 + n_j], None, self.source, first_line, first_index)
        _check_finite(probe, raw, fmt)
        if fmt.heading_column is not None and (problem := bare_heading_problem(fmt.heading_column, raw[:, -1])):
            raise LogError(f"{probe.where(problem[0])}: {problem[1]}")
        scale = TIME_UNITS[fmt.time_unit]
        time = raw[:, 0] * scale
        check_time(probe, time, None if self._last is None else self._last[0] * scale, fmt.max_gap)
        ext = raw if self._last is None else np.vstack([self._last[None], raw])
        ext = ext if self._radii is None else np.hstack([ext[:, :1], ext[:, 1:1 + n_j] / self._radii, ext[:, 1 + n_j:]])
        ext_time = ext[:, 0] * scale
        pos = np.empty((len(raw), n_j))
        for j, joint in enumerate(self.joints):
            prev = None if self._positions is None else self._positions[j]
            pos[:, j] = self._decode_joint(joint, ext[:, 1 + j], ext_time, prev, probe)
        check_jumps(probe, pos, self._positions, ext_time, fmt.max_rate)
        heading, external = None, np.radians(ext[:, -1]) if fmt.external_degrees else ext[:, -1]
        if fmt.heading_column is not None:
            u = np.unwrap(external)
            heading = u if self._last is None else self._heading + (u[1:] - u[0])
        elif fmt.gyro_column is not None:
            heading = self._heading + _cumtrapz(external, ext_time, start=self._last is None)
        if heading is not None:
            self._heading = heading[-1]
        self._last, self._positions = raw[-1].copy(), pos[-1].copy()  # as read: counts and rates continue from it
        if fmt.steer_convention == "heading":
            check_steer_range(self.robot, self.joints, pos, probe.where)
            pos = convert_steering(self.robot, self.joints, pos, to="beta", source=self.source)
        return JointLog(time, self.joints, pos, heading, self.source, first_line, first_index)

    def _decode_joint(self, joint: str, col: np.ndarray, t: np.ndarray, prev: float | None, probe: JointLog):
        kind = self.fmt.steer if joint.endswith(".steer") else self.fmt.spin
        new = col if prev is None else col[1:]
        if kind in ("angle", "degrees", "distance"):  # travel in m: divided by the radius in decode
            return np.radians(new) if kind == "degrees" else new
        if kind in ("velocity", "speed"):
            return (0.0 if prev is None else prev) + _cumtrapz(col, t, start=prev is None)
        enc = self.fmt.encoder_of(joint, self.source)
        name = f"column '{self.fmt.column_of(joint)}'"
        absolute = isinstance(enc, AbsoluteEncoder)
        try:
            if absolute:
                return enc.angle(new, name=name)
            steps = enc.angle_increments(col, name=name)
        except EncoderError as err:  # its index counts the readings given; `col` has the previous chunk's last first
            row = None if err.index is None else err.index - (0 if absolute else len(col) - len(new))
            raise LogError(f"{probe.source if row is None else probe.where(row)}: {err}") from None
        start = np.zeros(1) if prev is None else np.full(1, prev)
        out = start[0] + np.cumsum(steps)
        return np.concatenate([start, out]) if prev is None else out


def joint_names(joints: Sequence[str], source: str) -> tuple[str, ...]:
    """`joints` as a tuple; a lone string (``"left.spin"``, read as one joint per letter) is a :class:`LogError`."""
    return as_names(joints, f"{source}: joints", "joint names", LogError)


def check_time(log: JointLog, time: np.ndarray, previous: float | None, max_gap: float | None) -> None:
    """Refuse time that repeats, goes backwards or (with `max_gap`) jumps; `previous`: the last time before."""
    t = time if previous is None else np.concatenate([[previous], time])
    with np.errstate(over="ignore", invalid="ignore"):  # an overflowing step is named by check_jumps
        dt = np.diff(t)
    shift = 0 if previous is None else 1
    bad = np.flatnonzero(~(dt > 0))
    if bad.size:
        i = int(bad[0]) + 1 - shift
        what = "repeats the previous sample (a zero time step)" if dt[bad[0]] == 0 else "goes backwards"
        raise LogError(f"{log.where(i)}: time {float(time[i])!r} s {what}; time must increase strictly")
    if max_gap is not None and dt.size and dt.max() > max_gap:
        k = int(np.argmax(dt > max_gap))  # the first gap (the largest was named: of equal steps, a rounding's)
        raise LogError(f"{log.where(k + 1 - shift)}: time step of {dt[k]:.6g} s exceeds max_gap = {max_gap:g} s "
                       "(a gap)")


def check_jumps(log: JointLog, positions: np.ndarray, previous: np.ndarray | None, time: np.ndarray,
                max_rate: float | None) -> None:
    """Refuse a spin joint (``*.spin``) turning faster than `max_rate` [rad/s] between two samples, and time
    steps that overflow. `positions` ``(N, n)`` [rad] of `log`'s joints; `previous` ``(n,)`` the positions of the
    sample before (None at the start); `time` ``(N + 1,)`` [s] with that sample's time first (``(N,)`` without).
    Vectorised; the message names the first bad row."""
    spin = [j for j, name in enumerate(log.joints) if name.endswith(".spin")]
    full = positions if previous is None else np.vstack([np.asarray(previous, dtype=float)[None], positions])
    shift = 1 if previous is None else 0  # row of `log` where step k ends
    with np.errstate(over="ignore", invalid="ignore"):
        dt = np.diff(time)
        bad_t = np.flatnonzero(~np.isfinite(dt))
        if bad_t.size:
            i = int(bad_t[0]) + shift
            raise LogError(f"{log.where(i)}: time {float(log.time[i])!r} s: the time step overflows (values too "
                           "large to subtract)")
        if max_rate is None or not spin or len(full) < 2:
            return _check_spin_angles(log, positions, spin)
        step = np.abs(np.diff(full[:, spin], axis=0))
        bad = ~(step <= max_rate * dt[:, None])
        if not bad.any():
            return _check_spin_angles(log, positions, spin)
        k, c = (int(x) for x in np.argwhere(bad)[0])
        rate = float(step[k, c] / dt[k])
    name, turn = log.joints[spin[c]], float(step[k, c])
    if not np.isfinite(turn):  # finite positions whose difference overflows ("turns inf rad")
        a, b = (float(x) for x in full[k:k + 2, spin[c]])
        what = f"from {a:.6g} rad to {b:.6g} rad, a step that overflows (values too large to subtract)"
    else:  # a rate beyond the largest float ("inf rad/s")
        speed = f" ({rate:.3g} rad/s > " if np.isfinite(rate) else ", a rate that overflows (at most "
        what = f"turns {turn:.6g} rad in {float(dt[k]):.6g} s{speed}{max_rate:g} rad/s)"
    raise LogError(f"{log.where(k + shift)}: {name}: {what}: an implausible jump (encoder glitch, wrong counter width "
                   "or counts per revolution?)")


def _check_spin_angles(log: JointLog, positions: np.ndarray, spin: list[int]) -> None:
    """Refuse a spin angle beyond :data:`MAX_SPIN_ANGLE` [rad] (`positions` ``(N, n)``, the rows of `log`): its
    increments would be round-off (a counter that was never reset, a value in the wrong unit)."""
    far = np.abs(positions[:, spin]) > MAX_SPIN_ANGLE
    if far.any():
        k, c = (int(x) for x in np.argwhere(far)[0])
        raise LogError(f"{log.where(k)}: {log.joints[spin[c]]}: a cumulative angle of {positions[k, spin[c]]:.6g} rad, "
                       f"beyond {MAX_SPIN_ANGLE:.3g} rad (7e11 turns), where floats are 1 mrad or more apart and its "
                       "steps would be round-off: log the angle since the start of the run")


def read_csv(path: str | os.PathLike[str], joints: Sequence[str], fmt: LogFormat = LogFormat(), *,
             robot: Robot | None = None, wheels: Sequence[str] = (), chunk_size: int = 1 << 16,
             progress: Callable[[int], object] | None = None) -> Iterator[JointLog]:
    """Read a CSV log in chunks of `chunk_size` rows, validated and decoded (bounded memory).

    `joints`: the joints needed (``model.joints``). `robot`: the robot logged, whose wheels convert the steering
    headings to β (required when `joints` has steering joints, unless ``fmt.steer_convention == "beta"``);
    `wheels` (default: `robot`'s wheel names) to refuse columns ``X.spin``/``X.steer`` for a wheel ``X`` the robot
    lacks. `progress` is called with the bytes read.
    """
    check_chunk_size(chunk_size, LogError)
    source = os.fspath(path)
    wheels = robot.wheel_names if robot is not None and not wheels else wheels
    decoder = Decoder(joints, fmt, source, robot)
    problem = regular_file_problem(source, "log")  # a FIFO waited for a writer forever
    if problem:
        raise LogError(f"{source}: {problem}")
    try:  # utf-8-sig: a byte-order mark (spreadsheet exports) is not part of the first column's name
        f = open(source, encoding="utf-8-sig", errors="surrogateescape", newline="")  # bad bytes found per chunk
    except OSError as err:
        raise LogError(f"{source}: cannot open: {err.strerror}") from None
    try:
        header_line = f.readline(MAX_HEADER + 1)
        if len(header_line) > MAX_HEADER:
            raise LogError(f"{source}:1: the header line is longer than {MAX_HEADER} characters: not a CSV log")
        encoded([header_line], source, 1)
        if not header_line.strip():
            raise LogError(f"{source}:1: empty file or no header line")
        header = header_names(header_line, fmt.delimiter)  # quotes of a spreadsheet's export removed
        usecols = _columns(header, joints, fmt, wheels, source)
        if progress is not None:
            progress(len(header_line.encode()))
        line, index = 2, 0
        while True:
            lines = read_lines(f, chunk_size, source, line)
            if not lines:
                break
            keep = check_lines(lines, fmt.delimiter, len(header), source, line)
            rows = lines if keep is None else [ln for ln, k in zip(lines, keep, strict=True) if k]
            raw = parse_rows(rows, usecols, fmt.delimiter, source, line, lines, header)
            if raw.size:
                yield decoder.decode(raw, line if len(rows) == len(lines) else None, index)
            if progress is not None:
                progress(sum(map(len, lines)))
            line, index = line + len(lines), index + len(rows)
        if index == 0:
            raise LogError(f"{source}: no samples after the header")
    finally:
        f.close()


def load_csv(path: str | os.PathLike[str], joints: Sequence[str], fmt: LogFormat = LogFormat(), *,
             robot: Robot | None = None, wheels: Sequence[str] = ()) -> JointLog:
    """A whole CSV log in memory (see :func:`read_csv`)."""
    return concatenate(list(read_csv(path, joints, fmt, robot=robot, wheels=wheels)))


def concatenate(chunks: Sequence[JointLog]) -> JointLog:
    """Chunks of one log joined into one :class:`JointLog`."""
    first = chunks[0]
    heading = None if first.heading_world is None else np.concatenate([c.heading_world for c in chunks])
    return JointLog(np.concatenate([c.time for c in chunks]), first.joints,
                    np.concatenate([c.positions for c in chunks]), heading, first.source, first.first_line,
                    first.first_index)


def _columns(header: list[str], joints: Sequence[str], fmt: LogFormat, wheels: Sequence[str],
             source: str) -> list[int]:
    seen = set()
    for name in header:
        if name in seen:
            raise LogError(f"{source}:1: column '{name}' appears twice")
        seen.add(name)
    renamed = {c for _, c in fmt.columns}
    other = [d for d in ",;\t|" if d != fmt.delimiter and d in header[0]] if len(header) == 1 else []
    if other:
        raise LogError(f"{source}:1: one column {short(header[0])}: fields separated by {other[0]!r}, not "
                       f"{fmt.delimiter!r}")
    for name in header:
        wheel, dot, joint = name.rpartition(".")
        if dot and joint in ("spin", "steer") and wheels and wheel not in wheels and name not in renamed:
            raise LogError(f"{source}:1: column '{name}' names no wheel of the robot"
                           f"{did_you_mean(name, wheels, header)} (wheels: {', '.join(wheels)})")
    for joint, _ in fmt.columns:  # a misspelt joint's column would be ignored
        wheel, _, kind = joint.rpartition(".")
        if wheels and (kind not in ("spin", "steer") or wheel not in wheels):
            raise LogError(f"{source}: a column is given for '{joint}', no joint of the robot"
                           f"{did_you_mean(joint, wheels)} (joints WHEEL.spin, WHEEL.steer; wheels: "
                           f"{', '.join(wheels)})")
    wanted, roles = [fmt.time_column, *(fmt.column_of(j) for j in joints)], ["time", *joints]
    for role, name in (("heading", fmt.heading_column), ("gyro", fmt.gyro_column)):
        if name is not None:
            wanted.append(name)
            roles.append(role)
    for k, name in enumerate(wanted):  # one column read twice: two encoders were read from one
        if name in wanted[:k]:
            raise LogError(f"{source}:1: column '{name}' is read for both {roles[wanted.index(name)]} and "
                           f"{roles[k]}")
    for name in wanted:
        if name not in header:
            unread = [h for h in header if h not in wanted]  # not a column read for another joint
            unit = next((h for h in unread if h.startswith(f"{name} [") and h.endswith("]")), None)
            if unit is not None:  # 'did you mean 'time [s]'?' named nothing a caller could pass
                raise LogError(f"{source}:1: missing column '{name}': the header gives its unit ('{unit}'); read the "
                               "units it declares with fmt=header_format(path, robot.name, joints) "
                               "(wmrkit.odometry.header), as 'wmrkit odometry' does")
            close = difflib.get_close_matches(name, unread, n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            raise LogError(f"{source}:1: missing column '{name}'{hint} (columns: {short(', '.join(header), 200)})")
    return [header.index(n) for n in wanted]


def _check_finite(log: JointLog, raw: np.ndarray, fmt: LogFormat) -> None:
    """Refuse a value of `raw` (time, joints, external heading) that is not finite, naming its row and its joint or
    column (the gyro's as the gyro's: it was called 'heading')."""
    bad = ~np.isfinite(raw)
    if bad.any():
        i, c = (int(x) for x in np.argwhere(bad)[0])
        name = (f"column '{fmt.time_column}'" if c == 0 else log.joints[c - 1] if c <= len(log.joints)
                else f"column '{fmt.heading_column or fmt.gyro_column}'")
        raise LogError(f"{log.where(i)}: {name}: value {float(raw[i, c])!r} is not a finite number")


def _cumtrapz(rate: np.ndarray, t: np.ndarray, *, start: bool) -> np.ndarray:
    """Trapezoidal running integral of `rate` over `t`; includes the leading 0 when `start`."""
    steps = np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))
    return np.concatenate([[0.0], steps]) if start else steps


def _quoted(names: Sequence[str]) -> str:
    return ", ".join(f"'{n}'" for n in names)
