"""The geometric path followers (pure pursuit, Stanley) on the catalog's robots and built-in references, at the
defaults of ``wmrkit track`` (each robot's reference size and lookahead, its tracked point starting on the
reference): writes ``trackers-table.md``, the table of docs/control.md (``tests/control/test_trackers_table.py``
recomputes some of its rows).

Columns: RMS and max cross-track error [mm] of the tracked point, the seconds a steered wheel was held at the end of
its range (the longest of the wheels), and the tracked point's final distance from the path's end [mm] (the rows
where it exceeds the follower's tolerance, ``trackers.ARRIVAL_FRACTION`` of its length, are those whose run gives an
ArrivalWarning, not repeated on stderr)."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.cli.control import min_turning_radius
from wmrkit.control.references import builtin_reference, default_size
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning

HERE = Path(__file__).resolve().parent
ROBOTS = ("ackermann", "bicycle", "forklift", "diff-drive", "agv-drive-unit", "thesis-tricycle")
REFERENCES = ("line", "circle", "square", "figure-eight", "arc-line", "corner")
CONTROLLERS = ("pure-pursuit", "stanley")
HEADER = ["| robot | reference | controller | RMS cross-track [mm] | max cross-track [mm] | saturated [s] | "
          "final distance to the path's end [mm] |", "|---|---|---|---|---|---|---|"]


def row(robot_name: str, ref_name: str, controller: str) -> str:
    """One row of the table: `robot_name` following built-in `ref_name` under `controller`, CLI defaults."""
    robot = catalog.load(robot_name)
    ref = builtin_reference(ref_name, size=default_size(ref_name, min_turning_radius(robot)))
    with warnings.catch_warnings():  # its ArrivalWarning (ended beyond its tolerance from the path's end): the
        warnings.simplefilter("ignore", ArrivalWarning)  # row's last column states that distance
        run = track(robot, ref, controller=controller)
    s = run.summary()
    held = max((v["duration"] for v in run.range_violations()), default=0.0)
    end = float(np.hypot(*(run.tracked[-1, :2] - ref.pose[-1, :2])))
    return (f"| {robot_name} | {ref_name} | {controller} | {1e3 * s['rms_cross_track']:.1f} | "
            f"{1e3 * s['max_cross_track']:.1f} | {held:.1f} | {1e3 * end:.1f} |")


def table() -> list[str]:
    rows = list(HEADER)
    for robot_name in ROBOTS:
        for ref_name in REFERENCES:
            for controller in CONTROLLERS:
                rows.append(row(robot_name, ref_name, controller))
                print(rows[-1], flush=True)
    return rows


if __name__ == "__main__":
    text = "\n".join(table()) + "\n"
    if "--print" not in sys.argv[1:]:
        (HERE / "trackers-table.md").write_text(text)
