"""Cold start of every command (issue 8): the first run after install, numba's disk cache empty.

Each command runs as a fresh process with an empty ``NUMBA_CACHE_DIR``, so nothing compiled earlier is reused.
The comparison is the same command compiling every kernel it touches before running (``WMRKIT_INTERPRET_BUDGET=0``,
what every first run did before kernels ran small inputs as Python). Target: under 2 s each on the 2-core machine.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ._harness import Result

COMMANDS = [
    ["robots"], ["show", "forklift"], ["kinematics", "forklift"], ["ik", "swerve-4", "--twist", "1", "0.5", "0.3"],
    ["fk", "diff-drive", "--spin", "left=10", "--spin", "right=12"], ["analyze", "forklift"],
    ["odometry", "forklift", "{log}", "--quiet"],
]


def _log(directory: Path) -> Path:
    """A 30 s forklift log with units in its header (what examples/odometry_forklift_log.py writes)."""
    from wmrkit import catalog
    from wmrkit.odometry.logs import write_log
    from wmrkit.odometry.synthetic import TwistProfile, simulate

    robot = catalog.load("forklift")
    run = simulate(robot, TwistProfile.from_segments([(30.0, 1.0, 0.0, 0.1)]).about((-1.0, 0.0)), 100.0)
    path = directory / "forklift.csv"
    write_log(path, run.log, robot)
    return path


def _cold(argv: list[str], budget: str | None) -> float:
    with tempfile.TemporaryDirectory(prefix="wmrkit-cold-") as cache:  # an empty numba cache: a first run
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        if budget is not None:
            env["WMRKIT_INTERPRET_BUDGET"] = budget
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "wmrkit", *argv], env=env, capture_output=True, check=True)
        return time.perf_counter() - t0


def run(quick: bool) -> list[Result]:
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        log = str(_log(Path(tmp)))
        for argv in COMMANDS[:3] if quick else COMMANDS:
            argv = [a.format(log=log) for a in argv]
            ours = min(_cold(argv, None) for _ in range(1 if quick else 2))
            compiled = _cold(argv, "0")
            out.append(Result(f"cold start: wmrkit {argv[0]}", 1, ours, "compile-first", compiled, "< 2 s"))
    return out
