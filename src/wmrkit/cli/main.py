"""Entry point of the ``wmrkit`` command. An answer exits 0, or 1 when it is no (docs/limits.md, Exit codes); user
mistakes print one line and exit 2; bugs keep their traceback."""

from __future__ import annotations

import argparse
import fnmatch
import glob
import importlib
import itertools
import json
import os
import re
import sys
import threading
from collections.abc import Mapping, Sequence
from typing import NoReturn

from .._shapes import reads_as_number
from ..errors import DescriptionError, WmrkitError
from ._common import check_blank, check_outputs, collecting_warnings, named_values, output_option

#: Each command and the module of ``wmrkit.cli`` that registers it (``add_parsers``), in ``--help`` order.
COMMANDS = {
    "robots": "robots", "show": "robots", "kinematics": "kinematics", "ik": "ik", "fk": "ik",
    "analyze": "analyze", "odometry": "odometry", "studio": "studio",
    "batch": "batch", "sweep": "batch", "calibrate": "slip", "slip-study": "slip",
    "vision": "vision", "follow-line": "vision", "park": "park",
    "tyre": "dynamics", "simulate": "dynamics", "track": "control", "feasibility": "control",
}


class UsageError(WmrkitError):
    """A command line argparse refuses (printed with the usage in text mode, as JSON under ``--json``)."""

    def __init__(self, message: str, usage: str) -> None:
        super().__init__(message)
        self.usage = usage


#: A word that starts with a minus and a digit is a value, not an option: '-90deg', '-1e-3', '-0.5 rad' (no option
#: of wmrkit starts with a digit; argparse's own test takes only '-90' and '-0.5').
NEGATIVE_VALUE = re.compile(r"^-\.?\d|^-inf$")


class _Parser(argparse.ArgumentParser):
    @property
    def _negative_number_matcher(self) -> re.Pattern:
        return NEGATIVE_VALUE

    @_negative_number_matcher.setter
    def _negative_number_matcher(self, _default: re.Pattern) -> None:
        pass  # argparse sets its own in __init__

    def error(self, message: str) -> NoReturn:
        command = self.prog.removeprefix("wmrkit").strip()
        raise UsageError(f"{command}: {message}" if command else message, self.format_usage())


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; with `command`, only that command's module is imported (a fast start)."""
    parser = _Parser(
        prog="wmrkit",
        description="Kinematic models, analysis and odometry for any wheeled mobile robot.",
    )
    parser.add_argument("--version", action="version", version=f"wmrkit {_version()}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    wanted = [COMMANDS[command]] if command in COMMANDS else list(dict.fromkeys(COMMANDS.values()))
    for name in wanted:
        importlib.import_module(f"{__package__}.{name}").add_parsers(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``wmrkit`` with `argv`; return the exit code (0 an answer, 1 an answer that is no, 2 no answer)."""
    argv = sys.argv[1:] if argv is None else argv
    command = next((a for a in argv if not a.startswith("-")), None)
    as_json = wants_json(argv)
    done = threading.Event()
    if not as_json:
        threading.Thread(target=_compile_notice, args=(done,), daemon=True).start()
    parser = args = None
    try:
        parser = build_parser(command)
        args, unknown = parser.parse_known_args(argv)
        if unknown:  # argparse's parse_args says so with wmrkit's usage; the command's own names the command
            chosen_parser(parser, args).error(f"unrecognized arguments: {' '.join(unknown)}")
        as_json = bool(getattr(args, "json", False))  # as parsed: '--js' is --json too
        check_blank(parser, args)
        check_outputs(parser, args)
        with collecting_warnings():
            return int(args.run(args) or 0)
    except WmrkitError as err:
        report_error(err, as_json, argv, given_names(parser, args))
        return 2
    except BrokenPipeError:  # e.g. `wmrkit robots | head` (an OSError: caught first)
        return 0
    except MemoryError:  # no answer (2), not a "no" (1, the exit status of an uncaught exception)
        report_error(WmrkitError(f"out of memory: the machine could not hold this run of '{command}' (its sizes "
                                 "and the memory they take: docs/limits.md); free memory or ask for less"), as_json,
                     argv)
        return 2
    except OSError as err:
        if err.filename is None:  # not about a file: a bug, with its traceback
            raise
        # a write that fails late (a full disk, mkdir in /proc as root): the text names the option, the JSON the file
        option = "" if as_json else output_option(args, err.filename)
        report_error(WmrkitError(f"{option}{err.filename}: {err.strerror or err}"), as_json, argv)
        return 2
    finally:
        done.set()


def chosen_parser(parser: argparse.ArgumentParser, args: argparse.Namespace) -> argparse.ArgumentParser:
    """The parser of the (sub)command that `args` chose ('batch odometry': batch's odometry parser)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and getattr(args, action.dest, None) in action.choices:
            return chosen_parser(action.choices[getattr(args, action.dest)], args)
    return parser


def given_names(parser: argparse.ArgumentParser | None, args: argparse.Namespace | None) -> dict[str, str]:
    """Each text value of the parsed command line and the argument that gave it, as the user sees it (``{"run.csv":
    "--torques", "img.png": "IMAGE"}``; the first of two that gave the same), and the NAME of each ``NAME=VALUE``
    (``{"nope.spin": "--column"}``); {} before the parsing."""
    if parser is None or args is None:
        return {}
    names: dict[str, str] = {}
    for name, _, value in named_values(parser, args):
        if isinstance(value, str):
            names.setdefault(value, name)
    for value, name in list(names.items()):  # the NAME of a NAME=VALUE (--column, --spin): a joint an error quotes
        key, sep, _ = value.partition("=")
        if sep and key:
            names.setdefault(key, name)
    return names


def wants_json(argv: Sequence[str]) -> bool:
    """Whether `argv` asks for ``--json``, before it is parsed (for the compile notice and an error of the parsing):
    the option or an abbreviation of it that argparse takes for it ('--js'; '--j', where it is ambiguous, too)."""
    words = argv[:argv.index("--")] if "--" in argv else argv
    return any(len(w) >= 3 and "--json".startswith(w) for w in words)


#: Seconds of uninterrupted kernel compilation after which the command says why it is quiet.
COMPILE_NOTICE_AFTER = 2.0
#: The line it prints on stderr (before an answer or an error line).
COMPILE_NOTICE = "wmrkit: compiling numerical kernels for this machine (first run only; cached for the next runs)..."
#: The line instead when numba found no writable directory to cache them in (``_jit.UNCACHED``).
COMPILE_NOTICE_UNCACHED = ("wmrkit: compiling numerical kernels for this machine (again at every run: no writable "
                           "cache directory; set NUMBA_CACHE_DIR to one)...")


#: The line instead when the dynamics kernels compile for the first time (``simulate``, ``track --dynamics``, the slip
#: studies), printed as soon as they start: they take the longest.
DYNAMICS_NOTICE = ("wmrkit: compiling the dynamics kernels for this machine (first run only, about 20 s; cached for "
                   "the next runs)...")
#: Seconds of compilation after which :data:`DYNAMICS_NOTICE` is printed.
DYNAMICS_NOTICE_AFTER = 0.25


def _compile_notice(done: threading.Event, poll: float = 0.25) -> None:
    """Say once on stderr that numba is compiling, when it has compiled for :data:`COMPILE_NOTICE_AFTER` s without
    a pause (a first run on a machine, silent otherwise), or for :data:`DYNAMICS_NOTICE_AFTER` s the dynamics
    kernels that are not cached yet (about 20 s); numba is never imported here, only watched once a command has
    imported it."""
    busy, dynamics = 0.0, None
    while not done.wait(poll):
        busy = busy + poll if _compiling() else 0.0
        if dynamics is None and busy > 0:
            dynamics = _first_dynamics_compile()
        if dynamics and busy >= DYNAMICS_NOTICE_AFTER:
            print(DYNAMICS_NOTICE, file=sys.stderr, flush=True)
            return
        if busy >= COMPILE_NOTICE_AFTER:
            uncached = getattr(sys.modules.get("wmrkit._jit"), "UNCACHED", ())
            print(COMPILE_NOTICE_UNCACHED if uncached else COMPILE_NOTICE, file=sys.stderr, flush=True)
            return


def report_error(err: WmrkitError, as_json: bool, argv: Sequence[str] = (),
                 names: Mapping[str, str] | None = None) -> None:
    """One line on stderr: ``wmrkit: error: ...``, or under ``--json`` a JSON object with the error's place.

    JSON: ``{"error": message, "file": ..., "wheel": ..., "field": ..., "line": ...}``; the place keys are null when the
    error has no such place. A message about a file of the command line (`argv`), ``FILE[:LINE]: [column
    'NAME': |WHEEL.spin: |WHEEL.steer: |lines[I].n: |--OPTION: ]...`` (logs, torque files, references, trajectories,
    points files, images), gives ``file``, ``line`` and ``field`` (and ``wheel``, that of a joint), the field being
    the argument that gave the file (`names`: :func:`given_names`) when the message names none; one about an
    option, ``--OPTION[ VALUE]: ...`` (or argparse's ``argument --OPTION: ...``), gives the option as ``field`` (and,
    for ``--steer``, the wheel).
    """
    if not as_json:
        if isinstance(err, UsageError):
            print(err.usage, end="", file=sys.stderr)
        print(f"wmrkit: error: {one_line(str(err))}", file=sys.stderr)
        return
    data = {"error": one_line(str(err)), "file": None, "wheel": None, "field": None, "line": None}
    if isinstance(err, DescriptionError):
        loc = err.loc
        data["error"], data["file"], data["line"] = one_line(err.message), err.source, err.line
        if len(loc) >= 2 and loc[0] == "wheels" and isinstance(loc[1], int):
            data["wheel"] = err.wheel if err.wheel is not None else loc[1]
            loc = loc[2:]
        data["field"] = ".".join(str(p) for p in loc) or None
    else:
        data |= (_file_place(data["error"], argv) or _option_place(err, data["error"], argv)
                 or _argument_place(data["error"], names))
    if data["file"] is not None and data["field"] is None:  # an argument it quotes, else the whole file: the
        # argument that gave it
        data["field"] = _quoted_argument(data["error"], names) or (names or {}).get(data["file"])
    print(json.dumps(data), file=sys.stderr)


#: The option that starts an error's message, as the message names it: ``--chunk: ...``, ``-n/--runs: ...``,
#: ``--configs must be ...``, ``--steer front=1e7 turn: ...``; and the argument argparse names in a usage error
#: (``sweep: argument --metric: invalid choice ...``), or the first of those it lists (``park: unrecognized
#: arguments: --space 1``, a stray word: ``analyze: unrecognized arguments: abc``, ``tyre: ambiguous option: --slip
#: could match ...``, ``odometry: the following arguments are required: ROBOT, LOG``, ``simulate: one of the
#: arguments --torques --path is required``).
_OPTION_FIRST = re.compile(r"(-\w/--[\w-]+|--[\w-]+)(?=[\s:=]|$)")
_ARGPARSE_ARGUMENT = re.compile(r"(?:[\w -]+: )?(?:argument ([^\s:]+): |(?:unrecognized arguments|ambiguous option): "
                                r"(\S+)|the following arguments are required: ([^\s,]+)|one of the arguments "
                                r"(\S+) .*is required)")
#: The option a message names in parentheses, after the name of its value (``blur (--blur): ...``, ``line width
#: (--line-width) 100 m ...``, ``duration 1e+12 s ...; give a shorter duration (--duration)``).
_OPTION_IN_PARENTHESES = re.compile(r"\((--[\w-]+)[^)]*\)")
_ANY_OPTION = re.compile(r"(?<![\w-])--[A-Za-z][\w-]*")


def _option_place(err: WmrkitError, message: str, argv: Sequence[str] = ()) -> dict:
    """``field`` (the option) and ``wheel`` (the wheel its value names, :class:`._common.OptionError`) of an error
    about an option of the command line: the argument an :class:`._common.OptionError` names as its ``field``, the
    option the message starts with, after the words of the command in `argv` (``ik: --twist 1e7: ...``, ``vision
    calibrate: --size: ...``), the only option it names, in parentheses (``follow-line: blur (--blur): ...``), or,
    of the options it names, the first one `argv` gives (``duration (--duration) 20 s is shorter than one period
    (--period, 100 s)`` after ``--period 100``; ``two --vary axes move the same field``); {} when it names none so."""
    from ._common import OptionError

    if isinstance(err, UsageError):
        place = _ARGPARSE_ARGUMENT.match(message)
        return {} if place is None else {"field": next(g for g in place.groups() if g), "wheel": None}
    if isinstance(err, OptionError) and err.field is not None:
        return {"field": err.field, "wheel": err.wheel}
    rest = _after_command(message, argv)
    place = _OPTION_FIRST.match(rest)
    if place is not None:
        return {"field": place.group(1), "wheel": err.wheel if isinstance(err, OptionError) else None}
    named = list(dict.fromkeys(_ANY_OPTION.findall(rest)))
    inside = _OPTION_IN_PARENTHESES.search(rest)
    if inside is not None and named == [inside.group(1)]:
        return {"field": inside.group(1), "wheel": None}
    typed = {a.partition("=")[0] for a in argv}  # of the options it names, the first one typed
    given = [option for option in named if option in typed]
    return {"field": given[0], "wheel": None} if given else {}


#: A value the message quotes (``no robot 'nope' in the catalog``, ``parameter 'front_left.x': ...``).
_QUOTED = re.compile(r"'([^'\n]+)'")


def _argument_place(message: str, names: Mapping[str, str] | None) -> dict:
    """``field`` of an error that names no option or file: the one argument (`names`: :func:`given_names`) whose
    value the message quotes (not a number: ``got '0'`` would be anyone's), else ROBOT when the message is about a
    robot (``robot 'x': its origin ...``) and the command has that argument; {} otherwise."""
    field = _quoted_argument(message, names)
    if field is None and re.search(r"\brobot '", message) and "ROBOT" in (names or {}).values():
        field = "ROBOT"
    return {} if field is None else {"field": field}


def _quoted_argument(message: str, names: Mapping[str, str] | None) -> str | None:
    """The one argument whose value (or NAME of NAME=VALUE) `message` quotes, a number's excepted; else None."""
    names = names or {}
    quoted = {names[q] for q in _QUOTED.findall(message) if q in names and not reads_as_number(q)}
    return quoted.pop() if len(quoted) == 1 else None



def _after_command(message: str, argv: Sequence[str]) -> str:
    """`message` without the words of the (sub)command in `argv` it starts with (``locate: ``, ``vision locate: ``,
    ``follow-line: ``)."""
    words = list(itertools.takewhile(lambda a: not a.startswith("-"), argv))[:2]
    prefix = next((p for p in (" ".join(words), *words) if p and message.startswith(f"{p}: ")), None)
    return message if prefix is None else message[len(prefix) + 2:]


def _file_place(message: str, argv: Sequence[str]) -> dict:
    """``file``, ``line`` and ``field`` of a message that starts with a file given in `argv` (a path: a name with a
    dot or a slash, or one that exists; the longest first), with a file inside a folder given there (the files
    a command writes into its output folder), or with a file that a glob pattern given there matches."""
    paths = [a for a in argv if "." in a or "/" in a or os.path.exists(a)]
    name = max((a for a in paths if message.startswith(f"{a}:")), key=len, default=None)
    if name is None:
        inside = (re.match(re.escape(a.rstrip("/")) + r"/[^:\n]+(?=:)", message) for a in paths if a.strip("/"))
        name = max((m.group(0) for m in inside if m), key=len, default=None)
    if name is None:  # a file that a pattern of the command line matched ('logs/*.csv' of the batch commands)
        first = re.match(r"[^:\n]+(?=:)", message)
        if first and any(glob.has_magic(a) and fnmatch.fnmatchcase(first.group(0), a) for a in argv):
            name = first.group(0)
    if name is None:
        return {}
    # the column as "column 'NAME':" or, in a log's row errors, as the joint "WHEEL.spin:" / "WHEEL.steer:"
    place = re.match(r"(?:(\d+):)?(?: column '([^']*)':| ([^\s:']+\.(?:spin|steer)):)?(.*)", message[len(name) + 1:],
                     flags=re.S)
    line, column, joint, rest = place.groups()
    missing = re.match(r"\s*missing column '([^']*)'", rest)  # "x.csv:1: missing column 'right.spin' (columns: ...)"
    if joint is None:  # a place in a JSON file: "p.json: lines[0].n: must be -1, 0 or 1"; an option measured in the
        # file: "img.png: --rows: rows A must be in (0, 120) px"
        path = re.match(r"\s*([A-Za-z_]\w*(?:\[\d+\])+(?:\.\w+|\[\d+\])*|--[\w-]+):(.*)", rest, flags=re.S)
        joint, rest = (path.group(1), path.group(2)) if path else (None, rest)
    return {"error": rest.strip(), "file": name, "line": int(line) if line else None,
            "field": column or joint or (missing.group(1) if missing else None),
            "wheel": joint.rsplit(".", 1)[0] if joint and re.search(r"\.(?:spin|steer)$", joint) else None}


#: Longest error message printed [characters]; longer ones (quoting huge user text) are cut.
MAX_MESSAGE = 2000


def one_line(text: str) -> str:
    """`text` as one printable line: line breaks and control characters escaped, lone surrogates (from bytes
    that are not UTF-8) replaced, cut to :data:`MAX_MESSAGE` characters."""
    text = text.encode("utf-8", "backslashreplace").decode("utf-8")
    if not text.isprintable():
        text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    return text if len(text) <= MAX_MESSAGE else text[:MAX_MESSAGE] + f"... ({len(text)} characters)"


def _version() -> str:
    from .. import __version__

    return __version__


def _first_dynamics_compile() -> bool | None:
    """Whether a command compiles the dynamics kernels for the first time (``dynamics._kernels.first_compile``); None
    until it has imported them."""
    first_compile = getattr(sys.modules.get("wmrkit.dynamics._kernels"), "first_compile", None)
    return None if first_compile is None else first_compile()


def _compiling() -> bool:
    """Whether another thread holds numba's compiler lock (False while numba is not imported)."""
    lock = getattr(getattr(sys.modules.get("numba.core.compiler_lock"), "global_compiler_lock", None), "_lock", None)
    if lock is None or lock.acquire(blocking=False) is False:
        return lock is not None
    lock.release()
    return False


if __name__ == "__main__":
    sys.exit(main())
