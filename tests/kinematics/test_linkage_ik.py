"""``ik`` judges its steering angles against the held ``linkage`` couplings' ideal law (kinematics/linkage_check.py).

Before: ``wheel_commands`` gave each steerable wheel its own angle (8.9) and ignored linkages, so a synchro drive
(one ``parallel`` linkage of all its wheels) asked to turn, ``wmrkit ik synchro.yaml --twist 1 0 0.5``, printed
three different headings and ``feasible: yes``. Every expectation here is computed independently of the law's code:
a ``parallel`` linkage with equal rest headings can give a twist iff the steering axes' velocities ``v + omega x p``
are all parallel (cross products), an Ackermann linkage iff their normals meet on the fixed wheels' axle line.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from wmrkit import Robot, catalog
from wmrkit.cli.main import main
from wmrkit.kinematics.linkage_check import ik_breaches
from wmrkit.kinematics.wheel_ik import SLIP_TOL, wheel_commands

TRIANGLE = [(0.2, 0.0), (-0.1, 0.173), (-0.1, -0.173)]


def synchro(points=TRIANGLE, law: str | None = None) -> Robot:
    """A synchro drive: steerable wheels at `points`, all heading 0, one linkage of all of them."""
    wheels = [{"name": f"w{k}", "type": "steerable", "position": list(p), "heading": 0, "r": 0.05}
              for k, p in enumerate(points)]
    link = {"kind": "linkage", "joints": [f"w{k}.steer" for k in range(len(points))]}
    return Robot.from_dict({"name": "synchro", "wheels": wheels,
                            "couplings": [link if law is None else {**link, "law": law}]})


def axis_velocities(points, twist) -> np.ndarray:
    vx, vy, w = twist
    return np.array([(vx - w * y, vy + w * x) for x, y in points])


def all_parallel(points, twist, floor: float) -> bool:
    """Brute force: every axis velocity parallel to the fastest one, within a side speed of `floor`."""
    v = axis_velocities(points, twist)
    ref = v[int(np.argmax(np.hypot(*v.T)))]
    u = ref / np.hypot(*ref) if np.hypot(*ref) > 0 else ref
    return bool(np.all(np.abs(v[:, 0] * u[1] - v[:, 1] * u[0]) <= floor))


def test_a_synchro_drive_asked_to_turn_is_not_feasible_and_the_linkage_is_named(capsys):
    robot = synchro()
    c = wheel_commands(robot, [1.0, 0.0, 0.5])
    assert not all_parallel(TRIANGLE, (1.0, 0.0, 0.5), 1e-3)
    assert c.in_linkage.tolist() == [False] and not c.feasible and c.to_dict()["out_of_linkage"] == [
        "linkage(w0.steer, w1.steer, w2.steer)"]
    straight = wheel_commands(robot, [1.0, 0.3, 0.0])
    assert straight.in_linkage.tolist() == [True] and straight.feasible


def test_the_cli_says_no_naming_the_linkage_and_the_wheels(tmp_path, capsys):
    path = tmp_path / "synchro.yaml"
    path.write_text(json.dumps({"name": "synchro", "wheels": [
        {"name": n, "type": "steerable", "position": list(p), "heading": 0, "r": 0.05}
        for n, p in zip("abc", TRIANGLE, strict=True)],
        "couplings": [{"kind": "linkage", "joints": ["a.steer", "b.steer", "c.steer"]}]}))
    assert main(["ik", str(path), "--twist", "1", "0", "0.5"]) == 1
    out, err = capsys.readouterr()
    assert out.rstrip().endswith("feasible: NO (a steering linkage cannot set these headings)")
    assert err.startswith("wmrkit: warning: twist not feasible for robot 'synchro': a steering linkage cannot set "
                          "these headings: the steering linkage of wheels 'a', 'b' and 'c' (law parallel) sets a at "
                          "heading")
    assert err.count("\n") == 1
    assert main(["ik", str(path), "--twist", "1", "0", "0.5", "--json"]) == 1
    data = json.loads(capsys.readouterr()[0])
    assert data["out_of_linkage"] == ["linkage(a.steer, b.steer, c.steer)"] and data["feasible"] is False
    assert len(data["warnings"]) == 1


@settings(max_examples=300, deadline=None)
@given(twist=st.tuples(*[st.floats(-2, 2)] * 3))
def test_a_parallel_linkage_holds_exactly_when_the_axis_velocities_are_parallel(twist):
    robot = synchro()
    strict, loose = all_parallel(TRIANGLE, twist, 1e-10), all_parallel(TRIANGLE, twist, 1e-7)
    assume(strict == loose)  # away from the floor's edge
    assert bool(wheel_commands(robot, twist).in_linkage[0]) == strict


def test_two_wheels_on_a_line_turn_together_about_points_on_it():
    """Two synchro wheels on the y axis have parallel velocities iff vy = 0 (the ICR on their line) or omega = 0."""
    robot = synchro([(0.0, 0.2), (0.0, -0.2)])
    assert wheel_commands(robot, [1.0, 0.0, 0.5]).feasible
    assert not wheel_commands(robot, [1.0, 0.1, 0.5]).feasible


def test_a_wheel_at_the_icr_takes_the_angle_the_linkage_gives_it():
    """ICR at w0's steering axis: w0 does not roll, so the linkage may set it at w1's angle (90 deg)."""
    robot = synchro([(0.2, 0.0), (-0.2, 0.0)])
    twist = [0.0, -0.2, 1.0]  # v + omega x p = 0 at (0.2, 0)
    assert np.allclose(axis_velocities([(0.2, 0.0)], twist), 0.0)
    c = wheel_commands(robot, twist)
    assert c.held[0] and c.feasible


@pytest.mark.parametrize(("omega", "feasible"), [(1e-320, True), (1e-10, True), (1e-8, False)])
def test_the_slip_floor_judges_a_tiny_turn_by_the_side_speed_it_leaves(omega, feasible):
    """A turn in place: the axes move at 0.2 omega tangentially, 120 deg apart, so a wheel set parallel to the
    fastest one slips at 0.2 omega sin(120 deg) = 0.173 omega: within the slip floor (1e-9 m/s) below 5.8e-9 rad/s."""
    robot = synchro()
    c = wheel_commands(robot, [0.0, 0.0, omega])
    assert bool(c.feasible) is feasible
    if not feasible:
        (b,) = ik_breaches(robot, np.array([0.0, 0.0, omega]), c.beta, SLIP_TOL)
        assert b.slip == pytest.approx(0.2 * omega * math.sin(math.radians(120)), rel=1e-2)


def ackermann_car(wheelbase: float, track: float, rear_x: float, axle_heading: float) -> Robot:
    """A car whose fixed axle is at `rear_x` [m] along its rolling direction `axle_heading` [rad]."""
    c, s = math.cos(axle_heading), math.sin(axle_heading)

    def at(x, y):
        return [x * c - y * s, x * s + y * c]

    h = math.degrees(axle_heading)
    wheels = [{"name": "rl", "type": "fixed", "position": at(rear_x, track / 2), "heading": f"{h} deg", "r": 0.3},
              {"name": "rr", "type": "fixed", "position": at(rear_x, -track / 2), "heading": f"{h} deg", "r": 0.3},
              {"name": "fl", "type": "steerable", "position": at(rear_x + wheelbase, track / 2),
               "heading": f"{h} deg", "r": 0.3},
              {"name": "fr", "type": "steerable", "position": at(rear_x + wheelbase, -track / 2),
               "heading": f"{h} deg", "r": 0.3}]
    return Robot.from_dict({"name": "car", "wheels": wheels,
                            "couplings": [{"kind": "linkage", "joints": ["fl.steer", "fr.steer"]}]})


@settings(max_examples=200, deadline=None)
@given(wheelbase=st.floats(0.3, 5), track=st.floats(0.2, 3), rear_x=st.floats(-2, 2),
       axle_heading=st.floats(-math.pi, math.pi), speed=st.floats(-3, 3), omega=st.floats(-3, 3))
def test_an_ackermann_linkage_holds_for_every_twist_the_fixed_wheels_roll_with(wheelbase, track, rear_x,
                                                                                axle_heading, speed, omega):
    """Property: with the fixed axle's lateral speed zero (the ICR on its line), the law never says no."""
    robot = ackermann_car(wheelbase, track, rear_x, axle_heading)
    c, s = math.cos(axle_heading), math.sin(axle_heading)
    px, py = rear_x * c, rear_x * s  # the axle's midpoint: no lateral speed there
    twist = [speed * c + omega * py, speed * s - omega * px, omega]
    cmd = wheel_commands(robot, twist)
    assert np.abs(cmd.slip).max() <= 1e-9  # a twist the fixed wheels roll with
    assert cmd.in_linkage.all() and cmd.feasible


def test_the_catalog_car_s_ik_headings_meet_on_the_rear_axle_and_hold_the_law():
    robot = catalog.load("ackermann")
    cmd = wheel_commands(robot, [1.0, 0.0, 0.2])
    icr_y = 1.0 / 0.2  # on the rear axle line x = 0
    for name in ("front_left", "front_right"):
        x, y = robot.wheel(name).position
        want = math.atan2(x, icr_y - y)  # the heading perpendicular to the ICR -> wheel line
        got = cmd.heading[robot.wheel_names.index(name)]
        assert math.remainder(got - want, math.pi) == pytest.approx(0.0, abs=1e-12)
    assert cmd.in_linkage.all() and cmd.feasible


def test_a_linkage_with_no_law_is_not_judged():
    """A four-wheel-steer car's front pair, no fixed wheel, no law: wmrkit does not guess (as the dynamics)."""
    points = [(0.5, 0.3), (0.5, -0.3), (-0.5, 0.3), (-0.5, -0.3)]
    wheels = [{"name": f"w{k}", "type": "steerable", "position": list(p), "heading": 0, "r": 0.1}
              for k, p in enumerate(points)]
    robot = Robot.from_dict({"name": "4ws", "wheels": wheels,
                             "couplings": [{"kind": "linkage", "joints": ["w0.steer", "w1.steer"]}]})
    assert wheel_commands(robot, [1.0, 0.0, 0.5]).in_linkage.all()
    stated = Robot.from_dict({"name": "4ws", "wheels": wheels, "couplings": [
        {"kind": "linkage", "joints": ["w0.steer", "w1.steer"], "law": "parallel"}]})
    assert not wheel_commands(stated, [1.0, 0.0, 0.5]).in_linkage.all()  # w0, w1 at x = 0.5: not parallel
    assert wheel_commands(stated, [1.0, 0.0, 0.0]).in_linkage.all()


def test_a_batch_is_judged_twist_by_twist():
    robot = synchro()
    twists = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.5], [0.0, 1.0, 0.0]])
    c = wheel_commands(robot, twists)
    assert c.in_linkage[:, 0].tolist() == [True, False, True]
    assert c.feasible.tolist() == [True, False, True]
