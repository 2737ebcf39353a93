"""Units written in a CSV log's header: a log says what its columns hold (``docs/odometry.md``).

A column name may carry its unit in brackets: ``time [ms]``, ``left.spin [rad]``, ``left.spin [rad/s]``,
``left.spin [counts]``, ``left.spin [m]`` or ``[m/s]`` (the wheel's travel or speed, divided by its radius),
``left.spin [deg]``, ``[deg/s]``, ``[rev]`` (``[turn]``), ``[rev/s]`` (``[turn/s]``), ``[rpm]`` (read in rad, rad/s),
``left.spin [counts:u16]`` (an incremental encoder on an unsigned 16-bit counter that wraps;
``s16`` signed, any width from 8 to 64 bits), ``steer.steer [rad]``, ``steer.steer [deg]``, ``steer.steer [counts]``.
A log written this way needs no ``--spin``/``--steer``/``--counter-bits`` options, and an option that contradicts
the header is an error rather than a silent misreading.

Steering columns are headings (0 = rolling straight ahead; :mod:`.steering`). A steering unit may name its
convention: ``steer.steer [deg:beta]`` (also ``rad:beta``, ``counts:beta``) marks a file written in the thesis's β
by an older wmrkit version, read as such; ``[deg:heading]`` says the default explicitly.
"""

from __future__ import annotations

import csv
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WmrkitError
from ..limits import regular_file_problem
from ..units import UNITS, split_unit

if TYPE_CHECKING:
    from ..robot import Robot
    from .logs import LogFormat

#: Units a joint column may declare, and the log-format mode each means.
SPIN_UNITS = {"rad": "angle", "rad/s": "velocity", "counts": "counts", "m": "distance", "m/s": "speed",
              "deg": "angle", "deg/s": "velocity", "rev": "angle", "rev/s": "velocity", "turn": "angle",
              "turn/s": "velocity", "rpm": "velocity"}
#: Radians (rad/s) in one unit of the spin units that are not rad (:attr:`~.logs.LogFormat.spin_scale`), from the
#: description's angle units (:data:`wmrkit.units.UNITS`).
SPIN_SCALES = {"deg": UNITS["angle"]["deg"], "rev": UNITS["angle"]["turn"], "turn": UNITS["angle"]["turn"]}
SPIN_SCALES |= {f"{unit}/s": k for unit, k in SPIN_SCALES.items()} | {"rpm": UNITS["angle"]["turn"] / 60}
#: The spin modes of :class:`~.logs.LogFormat` (``--spin`` takes the first three; a header's m, m/s the others).
SPIN_MODES = ("angle", "counts", "velocity", "distance", "speed")
STEER_UNITS = {"rad": "angle", "deg": "degrees", "counts": "counts"}
#: Conventions a steering unit may name after a colon (``deg:beta``).
STEER_CONVENTIONS = ("heading", "beta")
TIME_UNITS = ("s", "ms", "us", "ns")
#: The units the external heading columns may declare (``LogFormat.heading_column``, ``gyro_column``); without one
#: they are read in the first (a WPILib gyro's angle is in degrees: ``yaw [deg]``, ``gz [deg/s]``).
EXTERNAL_UNITS = {"heading": ("rad", "deg"), "gyro": ("rad/s", "deg/s")}

_COUNTER = re.compile(r"^counts:([us])(\d{1,2})$")
#: What a unit in brackets looks like (``ms``, ``rad/s``, ``counts:u16``, ``deg:heading``, ``min``), unlike an index.
_UNIT_WORD = re.compile(r"^[A-Za-z][A-Za-z0-9/:^*._-]*$")


class HeaderError(WmrkitError, ValueError):
    """A unit in a log's header that wmrkit cannot read, or that contradicts an option."""


@dataclass(frozen=True)
class HeaderUnits:
    """What a header says: plain column names, per-kind modes (None: not said), counter width and signedness."""

    columns: tuple[tuple[str, str], ...]  # (plain name, name as written) for every column with a unit
    time_unit: str | None = None
    spin: str | None = None
    steer: str | None = None
    bits: int | None = None
    signed: bool = False
    steer_convention: str | None = None
    external_degrees: bool = False  # the heading or gyro column is in deg (deg/s)
    spin_scale: float = 1.0  # radians in one unit of the spin columns (deg, rev, rpm: SPIN_SCALES)

    @property
    def declared(self) -> bool:
        return bool(self.columns)


def read_header_units(path: str | Path, *, max_chars: int = 1 << 16, delimiter: str = ",", time_column: str = "time",
                      roles: Mapping[str, str] | None = None) -> HeaderUnits:
    """The units of a CSV log's header line (bounded read; :func:`parse_header_units`); an unreadable file says
    nothing here."""
    if regular_file_problem(path, "log"):  # a FIFO's open waits for a writer: its reader refuses it
        return HeaderUnits(())
    try:
        with open(path, encoding="utf-8-sig", errors="replace", newline="") as f:
            line = f.readline(max_chars)
    except OSError:
        return HeaderUnits(())
    return parse_header_units(header_names(line, delimiter), source=str(path), time_column=time_column,
                              roles=roles)


def header_names(line: str, delimiter: str = ",") -> list[str]:
    """The column names of a header line, read as CSV: a spreadsheet's quotes (``"time [s]"``) are not part of the
    names, and a quoted delimiter is (``"battery, volts"``); spaces around a name are dropped."""
    return [name.strip() for name in next(csv.reader([line.strip("\r\n")], delimiter=delimiter,
                                                     skipinitialspace=True), [""])]


def parse_header_units(names: list[str], *, source: str = "<log>", time_column: str = "time",
                       roles: Mapping[str, str] | None = None) -> HeaderUnits:
    """Parse ``name [unit]`` header entries (see the module docstring).

    The time unit is the unit of `time_column` only; joint units are those of ``WHEEL.spin``/``WHEEL.steer``
    columns and of the columns `roles` names (plain column name -> ``"spin"``, ``"steer"``, or ``"heading"`` [rad
    or deg] and ``"gyro"`` [rad/s or deg/s], the external heading columns). The units of other columns (a battery
    voltage, a latency in ms) are not the log's and are ignored."""
    columns, modes, bits, signed, time_unit = [], {"spin": set(), "steer": set()}, set(), set(), None
    conventions, roles, external_degrees, spin_units = set(), dict(roles or {}), False, set()
    for written in names:
        parts = split_unit(written)
        if parts is None:
            continue
        plain, unit = parts
        columns.append((plain, written))
        joint = plain.rpartition(".")[2] if "." in plain else None
        kind = roles.get(plain, joint if joint in ("spin", "steer") else None)
        if plain == time_column:
            if unit not in TIME_UNITS:
                raise HeaderError(f"{source}:1: column '{plain}': unknown unit '{unit}' (time units: "
                                  f"{', '.join(TIME_UNITS)})")
            time_unit = unit
            continue
        if kind in EXTERNAL_UNITS:
            if unit not in EXTERNAL_UNITS[kind]:
                raise HeaderError(f"{source}:1: column '{plain}': unknown unit '{unit}' (for a {kind} column: "
                                  f"{', '.join(EXTERNAL_UNITS[kind])})")
            external_degrees = unit.startswith("deg")
            continue
        if kind is None:  # not a column of the log's joints: its unit is not ours to read
            continue
        table = STEER_UNITS if kind == "steer" else SPIN_UNITS
        base, colon, convention = unit.rpartition(":")
        if colon and convention in STEER_CONVENTIONS:
            if kind != "steer":
                raise HeaderError(f"{source}:1: column '{plain}': ':{convention}' names a steering convention; "
                                  "only steer columns have one")
            conventions.add(convention)
            unit = base
        counter = _COUNTER.match(unit)
        if counter is not None:
            width = int(counter.group(2))
            if not 8 <= width <= 64:
                raise HeaderError(f"{source}:1: column '{plain}': counter width {width} bits (8 to 64)")
            bits.add(width)
            signed.add(counter.group(1) == "s")
            unit = "counts"
        if unit not in table:
            extra = "files in the thesis's beta: deg:beta, rad:beta" if kind == "steer" else "counters: counts:u16"
            raise HeaderError(f"{source}:1: column '{plain}': unknown unit '{unit}' (for a {kind} joint: "
                              f"{', '.join(table)}; {extra}, ...)")
        modes[kind].add(table[unit])
        if kind == "spin":
            spin_units.add(unit)
    for kind, found in modes.items():
        if len(found) > 1:
            raise HeaderError(f"{source}:1: the {kind} columns mix units ({', '.join(sorted(found))}); one per log")
    if len({SPIN_SCALES.get(u, 1.0) for u in spin_units}) > 1:  # rad and deg: both angles, not one scale
        raise HeaderError(f"{source}:1: the spin columns mix units ({', '.join(sorted(spin_units))}); one per log")
    if len(bits) > 1 or len(signed) > 1:
        raise HeaderError(f"{source}:1: the counter columns mix widths or signedness; one counter per log")
    if len(conventions) > 1:
        raise HeaderError(f"{source}:1: the steer columns mix conventions (heading, beta); one per log")
    return HeaderUnits(tuple(columns), time_unit, next(iter(modes["spin"]), None), next(iter(modes["steer"]), None),
                       next(iter(bits), None), next(iter(signed), False), next(iter(conventions), None),
                       external_degrees, SPIN_SCALES.get(next(iter(spin_units), "rad"), 1.0))


def travel_radii(joints: Sequence[str], spin: str, robot: Robot | None, source: str,
                 spin_scale: float = 1.0) -> np.ndarray | None:
    """What divides each joint's column into radians: its wheel's radius for spin joints logged as the wheel's
    travel [m] or speed [m/s] (WPILib's ``SwerveModulePosition.distanceMeters``), ``1 / spin_scale`` for spins in
    another angle unit (deg, rev), 1 for steering; None when nothing is divided. Travel needs the robot
    (:class:`HeaderError`)."""
    if spin not in ("distance", "speed"):
        return None if spin_scale == 1.0 else np.array([1.0 if j.endswith(".steer") else 1.0 / spin_scale
                                                        for j in joints])
    if robot is None:
        raise HeaderError(f"{source}: spin columns in m or m/s (the wheels' travel) need the robot's wheel radii: "
                          "pass robot=")
    return np.array([1.0 if j.endswith(".steer") else robot.wheel(j.rpartition(".")[0]).r for j in joints])


def _plain(name: str) -> str:
    """A column name without the unit it may carry (``'time [ms]'`` -> ``'time'``, ``'time [min]'`` -> ``'time'``,
    whose unit the header's reader then refuses by name); a name whose brackets hold no unit word (``'position[0]'``,
    an exported array) is a name."""
    parts = split_unit(name)
    return parts[0] if parts is not None and _UNIT_WORD.match(parts[1]) else name


def bare_heading_problem(column: str, heading: Sequence[float]) -> tuple[int, str] | None:
    """``(row, message)`` for a heading column whose name writes no unit (``yaw``, not ``yaw [rad]``) holding a
    value beyond one turn, else None: read as radians, a yaw logged in degrees gave theta = 213 rad with exit 0. The
    rule of bare angles in descriptions (:data:`~wmrkit.units.BARE_ANGLE_LIMIT`); an unwrapped heading in rad
    writes its unit in the header."""
    from ..units import BARE_ANGLE_LIMIT

    beyond = np.flatnonzero(np.abs(np.asarray(heading, dtype=float)) > BARE_ANGLE_LIMIT)
    if _plain(column) != column or not beyond.size:  # the header writes the column's unit
        return None
    i = int(beyond[0])
    return i, (f"column '{column}': {float(heading[i]):g} is beyond one turn as radians, probably degrees: a heading "
               f"column without a unit is read in rad (write its unit in the header: '{column} [deg]' for degrees, "
               f"'{column} [rad]' for an unwrapped heading in rad)")


def merge_option(name: str, given: object | None, declared: object | None, default: object, source: str) -> object:
    """An option's value: the header's when the option was not given; the option's when the header is silent;
    an error when both are given and disagree."""
    if declared is None:
        return default if given is None else given
    if given is not None and given != declared:
        raise HeaderError(f"{source}: the header says {name} {declared}, the option says {given}; drop the option "
                          "or fix the header")
    return declared


def header_format(path: str | os.PathLike[str], robot_name: str, joints: Sequence[str], *, time_column: str = "time",
                  time_unit: str | None = None, columns: Mapping[str, str] | None = None, spin: str | None = None,
                  steer: str | None = None, steer_convention: str | None = None, counter_bits: int | None = None,
                  signed: bool = False, cpr: float | None = None, gear: float | None = None,
                  steer_resolution: float | None = None, heading_column: str | None = None,
                  gyro_column: str | None = None, max_gap: float | None = None) -> LogFormat:
    """The :class:`~.logs.LogFormat` of the CSV log at `path` for `joints` of robot `robot_name`: the settings given
    (None: not given; named as the ``wmrkit odometry`` options) merged with the units its header declares
    (:func:`merge_option`: a setting and a header that disagree are an error), else the defaults. Joints read as
    counts get the given encoder settings over the catalog's (:func:`~.encoders.encoders_for`)."""
    from .encoders import EncoderError, encoders_for
    from .logs import LogFormat

    source = os.fspath(path)
    given = {"time": time_column, "heading": heading_column, "gyro": gyro_column} | dict(columns or {})
    plain = {k: None if c is None else _plain(c) for k, c in given.items()}  # 'time [ms]' names the column 'time'
    time_column, heading_column, gyro_column = plain["time"], plain["heading"], plain["gyro"]
    columns = {j: plain[j] for j in columns or {}}
    roles = {c: j.rpartition(".")[2] for j, c in columns.items()}
    roles |= {c: kind for c, kind in ((heading_column, "heading"), (gyro_column, "gyro")) if c is not None}
    units = read_header_units(path, time_column=time_column, roles=roles)  # nothing from a missing file
    for key, name in given.items():  # a unit typed with a name that the header writes otherwise: a missing column
        if name is not None and name != plain[key] and dict(units.columns).get(plain[key]) != name:
            raise HeaderError(f"{source}:1: no column '{name}' (the header names it "
                              f"'{dict(units.columns).get(plain[key], plain[key])}')")
    spin = merge_option("--spin", spin, units.spin, "angle", source)
    steer = merge_option("--steer", steer, units.steer, "angle", source)
    convention = merge_option("--steer-convention", steer_convention, units.steer_convention, "heading", source)
    unit = merge_option("--time-unit", time_unit, units.time_unit, "s", source)
    bits = merge_option("--counter-bits", counter_bits, units.bits, None, source)
    counted = [j for j in joints if (steer if j.endswith(".steer") else spin) == "counts"]
    renamed = dict(units.columns)  # 'left.spin [counts]' read as left.spin
    try:
        encoders = encoders_for(robot_name, counted, counts_per_rev=cpr, gear_ratio=gear, bits=bits,
                                signed=signed or units.signed, steer_resolution=steer_resolution)
    except EncoderError as e:  # name the file and the column (the --json "field"), as the log's other errors do
        if e.joint is None:
            raise
        raise HeaderError(f"{source}:1: column '{(columns or {}).get(e.joint, e.joint)}': {e}") from None
    named = {j: renamed[j] for j in joints if j in renamed} | {j: renamed.get(c, c) for j, c in (columns or {}).items()}
    return LogFormat(time_column=renamed.get(time_column, time_column), time_unit=unit, columns=tuple(named.items()),
                     spin=spin, steer=steer, encoders=encoders,
                     heading_column=None if heading_column is None else renamed.get(heading_column, heading_column),
                     gyro_column=None if gyro_column is None else renamed.get(gyro_column, gyro_column),
                     max_gap=max_gap, steer_convention=convention, external_degrees=units.external_degrees,
                     spin_scale=units.spin_scale)
