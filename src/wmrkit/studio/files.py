"""Description files of the studio: list, open and save, only inside the directory the studio was started for.

A path from the page is relative to that root; absolute paths, ``..`` that leaves it, symbolic links that point
out of it and other extensions than ``.yaml``/``.yml``/``.json`` are refused. Saving writes exactly what
:meth:`wmrkit.Robot.to_file` writes, so ``wmrkit show`` reads the same robot back.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .. import catalog
from ..description import load_robot_file
from ..errors import WmrkitError
from .api import StudioError, description_of, robot_of

SUFFIXES = (".yaml", ".yml", ".json")
#: At most this many files are listed, at most this deep below the root.
MAX_FILES, MAX_DEPTH = 500, 3


class ForbiddenPathError(WmrkitError, PermissionError):
    """A path outside the studio's directory (or not a description file)."""


def safe_path(root: Path, relative: Any) -> Path:
    """`relative` resolved inside `root`, or :class:`ForbiddenPathError`."""
    if not isinstance(relative, str) or not relative.strip() or "\x00" in relative:
        raise StudioError("path: a file name relative to the studio's directory")
    candidate = Path(relative)
    if candidate.is_absolute() or candidate.drive:
        raise ForbiddenPathError(f"path: '{relative}' is absolute; give a path inside the studio's directory")
    root = root.resolve()
    full = (root / candidate).resolve()
    if not full.is_relative_to(root) or full == root:
        raise ForbiddenPathError(f"path: '{relative}' is outside the studio's directory")
    if full.suffix.lower() not in SUFFIXES:
        raise ForbiddenPathError(f"path: '{relative}': only description files ({', '.join(SUFFIXES)})")
    return full


def list_files(root: Path) -> list[str]:
    """Description files below `root` (relative POSIX paths, sorted; hidden folders skipped)."""
    root = root.resolve()
    found: list[str] = []
    stack = [(root, 0)]
    while stack and len(found) < MAX_FILES:
        folder, depth = stack.pop()
        try:
            entries = sorted(folder.iterdir())
        except OSError:
            continue
        for p in entries:
            if p.name.startswith("."):
                continue
            if p.is_dir() and depth < MAX_DEPTH and p.resolve().is_relative_to(root):
                stack.append((p, depth + 1))
            elif p.is_file() and p.suffix.lower() in SUFFIXES and p.resolve().is_relative_to(root):
                found.append(p.relative_to(root).as_posix())
    return sorted(found)[:MAX_FILES]


def open_robot(root: Path, request: Any) -> dict[str, Any]:
    """``{"path": ...}`` (a file in `root`) or ``{"catalog": name}`` -> its description (SI) and source text."""
    if not isinstance(request, Mapping):
        raise StudioError("the request body must be a JSON object")
    if "catalog" in request:
        name = request["catalog"]
        if not isinstance(name, str):
            raise StudioError("catalog: a robot name (see 'wmrkit robots')")
        robot = catalog.load(name)
        return {"catalog": name, "description": description_of(robot), "text": catalog.source_text(name)}
    path = safe_path(root, request.get("path"))
    if not path.is_file():
        raise StudioError(f"path: no file '{request['path']}' in the studio's directory")
    robot = load_robot_file(path)
    return {"path": path.relative_to(root.resolve()).as_posix(), "description": description_of(robot),
            "text": path.read_text(encoding="utf-8")}


def save_robot(root: Path, request: Any) -> dict[str, Any]:
    """``{"path", "description"}``: validate, write with :meth:`Robot.to_file`, return the text written."""
    robot = robot_of(request)
    path = safe_path(root, request.get("path"))
    if not path.parent.is_dir():
        raise StudioError(f"path: the folder of '{request['path']}' does not exist")
    robot.to_file(path)
    return {"path": path.relative_to(root.resolve()).as_posix(), "description": description_of(robot),
            "text": path.read_text(encoding="utf-8")}
