"""Built-in robots: description files shipped in this folder, usable by name anywhere a robot is expected."""

from __future__ import annotations

import difflib
import functools
import os
from importlib import resources
from pathlib import Path

from ..description import robot_from_text
from ..documents import read_document, read_file
from ..errors import DescriptionError, UnknownNameError
from ..robot import Robot


def names() -> tuple[str, ...]:
    """Names of the catalog robots, sorted."""
    return tuple(sorted(p.name[:-5] for p in resources.files(__name__).iterdir() if p.name.endswith(".yaml")))


def load(name: str) -> Robot:
    """The catalog robot `name`, or :class:`UnknownNameError` with a suggestion."""
    if not isinstance(name, str):
        raise TypeError(f"a catalog robot's name is a str, got {type(name).__name__} (a file: Robot.from_file)")
    return _load(name)


@functools.cache
def _load(name: str) -> Robot:
    if name not in names():
        close = difflib.get_close_matches(name.lower(), names(), n=1)  # 'FORKLIFT' had no suggestion
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise UnknownNameError(f"no robot '{name}' in the catalog{hint}; 'wmrkit robots' lists them")
    text = resources.files(__name__).joinpath(f"{name}.yaml").read_text(encoding="utf-8")
    return robot_from_text(text, source=f"catalog:{name}")


def source_text(name: str) -> str:
    """The description file of catalog robot `name`, with its comments on where the numbers come from."""
    load(name)
    return resources.files(__name__).joinpath(f"{name}.yaml").read_text(encoding="utf-8")


def resolve(spec: str | os.PathLike[str]) -> Robot:
    """A robot from a command-line argument: a description file path if one exists, else a catalog name (also when
    a folder of that name exists: a folder 'forklift/' of logs hid the catalog's forklift)."""
    if isinstance(spec, os.PathLike):
        spec = os.fspath(spec)
    if not isinstance(spec, str):
        raise TypeError(f"a robot is a catalog name or a description file's path, got {type(spec).__name__}")
    path = _file(spec)
    if path is not None:
        if not path.exists():
            hint = f" (the catalog's robot is '{path.stem}', without '{path.suffix}')" if path.stem in names() else ""
            raise UnknownNameError(f"{spec}: no such file{hint}")
        return Robot.from_file(path)
    if spec not in names():
        files = [p for p in (Path(spec + ext) for ext in (".yaml", ".yml", ".json")) if p.is_file()]
        if files:
            raise UnknownNameError(f"no robot '{spec}' in the catalog; did you mean the file '{files[0]}'?")
    return load(spec)


def _file(spec: str) -> Path | None:
    """The description file :func:`resolve` reads for `spec`, or None for a catalog name."""
    path = Path(spec)
    if path.suffix.lower() in (".yaml", ".yml", ".json") or (path.exists() and not (path.is_dir() and spec in names())):
        return path
    return None


def locate(err: DescriptionError, spec: str) -> DescriptionError:
    """`err`, raised about a field of the robot :func:`resolve` gave for `spec` (a check of the dynamics, whose
    robot knows no file), placed in that robot's description: its file (``catalog:NAME``) and the field's line."""
    path = _file(spec)
    source = f"catalog:{spec}" if path is None else str(path)
    try:
        text = source_text(spec) if path is None else read_file(path)
        line = read_document(text, source, "json" if source.lower().endswith(".json") else "yaml")[1](err.loc)
    except (OSError, DescriptionError, UnknownNameError):  # the file changed since: its place without a line
        line = None
    return DescriptionError(err.message, source=source, loc=err.loc, line=line, wheel=err.wheel)
