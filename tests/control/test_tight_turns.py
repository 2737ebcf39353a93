"""A built-in reference tighter than a car can turn (control/turn_limits.py): ``wmrkit track`` and ``wmrkit
feasibility`` say so in one line. Before, ``wmrkit track ackermann --reference circle --size 1`` only said its
linkage was held at one stop, then at the other (the car backing up), and ``wmrkit feasibility`` said 'feasible:
yes' (Table 8.1 judges continuity only)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control.turn_limits import point_turning_radius

#: The catalog car: wheelbase 2.70 m, track 1.55 m, stops at +-40 deg. Its inner wheel at its stop puts the ICR
#: 2.7 / tan(40 deg) m beside it on the rear axle's line, half a track more from the axle's midpoint (closed form).
R_MIN = 2.70 / math.tan(math.radians(40.0)) + 0.775


@pytest.mark.parametrize("point", [(0.0, 0.0), (2.809, 0.0), (1.0, 0.5)])
def test_a_point_of_the_car_turns_on_the_closed_form_radius(point):
    """On its tightest circle (either way) every point turns about an ICR R_MIN beside the rear axle's midpoint:
    the point's tightest is the nearer of the two."""
    x, y = point
    expected = min(math.hypot(x, y - R_MIN), math.hypot(x, y + R_MIN))
    assert point_turning_radius(catalog.load("ackermann"), point) == pytest.approx(expected, rel=1e-9)
    assert point_turning_radius(catalog.load("diff-drive"), point) == 0.0  # turns on the spot: no limit


def test_track_says_the_circle_is_tighter_than_the_car_turns(capsys):
    """The P law tracks a point 2.809 m ahead of the rear axle (4.882 m at least on a circle); where the 1 m circle
    runs beside it, the law asks the car to back up (the commanded speed of its rear axle negative), and a car
    backing up turns the other way at the same steering: its linkage swings to the other stop. Said once, with the
    times of the commanded reversal."""
    assert main(["track", "ackermann", "--reference", "circle", "--size", "1", "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    first = run["warnings"][0]
    tracked = math.hypot(2.809, R_MIN)
    assert first.startswith(f"the reference turns on 1 m at its tightest, tighter than the robot can drive: the "
                            f"tracked point turns on {tracked:.4g} m at least; the robot's minimum turning radius is "
                            f"{R_MIN:.4g} m")
    left, right = (np.array(run["wheels"][w]["spin"]) * 0.33 for w in ("rear_left", "rear_right"))
    t, speed, omega = np.array(run["t"]), 0.5 * (left + right), (right - left) / 1.55  # the rear axle's commands
    back = t[speed < -1e-9]
    assert len(back) > 100  # seconds of it
    assert f"the law backs it up where the reference runs beside it (t = {back[0]:.4g} to {back[-1]:.4g} s" in first
    steer = np.array(run["wheels"]["front_left"]["heading"])
    both = (speed < -0.05) & (omega > 0.05)  # backing up and turning left: the steering at the right
    assert both.sum() > 20 and np.all(steer[both] < 0)


def test_default_and_unlimited_robots_are_not_warned(capsys):
    """The car's default circle (6 m: 1.5 times R_MIN, rounded up) and a diff drive's 1 m circle: no such line."""
    for argv in (["track", "ackermann", "--reference", "circle", "--duration", "2"],
                 ["track", "diff-drive", "--reference", "circle", "--size", "1", "--duration", "2"]):
        assert main([*argv, "--json"]) == 0
        assert not [w for w in json.loads(capsys.readouterr().out)["warnings"] if "tighter than" in w], argv


def test_feasibility_says_the_circle_is_tighter_than_the_car_turns(capsys):
    """Table 8.1 judges the 1 m circle feasible (it is continuous); the judged point, the rear axle's midpoint, turns
    on R_MIN at least: said in a warning, the verdict unchanged."""
    assert main(["feasibility", "ackermann", "--reference", "circle", "--size", "1", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["feasible"] is True
    assert answer["warnings"] == [f"the reference turns on 1 m at its tightest, tighter than the robot can drive: the "
                                  f"robot's minimum turning radius is {R_MIN:.4g} m (of its rear axle's midpoint, at "
                                  "its steering stops): Table 8.1 judges the reference's continuity only, not this"]
