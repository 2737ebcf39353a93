"""``analyze`` says what a robot's held steering linkages leave of the motions its wheels allow (linkage_reach.py).

Before: a car whose front wheels a ``parallel`` linkage keeps parallel, beside a fixed rear axle, was reported type 4
(m = 1, d = 1) and nothing more, though the linked front axles meet the rear axle only at infinity: it can only drive
straight, and at any other steering it cannot move without slipping. Its actuation line listed
``front_left.steer, front_right.steer`` as two actuators and its minimal actuator sets held both, though one
linkage is one steering actuator. The thesis's type stays (the wheels' geometry); a line and the JSON's
``linkages`` say what the linkages leave. The references are geometry: two wheels held parallel have axles that
meet only at infinity, or anywhere on their common axle line when their axles coincide.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.analysis.linkage_reach import linked_reach, reachable
from wmrkit.analysis.summary import analyze
from wmrkit.cli.main import main
from wmrkit.kinematics.actuation import actuation_analysis, minimal_actuator_sets
from wmrkit.wheels import WheelError

L, T = 2.7, 0.775  # wheelbase and half track [m]


def car(law: str | None) -> Robot:
    """Fixed rear axle on x = 0, front wheels at x = L linked by a linkage of `law` (None: the default)."""
    wheels = [{"name": "rear_left", "type": "fixed", "position": [0, T], "heading": 0, "r": 0.33,
               "actuated": ["spin"], "sensed": ["spin"]},
              {"name": "rear_right", "type": "fixed", "position": [0, -T], "heading": 0, "r": 0.33,
               "actuated": ["spin"], "sensed": ["spin"]},
              {"name": "front_left", "type": "steerable", "position": [L, T], "heading": 0, "r": 0.33,
               "actuated": ["steer"], "sensed": ["steer"]},
              {"name": "front_right", "type": "steerable", "position": [L, -T], "heading": 0, "r": 0.33,
               "actuated": ["steer"], "sensed": ["steer"]}]
    link = {"kind": "linkage", "joints": ["front_left.steer", "front_right.steer"]}
    return Robot.from_dict({"name": f"car-{law}", "wheels": wheels, "couplings": [
        {"kind": "differential", "joints": ["rear_left.spin", "rear_right.spin"]},
        link if law is None else {**link, "law": law}]})


def test_a_parallel_linked_car_only_drives_straight(tmp_path, capsys):
    robot = car("parallel")
    a = analyze(robot, resolution=36)
    assert (a.classification.type, a.classification.mobility, a.classification.steerability) == (4, 1, 1)
    reach = a.linked
    assert (reach.mobility, reach.steerability, reach.every) == (1, 0, False)
    assert reach.icrs == ((0.0, 1.0, 0.0),)  # at infinity along y: translation along x
    assert ("  with its steering linkages held: m = 1, d = 0: only one ICR, at infinity: translation only, along "
            "+-(1.000, 0.000) (at any other steering its linkages give it cannot move without slipping); the type "
            "is of the wheels alone (thesis Table 5.1)") in a.format_text().splitlines()
    path = tmp_path / "car.json"
    path.write_text(json.dumps(robot.to_dict()))
    assert main(["analyze", str(path), "--json", "--resolution", "36"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["type"], out["mobility"], out["steerability"]) == (4, 1, 1)  # the thesis's, kept
    assert out["linkages"]["held"] == ["linkage(front_left.steer, front_right.steer) (law parallel)"]
    assert (out["linkages"]["mobility"], out["linkages"]["steerability"], out["linkages"]["every_icr"]) == (1, 0, False)
    assert out["linkages"]["icr_texts"] == ["ICR at infinity: translation only, along +-(1.000, 0.000)"]


def test_reachable_icrs_of_the_parallel_car_are_where_its_front_axles_are_parallel():
    """Brute force on the rear axle x = 0: the front axles aimed at (0, y) make angles atan2(y -+ T, -L), parallel
    (mod pi) only at infinity."""
    robot = car("parallel")
    y = np.random.default_rng(3).uniform(-50, 50, 40)
    h = np.concatenate([np.c_[np.zeros(40), y, np.ones(40)], [[0.0, 1.0, 0.0], [0.0, -3.0, 0.0]]])
    apart = np.abs(np.sin(np.arctan2(y - T, -L) - np.arctan2(y + T, -L)))
    assert (apart > 1e-3).all()
    np.testing.assert_array_equal(reachable(robot, h), np.r_[np.zeros(40, bool), True, True])


@pytest.mark.parametrize("robot", [car("ackermann"), car(None), catalog.load("ackermann")], ids=str)
def test_an_ackermann_linkage_reaches_every_icr_of_the_axle(robot):
    a = analyze(robot, resolution=36)
    assert (a.linked.mobility, a.linked.steerability, a.linked.every) == (1, 1, True)
    assert "with its steering linkages held" not in a.format_text()
    assert a.to_dict()["linkages"]["every_icr"] is True


def test_without_a_held_linkage_there_is_nothing_to_say():
    for name in ("forklift", "swerve-4", "diff-drive"):
        a = analyze(catalog.load(name), resolution=8)
        assert a.linked is None and a.to_dict()["linkages"] is None


def _steered(points, linked) -> Robot:
    wheels = [{"name": f"w{k}", "type": "steerable", "position": list(p), "heading": 0, "r": 0.05,
               "actuated": ["spin", "steer"] if k == 0 else ["steer"], "sensed": ["steer"]}
              for k, p in enumerate(points)]
    return Robot.from_dict({"name": "linked", "wheels": wheels, "couplings": [
        {"kind": "linkage", "joints": [f"w{k}.steer" for k in linked], "law": "parallel"}]})


def test_a_synchro_drive_only_translates():
    """Three wheels held parallel, not collinear: their axles meet only at infinity."""
    reach = linked_reach(_steered([(0.2, 0.0), (-0.1, 0.173), (-0.1, -0.173)], [0, 1, 2]), 36)
    assert (reach.mobility, reach.steerability, reach.every) == (1, 1, False)
    assert reach.words == ("every ICR at infinity (translation in any direction); no finite ICR found: it only "
                           "translates")


def test_the_finest_resolution_judges_a_grid_of_at_most_360_points_a_turn():
    """At --resolution 1440 a plane of ICRs (2 million for a synchro drive) took 5 s for a verdict 360 gives."""
    robot = _steered([(0.2, 0.0), (-0.1, 0.173), (-0.1, -0.173)], [0, 1, 2])
    fine, coarse = linked_reach(robot, 1440), linked_reach(robot, 360)
    assert fine.sampled == coarse.sampled == 91 * 360 + 360 + 1 and fine.words == coarse.words


def test_a_front_linked_four_wheel_steer_also_turns_about_its_front_axle_line():
    """The front pair held parallel (heading 0) meets at infinity or anywhere on its common axle x = 0.5."""
    robot = _steered([(0.5, 0.3), (0.5, -0.3), (-0.5, 0.3), (-0.5, -0.3)], [0, 1])
    reach = linked_reach(robot, 36)
    assert (reach.mobility, reach.steerability) == (1, 1)
    assert reach.words == ("every ICR at infinity (translation in any direction) and ICRs on the line through w0 "
                           "and w1 (36 of 36 sampled)")
    off = np.c_[np.full(5, 0.7), np.linspace(-2, 2, 5), np.ones(5)]
    assert not reachable(robot, off).any()


def test_a_linkage_is_one_steering_actuator(capsys):
    robot = car("parallel")
    assert "(differential of rear_left and rear_right, linkage of front_left and front_right)" in \
        analyze(robot, resolution=8).format_text()
    assert actuation_analysis(robot).steering_actuators == ("linkage(front_left.steer, front_right.steer)",)
    sets = minimal_actuator_sets(robot)
    assert sets and all(sum(j.endswith(".steer") for j in s) == 1 for s in sets)
    assert ("rear_left.spin", "front_left.steer") in sets


def test_a_steer_heading_beyond_the_limit_is_named_as_a_heading(capsys):
    """Before: '--steer steer=1e6 turn: wheel 'steer': beta: expected an angle of at most 1e+06 turns [rad], got
    6283186.877975913': the thesis's beta, in radians, though the user gave a heading in turns."""
    assert main(["analyze", "forklift", "--steer", "steer=1e6 turn"]) == 2
    err = capsys.readouterr().err
    assert err == ("wmrkit: error: --steer steer=1e6 turn: wheel 'steer': heading: 1000000 turns is beyond "
                   "+-999999.75 turns, where the thesis's beta (heading - delta + 90 deg) of one sign reaches the "
                   "limit of every angle, 1e+06 turns (no angle to steer by)\n")
    with pytest.raises(WheelError, match=r"^wheel 'steer': heading: 1000000 turns is beyond \+-999999.75 turns"):
        catalog.load("forklift").with_steering({"steer": 2e6 * np.pi})
