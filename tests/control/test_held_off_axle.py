"""A steering gear or linkage that holds its wheels off the axles the commanded twist needs is reported
(``TrackingRun.held_off_axle``, JSON ``held_off_axle``, a warning of ``wmrkit track``). Before, ``wmrkit track
geared.json --reference circle --size 3`` (two double wheels whose steering a gear turns 1:2) ended 0.46 m off the
circle without a word: the gear held the wheels up to 75 deg off the commanded twist's axles and the kinematic loop
moved the robot with the least-squares twist of its wheels, 1.5 rad/s off the commanded turn rate. The thesis's laws,
pure pursuit and Stanley now command the twists the geared headings allow (control/coupled_point.py,
control/coupled_arcs.py: nothing to report); a car whose front wheels a parallel linkage turns together (not
Ackermann's) still has its wheels held off the axles of pure pursuit's turns about its rear axle, reported below."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from test_linked_ranges import _geared

from geared import SYNCHRO
from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control import builtin_reference
from wmrkit.control.track import track
from wmrkit.robot import Robot

GEAR = "gear(front.steer, rear.steer)"
PARALLEL = "linkage(front_left.steer, front_right.steer)"
CIRCLE = builtin_reference("circle", size=3.0)


def _parallel_car():
    """The catalog car, its front wheels on a parallel linkage: no turn of its rear axle puts both on their axles."""
    data = catalog.load("ackermann").to_dict()
    data["couplings"][1] = {"kind": "linkage", "joints": ["front_left.steer", "front_right.steer"], "law": "parallel"}
    return Robot.from_dict(data)


def _axle_miss(robot, twist: np.ndarray, commanded: np.ndarray) -> np.ndarray:
    """``(n, n_steer)`` [rad]: each steered wheel's commanded heading off the direction its steering axis moves at
    the commanded `twist` (mod pi), from the wheel positions (brute force: ``v + omega z x p``)."""
    out = np.zeros(commanded.shape)
    for k, name in enumerate(robot.steer_names):
        x, y = robot.wheel(name).position
        vx, vy = twist[:, 0] - twist[:, 2] * y, twist[:, 1] + twist[:, 2] * x
        out[:, k] = np.abs([math.remainder(a, math.pi) for a in np.arctan2(vy, vx) - commanded[:, k]])
    return out


def test_a_linkage_off_the_commanded_axles_is_reported_with_the_twist_the_robot_moved_with():
    robot = _parallel_car()
    run = track(robot, builtin_reference("circle", size=8.0), duration=3.0, controller="pure-pursuit")
    (v,) = run.held_off_axle()
    assert (v["coupling"], v["wheels"], v["from"], v["to"]) == (PARALLEL, ["front_left", "front_right"], 0.0, 3.0)
    miss = _axle_miss(robot, run.twist, run.commanded)
    assert v["axle_miss"] == pytest.approx(miss.max(), abs=1e-9) and v["axle_miss"] > 0.02
    # the twist the robot moved with, against the poses' own rates (central differences, 0.05 s apart)
    dpose = np.gradient(run.pose, run.t, axis=0)[1:-1]
    c, s = np.cos(run.pose[1:-1, 2]), np.sin(run.pose[1:-1, 2])
    body = np.stack([c * dpose[:, 0] + s * dpose[:, 1], -s * dpose[:, 0] + c * dpose[:, 1], dpose[:, 2]], axis=1)
    np.testing.assert_allclose(run.moved[1:-1], body, atol=1e-3)
    assert v["twist_miss"][1] > 1e-3  # the commanded turn rate is off the one the linked wheels give
    assert json.loads(json.dumps(run.to_dict()))["held_off_axle"] == [v]


def test_track_warns_of_a_linkage_holding_its_wheels_off_the_commanded_axles(tmp_path, capsys):
    path = tmp_path / "parallel.json"
    path.write_text(json.dumps(_parallel_car().to_dict()))
    assert main(["track", str(path), "--reference", "circle", "--size", "8", "--duration", "3", "--json",
                 "--controller", "pure-pursuit"]) == 0
    answer = json.loads(capsys.readouterr().out)
    (said,) = [w for w in answer["warnings"] if "axles the commanded twist needs" in w]
    v = answer["held_off_axle"][0]
    assert v["coupling"] == PARALLEL  # the JSON's channel name; the warning speaks the description's terms
    assert said.startswith("the steering linkage of wheels 'front_left' and 'front_right' held them up to "
                           f"{math.degrees(v['axle_miss']):.3g} deg off the axles the commanded twist needs for 3 s "
                           "(t = 0 to 3 s): that twist is not realisable")
    assert f"{v['twist_miss'][0]:.3g} m/s and {v['twist_miss'][1]:.3g} rad/s off the commanded one" in said


def test_the_p_law_on_the_geared_units_holds_the_axles_and_is_not_reported(tmp_path, capsys):
    """``wmrkit track geared.json --reference circle --size 3 --json``: before, "held off axle" and 0.457 m off the
    circle at its end; the law now commands twists the geared headings allow."""
    path = tmp_path / "geared.json"
    path.write_text(json.dumps(_geared().to_dict()))
    assert main(["track", str(path), "--reference", "circle", "--size", "3", "--duration", "3", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["held_off_axle"] == [] and not [w for w in answer["warnings"] if GEAR in w]
    assert answer["summary"]["max_error"] < 1e-8


def test_a_linkage_on_the_commanded_axles_is_not_reported():
    """The catalog car's Ackermann linkage sets both front wheels on the axles of any twist its rear axle allows."""
    run = track(catalog.load("ackermann"), builtin_reference("circle", size=6.0), duration=5.0)
    assert run.held_off_axle() == [] and run.moved is not None


def test_feasibility_judges_a_robot_its_couplings_leave_one_steering_degree_of_freedom_as_type_4(tmp_path, capsys):
    """A synchro drive (three wheels on one parallel linkage: it cannot turn) answered "feasible: yes" to a circle
    without a word of its linkage; the geared units' warning sent the user to ``wmrkit ik``, which then did not check a
    steering gear's angles (it answered "feasible: yes" to headings out of the ratios). Then both said their coupling
    "is not considered". Now the laws control both as the type 4 they are (one steering degree of freedom, no fixed
    wheel: control/coupled_point.py), and Table 8.1 judges them so: ``(x, y)`` of the point, chi continuous."""
    synchro, geared = tmp_path / "synchro.yaml", tmp_path / "geared.json"
    synchro.write_text(SYNCHRO)
    geared.write_text(json.dumps(_geared().to_dict()))
    said = "steers through couplings that leave it one steering degree of freedom and has no fixed wheel: Table 8.1 "
    for path, size in ((synchro, []), (geared, ["--size", "3"])):
        assert main(["feasibility", str(path), "--reference", "circle", *size]) == 0
        out, err = capsys.readouterr()
        assert said in err and "is not considered" not in err and "column 'type 4, off axle'" in out
    assert main(["feasibility", "ackermann", "--reference", "circle"]) == 0  # its linkage sets the axles d asks
    assert capsys.readouterr().err == ""
