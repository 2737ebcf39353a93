"""Files replaced in one step: written beside their place, then moved onto it, so that a reader (the studio, a
resumed batch) or a crash (a full disk, an interrupt) never meets half a file, and a failed write leaves the old
file as it was."""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A scratch path beside `path` (the file a symbolic link points to) for the block to write; moved onto it, with
    the old file's permissions, when the block succeeds, and removed when it fails."""
    target = Path(path)
    target = target.resolve() if target.is_symlink() else target
    scratch = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        yield scratch
        if target.is_file():
            shutil.copymode(target, scratch)
        os.replace(scratch, target)
    finally:
        scratch.unlink(missing_ok=True)
