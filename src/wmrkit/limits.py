"""Limits of robot descriptions (``docs/limits.md``): sizes, printable text, and the physical envelope.

Checks called by :mod:`wmrkit.description` while it validates a description; each raises the description's
located one-line error through the checker's ``fail(message, loc)``.
"""

from __future__ import annotations

import math
import os
import re
import stat
import sys
from collections.abc import Collection
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import DescriptionError

if TYPE_CHECKING:
    from .wheels import Wheel

#: Largest description [bytes of a file, characters of a text]; one of MAX_WHEELS wheels takes ~300 bytes.
MAX_FILE_SIZE = 1 << 18
#: Largest coordinate of a position in a trajectory or reference file [m] (beyond it differences of positions lose
#: their precision and squares overflow).
MAX_COORDINATE = 1e9
#: Largest file read whole into memory [bytes]: trajectories (TUM, CSV), references, torque files, the log of a Monte
#: Carlo study. The joint logs of odometry are read in chunks and have no such limit.
MAX_TABLE_SIZE = 1 << 26
#: Most samples of a joint log read at once (``chunk_size``): the chunks bound the memory of a log of any length.
MAX_CHUNK = 1 << 22
#: Fastest speed a command or program may ask of a wheeled robot [m/s].
MAX_SPEED = 1e3
#: Largest torque [N m] a torque file (``simulate --torques``) or ``Inputs.torques`` applies to a joint: the largest
#: load of one tyre (``dynamics.tyres.MAX_LOAD``, 1e7 N: a thousand tonnes) on a lever of the longest length wmrkit
#: handles (MAX_SIZE, 1 km), a hundred thousand times the largest wheel motors built. Beyond it a value is a unit
#: mistake or a placeholder: 1e12 N m on the skid steer's wheels, and 1e308, overflowed the run.
MAX_TORQUE = 1e10
#: Largest speed [m/s], turn rate [rad/s] or joint rate [rad/s] a kinematic query accepts (``wmrkit ik --twist``,
#: ``fk --spin``, the studio's drive): far beyond any wheeled robot, and small enough that no result overflows.
MAX_QUERY_RATE = 1e6
#: Most wheels in a robot: the chapter-4 searches grow combinatorially with the wheel count.
MAX_WHEELS = 64
#: Longest robot and wheel names, and notes [characters]: they are printed in tables and reports.
MAX_NAME, MAX_NOTES = 64, 4096
#: The robot's reach (its largest length from its origin: wheel distance, radius, offset) lies in [MIN_SIZE, MAX_SIZE]
#: [m] (``kinematics.linalg.reach``; its three sizes: docs/limits.md, the physical envelope).
MIN_SIZE, MAX_SIZE = 1e-6, 1e3
#: Radii, roller radii, castor offsets and half-widths are at least MIN_RATIO times the robot's reach.
MIN_RATIO = 1e-4
#: A coupling's ratios: each of magnitude in [MIN_COUPLING_RATIO, MAX_COUPLING_RATIO], the largest at most
#: 1 / MIN_RATIO times the smallest (rank decisions would lose the smaller to round-off).
MIN_COUPLING_RATIO, MAX_COUPLING_RATIO = 1e-6, 1e6
#: Two mount points closer than ONE_PLACE times the robot's size L are at one place, as described (a warning when
#: read: ``_description_wheels._warn_coincident``); ``analysis.conditioning.ROUNDING``, the same, is not imported
#: with every description (the analysis package takes 0.3 s to import).
ONE_PLACE = 1e-12
#: Swedish gamma at least this far from 0 and 180 deg; castor delta at least this far from +-90 deg [rad].
ANGLE_MARGIN = math.radians(1.0)


#: Relative round-off of an edge computed from typed numbers: 1e-4 of a reach, 1e4 times a ratio. Decimals read as
#: binary floats, and their product, are each off by half an ulp: ``1e-4 * 0.979`` rounds above ``9.79e-05``, and
#: a radius exactly 1e-4 of a reach of 0.979 m was refused as less than that.
EDGE_ROUNDOFF = 4 * sys.float_info.epsilon


def below(value: float, edge: float) -> bool:
    """Whether `value` lies below `edge` (computed from typed numbers) by more than its round-off."""
    return value < edge * (1.0 - EDGE_ROUNDOFF)


def shown(value: float, edge: float) -> str:
    """`value` printed ``:g``, or with every digit when that would print the `edge` it lies beyond."""
    return f"{value:g}" if f"{value:g}" != f"{edge:g}" else repr(value)


#: Control characters (C0, DEL, C1) and lone surrogates (bytes that are not UTF-8): they break printing.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\ud800-\udfff]")


def check_length(length: float, error: type[Exception], what: str = "length") -> None:
    """Raise `error` unless `length` [m] lies in the lengths wmrkit handles, ``[MIN_SIZE, MAX_SIZE]`` (a
    characteristic length D far outside them makes the condition number overflow or lose its rank decisions)."""
    if not MIN_SIZE <= length <= MAX_SIZE:  # NaN included
        raise error(f"{what}: {length:g} m is outside the lengths wmrkit handles ({MIN_SIZE:g} to {MAX_SIZE:g} m)")


def check_seed(seed: object, error: type[Exception], what: str = "seed") -> None:
    """Raise `error` unless `seed` is an integer >= 0 (what numpy's generators take)."""
    if isinstance(seed, bool) or not (isinstance(seed, int | np.integer) and seed >= 0):
        raise error(f"{what} must be an integer >= 0, got {seed!r}")


def check_chunk_size(chunk_size: object, error: type[Exception], what: str = "chunk_size") -> None:
    """Raise `error` unless `chunk_size` is a number of samples in ``[1, MAX_CHUNK]``."""
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or not 1 <= chunk_size <= MAX_CHUNK:
        raise error(f"{what} must be in [1, {MAX_CHUNK}] samples (it bounds the memory), got {chunk_size}")


def regular_file_problem(path: str | os.PathLike[str], what: str) -> str | None:
    """Why `path` is no file to read (a `what`): a folder, or not a regular file (a FIFO waits for a writer
    forever, a device such as /dev/zero never ends); None when it is one or cannot be examined (left to its
    reader)."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):  # ValueError: a NUL in the name
        return None
    if stat.S_ISREG(mode):
        return None
    kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file (a FIFO, socket or device)"
    return f"{kind}; a {what} is a file"


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether `a` and `b` name one file (links and relative paths resolved; they need not exist). A name the system
    cannot look up (a NUL in it) is no file."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
    except ValueError:
        return False


def check_table_size(path: str | os.PathLike[str], error: type[Exception], what: str) -> None:
    """Raise `error` naming `path` when it is not a regular file (:func:`regular_file_problem`) or when the file (a
    `what`, read whole) is larger than :data:`MAX_TABLE_SIZE`; a file that cannot be examined is left to its
    reader."""
    problem = regular_file_problem(path, what)
    if problem:
        raise error(f"{os.fspath(path)}: {problem}")
    try:
        size = os.stat(path).st_size
    except (OSError, ValueError):
        return
    if size > MAX_TABLE_SIZE:
        raise error(f"{os.fspath(path)}: {size} bytes: a {what} is read whole and may hold at most "
                    f"{MAX_TABLE_SIZE} bytes (docs/limits.md); decimate or split it")


def _check_size(size: int, unit: str, source: str, what: str = "description") -> None:
    if size > MAX_FILE_SIZE:
        raise DescriptionError(f"{size} {unit}: a {what} holds at most {MAX_FILE_SIZE} {unit} (docs/limits.md)",
                               source=source)


def _check_text_fields(name: str, notes: str, check: Any) -> None:
    """The robot's name and notes are printed: text of bounded length that UTF-8 can encode (no lone surrogates)
    and without control characters; the name is also printable on one line (``str.isprintable``). Wheel names are
    identifiers (WHEEL_NAME) of at most MAX_NAME characters (checked in :func:`_check_envelope`)."""
    for key, value, limit in (("name", name, MAX_NAME), ("notes", notes, MAX_NOTES)):
        if len(value) > limit:
            check.fail(f"at most {limit} characters, got {len(value)}", (key,))
        bad = next((c for c in value if not c.isprintable()), None) if key == "name" else _CONTROL.search(value)
        if bad is not None:
            char = bad if isinstance(bad, str) else bad.group()
            check.fail(f"must be printable text{' on one line' if key == 'name' else ''}, got the character "
                       f"{char!a}", (key,))


def _check_envelope(wheels: list[Wheel], check: Any, positioned: Collection[int] = ()) -> None:
    """The physical envelope wmrkit's numbers are valid in (docs/limits.md): the robot's reach (its largest length
    from its origin, ``kinematics.linalg.reach``, here of the wheels being read) from 1 um to 1 km, radii and
    offsets not below MIN_RATIO of it (rank decisions are made relative to a size at most twice it),
    Swedish rollers and castor axles at least ANGLE_MARGIN away from the angles where the wheel degenerates.

    `positioned`: indices of the wheels described by ``position: [x, y]`` rather than ``l``/``alpha``; a distance
    out of range is then reported at the coordinate the user gave (``position[0]`` or ``position[1]``)."""

    def where(i: int, key: str) -> tuple:
        if key != "l" or i not in positioned:
            return ("wheels", i, key)
        x, y = wheels[i].position
        return ("wheels", i, "position", int(abs(y) > abs(x)))

    def what(size: float, i: int, key: str) -> str:
        text = f"{shown(size, MAX_SIZE)} m"
        return text if key != "l" or i not in positioned else f"{text} from the robot's origin"

    lengths = [[(abs(getattr(w, k)), i, k) for k in
                ("l", *(k for k in ("r", "r_r", "d", "b") if k in w.kind.required or k in w.kind.optional))]
               for i, w in enumerate(wheels)]
    size = max(value for own in lengths for value, _, _ in own)
    if size < MIN_SIZE:  # the robot's, not a wheel's: said before any wheel's, at the first length of that size
        _, i, key = next(x for own in lengths for x in own if x[0] == size)
        check.fail(f"the robot's size ({shown(size, MIN_SIZE)} m, its largest length) is below {MIN_SIZE:g} m (1 um)",
                   where(i, key))
    for i, w in enumerate(wheels):  # each wheel's mistakes in file order, the first wheel's first (not the last's)
        if len(w.name) > MAX_NAME:
            check.fail(f"at most {MAX_NAME} characters, got {len(w.name)}", ("wheels", i, "name"))
        for value, _, key in lengths[i]:
            if not value <= MAX_SIZE:
                check.fail(f"{what(value, i, key)}: longer than {MAX_SIZE:g} m, outside the lengths wmrkit handles "
                           "(1 um to 1 km)", where(i, key))
            if key != "l" and size <= MAX_SIZE and below(value, MIN_RATIO * size):  # else a length is too long
                check.fail(f"{shown(value, MIN_RATIO * size)} m is less than {MIN_RATIO:g} of the robot's size "
                           f"({size:g} m, its largest length): too small to tell from 0 in the rank decisions",
                           ("wheels", i, key))
        if w.type == "swedish" and abs(math.sin(w.gamma)) < math.sin(ANGLE_MARGIN):
            check.fail(f"gamma = {math.degrees(w.gamma):.6g} deg: rollers within {math.degrees(ANGLE_MARGIN):g} "
                       "deg of the axle roll (almost) nowhere: the roller rate ~ 1/sin(gamma) explodes (eq. 3.19)",
                       ("wheels", i, "gamma"))
        if w.type == "castor" and abs(math.cos(w.delta)) < math.sin(ANGLE_MARGIN):
            check.fail(f"delta = {math.degrees(w.delta):.6g} deg: an axle within {math.degrees(ANGLE_MARGIN):g} "
                       "deg of the arm cannot steer the castor (det J_c = -r d cos(delta) ~ 0, eq. 3.19)",
                       ("wheels", i, "delta"))
