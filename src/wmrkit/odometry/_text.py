"""The text of a CSV log, checked line by line in chunks (vectorised over the bytes): what :mod:`.logs` parses.

Rows are read in bounded pieces (:data:`MAX_LINE`), so a file whose tail is one endless "line" (a logger's
preallocated block of NUL bytes after a power loss, a binary file) costs no more memory than a chunk. The text
of the readers' messages too: a did-you-mean for a misspelt joint; and the rows' numbers (:func:`parse_rows`), read
as every text table's (:mod:`wmrkit._numbers`).
"""

from __future__ import annotations

import difflib
import functools
import itertools
import re
from collections.abc import Sequence
from typing import IO

import numpy as np

from .._numbers import number_problem, short  # noqa: F401 (short: the readers' quoting)

#: Longest row read [characters]: a longer line is not a row of a CSV log.
MAX_LINE = 1 << 18
#: Lines read between two length checks: at most this many pieces of :data:`MAX_LINE` are held before refusing.
_BATCH = 256


def _error(message: str) -> Exception:
    """A :class:`.logs.LogError` (imported here: :mod:`.logs` imports this module)."""
    from .logs import LogError

    return LogError(message)


def read_lines(f: IO[str], count: int, source: str, line: int) -> list[str]:
    """Up to `count` lines of the text file `f` (line `line` first), refusing a line longer than :data:`MAX_LINE`
    without ever holding more than :data:`_BATCH` such pieces."""
    pieces, lines = iter(functools.partial(f.readline, MAX_LINE + 1), ""), []
    while len(lines) < count:
        batch = list(itertools.islice(pieces, min(_BATCH, count - len(lines))))
        if batch and max(map(len, batch)) > MAX_LINE:
            k = len(lines) + next(k for k, ln in enumerate(batch) if len(ln) > MAX_LINE)
            raise _error(f"{source}:{line + k}: a line longer than {MAX_LINE} characters: not a row of a CSV log")
        lines += batch
        if len(batch) < _BATCH:
            break
    return lines


_CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")  # all but tab, newline, carriage return


def encoded(lines: list[str], source: str, line: int) -> tuple[np.ndarray, np.ndarray]:
    """`lines` joined as UTF-8 bytes ``(B,)`` uint8, and where the newlines are; refuses bytes that are not UTF-8
    (read as lone surrogates) and control characters other than tab and line ends, naming the line. Vectorised."""
    text = "".join(lines)
    try:
        b = np.frombuffer(text.encode("utf-8"), dtype=np.uint8)
    except UnicodeEncodeError as err:
        where = line + text.count("\n", 0, err.start)
        raise _error(f"{source}:{where}: bytes that are not UTF-8 text (a binary file, or another encoding?)"
                       ) from None
    newlines = np.flatnonzero(b == 10)
    if np.count_nonzero(b < 32) != len(newlines) or np.count_nonzero(b == 127):  # else only newlines: fine
        bad = _CONTROL.search(text)
        if bad is not None:
            where = line + text.count("\n", 0, bad.start())
            raise _error(f"{source}:{where}: control character {bad.group()!r} in a text log (a binary file?)")
    return b, newlines


def check_lines(lines: list[str], delimiter: str, width: int, source: str, line: int) -> np.ndarray | None:
    """Check every line of a chunk at once (vectorised over the bytes): text, field count, line end.

    Returns which lines hold data (None: all of them); blank lines are skipped. A last line without its line end
    (only the file's last line can lack one) is reported: the file was probably cut while being written.
    """
    b, ends = encoded(lines, source, line)
    if not lines[-1].endswith("\n"):
        ends = np.append(ends, len(b) - 1)
    if len(ends) == len(lines):
        counts = np.diff(np.searchsorted(np.flatnonzero(b == ord(delimiter)), ends), prepend=0)
        suspects = np.flatnonzero(counts != width - 1)
    else:  # lines ending in a lone carriage return: count per line
        suspects = np.array([k for k, ln in enumerate(lines) if ln.count(delimiter) != width - 1], dtype=int)
    if width == 1:
        suspects = np.arange(len(lines))
    data_lines = None
    for k in suspects.tolist():  # blank lines, or the first bad one
        if not lines[k].strip():
            data_lines = np.ones(len(lines), dtype=bool) if data_lines is None else data_lines
            data_lines[k] = False
        elif lines[k].count(delimiter) != width - 1:
            raise _error(f"{source}:{line + k}: expected {width} fields, got {lines[k].count(delimiter) + 1} "
                           f"(the header has {width})")
    last = len(lines) - 1
    if (data_lines is None or data_lines[last]) and not lines[last].endswith(("\n", "\r")):
        raise _error(f"{source}:{line + last}: the last line has no line end: the file looks truncated "
                       "(end a complete line with a newline)")
    return data_lines


def did_you_mean(joint: str, wheels: Sequence[str], taken: Sequence[str] = ()) -> str:
    """`` (did you mean 'WHEEL.KIND'?)`` for a misspelt joint name `joint` (``lefft.spin``, ``left.spn``), or ``""``
    when no joint of `wheels` but those `taken` (columns of their own) is that close: a log of another robot
    (``front_left.spin`` on a differential drive) gets no hint that would point at the wrong fix."""
    kind = joint.rpartition(".")[2]
    kinds = (kind,) if kind in ("spin", "steer") else ("spin", "steer")
    names = [f"{w}.{k}" for w in wheels for k in kinds if f"{w}.{k}" not in taken]
    close = difflib.get_close_matches(joint, names, n=1, cutoff=0.85)
    return f" (did you mean '{close[0]}'?)" if close else ""


def parse_rows(rows: list[str], usecols: list[int], delimiter: str, source: str, line: int, lines: list[str],
               header: list[str]) -> np.ndarray:
    """The numbers of the columns `usecols` of `rows` ``(R, len(usecols))``; a field that is not a number is refused
    naming its line and its column as the header writes it (:func:`wmrkit._numbers.number_problem`: finite numbers
    in ASCII digits only)."""
    if not rows:
        return np.zeros((0, len(usecols)))
    try:
        data = np.loadtxt(rows, delimiter=delimiter, usecols=usecols, ndmin=2, comments=None, dtype=float)
    except ValueError:  # field counts are already checked (check_lines): a field is not a number
        data = None
    if data is not None and np.isfinite(data).all():  # else 'nan', 'inf' or '1e400' (read as inf): named below
        return data
    for k, ln in enumerate(lines):  # error path: find the first bad line
        if not ln.strip():
            continue
        fields = ln.strip("\r\n").split(delimiter)
        if len(fields) != len(header):
            raise _error(f"{source}:{line + k}: expected {len(header)} fields, got {len(fields)}")
        for c in usecols:
            problem = number_problem(fields[c])
            if problem is not None:
                raise _error(f"{source}:{line + k}: column '{header[c]}': {problem} (field {c + 1})")
    raise _error(f"{source}:{line}: cannot read the rows that start here")  # pragma: no cover

