"""Steering in the loop (§8.4): roots within range, 2/4 quadrants, swerve motion modes, skew-free discretisation."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control.forklift import from_thesis_pose, with_steer_range
from wmrkit.control.points import ControlError
from wmrkit.control.references import builtin_reference
from wmrkit.control.steering import ackermann_twist, choose_steering, crab_twist, discretize_twist, icr_twist
from wmrkit.control.track import track
from wmrkit.kinematics.wheel_ik import wheel_commands
from wmrkit.odometry.integrators import integrate_exact

angles = st.floats(-math.pi, math.pi)


def _wrapped(a):
    return np.angle(np.exp(1j * np.asarray(a)))


@settings(max_examples=300)
@given(h=angles, s=st.floats(-5, 5), cur=angles, lo=st.floats(-math.pi, 0), width=st.floats(0.5, 2 * math.pi - 0.1))
def test_choice_is_a_root_and_within_range(h, s, cur, lo, width):
    """The chosen (heading, spin) is (h, s) or (h + pi, -s), and inside the range whenever one root fits."""
    rng = np.array([[lo, lo + width]])
    c = choose_steering([h], [s], [cur], ranges=rng)
    same = abs(_wrapped(c.heading[0] - h)) < 1e-9 and c.spin[0] == s
    flipped = abs(_wrapped(c.heading[0] - h - math.pi)) < 1e-9 and c.spin[0] == -s
    fits = c.in_range[0]
    assert (same or flipped) if fits else True
    if width >= math.pi:  # a range of half a turn or more always holds one of two opposite roots
        assert fits
    if fits:
        off = (c.heading[0] - lo) % (2 * math.pi)
        assert off <= width + 1e-9 or off >= 2 * math.pi - 1e-9


@pytest.mark.parametrize(("h", "s"), [(math.pi / 2, 2.0), (math.pi / 2, -2.0), (-math.pi / 2, 2.0),
                                      (-math.pi / 2, -2.0)])
def test_closest_breaks_a_tie_by_rolling_forward(h, s):
    """Both roots 90 deg from the current heading: the one whose spin is >= 0, as the IK and WPILib's optimize (it
    took the first root given, whichever way it rolled)."""
    c = choose_steering([h], [s], [0.0], ranges=[[-math.pi, math.pi]])
    assert c.spin[0] == abs(s) and abs(_wrapped(c.heading[0] - (h if s > 0 else h + math.pi))) < 1e-12


@settings(max_examples=300)
@given(h=angles, s=st.floats(-5, 5))
def test_quadrant_policies(h, s):
    four = choose_steering([h], [s], [0.0], policy="4-quadrant")
    two = choose_steering([h], [s], [0.0], policy="2-quadrant")
    assert four.spin[0] >= 0 or s == 0
    assert -math.pi / 2 - 1e-9 < two.heading[0] <= math.pi / 2 + 1e-9


def test_steering_stays_within_range_with_2_quadrant_steering():
    """The forklift with its +-90 deg wheel on references with reversals and corners: never out of range."""
    truck = with_steer_range(catalog.load("forklift"), "steer", -math.pi / 2, math.pi / 2)
    for name, pose in (("corner", from_thesis_pose([0, 0, 0])), ("circle", [0.3, -0.5, 2.8])):
        run = track(truck, builtin_reference(name), gain=1.0, initial_pose=pose, policy="2-quadrant", duration=10)
        assert np.all(np.abs(run.heading[:, 0]) <= math.pi / 2 + 1e-9)
    run = track(truck, builtin_reference("corner"), gain=1.0, initial_pose=from_thesis_pose([0, 0, 0]),
                policy="4-quadrant", duration=10)  # the range wins over the policy
    assert np.all(np.abs(run.heading[:, 0]) <= math.pi / 2 + 1e-9)


SWERVE = catalog.load("swerve-4")


def _headings(twist):
    c = wheel_commands(SWERVE, twist)
    return np.asarray(SWERVE.heading_of_beta(c.beta)), np.asarray(c.spin)


def test_crab_mode_points_every_module_the_same_way():
    h, s = _headings(crab_twist(1.0, 0.7))
    assert np.allclose(_wrapped(h - 0.7), 0, atol=1e-12) or np.allclose(np.abs(_wrapped(h - 0.7)), math.pi)
    assert np.allclose(np.abs(s), 1.0 / 0.0508)


@given(cx=st.floats(-3, 3), cy=st.floats(-3, 3), w=st.floats(0.1, 2))
@settings(max_examples=200)
def test_icr_mode_rolls_every_module_perpendicular_to_the_icr(cx, cy, w):
    """Arbitrary ICR (ros2_controllers #2000): each module's rolling direction is perpendicular to ICR -> module."""
    pos = np.array([wh.position for wh in SWERVE.wheels])
    if np.min(np.hypot(*(pos - [cx, cy]).T)) < 0.05:
        return
    h, _ = _headings(icr_twist([cx, cy], w))
    radial = pos - [cx, cy]
    roll = np.column_stack([np.cos(h), np.sin(h)])
    np.testing.assert_allclose(np.sum(roll * radial, axis=1), 0, atol=1e-9)


def test_ackermann_mode_puts_the_icr_on_the_virtual_rear_axle():
    t = ackermann_twist(1.0, 0.5, axle_x=-0.28)
    icr = np.array([-t[1] / t[2], t[0] / t[2]])  # v_origin = omega (c_y, -c_x)
    np.testing.assert_allclose(icr, [-0.28, 2.0])
    np.testing.assert_allclose(ackermann_twist(1.0, 0.0, -0.28), [1, 0, 0])


@settings(max_examples=300)
@given(vx=st.floats(-3, 3), vy=st.floats(-3, 3), w=st.floats(-4, 4), dt=st.floats(0.005, 0.5))
def test_skew_free_twist_ends_at_the_straight_pose(vx, vy, w, dt):
    """Held for dt through the exact SE(2) step, the discretised twist ends at (vx dt, vy dt, omega dt)."""
    end = integrate_exact([0.0, 0.0, 0.0], discretize_twist([vx, vy, w], dt), dt)
    np.testing.assert_allclose(end, [vx * dt, vy * dt, w * dt], atol=1e-12)


def test_skew_free_matches_wpilib():
    kin = pytest.importorskip("wpimath.kinematics")
    got = discretize_twist([1.0, 0.3, 2.0], 0.02)
    want = kin.ChassisSpeeds.discretize(kin.ChassisSpeeds(1.0, 0.3, 2.0), 0.02)
    np.testing.assert_allclose(got, [want.vx, want.vy, want.omega], atol=1e-12)
    rng = np.random.default_rng(8)
    for twist, dt in zip(rng.normal(size=(200, 3)) * [1.0, 1.0, 3.0], rng.uniform(0.005, 0.5, 200), strict=True):
        if abs(twist[2] * dt) < 3.0:  # within half a turn a period (below)
            want = kin.ChassisSpeeds.discretize(kin.ChassisSpeeds(*twist), float(dt))
            # WPILib's Pose2d.log divides by cos(dtheta) - 1: about 1e-16 / dtheta^2 relative at small turns
            np.testing.assert_allclose(discretize_twist(twist, dt), [want.vx, want.vy, want.omega], rtol=1e-8,
                                       atol=1e-12)
    # beyond half a turn a period WPILib wraps the period's turn into (-pi, pi] (another omega); wmrkit keeps it
    want = kin.ChassisSpeeds.discretize(kin.ChassisSpeeds(0.5, 0.2, 3.0), 2.0)
    assert want.omega == pytest.approx(3.0 - math.pi, abs=1e-12) and discretize_twist([0.5, 0.2, 3.0], 2.0)[2] == 3.0
    end = integrate_exact([0.0, 0.0, 0.0], discretize_twist([0.5, 0.2, 3.0], 2.0), 2.0)
    np.testing.assert_allclose(end, [1.0, 0.4, 6.0], atol=1e-12)


def test_skew_free_discrete_loop_removes_the_drift_of_translating_while_rotating():
    """A holonomic robot told to translate and spin: holding the plain twist skews the path, the discretised one
    lands on the straight line at every sample (the WPILib #5349 symptom)."""
    from wmrkit.control.loop import simulate

    spin = np.array([0.5, 0.0, 2.0])  # world-frame x velocity 0.5 while turning at 2 rad/s

    def ctrl(t, pose, integral):
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return np.array([c * spin[0], -s * spin[0], spin[2]]), np.zeros(3)

    robot = catalog.load("mecanum-4")
    plain = simulate(robot, ctrl, np.zeros(3), 2.0, period=0.1)
    fixed = simulate(robot, ctrl, np.zeros(3), 2.0, period=0.1, skew_free=True)
    assert np.abs(plain["pose"][:, 1]).max() > 5e-3
    np.testing.assert_allclose(fixed["pose"][:, 1], 0.0, atol=1e-12)


def test_steer_range_description_field():
    """``steer_range: [min, max]`` in headings: parsed with units, round-trips, located errors."""
    from wmrkit import Robot
    from wmrkit.errors import DescriptionError

    wheel = {"name": "s", "type": "steerable", "position": [1, 0], "r": 0.1, "steer_range": ["-90 deg", "90 deg"]}
    robot = Robot.from_dict({"name": "x", "wheels": [wheel]})
    assert robot.wheel("s").steer_range == pytest.approx((-math.pi / 2, math.pi / 2))
    assert Robot.from_dict(robot.to_dict()) == robot
    for bad, message in ((["90 deg", "-90 deg"], "min < max"), ([0], "two headings"), (["1 m", 1], "angle")):
        with pytest.raises(DescriptionError, match=message):
            Robot.from_dict({"name": "x", "wheels": [{**wheel, "steer_range": bad}]})
    fixed = {"name": "f", "type": "fixed", "position": [0, 0], "beta": 0, "r": 0.1, "steer_range": [0, 1]}
    with pytest.raises(DescriptionError, match=r"wheels\[0\]\.steer_range: a fixed wheel does not steer"):
        Robot.from_dict({"name": "x", "wheels": [fixed]})


@pytest.mark.parametrize("period", [None, 0.05])
def test_a_reference_beyond_the_steering_range_is_reported_not_followed(period):
    """The car's front wheels turn +-40 deg: a 1 m circle needs more. The ideal loop used to move the car with the
    commanded twist whatever its wheels could do (a perfect 1e-8 m track of an impossible circle); now the wheels
    stay within their range, the car moves with the least-squares twist of its drive wheels there, and the run
    lists which wheel was held at its limit and when."""
    car = catalog.load("ackermann")
    run = track(car, builtin_reference("circle", size=1.0), period=period, duration=12)
    assert np.all(np.abs(run.heading) <= math.radians(40) + 1e-9)
    held: dict[str, list] = {}
    for v in run.range_violations():  # a wheel at its own stop, and held by the linkage at the other's
        held.setdefault(v["wheel"], []).append(v)
    assert set(held) == {"front_left", "front_right"}
    for name, entries in held.items():  # held to the run's end: the time held is the span, none past the last sample
        assert max(v["to"] for v in entries) == run.t[-1]
        assert all(v["duration"] <= v["to"] - v["from"] + 1e-9 for v in entries)
        hit = run.beyond_range[:, car.steer_names.index(name)]
        total = sum(v["duration"] for v in entries)
        assert total > 5 and total == pytest.approx(np.diff(run.t)[hit[:-1]].sum(), abs=1e-12)
    assert run.summary()["max_error"] > 0.3  # the circle is not followed
    assert run.to_dict()["beyond_steer_range"] == run.range_violations()
    wide = track(car, builtin_reference("circle", size=8.0), period=period, duration=12)  # within the range
    unlimited = replace(car, wheels=tuple(replace(w, steer_range=None) for w in car.wheels))
    assert wide.range_violations() == []
    assert np.array_equal(wide.pose, track(unlimited, builtin_reference("circle", size=8.0), period=period,
                                           duration=12).pose)


def test_the_dynamic_plant_keeps_the_wheel_within_its_range():
    """Through the dynamics the steering servo is given the angle at the end of the range, never beyond."""
    truck = with_steer_range(catalog.load("forklift"), "steer", -math.radians(25), math.radians(25))
    run = track(truck, builtin_reference("circle", size=2.0), dynamics=True, duration=8)
    assert np.abs(run.heading[:, 0]).max() <= math.radians(25) + 1e-3  # the servo's overshoot at most
    assert [v["wheel"] for v in run.range_violations()] == ["steer"]
    free = track(catalog.load("forklift"), builtin_reference("circle", size=2.0), dynamics=True, duration=8)
    assert np.abs(free.heading[:, 0]).max() > math.radians(35) and free.range_violations() == []


def test_track_cli_warns_when_a_wheel_is_held_at_its_range(capsys):
    from wmrkit.cli.main import main

    assert main(["track", "ackermann", "--reference", "circle", "--size", "1", "--duration", "5"]) == 0
    err = capsys.readouterr().err
    linkage = "the steering linkage of wheels 'front_left' and 'front_right' held them at a steering limit: "
    assert err.count(linkage) == 1 and "'front_left' was asked to steer beyond its range [-40, 40] deg" in err
    assert main(["track", "ackermann", "--reference", "circle", "--size", "8", "--duration", "5"]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize(("wanted", "held", "same_spin"), [
    (70.0, 40.0, True), (45.0, 40.0, True), (-70.0, -40.0, True),  # past an end: that end, rolling forward
    (120.0, -40.0, False), (-125.0, 40.0, False),  # nearer the other root's end: reversed
])
def test_a_wheel_that_cannot_fit_its_range_is_held_at_the_end_nearest_to_what_is_asked(wanted, held, same_spin):
    """Neither root of (8.9) fits +-40 deg: the wheel is held at the end nearest to either root, with that root's
    spin. 116bfba held every such wheel at the end nearest to the reversed root (70 deg asked, -40 deg held with
    the spin reversed): a car told to turn left turned right."""
    ch = choose_steering([math.radians(wanted)], [2.0], [0.0], ranges=[[-math.radians(40), math.radians(40)]])
    assert not ch.in_range[0]
    assert ch.heading[0] == pytest.approx(math.radians(held))
    assert ch.spin[0] == (2.0 if same_spin else -2.0)


@pytest.mark.parametrize(("wanted", "margin", "held", "same_spin"), [
    (91.0, 0.0, -40.0, False),  # no margin: the other end (miss 49 deg against 51)
    (91.0, math.radians(5), 40.0, True),  # within 5 deg of the tie: stays at +40
    (92.0, math.radians(5), 40.0, True),  # 48 against 52 deg: still within
    (93.0, math.radians(5), -40.0, False),  # 47 against 53: past the margin
    (91.0, math.inf, 40.0, True), (125.0, math.inf, 40.0, True),  # never changes ends
])
def test_a_held_wheel_changes_ends_only_past_the_hold_margin(wanted, margin, held, same_spin):
    """Held at +40 deg (`current`), asked a heading past the tie at 90 deg between the two ends of a +-40 deg rack:
    the wheel stays unless the other end is nearer by more than `hold_margin`."""
    rng = [[-math.radians(40), math.radians(40)]]
    ch = choose_steering([math.radians(wanted)], [2.0], [math.radians(40)], ranges=rng, hold_margin=margin)
    assert not ch.in_range[0]
    assert ch.heading[0] == pytest.approx(math.radians(held))
    assert ch.spin[0] == (2.0 if same_spin else -2.0)
    free = choose_steering([math.radians(wanted)], [2.0], [0.0], ranges=rng, hold_margin=margin)  # not at an end
    assert free.heading[0] == pytest.approx(-math.radians(40))  # the end nearest to either root, as without one


@pytest.mark.parametrize("bad", [-0.1, math.nan, True, "0.1", None])
def test_a_hold_margin_that_is_not_an_angle_is_refused(bad):
    with pytest.raises(ControlError, match="hold_margin: expected an angle >= 0"):
        choose_steering([0.0], [1.0], [0.0], hold_margin=bad)


def test_the_continuous_loop_steps_over_a_wheel_changing_ends(monkeypatch):
    """`wmrkit track ackermann --reference circle --size 3`: the 3 m circle asks a front wheel for more than its
    +-40 deg and, at times, for a heading near 90 deg, where the two ends tie. Without memory the wheel swapped ends
    at every crossing and the continuous loop spent its 2 min of computing (95,000 evaluations) to reach t = 17 s
    of 38 and answer "too stiff". Now the held wheel changes ends past HOLD_MARGIN, located as an event: about 1,700
    evaluations. Bounded here by the evaluations, not by a clock; and the wheel changes ends a few times, not at
    every step."""
    from wmrkit.control import loop

    monkeypatch.setattr(loop, "MAX_EVALUATIONS", 10_000)
    monkeypatch.setattr(loop, "EVALUATIONS_PER_SECOND", 0)
    run = track(catalog.load("ackermann"), builtin_reference("circle"))
    front = run.heading[:, 0]
    held = np.isclose(np.abs(front), math.radians(40), rtol=0, atol=1e-9)
    assert held.sum() > 300
    assert np.count_nonzero(np.diff(np.sign(front[held]))) <= 4
    assert {v["wheel"] for v in run.range_violations()} == {"front_left", "front_right"}


def test_a_car_held_at_its_steering_stops_still_turns_the_way_it_is_told():
    """The 1 m circle asks about 70 deg of the +-40 deg rack: whenever the front wheels are held at a stop, the car
    turns the way the law asks (the sign of the realised rate of turn, from the poses of the held periods, is the
    commanded one), and the wheels cross over only where the law's turn changes sign (116bfba: the wrong stop,
    so turns the wrong way, and about 190 crossings in this run)."""
    car = catalog.load("ackermann")
    run = track(car, builtin_reference("circle", size=1.0), period=0.05, duration=12)
    front = run.heading[:-1, 0]  # the linkage's leader; the inner wheel is at the stop, the outer one on the law
    held = np.isclose(np.abs(run.heading[:-1]), math.radians(40), rtol=0, atol=1e-9).any(axis=1)
    realised = np.diff(run.pose[:, 2]) / 0.05
    assert held.sum() > 100
    assert np.array_equal(np.sign(realised[held]), np.sign(run.twist[:-1, 2][held]))
    assert np.count_nonzero(np.diff(np.sign(front))) <= 6


def test_a_robot_without_actuators_described_is_tracked_with_its_steering_ranges():
    """No `actuated:` joints: the robot is taken to move as the IK spins every wheel (116bfba refused every such
    run, even with ranges a wheel never leaves)."""
    swerve = catalog.load("swerve-4")
    free = replace(swerve, wheels=tuple(replace(w, actuated=(), steer_range=(-math.pi / 2, math.pi / 2))
                                        for w in swerve.wheels))
    run = track(free, builtin_reference("circle", size=2.0), duration=8)
    assert run.range_violations() == [] and run.summary()["max_error"] < 1e-6
    car = catalog.load("ackermann")
    bare = replace(car, wheels=tuple(replace(w, actuated=()) for w in car.wheels))
    held = track(bare, builtin_reference("circle", size=1.0), duration=8)
    assert {v["wheel"] for v in held.range_violations()} == {"front_left", "front_right"}


def test_the_loop_through_the_slip_models_keeps_the_wheel_within_its_range():
    """The loop that feeds back an estimate (or commands the slip models) applied no range before: the forklift held
    to +-25 deg steered 34 deg with no violation reported."""
    truck = with_steer_range(catalog.load("forklift"), "steer", -math.radians(25), math.radians(25))
    run = track(truck, builtin_reference("circle", size=2.0), dynamics=True, feedback="wls", duration=8)
    assert np.abs(run.heading[:, 0]).max() <= math.radians(25) + 1e-3
    assert [v["wheel"] for v in run.range_violations()] == ["steer"]


def _double_unit(steer_range, heading=0.0, actuated=("spin1", "spin2")):
    """A double wheel (a differential steering unit) in front, a double castor behind."""
    from wmrkit import Robot

    return Robot.from_dict({"name": "double-unit", "wheels": [
        {"name": "drive", "type": "double", "position": [0.3, 0], "heading": heading, "b": 0.06, "r": 0.08,
         "actuated": list(actuated), "sensed": ["steer"], "steer_range": steer_range},
        {"name": "trailer", "type": "double_castor", "position": [-0.3, 0], "beta": "90 deg", "d": 0.1, "b": 0.05,
         "r": 0.04}]})


def test_the_other_root_is_flagged_and_a_double_wheel_swaps_its_sub_wheels():
    from wmrkit.control.steering import reverse_spins, spin_columns

    ch = choose_steering([0.3, 0.3, 0.8], [1.0, 1.0, 1.0], [0.3, 0.3 + math.pi, 0.0],
                         ranges=[[-1.0, 1.0], [-4.0, -2.0], [-0.5, 0.5]])
    assert ch.reversed.tolist() == [False, True, False]  # the last held at 0.5, nearer its own root
    assert np.allclose(ch.spin, np.where(ch.reversed, -1.0, 1.0))
    robot = _double_unit(["-10 deg", "10 deg"])
    columns = spin_columns(robot)
    drive = robot.steer_names.index("drive")
    rates = np.arange(1.0, len(robot.rate_names) + 1)
    c1, c2 = columns[drive]
    assert (robot.rate_names[c1], robot.rate_names[c2]) == ("drive.spin1", "drive.spin2")
    flipped = rates.copy()
    reverse_spins(flipped, columns, np.arange(len(columns)) == drive)
    assert (flipped[c1], flipped[c2]) == (-rates[c2], -rates[c1])
    assert np.array_equal(np.delete(flipped, [c1, c2]), np.delete(rates, [c1, c2]))


def test_a_double_wheel_held_at_its_range_moves_the_robot_the_same_either_way_round():
    """A double wheel (a differential steering unit) held at +10 deg, or at 190 deg (the same axle line, its
    sub-wheels on the other sides, reached through the other root of (8.9)), moves the robot the same way. Before,
    every run of a double wheel with a steer_range stopped at 'expected at least one joint rate' (its spins,
    spin1/spin2, were not taken as drive joints), and the other root kept the IK's spins of the first root."""
    direct = track(_double_unit(["-10 deg", "10 deg"]), builtin_reference("circle", size=1.0), period=0.05,
                   duration=6)
    other = track(_double_unit(["170 deg", "190 deg"], heading=math.pi), builtin_reference("circle", size=1.0),
                  period=0.05, duration=6)
    assert [v["wheel"] for v in direct.range_violations()] == ["drive"]
    assert np.allclose(np.cos(other.heading[:, 0] - direct.heading[:, 0]), -1.0, rtol=0, atol=1e-12)
    assert np.allclose(other.pose, direct.pose, atol=1e-9)
    assert np.abs(direct.pose[-1, :2]).max() > 0.5  # it moved


def test_the_dynamics_refuse_a_steered_wheel_nothing_steers():
    """Through the dynamics a steering joint without a servo is not steered: a double wheel steered by its spins
    alone drifted 0.9 m off a 1 m circle in 3 s (its commanded spins have no steering loop), and was reported 'held
    at its end' of a range while it steered 94 deg; the forklift without its steering motor drove straight."""
    from wmrkit.control.steering import check_steering_driven

    circle = builtin_reference("circle", size=1.0)
    with pytest.raises(ControlError, match="wheel 'drive': its steering is not actuated"):
        track(_double_unit(["-10 deg", "10 deg"]), circle, dynamics=True, duration=1)
    truck = catalog.load("forklift")
    free = replace(truck, wheels=tuple(replace(w, actuated=tuple(a for a in w.actuated if a != "steer"))
                                       for w in truck.wheels))
    for kwargs in ({}, {"feedback": "wls"}):
        with pytest.raises(ControlError, match="wheel 'steer': its steering is not actuated"):
            track(free, circle, dynamics=True, duration=1, **kwargs)
    check_steering_driven(_double_unit(["-10 deg", "10 deg"], actuated=("steer", "spin1", "spin2")))
    check_steering_driven(truck)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: choose_steering([math.nan], [1.0], [0.0]), "heading: expected finite numbers, got nan"),
    (lambda: choose_steering([0.0, 1.0], [1.0], [0.0, 0.0, 0.0]),
     r"shapes that do not broadcast together: heading \(2,\), spin \(1,\), current \(3,\)"),
    (lambda: crab_twist([1.0, 2.0], [0.0, 1.0, 2.0]), r"speed \(2,\), direction \(3,\)"),
    (lambda: icr_twist(np.zeros((4, 2)), [1.0, 2.0]), r"icr_xy\[\.\.\., 0\] \(4,\).*omega \(2,\)"),
    (lambda: ackermann_twist(1.0, math.inf), "curvature: expected finite numbers, got inf"),  # was [1, nan, inf]
    (lambda: discretize_twist([1.0, 0.0, 1.0], math.nan), "dt = nan"),  # was NaN
    (lambda: discretize_twist([1.0, 0.0, 1.0], -0.1), "dt = -0.1"),
    (lambda: discretize_twist([1.0, 0.0, 20 * math.pi], 0.1), r"omega dt = 6\.28319 rad is \(nearly\) a whole"),
    (lambda: discretize_twist([[0.0, 0.0, 0.0], [0.0, 1.0, -40 * math.pi]], 0.1), r"omega dt = -12\.5664 rad"),
])
def test_the_steering_helpers_refuse_what_they_cannot_use_by_name(call, message):
    """Found by the audit of the Python doors: numpy's broadcast errors, or NaN results, before."""
    with pytest.raises(ControlError, match=message):
        call()
