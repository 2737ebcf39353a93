"""Errors a user can cause. The CLI turns every :class:`WmrkitError` into one line and exit code 2."""

from __future__ import annotations

import threading
import warnings
from collections.abc import Callable, Sequence
from typing import TypeVar

T = TypeVar("T")
_CATCHING = threading.Lock()  # warnings.catch_warnings changes process-wide state: one reader at a time


class WmrkitError(Exception):
    """Base of every error a user can cause (bad input, impossible request)."""


class ShapeError(WmrkitError, ValueError):
    """A bad argument at a Python array or keyword door: a wrong shape or type, text where a number is expected, a
    value that is not finite or out of range (docs/conventions.md); the message names the argument."""


class UnknownNameError(WmrkitError, LookupError):
    """A wheel, joint, robot or velocity name that does not exist."""

    def __str__(self) -> str:  # LookupError would otherwise repr() the message
        return str(self.args[0]) if self.args else ""


#: Every character ``str.splitlines`` breaks at, escaped so that a message stays on one line.
_ONE_LINE = str.maketrans({c: repr(c)[1:-1] for c in "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"})


def field_path(loc: tuple[str | int, ...]) -> str:
    """A field's location as written in errors: ``("wheels", 0, "r")`` -> ``wheels[0].r``."""
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc).lstrip(".")


class DescriptionError(WmrkitError, ValueError):
    """A robot description is wrong at a known place: file, wheel, field.

    Printed as ``source:line: wheels[0].r: message`` (line 1-based, omitted when unknown).
    """

    def __init__(
        self, message: str, *, source: str, loc: tuple[str | int, ...] = (), line: int | None = None,
        wheel: str | None = None,
    ) -> None:
        self.message, self.source, self.loc, self.line, self.wheel = message, source, tuple(loc), line, wheel
        super().__init__(self._format())

    def _format(self) -> str:
        where = self.source if self.line is None else f"{self.source}:{self.line}"
        path = field_path(self.loc)
        text = f"{where}: {path}: {self.message}" if path else f"{where}: {self.message}"
        return text.translate(_ONE_LINE)  # names and values quoted from a file may hold line breaks

    def __str__(self) -> str:
        return self._format()


class SingularError(WmrkitError, ValueError):
    """A requested model does not exist at this configuration (non-assignable set, singular wheel)."""


class SelectionError(WmrkitError, ValueError):
    """A choice of velocities or joints a method refuses (e.g. omega as an actuator); the message says why."""


#: Names a message lists before counting the rest (:func:`name_list`).
MAX_LISTED = 8


def name_list(names: Sequence[str], limit: int = MAX_LISTED) -> str:
    """``"a, b, c"``, or past `limit` names the first ones and a count: ``"a, b, ..., h and 181 more"`` (a message
    about 64 double wheels listed 189 rates, 2,000 characters, on its one line)."""
    names = list(names)
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown} and {len(names) - limit} more"


def said_warnings(read: Callable[[], T], category: type[Warning] | tuple[type[Warning], ...]) -> tuple[T, list[str]]:
    """``read()`` and the lines of the `category` warnings (a class or a tuple of them) it raised (said by the
    caller: the CLI's ``wmrkit: warning:`` lines, the studio's answers), in order, said nowhere else; other warnings
    are passed on as they were. Not nested (one reader at a time): give every category at once."""
    with _CATCHING, warnings.catch_warnings(record=True) as caught:
        for c in category if isinstance(category, tuple) else (category,):
            warnings.simplefilter("always", c)
        out = read()
    said = []
    for w in caught:
        if issubclass(w.category, category):
            said.append(str(w.message))
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return out, said
