"""Writing joint logs as CSV files (synthetic logs, a log read back), in the format :mod:`.logs` reads."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..robot import Robot
    from .logs import JointLog


def write_csv(path: str | os.PathLike[str], names: Sequence[str], values: np.ndarray, *,
              fmt: str = "%.17g") -> None:
    """Write a CSV file with header `names` and rows `values` ``(N, len(names))`` (e.g. a synthetic log)."""
    values = np.asarray(values)
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write(",".join(names) + "\n")
        row = ",".join([fmt] * len(names)) + "\n"
        for start in range(0, len(values), 1 << 16):
            block = values[start:start + (1 << 16)]
            f.write((row * len(block)) % tuple(block.ravel().tolist()))  # one formatting call per block


def write_log(path: str | os.PathLike[str], log: JointLog, robot: Robot | None = None, *,
              fmt: str = "%.17g") -> None:
    """Write `log` as a CSV log in the default format (``time``, then its joints; steering as headings, converted
    with `robot`'s wheels, so that :func:`load_csv` with the same robot reads it back)."""
    write_csv(path, ("time", *log.joints), np.column_stack([log.time, log.heading_positions(robot)]), fmt=fmt)
