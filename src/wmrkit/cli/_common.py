"""Small helpers shared by the command modules: robot argument, JSON output, angle parsing."""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import math
import os
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterable, Iterator
from contextvars import ContextVar
from pathlib import Path
from typing import Any

from .. import catalog
from ..errors import WmrkitError, said_warnings
from ..limits import same_file
from ..robot import Robot
from ..units import Kind, UnitError, parse_quantity

#: The integration schemes (docs/odometry.md), named once for every option that takes one.
SCHEMES_HELP = ("exact (SE(2) arcs), rk2 (midpoint), euler (heading at the step's start) or paper002 (at its end, "
                "Tello-Cristiany et al. (15))")


def add_robot_argument(parser: argparse.ArgumentParser) -> None:
    """The ROBOT positional: a catalog name or a description file."""
    parser.add_argument("robot", metavar="ROBOT", help="catalog name (see 'wmrkit robots') or a .yaml/.json file")


def add_json_flag(parser: argparse.ArgumentParser) -> None:
    """``--json``: machine-readable output on stdout."""
    parser.add_argument("--json", action="store_true", help="print machine-readable JSON")


def load_robot(spec: str) -> Robot:
    """The robot named by a ROBOT argument; the description's warnings said (:func:`warn`)."""
    from ..description import DescriptionWarning
    robot, lines = said_warnings(lambda: catalog.resolve(spec), DescriptionWarning)
    for line in lines:
        warn(line)
    return robot


def dynamic_model(robot: Robot, spec: str, tyre: str | None = None, *, say: bool = True) -> Any:
    """The :class:`~wmrkit.dynamics.model.DynamicModel` of `robot`, loaded from the ROBOT argument `spec`: what its
    description lacks for the dynamics (a body, an inertia) is an error naming its file, line, wheel and field. Its
    :class:`~wmrkit.dynamics.linkages.LinkageWarning` lines are said (:func:`warn`) unless `say` is False (a caller
    whose run builds the model again and says them then)."""
    from ..dynamics.linkages import LinkageWarning
    from ..dynamics.model import DynamicModel
    from ..errors import DescriptionError

    try:
        model, lines = said_warnings(lambda: DynamicModel.of(robot, tyre), LinkageWarning)
    except DescriptionError as err:
        if err.source != f"robot '{robot.name}'":
            raise
        raise catalog.locate(err, spec) from None
    for line in lines if say else ():
        warn(line)
    return model


def wheel_column_width(robot: Robot, least: int = 14) -> int:
    """Width of a table's wheel-name column: `least`, or the longest name and two spaces (ROS 2's
    'front_left_wheel_joint' ran into the next column)."""
    return max(least, max(len(w.name) for w in robot.wheels) + 2)


#: The warnings the running command has said (:func:`collecting_warnings`), for its JSON answer.
_SAID: ContextVar[list[str] | None] = ContextVar("wmrkit_cli_warnings", default=None)


@contextlib.contextmanager
def collecting_warnings() -> Iterator[list[str]]:
    """Collect the :func:`warn` calls of one command run (``wmrkit.cli.main.main`` wraps each run in it)."""
    said: list[str] = []
    token = _SAID.set(said)
    try:
        yield said
    finally:
        _SAID.reset(token)


def warn(message: str) -> None:
    """A warning: one line ``wmrkit: warning: MESSAGE`` on stderr for people, and MESSAGE in the ``"warnings"``
    list of the command's JSON answer (:func:`print_json`) for scripts."""
    print(f"wmrkit: warning: {message}", file=sys.stderr)
    said = _SAID.get()
    if said is not None:
        said.append(message)


def say_caught(caught: Iterable[warnings.WarningMessage], skip: tuple[type[Warning], ...] = ()) -> None:
    """Say the warnings a command's run recorded (``warnings.catch_warnings(record=True)``): wmrkit's own, each
    message once, with :func:`warn` (but those of a category in `skip`, which the caller says otherwise); the
    others (numpy's, scipy's, ...) passed on as they were, once per message and place."""
    caught = list(caught)
    foreign = {(w.category, str(w.message), w.filename, w.lineno): w for w in caught if not _own(w.category)}
    for w in foreign.values():
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    for line in dict.fromkeys(str(w.message) for w in caught if _own(w.category) and not issubclass(w.category, skip)):
        warn(line)


def _own(category: type[Warning]) -> bool:
    """Whether `category` is one of wmrkit's warning classes."""
    return category.__module__.split(".")[0] == "wmrkit"


def said() -> list[str]:
    """The messages of :func:`warn` in this command run so far ([] outside a run)."""
    return list(_SAID.get() or [])


def print_json(data: Any) -> None:
    """Print `data` as JSON (NaN and infinities become null: JSON has none). A mapping (every command's answer but
    the ``robots`` list) gets a top-level ``"warnings"`` list, [] when none: its own (a parking plan's), then the
    messages of :func:`warn` in this run that are not among them (docs/limits.md, JSON answers)."""
    if isinstance(data, dict):
        own = list(data.get("warnings") or [])
        data = {**data, "warnings": own + [m for m in said() if m not in own]}
    print(json.dumps(json_values(data), indent=2, allow_nan=False))  # a NaN left is a bug: raised, never printed


def json_values(x: Any) -> Any:
    """`x` (nested dicts, lists, tuples) ready for JSON: NaN and infinities None (JSON has none), -0.0 written 0.0
    (a computed zero's sign is no result)."""
    if isinstance(x, float):
        return x + 0.0 if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: json_values(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [json_values(v) for v in x]
    return x


def check_plot_path(path: str | None, what: str = "--plot") -> None:
    """A figure file given to `what` (when given) has an extension wmrkit draws to
    (:func:`wmrkit.plotting.files.check_figure_path`), checked before the work that draws it."""
    if path is not None:
        from ..plotting.files import check_figure_path

        check_figure_path(path, what)


#: Options naming a file a command writes, and those naming a folder it writes into (created with its parents when
#: missing); ``--codegen LANG DIR`` names a folder too.
OUTPUT_FILES, OUTPUT_FOLDERS = ("out", "plot", "animate"), ("report", "trajectories")


def named_values(parser: argparse.ArgumentParser, args: argparse.Namespace):
    """``(name, dest, value)`` of every argument of the chosen (sub)command, the name as the user sees it
    (``--out``, ``ROBOT``), lists flattened."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            chosen = action.choices.get(getattr(args, action.dest, None))
            if chosen is not None:
                yield from named_values(chosen, args)
            continue
        value = getattr(args, action.dest, None)
        metavar = " ".join(action.metavar) if isinstance(action.metavar, tuple) else action.metavar
        name = "/".join(action.option_strings) or metavar or action.dest.upper()
        for v in (value if isinstance(value, list) else [value]):
            for x in (v if isinstance(v, list) else [v]):
                yield name, action.dest, x


def check_blank(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse, before any work, an argument given as empty text (a file or a robot named ''), naming it: read as a
    path, '' would be the current folder."""
    for name, _, value in named_values(parser, args):
        if isinstance(value, str) and not value.strip():
            raise WmrkitError(f"{name}: empty value")


def check_outputs(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse, before any work, an output the command could not write: a file whose folder is missing or not
    writable, or that is a folder; a folder that is a file, or whose nearest existing parent is not writable; a file
    that is one of the command's input files or another of its outputs (it would replace it)."""
    given = [(dest, getattr(args, dest, None), dest in OUTPUT_FOLDERS) for dest in OUTPUT_FILES + OUTPUT_FOLDERS]
    if getattr(args, "codegen", None):
        given.append(("codegen", args.codegen[1], True))
    outputs = {dest for dest, path, _ in given if path is not None}
    others = [(name, dest, value) for name, dest, value in named_values(parser, args) if isinstance(value, str)]
    for dest, path, folder in given:
        problem = None if path is None else output_problem(path, folder)
        if problem:
            raise WmrkitError(f"--{dest} {path}: {problem}")
        for name, other, value in ([] if path is None or folder else others):
            # another output, or an input file (an existing one: ROBOT may name the catalog)
            if other != dest and (other in outputs or Path(value).is_file()) and same_file(path, value):
                raise WmrkitError(f"--{dest} {path}: is also {name} (the output would replace it)")


def output_option(args: argparse.Namespace | None, filename: str | os.PathLike[str]) -> str:
    """``"--report "`` when `filename` is an output option's path or inside its folder (else ``""``), to name the
    option in an error about that file."""
    target = Path(os.fspath(filename)).absolute()
    for dest in OUTPUT_FILES + OUTPUT_FOLDERS:
        path = getattr(args, dest, None)
        if isinstance(path, str) and path.strip():
            given = Path(path).absolute()
            if target == given or (dest in OUTPUT_FOLDERS and given in target.parents):
                return f"--{dest} "
    return ""


def output_problem(path: str, folder: bool) -> str | None:
    """Why `path` cannot be written as a file (or, with `folder`, as a folder made with its parents), or None."""
    if not path.strip():
        return "empty name"
    p = Path(path)
    if p.exists() and p.is_dir() != folder:
        return "is a folder" if not folder else "is a file, not a folder"
    parent = p.parent if not folder else next(a for a in (p, *p.parents) if a.exists())
    if not parent.is_dir():
        return f"no such folder '{parent}'" if not parent.exists() else f"'{parent}' is not a folder"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"cannot write into '{parent}' (permission denied)"
    try:  # os.access says yes to root everywhere: /proc refused the folder only after a 5-minute slip-study
        with tempfile.TemporaryDirectory(dir=parent, prefix=".wmrkit-probe-"):
            pass
    except OSError as err:
        return f"cannot write into '{parent}' ({err.strerror or err})"
    return None


def seed(text: str) -> int:
    """``--seed``: a whole number >= 0, what numpy's generators take (every command's, one rule and one message)."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got '{text}'")
    return value


@contextlib.contextmanager
def renaming(starts: dict[str, str]) -> Iterator[None]:
    """An error whose message starts with a key of `starts` (the library's name of a value or file: ``"speed: "``,
    ``"calibration: x1 "``, ``"image: "``) re-raised starting with its value instead (the option or file the user
    gave: ``"--speed: "``; the JSON error's field or file, ``cli.main.report_error``); the first key that matches
    is used; any other error passes as it is."""
    try:
        yield
    except WmrkitError as err:
        message = str(err)
        start = next((s for s in starts if message.startswith(s)), None)
        if start is None:
            raise
        raise WmrkitError(starts[start] + message.removeprefix(start)) from None


def parse_value(text: str, kind: Kind, what: str) -> float:
    """A number from the command line (SI, or with a unit such as ``deg``, ``mm``); errors name the option."""
    try:
        return parse_quantity(text, kind)
    except UnitError as err:
        raise WmrkitError(f"{what}: {err}") from None


def quantity(kind: Kind, option: str) -> Callable[[str], float]:
    """An argparse ``type=`` reading an option's value as :func:`parse_value` does: a bare number in SI, or with a
    unit of `kind` (``--duration 2s``, ``--period 50ms``). A value refused is the house one-line error naming the
    option, exit 2 (a :class:`WmrkitError`, which argparse passes on), not argparse's 'invalid float value'."""
    return functools.partial(parse_value, kind=kind, what=option)


def parse_angle(text: str, what: str) -> float:
    """An angle from the command line: radians, or degrees with a ``deg`` suffix."""
    return parse_value(text, "angle", what)


def parse_mount(values: list[str] | None) -> list[float] | None:
    """``--imu-mount ROLL PITCH YAW``: three angles [rad, or with 'deg'], None when not given."""
    if values is None:
        return None
    return [parse_angle(a, f"--imu-mount {n}") for a, n in zip(values, ("ROLL", "PITCH", "YAW"), strict=True)]


def parse_assignments(items: list[str] | None, what: str) -> dict[str, str]:
    """``NAME=VALUE`` pairs from repeated options, as a dict of strings."""
    out: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        if not sep or not name or not value:
            raise WmrkitError(f"{what}: expected NAME=VALUE, got '{item}'")
        if name in out:  # the last one would be kept silently
            raise WmrkitError(f"{what} {name}: given twice ('{out[name]}' and '{value}')")
        out[name] = value
    return out


def add_steer_option(parser: argparse.ArgumentParser, text: str = "heading of a steered wheel", note: str = "") -> None:
    """``--steer NAME=ANGLE`` (repeatable): the wheel's heading, radians or degrees with ``deg``; `note` ends the
    help."""
    parser.add_argument("--steer", action="append", metavar="NAME=ANGLE", default=[],
                        help=f"{text}: its rolling direction, 0 = straight ahead, counter-clockwise positive; "
                             f"radians, or degrees with 'deg' (repeatable){note}")


def steered_robot(spec: str, steer: list[str] | None) -> Robot:
    """The robot named by a ROBOT argument, at the headings of its ``--steer`` options (0 = straight ahead)."""
    return with_steer(load_robot(spec), steer)


class OptionError(WmrkitError):
    """A command-line argument's value refused, the message starting with the option (``--steer front=2 turn: ...``);
    `wheel`: the wheel the value names, `field`: the argument at fault when the message does not start with it
    (``LOG`` of ``give a LOG or --path NAME``), the ``"wheel"`` and ``"field"`` of the JSON error
    (``cli.main.report_error``)."""

    def __init__(self, message: str, *, wheel: str | None = None, field: str | None = None) -> None:
        super().__init__(message)
        self.wheel, self.field = wheel, field


def with_steer(robot: Robot, steer: list[str] | None) -> Robot:
    """`robot` at the headings of the ``--steer`` options `steer` (its described ones kept apart: the rest angles
    a linkage's law is measured from, :mod:`wmrkit.kinematics.linkage_law`); errors name the option and wheel."""
    for name, value in parse_assignments(steer, "--steer").items():
        try:
            heading = parse_angle(value, f"--steer {name}")
        except WmrkitError as err:  # "--steer NAME: cannot read 'fast' as an angle"
            raise OptionError(str(err), wheel=name) from None
        try:
            robot = robot.with_steering({name: heading})
        except WmrkitError as err:  # a beta beyond the angle limit (1e6 turns), no such wheel, one that does not steer
            raise OptionError(f"--steer {name}={value}: {err}", wheel=name) from None
    return robot
