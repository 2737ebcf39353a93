"""Description files of the studio: list, open and save, only inside the directory the studio was started for.

A path from the page is relative to that root; absolute paths, ``..`` that leaves it, symbolic links that point
out of it, hidden files and folders (a part starting with ``.``), names with control characters, lone surrogates
or leading or trailing spaces, names over :data:`MAX_NAME` characters and other extensions than
``.yaml``/``.yml``/``.json`` are refused. Saving writes exactly what :meth:`wmrkit.Robot.to_file` writes, so
``wmrkit show`` reads the same robot back; it replaces an existing file only when the request says
``"overwrite": true`` (else :class:`FileExistsStudioError`, answered 409, and the page asks the user).
"""

from __future__ import annotations

import itertools
import os
import re
from collections import deque
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .. import catalog
from ..description import robot_from_text
from ..documents import read_file
from ..errors import WmrkitError
from .api import StudioError, check_fields, description_of, robot_of, with_warnings

SUFFIXES = (".yaml", ".yml", ".json")
#: At most this many files are listed, at most this deep below the root.
MAX_FILES, MAX_DEPTH = 500, 3
#: At most this many folder entries are looked at when listing (a folder of 10^5 logs took 6 s, holding the server).
MAX_ENTRIES = 20_000
#: Longest path the page may give, and longest part of it (file systems allow 255 bytes per name) [characters].
MAX_PATH, MAX_NAME = 1000, 200
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
_SURROGATE = re.compile("[\ud800-\udfff]")


class ForbiddenPathError(WmrkitError, PermissionError):
    """A path outside the studio's directory (or not a description file)."""


class FileExistsStudioError(StudioError):
    """Saving would replace an existing file and the request did not say ``"overwrite": true``."""


def safe_path(root: Path, relative: Any) -> Path:
    """`relative` resolved inside `root`, or :class:`ForbiddenPathError` / :class:`StudioError` saying why."""
    if not isinstance(relative, str) or not relative.strip():
        raise StudioError("path: a file name relative to the studio's directory")
    shown = _shown(relative)
    if _CONTROL.search(relative):
        raise StudioError(f"path: {shown!r} holds a control character")
    if _SURROGATE.search(relative):  # JSON's "\ud800": no file name encodes it (a 500 UnicodeEncodeError before)
        raise StudioError(f"path: {shown!r} holds a lone surrogate, not a character")
    if len(relative) > MAX_PATH:
        raise StudioError(f"path: {len(relative)} characters, at most {MAX_PATH}")
    candidate = Path(relative)
    if candidate.is_absolute() or candidate.drive:
        raise ForbiddenPathError(f"path: '{shown}' is absolute; give a path inside the studio's directory")
    for part in relative.replace("\\", "/").split("/"):
        if len(part) > MAX_NAME:
            raise StudioError(f"path: a name of {len(part)} characters in '{shown}', at most {MAX_NAME}")
        if part != part.strip():
            raise StudioError(f"path: '{part}' in '{shown}' starts or ends with a space")
        if part.startswith(".") and part not in (".", ".."):
            raise ForbiddenPathError(f"path: '{part}' in '{shown}' is hidden (starts with '.'): not written or read")
    try:
        root = root.resolve()
        full = (root / candidate).resolve()
    except (OSError, RuntimeError) as err:  # RuntimeError: a symbolic link loop (Python < 3.13)
        raise StudioError(f"path: '{shown}': {getattr(err, 'strerror', None) or err}") from None
    if not full.is_relative_to(root) or full == root:
        raise ForbiddenPathError(f"path: '{shown}' is outside the studio's directory")
    if any(p.startswith(".") for p in full.relative_to(root).parts):
        raise ForbiddenPathError(f"path: '{shown}' leads into a hidden file or folder")
    if full.suffix.lower() not in SUFFIXES:
        raise ForbiddenPathError(f"path: '{shown}': only description files ({', '.join(SUFFIXES)})")
    return full


def _shown(relative: str) -> str:
    """A path for a message: at most 80 characters."""
    return relative if len(relative) <= 80 else relative[:77] + "..."


def list_files(root: Path) -> list[str]:
    """Description files below `root` (relative POSIX paths, sorted; hidden folders and names :func:`safe_path`
    refuses skipped), looking at no more than :data:`MAX_ENTRIES` folder entries, shallow folders first."""
    root = root.resolve()
    found: list[str] = []
    queue = deque([(root, 0)])
    budget = MAX_ENTRIES
    while queue and len(found) < MAX_FILES and budget > 0:
        folder, depth = queue.popleft()
        try:
            with os.scandir(folder) as it:
                entries = sorted(itertools.islice(it, budget), key=lambda e: e.name)
        except OSError:
            continue
        budget -= len(entries)
        for e in entries:
            if e.name.startswith(".") or not _plain_name(e.name):  # hidden, or a name safe_path refuses
                continue
            p = Path(e.path)
            try:
                if e.is_dir() and depth < MAX_DEPTH and p.resolve().is_relative_to(root):
                    queue.append((p, depth + 1))
                elif p.suffix.lower() in SUFFIXES and e.is_file() and p.resolve().is_relative_to(root):
                    found.append(p.relative_to(root).as_posix())
            except OSError:
                continue
    return sorted(found)[:MAX_FILES]


def _plain_name(name: str) -> bool:
    """A file or folder name :func:`safe_path` takes (so that every file listed opens)."""
    return (len(name) <= MAX_NAME and name == name.strip() and not _CONTROL.search(name)
            and not _SURROGATE.search(name))


def open_robot(root: Path, request: Any) -> dict[str, Any]:
    """``{"path": ...}`` (a file in `root`) or ``{"catalog": name}`` -> its description (SI), source text and
    ``warnings`` (the description's, naming the file, line and field)."""
    if not isinstance(request, Mapping):
        raise StudioError("the request body must be a JSON object")
    check_fields(request, "catalog", "path")
    if "catalog" in request and "path" in request:
        raise StudioError("give either 'catalog' or 'path', not both")
    if "catalog" in request:
        name = request["catalog"]
        if not isinstance(name, str):
            raise StudioError("catalog: a robot name (see 'wmrkit robots')")
        robot, said = with_warnings(lambda: catalog.load(name))
        return {"catalog": name, "description": description_of(robot), "text": catalog.source_text(name),
                "warnings": said}
    path = safe_path(root, request.get("path"))
    try:
        if not path.is_file():
            raise StudioError(f"path: no file '{_shown(request['path'])}' in the studio's directory")
    except OSError as err:
        raise StudioError(f"path: '{_shown(request['path'])}': {err.strerror or err}") from None
    text = read_file(path)  # at most MAX_FILE_SIZE bytes; an unreadable file is a DescriptionError naming it
    fmt = "json" if path.suffix.lower() == ".json" else "yaml"
    robot, said = with_warnings(lambda: robot_from_text(text, source=str(path), fmt=fmt))
    return {"path": path.relative_to(root.resolve()).as_posix(), "description": description_of(robot), "text": text,
            "warnings": said}


def save_robot(root: Path, request: Any) -> dict[str, Any]:
    """``{"path", "description", "overwrite"?}``: validate, write with :meth:`Robot.to_file`, return the text
    written. An existing file is replaced only with ``"overwrite": true`` (else :class:`FileExistsStudioError`)."""
    check_fields(request, "path", "description", "overwrite")
    robot = robot_of(request)
    path = safe_path(root, request.get("path"))
    overwrite = request.get("overwrite", False)
    if not isinstance(overwrite, bool):
        raise StudioError(f"overwrite: true or false, got {repr(overwrite)[:40]}")
    name = path.relative_to(root.resolve()).as_posix()
    shown = _shown(name)
    try:
        if not path.parent.is_dir():
            raise StudioError(f"path: the folder of '{shown}' does not exist")
        if path.is_dir():
            raise StudioError(f"path: '{shown}' is a folder, not a file")
        if path.exists() and not path.is_file():  # a named pipe: writing waited for a reader, holding the server
            raise StudioError(f"path: '{shown}' is not a regular file")
        if path.exists() and not overwrite:
            raise FileExistsStudioError(f"path: '{shown}' exists; replace it (overwrite) or choose another name")
        robot.to_file(path)
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise StudioError(f"path: cannot write '{shown}': {err.strerror or err}") from None
    return {"path": name, "description": description_of(robot), "text": text}
