"""Control ticks compiled in separate processes and loaded together from numba's disk cache: each robot's tick calls
its own IK (numba named the IK's symbol by a per-process count, so the second robot's tick called the first's IK)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SCRIPT = """
import json, sys
import numpy as np
from wmrkit import Robot, catalog, wheel_commands
from wmrkit.control.laws import PositionLaw
from wmrkit.control.tick import control_tick

out = {}
for track in sys.argv[1:]:
    d = catalog.load("diff-drive").to_dict()
    d["wheels"][0]["position"], d["wheels"][1]["position"] = [0.0, float(track)], [0.0, -float(track)]
    robot = Robot.from_dict(d)
    tick = control_tick(robot, PositionLaw.uniform("p", 0.7))
    twist, rates, heading = np.zeros(3), np.zeros(len(robot.rate_names)), np.array(robot.heading, dtype=float)
    tick.tick(0.1, 0.2, 0.3, 1.0, 1.0, 0.5, 0.5, 0.0, 0.4, heading, twist, rates, heading.copy())
    drive = [robot.rate_names.index(n) for n in ("left.spin", "right.spin")]  # the castor's follow its heading
    expected = wheel_commands(robot, twist).rates[drive]
    out[track] = float(np.abs(rates[drive] - expected).max())
print(json.dumps(out))
"""


def _run(tmp_path: Path, *tracks: str) -> dict[str, float]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache"), "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", SCRIPT, *tracks], env=env, capture_output=True, text=True,
                          timeout=300, check=True)
    return json.loads(done.stdout.splitlines()[-1])


def test_ticks_of_two_robots_compiled_apart_each_call_their_own_ik(tmp_path):
    """Two diff drives of different tracks (the same shapes: a wrong IK answers silently), each tick compiled in its
    own process, then both loaded in a third: each tick's rates are its own robot's wheel_commands."""
    assert _run(tmp_path, "0.2")["0.2"] < 1e-12
    assert _run(tmp_path, "0.3")["0.3"] < 1e-12
    both = _run(tmp_path, "0.2", "0.3")
    assert max(both.values()) < 1e-12, both
