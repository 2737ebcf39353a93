"""Steering ranges of linked wheels (control/linked_ranges.py): the loops through the dynamics keep a held linkage's
leader where every linked wheel fits its range and set the followers by the law, instead of clipping each wheel on
its own. Checked against the closed-form Ackermann geometry of the linked car (wheelbase 0.6 m, track 0.4 m): the
right wheel's heading whose axle meets the left one's on the rear axle line."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dynamics_robots import linked_car
from test_linked_servos import _geared_units

from wmrkit import Robot
from wmrkit.control import builtin_reference, control_point
from wmrkit.control.dynamic_plant import fast_law_controller, simulate_dynamics
from wmrkit.control.laws import PositionLaw
from wmrkit.control.steering import range_keeper
from wmrkit.control.track import initial_pose_on, track
from wmrkit.dynamics.linkages import SETPOINT_TOL

WHEELBASE, TRACK, LIMIT = 0.6, 0.4, 0.5


def _right(left: float) -> float:
    """fr's heading for fl's `left` (closed form: both axles through the ICR on the rear axle line; mod pi)."""
    return math.atan(WHEELBASE / (WHEELBASE / math.tan(left) + TRACK)) if left else 0.0


def _left(right: float) -> float:
    """fl's heading for fr's `right` (the same geometry, solved for the left wheel)."""
    return math.atan(WHEELBASE / (WHEELBASE / math.tan(right) - TRACK)) if right else 0.0


def _ranged_car(fl=(-LIMIT, LIMIT), fr=(-LIMIT, LIMIT)) -> Robot:
    data = linked_car().to_dict()
    for w in data["wheels"]:
        if w["name"] in ("fl", "fr"):
            w["steer_range"] = list(fl if w["name"] == "fl" else fr)
    return Robot.from_dict(data)


def _keep(robot, fl: float, spins=(1.0, 1.0), policy="closest"):
    headings = np.array([fl, _right(fl)])
    rates = np.zeros(len(robot.rate_names))
    for name, s in zip(("fl", "fr"), spins, strict=True):
        rates[robot.rate_names.index(f"{name}.spin")] = s
    fits = range_keeper(robot, policy)(headings, rates, np.zeros(2))
    return headings, rates, fits


@pytest.mark.parametrize("asked", [0.3, -0.3, 0.8, -0.8, 1.4, -0.9])  # the ICR beyond both wheels
def test_the_kept_headings_are_on_the_law_and_in_range(asked):
    """Before, a tight turn clipped fl and fr each at its own end, 0.5 and 0.5 (left) or -0.5 and -0.5 (right):
    up to 0.1 rad off the law; now the inner wheel is at its end and the outer one where the law sets it."""
    robot = _ranged_car()
    (fl, fr), rates, fits = _keep(robot, asked)
    assert fr == pytest.approx(_right(fl), abs=1e-12)
    assert -LIMIT - 1e-12 <= fl <= LIMIT + 1e-12 and -LIMIT - 1e-12 <= fr <= LIMIT + 1e-12
    if abs(asked) <= 0.3:  # both fit: kept as asked
        assert (fl, fr) == pytest.approx((asked, _right(asked)), abs=1e-12) and fits.all()
    elif asked > 0:  # a left turn: fl is the inner wheel
        assert fl == pytest.approx(LIMIT, abs=1e-12) and not fits.any()
    else:
        assert fr == pytest.approx(-LIMIT, abs=1e-12) and fl == pytest.approx(_left(-LIMIT), abs=1e-12)
        assert not fits.any()
    assert rates[robot.rate_names.index("fl.spin")] == rates[robot.rate_names.index("fr.spin")] == 1.0


@pytest.mark.parametrize("omega", [1.0, -1.0])
def test_a_turn_sharper_than_the_stops_holds_the_linkage_at_the_stop_of_that_turn(omega):
    """The twist (0.1 m/s, 0, +-1 rad/s): the ICR 0.1 m to the left (right) of the rear axle's middle, between the
    rear wheels; the inner front wheel is asked about 100 deg, past its 0.5 rad stop, the outer one about 80 deg.
    The linkage is held at the stop of that turn: the inner wheel at +-0.5, the outer one by the law (closed form),
    the wheels rolling forward. Before, the leader fl alone chose the end nearest its own roots: for the left turn
    the right stop (fl at -0.381, fr at -0.5), and the car turned away from its reference."""
    from wmrkit.kinematics.loop_ik import checked_rates

    robot = _ranged_car()
    rates, beta, _ = checked_rates(robot, np.array([0.1, 0.0, omega]), np.array(robot.beta, dtype=float))
    headings, rates = np.array(robot.heading_of_beta(beta)), np.array(rates)
    assert all(abs(math.remainder(h, math.pi)) > LIMIT + 0.5 for h in headings)  # both axles past the stops
    fits = range_keeper(robot)(headings, rates, np.zeros(2))
    fl, fr = headings
    if omega > 0:
        assert (fl, fr) == pytest.approx((LIMIT, _right(LIMIT)), abs=1e-12)
    else:
        assert (fl, fr) == pytest.approx((_left(-LIMIT), -LIMIT), abs=1e-12)
    assert not fits.any()
    assert rates[robot.rate_names.index("fl.spin")] > 0 and rates[robot.rate_names.index("fr.spin")] > 0


def test_a_follower_narrower_than_its_leader_bounds_the_leader():
    """fr within [-0.2, 0.2]: a left turn stops where fr reaches 0.2, fl at the closed form's 0.2-inverse."""
    robot = _ranged_car(fr=(-0.2, 0.2))
    (fl, fr), _, fits = _keep(robot, 0.45)
    assert fr == pytest.approx(0.2, abs=1e-12) and fl == pytest.approx(_left(0.2), abs=1e-12) and not fits.any()


def test_the_tracking_run_commands_headings_on_the_law_and_in_range():
    """``wmrkit track lcar.json --reference corner --dynamics --size 1 --duration 10``: before, the commanded
    headings were clipped wheel by wheel, fl at -0.5 and fr at +0.5 (1.2 rad off the law) for 8 s."""
    robot = _ranged_car()
    reference = builtin_reference("corner", size=1.0)
    cp = control_point(robot)
    out = simulate_dynamics(robot, fast_law_controller(cp, PositionLaw.uniform("p", 1.0), reference),
                            initial_pose_on(cp, reference), 10.0, period=0.02)
    heading = np.array(robot.heading_of_beta(out["target"]))
    assert np.all(np.abs(heading) <= LIMIT + 1e-12)
    off = [abs(math.remainder(fr - _right(fl), 2 * math.pi)) for fl, fr in heading]
    assert max(off) <= SETPOINT_TOL
    assert (np.abs(heading) >= LIMIT - 1e-12).any()  # the range was reached


def _geared(ranges: float | None = None, ratios=(1.0, 2.0)) -> Robot:
    """Two double wheels whose steering a gear turns in `ratios` (tests' ``_geared_units``), every joint driven,
    each unit's steering within +-`ranges` [rad] when given."""
    data = _geared_units(ratios).robot.to_dict()
    for w in data["wheels"]:
        w["actuated"] = ["steer", "spin1", "spin2"]
        if ranges is not None:
            w["steer_range"] = [-ranges, ranges]
    return Robot.from_dict(data)


@pytest.mark.parametrize(("asked", "kept"), [((0.1, -0.1), (-0.02, -0.04)), ((0.25, 0.5), (0.15, 0.3)),
                                            ((-0.25, -0.5), (-0.15, -0.3))])
def test_a_steering_gear_takes_its_least_squares_turn_within_both_ranges(asked, kept):
    """Units geared 1:2 (rest headings 0), each within +-0.3 rad: asked (0.1, -0.1) the gear turns u = (1 * 0.1 + 2 *
    -0.1) / 5 = -0.02; asked (0.25, 0.5) the rear's range stops the front at 0.15. Before, each unit kept its own
    heading (0.1, -0.1; 0.25, 0.3): off the gear's ratio, the servos fighting it."""
    robot = _geared(0.3)
    headings, rates = np.array(asked), np.zeros(len(robot.rate_names))
    fits = range_keeper(robot)(headings, rates, np.zeros(2))
    np.testing.assert_allclose(headings, kept, atol=1e-12)
    assert fits.all() == (abs(asked[0]) < 0.15)


@pytest.mark.parametrize("ratios", [(1.0, 2.0), (2.0, 1.0), (1.0, -3.0)])
@pytest.mark.parametrize("u", [0.3, 2.0, 2.9, -2.5, 3.1])
def test_headings_on_a_gear_turned_far_are_kept_on_it(ratios, u):
    """Units geared 1:2 (2:1, 1:-3), no range, asked headings on the gear at turn `u` (written wrapped): the kept
    headings are those, mod 2 pi. Before, each wheel's turn was wrapped to (-pi, pi] before the least-squares fit:
    at u = 2 rad the rear's 4 rad read -2.28 and the gear was fitted at u = -0.51, both wheels 2.5 and 5 rad off
    what the IK asked (tests/kinematics/test_steer_gear_roots.py puts the IK on the gear)."""
    robot = _geared(None, ratios)
    asked = np.array([math.remainder(ratios[0] * u, 2 * math.pi), math.remainder(ratios[1] * u, 2 * math.pi)])
    headings = asked.copy()
    range_keeper(robot)(headings, np.zeros(len(robot.rate_names)), np.zeros(2))
    np.testing.assert_allclose(np.remainder(headings - asked + math.pi, 2 * math.pi) - math.pi, 0.0, atol=1e-9)


def test_a_geared_robot_tracks_with_its_headings_in_the_ratios():
    """``track --dynamics`` on the geared units along a 3 m circle: the commanded headings in the gear's ratios
    (before: the wheel IK's, front 0.107 rad and rear -0.093 rad where the gear turns the rear twice the front)."""
    robot = _geared()
    reference = builtin_reference("circle", size=3.0)
    cp = control_point(robot)
    out = simulate_dynamics(robot, fast_law_controller(cp, PositionLaw.uniform("p", 1.0), reference),
                            initial_pose_on(cp, reference), 3.0, period=0.02)
    front, rear = np.array(robot.heading_of_beta(out["target"])).T
    assert np.abs(rear - 2 * front).max() <= SETPOINT_TOL
    assert np.abs(front).max() > 0.01  # it steers


@pytest.mark.parametrize("period", [None, 0.02])
def test_the_kinematic_loop_commands_headings_on_the_law_and_in_range(period):
    """``wmrkit track lcar.json --reference corner --size 1 --duration 10`` without ``--dynamics``: before, the
    kinematic plant clipped each wheel on its own, fl at -0.5 and fr at +0.5 (1.21 rad off the law) for 8 s. Now
    the headings are on the law (closed form) and in range, the inner wheel fl at its end, and the held car turns
    left, the way the law asks (the rate of turn from the poses)."""
    robot = _ranged_car()
    run = track(robot, builtin_reference("corner", size=1.0), duration=10.0, period=period)
    fl, fr = run.heading.T
    assert max(abs(math.remainder(b - _right(a), 2 * math.pi)) for a, b in zip(fl, fr, strict=True)) <= SETPOINT_TOL
    assert np.all(np.abs(run.heading) <= LIMIT + 1e-12)
    held = np.flatnonzero(np.isclose(fl[:-1], LIMIT, rtol=0, atol=1e-9))
    assert len(held) > 50
    assert np.array_equal(np.sign(np.diff(run.pose[:, 2])[held]), np.sign(run.twist[held, 2]))


def test_the_kinematic_loop_keeps_a_steering_gear_in_its_ratios():
    """``wmrkit track geared.json --reference circle --size 3 --duration 3`` without ``--dynamics``: before, the
    ideal plant commanded the wheel IK's headings (front 0.107 rad, rear -0.093 rad where the gear turns the rear
    twice the front) and tracked the circle to 6e-11 m, a motion the gear forbids; then the headings kept the ratios
    and the robot scrubbed (0.46 m off over the whole circle). Now the law commands twists the geared headings
    allow (control/coupled_point.py): the headings keep the ratios and the controlled point tracks to round-off."""
    robot = _geared()
    run = track(robot, builtin_reference("circle", size=3.0), duration=3.0)
    front, rear = run.heading.T
    assert np.abs(rear - 2 * front).max() <= SETPOINT_TOL
    assert np.abs(front).max() > 0.01 and run.summary()["max_error"] < 1e-8


def test_a_follower_held_by_its_linkage_is_not_said_to_be_beyond_its_range(capsys, tmp_path):
    """``wmrkit track lcar.json --reference corner --size 1 --duration 10 --json``: fl, the inner wheel of the left
    turn, is held at its end 0.5 rad, and fr where the law sets it from there (closed form: 0.411 rad), within its
    range. Before, both were listed alike and fr's warning said it "was asked to steer beyond its range ... and was
    held at its end"; now fr's entry names the linkage and the heading it was held at, and so does the linkage's one
    warning (it said a line per wheel, naming the linkage by its channel name, 'linkage(fl.steer, fr.steer)')."""
    import json

    from wmrkit.cli.main import main

    path = tmp_path / "lcar.json"
    path.write_text(json.dumps(_ranged_car().to_dict()))
    assert main(["track", str(path), "--reference", "corner", "--size", "1", "--duration", "10", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    fl, fr = sorted(answer["beyond_steer_range"], key=lambda v: v["wheel"])
    assert (fl["wheel"], fr["wheel"], "held_by" in fl) == ("fl", "fr", False)
    assert fr["held_by"] == "linkage(fl.steer, fr.steer)"
    assert fr["headings"] == pytest.approx([_right(LIMIT)] * 2, abs=1e-12) and abs(_right(LIMIT)) < LIMIT - 0.05
    (said,) = [w for w in answer["warnings"] if "'fr'" in w]
    assert said.startswith("the steering linkage of wheels 'fl' and 'fr' held them at a steering limit: 'fl' was "
                           f"asked to steer beyond its range [-{math.degrees(LIMIT):g}, {math.degrees(LIMIT):g}] deg "
                           f"for {fl['duration']:.3g} s (t = {fl['from']:.4g} to {fl['to']:.4g} s), held at its end, "
                           f"and 'fr' at {math.degrees(_right(LIMIT)):.4g} deg with it (within its range): ")
    assert "linkage(" not in said and "'fr' was asked" not in said


@pytest.mark.parametrize("v", [-1e-4, 1e-4])
@pytest.mark.parametrize("held", ["left", "right"])
def test_a_linkage_held_at_a_stop_keeps_it_within_the_hold_margin(v, held):
    """The twist (v, 0, 1 rad/s) with v a hair from 0: the car asked to turn about its rear axle's middle, where
    its two stops serve the asked axles alike (the sum of the misses ties at v = 0: forward the left stop turns
    it left, reversing the right one does). Held at either stop, the linkage stays there within the hold margin.
    Before, it stayed only where the leader fl alone would also go: its inner-wheel root near -72 deg is nearer
    the right stop, so held at the left one it swapped at the first hair of reversal (the catalog car on
    ``wmrkit track ackermann --reference corner``: right stop for 0.1 s after the corner, then back)."""
    from wmrkit.kinematics.loop_ik import checked_rates

    robot = _ranged_car()
    rates, beta, _ = checked_rates(robot, np.array([v, 0.0, 1.0]), np.array(robot.beta, dtype=float))
    headings, rates = np.array(robot.heading_of_beta(beta)), np.array(rates)
    stop = (LIMIT, _right(LIMIT)) if held == "left" else (_left(-LIMIT), -LIMIT)
    range_keeper(robot)(headings, rates, np.array(stop), math.radians(2.0))
    assert tuple(headings) == pytest.approx(stop, abs=1e-12)


@pytest.mark.parametrize("v", [-0.05, 0.05])
def test_a_linkage_held_at_a_stop_changes_stops_where_the_car_reverses(v):
    """Beyond the margin the stop follows the twist: turning left (1 rad/s) forward the left stop, reversing the
    right one (a car backing up steers right to turn left), whichever it was held at."""
    from wmrkit.kinematics.loop_ik import checked_rates

    robot = _ranged_car()
    for stop in ((LIMIT, _right(LIMIT)), (_left(-LIMIT), -LIMIT)):
        rates, beta, _ = checked_rates(robot, np.array([v, 0.0, 1.0]), np.array(robot.beta, dtype=float))
        headings, rates = np.array(robot.heading_of_beta(beta)), np.array(rates)
        range_keeper(robot)(headings, rates, np.array(stop), math.radians(2.0))
        assert math.copysign(1.0, headings[0]) == math.copysign(1.0, v)
        assert abs(headings[0] if v > 0 else headings[1]) == pytest.approx(LIMIT, abs=1e-12)


@pytest.mark.parametrize("omega", [1.0, -1.0])
@pytest.mark.parametrize("other_root", [False, True])
def test_a_turn_on_the_spot_from_straight_takes_the_stop_that_rolls_forward(omega, other_root):
    """The twist (0, 0, +-1 rad/s) from straight ahead: both stops miss the asked axles alike (mirror images), a
    tie that round-off used to break (the sampled catalog car took its right stop at the left corner of ``wmrkit
    track ackermann --reference corner --period 0.05``, by the sign of a speed of 3e-17 m/s, and reversed for
    0.15 s). Now the stop of the turn, rolling forward, whichever root of (8.9) the wheels are handed."""
    from wmrkit.kinematics.loop_ik import checked_rates

    robot = _ranged_car()
    rates, beta, _ = checked_rates(robot, np.array([0.0, 0.0, omega]), np.array(robot.beta, dtype=float))
    headings, rates = np.array(robot.heading_of_beta(beta)), np.array(rates)
    if other_root:
        for k, name in enumerate(("fl", "fr")):
            headings[k] += math.pi
            rates[robot.rate_names.index(f"{name}.spin")] *= -1
    range_keeper(robot)(headings, rates, np.zeros(2), math.radians(2.0))
    stop = (LIMIT, _right(LIMIT)) if omega > 0 else (_left(-LIMIT), -LIMIT)
    assert tuple(headings) == pytest.approx(stop, abs=1e-12)
    assert rates[robot.rate_names.index("fl.spin")] > 0 and rates[robot.rate_names.index("fr.spin")] > 0


def test_the_sampled_car_turns_forward_into_a_corner():
    """``wmrkit track ackermann --reference corner --period 0.05`` through its left corner (16 s): the linkage at
    its left stop from the corner, never at the right one (it was there from 16 to 16.1 s, the car reversing)."""
    from wmrkit import catalog

    run = track(catalog.load("ackermann"), builtin_reference("corner", size=8.0), period=0.05, duration=17.0)
    front_left = run.heading[:, 0]
    assert np.all(front_left[run.t >= 16.0] == pytest.approx(math.radians(40.0), abs=1e-12))
    assert np.all(front_left >= -1e-12)
