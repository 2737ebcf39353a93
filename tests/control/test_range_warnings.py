"""``wmrkit track``'s warnings of steered wheels held at their ranges' ends, in the description's terms."""

from __future__ import annotations

import json
import math

from wmrkit import catalog
from wmrkit.cli.control import range_warnings
from wmrkit.cli.main import main
from wmrkit.control.forklift import with_steer_range


def test_the_catalog_car_s_corner_says_one_warning_for_its_linkage(capsys):
    """``wmrkit track ackermann --reference corner``: four warnings, two per wheel, each naming the channel
    'linkage(front_left.steer, front_right.steer)' (an internal name) for what is one cause, the linkage at its
    stop. Now one warning names the linkage by its wheels, the wheel at its end and the other held with it. The
    corner turns left: the linkage stays at its left stop from the corner (16 s) until the car has turned (it also
    swapped to the right stop for 0.1 s at 16.05 s, the hold margin bypassed, test_linked_ranges.py)."""
    assert main(["track", "ackermann", "--reference", "corner", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    entries = answer["beyond_steer_range"]
    assert sorted((v["wheel"], "held_by" in v) for v in entries) == [("front_left", False), ("front_right", True)]
    assert entries[0]["from"] == entries[1]["from"] == 16.0 and entries[0]["to"] == entries[1]["to"] > 25
    (headings,) = [v["headings"] for v in entries if "held_by" in v]
    assert min(headings) > 0  # front_right held left of straight, with front_left at its left stop
    held = [w for w in answer["warnings"] if "steering limit" in w or ("range" in w and "Table 8.1" not in w)]
    assert len(held) == 1 and not [w for w in answer["warnings"] if ".steer" in w]
    (said,) = held
    assert said.startswith("the steering linkage of wheels 'front_left' and 'front_right' held them at a steering "
                           "limit: 'front_left' was asked to steer beyond its range [-40, 40] deg for ")
    for v in entries:  # every entry's wheel and times said, once
        assert said.count(f"(t = {v['from']:.4g} to {v['to']:.4g} s)") == 1 or "held_by" in v
        assert said.count(f"'{v['wheel']}' was asked") == 1 or "held_by" in v


def test_a_wheel_held_by_a_linkage_at_no_other_wheel_s_times_is_said_apart():
    """The robot's linkage held a wheel while the one at its end is not in the list (its interval elsewhere): the
    held wheel is said with its own times, within the one warning."""
    robot = catalog.load("ackermann")
    channel = robot.couplings[1].channel_name  # the steering linkage
    violations = [{"wheel": "front_left", "from": 1.0, "to": 2.0, "duration": 1.0},
                  {"wheel": "front_right", "from": 1.5, "to": 2.5, "duration": 1.0, "held_by": channel,
                   "headings": [0.5, 0.5]}]
    (said,) = range_warnings(robot, violations)
    assert "'front_left' was asked to steer beyond its range [-40, 40] deg for 1 s (t = 1 to 2 s), held at its end; " \
           "'front_right' at 28.65 deg (within its range) for 1 s (t = 1.5 to 2.5 s): the robot cannot" in said


def test_a_wheel_steered_on_its_own_keeps_its_own_warning():
    truck = with_steer_range(catalog.load("forklift"), "steer", -math.pi / 2, math.pi / 2)  # the real truck's
    (said,) = range_warnings(truck, [{"wheel": "steer", "from": 0.0, "to": 1.0, "duration": 1.05}])
    assert said.startswith("wheel 'steer' was asked to steer beyond its range [-90, 90] deg for 1.05 s (t = 0 to 1 s), "
                           "held at its end: the robot cannot follow")
