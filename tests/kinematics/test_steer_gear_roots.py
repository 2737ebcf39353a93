"""``ik`` sets a wheel in a steering gear on the root of (8.9) its gear sets, in every path (kinematics/gear_check.py).

Before: each geared wheel kept the root closest to its current heading (or the one in its ``steer_range``) and the
gear check compared headings mod 180 deg, so two double wheels geared 1:1 at (+-0.2, 0) m, turning in place from
headings 0, were printed at 90 and -90 deg, ``feasible: yes``, where the gear (equal rest headings) sets both at the
same heading; geared 1:2, the rear was printed half a turn from twice the front's heading. The expectations here are
independent of the code: a gear sets ``h_j - h_j0 = ratio_j u`` exactly (mod 360 deg, not 180), some turn ``u``.
The paths: ``wheel_commands`` (one twist and the compiled batch), the control loop's ``checked_steering_config``
(``_ik_fast.steering_one``), the compiled single-call ``realtime`` ik.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from wmrkit import Robot
from wmrkit.kinematics.loop_ik import checked_steering_config
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import forward_kinematics, wheel_commands

ULPS = 2 * float(np.spacing(2 * np.pi))  # atan2 of the plain-float and SIMD paths (tests/kinematics/test_linkage_roots)


def geared(positions, ratios, rests=(0.0, 0.0), ranges=(None, None)) -> Robot:
    """Two double wheels ``a``, ``b`` whose steering a gear turns in `ratios`; rest headings [rad], ranges [deg]."""
    unit = {"type": "double", "b": 0.06, "r": 0.08, "actuated": ["steer", "spin1", "spin2"]}
    wheels = [{**unit, "name": n, "position": list(p), "heading": h}
              | ({"steer_range": [f"{d} deg" for d in s]} if s else {})
              for n, p, h, s in zip("ab", positions, rests, ranges, strict=True)]
    return Robot.from_dict({"name": "geared", "wheels": wheels, "couplings": [
        {"kind": "gear", "joints": ["a.steer", "b.steer"], "ratios": list(ratios)}]})


def gear_turns(robot: Robot, heading) -> list[float]:
    """Brute force: the gear turns ``u`` (from either wheel, within 3 turns) that set both wheels exactly at
    `heading` [rad] (mod 2 pi), from the described headings."""
    (c,) = robot.couplings
    rest = [float(robot.wheel(n).heading) for n in robot.steer_names]
    found = []
    for ref in range(2):
        for n in range(-6, 7):
            u = (heading[ref] - rest[ref] + n * math.pi) / c.ratios[ref]
            if all(abs(math.remainder(h - h0 - k * u, 2 * math.pi)) < 1e-7
                   for h, h0, k in zip(heading, rest, c.ratios, strict=True)):
                found.append(u)
    return found


def fk_twist(robot: Robot, c) -> np.ndarray:
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    rates = {n: v for n, v in zip(robot.rate_names, c.rates.tolist(), strict=True) if not n.endswith(".steer")}
    return forward_kinematics(robot, rates, heading=c.heading[steer])[0]


def every_path(robot: Robot, twist, current, compiled: bool = True) -> tuple:
    """``wheel_commands``' commands, after checking that the other paths give its headings and feasibility (the
    compiled ``realtime`` one when `compiled`: it compiles a kernel for each new robot, some 3 s)."""
    twist, current = np.asarray(twist, dtype=float), np.asarray(current, dtype=float)
    c = wheel_commands(robot, twist, heading=current)
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    config = checked_steering_config(robot, twist, robot.beta_of_heading(current))
    np.testing.assert_allclose(config, c.beta, rtol=0, atol=ULPS)
    if not compiled:
        return c, c.heading[steer]
    rates, out = np.empty(len(robot.rate_names)), np.empty(len(steer))
    assert realtime(robot).ik(*twist.tolist(), current.copy(), rates, out) == bool(c.feasible)
    np.testing.assert_allclose(np.remainder(out - c.heading[steer] + np.pi, 2 * np.pi) - np.pi, 0.0, atol=ULPS)
    np.testing.assert_allclose(rates, c.rates, rtol=1e-12, atol=1e-12)
    return c, c.heading[steer]


def test_a_1_to_1_gear_sets_both_wheels_turning_in_place_at_one_heading():
    robot = geared([(0.2, 0.0), (-0.2, 0.0)], (1, 1))
    c, heading = every_path(robot, [0.0, 0.0, 1.0], [0.0, 0.0])
    # both axes move at 0.2 m/s, a ahead (+y), b back (-y): the tie rolls a forward at 90 deg, the gear sets b there
    np.testing.assert_allclose(np.degrees(heading), [90.0, 90.0], atol=1e-12)
    assert c.feasible and c.in_steer_gear.all() and gear_turns(robot, heading)
    np.testing.assert_allclose(fk_twist(robot, c), [0.0, 0.0, 1.0], atol=1e-12)


def test_a_1_to_1_gear_whose_second_wheel_fits_its_range_only_turned_is_turned_whole():
    """b steers within [-180, 0] deg: from headings 10 deg, a takes 90 deg (closer) and the gear would set b at 90
    deg, out of its range; both at -90 deg fit (it printed a 90, b -90 deg, feasible)."""
    robot = geared([(0.2, 0.0), (-0.2, 0.0)], (1, 1), ranges=(None, (-180.0, 0.0)))
    c, heading = every_path(robot, [0.0, 0.0, 1.0], np.radians([10.0, 10.0]))
    np.testing.assert_allclose(np.degrees(heading), [-90.0, -90.0], atol=1e-12)
    assert c.feasible and gear_turns(robot, heading)
    np.testing.assert_allclose(fk_twist(robot, c), [0.0, 0.0, 1.0], atol=1e-12)


def twist_for(positions, heading, omega) -> np.ndarray:
    """The twist turning at `omega` about the point where the wheels' axles meet (both roll along `heading`)."""
    rows = np.array([[math.cos(h), math.sin(h)] for h in heading])
    icr = np.linalg.solve(rows, [rows[k] @ np.asarray(positions[k]) for k in range(2)])
    return np.array([omega * icr[1], -omega * icr[0], omega])


def test_a_1_to_2_gear_sets_the_rear_at_twice_the_front_s_heading_not_half_a_turn_off():
    positions = [(0.3, 0.2), (-0.3, -0.2)]
    robot = geared(positions, (1, 2))
    twist = twist_for(positions, (0.5, 1.0), 0.7)
    c, heading = every_path(robot, twist, [0.0, -2.0])  # the rear's closer root is 1.0 - pi rad
    assert math.remainder(heading[1] - 2 * heading[0], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert c.feasible and gear_turns(robot, heading)
    np.testing.assert_allclose(fk_twist(robot, c), twist, atol=1e-12)


RATIOS = st.sampled_from([1.0, -1.0, 2.0, -2.0])


@settings(max_examples=120, deadline=None)
@given(pos=st.lists(st.floats(-1, 1), min_size=4, max_size=4), ratios=st.tuples(RATIOS, RATIOS),
       rests=st.tuples(st.floats(-3, 3), st.floats(-3, 3)), u=st.floats(-3, 3),
       omega=st.floats(0.2, 3).flatmap(lambda w: st.sampled_from([w, -w])),
       current=st.tuples(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi)))
def test_random_geared_robots_get_the_headings_their_gear_sets(pos, ratios, rests, u, omega, current):
    """Any twist a gear can roll (the axles meeting at the headings it sets at some turn u): feasible, headings the
    gear sets (mod 2 pi), fk at them gives the twist back, the Python paths agree (the compiled one on the fixed
    robots above and below: a kernel a robot, 354 s for these examples)."""
    positions = [(pos[0], pos[1]), (pos[2], pos[3])]
    assume(math.dist(*positions) > 0.1)
    heading = [h0 + k * u for h0, k in zip(rests, ratios, strict=True)]
    assume(abs(math.sin(heading[0] - heading[1])) > 0.1)  # the axles meet
    robot = geared(positions, ratios, rests=rests)
    twist = twist_for(positions, heading, omega)
    speeds = [math.hypot(twist[0] - omega * y, twist[1] + omega * x) for x, y in positions]
    assume(min(speeds) > 1e-3 and abs(speeds[0] - speeds[1]) > 1e-9 * max(speeds))  # no wheel at the ICR, no tie
    assume(max(abs(twist)) < 1e3)
    c, got = every_path(robot, twist, current, compiled=False)
    assert c.feasible and c.in_steer_gear.all()
    assert gear_turns(robot, got), (np.degrees(got), np.degrees(heading))
    np.testing.assert_allclose(fk_twist(robot, c), twist, rtol=1e-9, atol=1e-9 * max(1.0, max(abs(twist))))


def test_a_compiled_batch_sets_the_roots_one_call_sets():
    positions = [(0.3, 0.2), (-0.3, -0.2)]
    robot = geared(positions, (2, 1))
    rng = np.random.default_rng(5)
    fronts = rng.uniform(-3, 3, 80)
    twists = np.array([twist_for(positions, (2 * f, f), 0.5) for f in fronts])
    current = rng.uniform(-math.pi, math.pi, (80, 2))
    batch = wheel_commands(robot, twists, heading=current)  # >= 64 twists: the compiled kernels
    assert batch.feasible.all()
    for i in range(0, 80, 8):
        np.testing.assert_allclose(batch.heading[i], wheel_commands(robot, twists[i], heading=current[i]).heading,
                                   rtol=0, atol=ULPS)


def test_a_twist_no_turn_of_the_gear_rolls_keeps_each_wheel_on_the_root_closest_to_it():
    """Units geared 1:2 at (0.3, 0.2), (-0.3, -0.2) m at headings (0.2581, 0.5163) rad (the gear's), asked (0.4014,
    0.2698, 0.6511) (a twist of the kinematic track loop on the circle): the gear sets the rear at twice the front's
    heading, 1.19 rad off its line, so no turn of it holds. The rear was printed half a turn from its current heading
    (-3.002 rad), the root nearest the heading the gear would set; the loop's least-squares gear turn then jumped its
    set-point by 1.9 rad. Each wheel keeps the root of (8.9) closest to its current heading now: its line's."""
    positions = [(0.3, 0.2), (-0.3, -0.2)]
    robot = geared(positions, (1, 2))
    twist, current = np.array([0.4014, 0.2698, 0.6511]), np.array([0.2581, 0.5163])
    c, heading = every_path(robot, twist, current)
    assert not c.feasible and not c.in_steer_gear.all()
    for (x, y), h, h0 in zip(positions, heading, current, strict=True):
        line = math.atan2(twist[1] + twist[2] * x, twist[0] - twist[2] * y)  # the axis's velocity (8.9)
        assert abs(math.remainder(h - line, math.pi)) < 1e-12 and abs(math.remainder(h - h0, 2 * math.pi)) < math.pi / 2


@settings(max_examples=150, deadline=None)
@given(ratios=st.tuples(st.sampled_from([1.0, -1.0, 2.0, -2.0, 3.0, 0.5, 1.5]), st.sampled_from([1.0, 2.0, -3.0])),
       rests=st.tuples(st.floats(-3, 3), st.floats(-3, 3)), u=st.floats(-6, 6),
       flips=st.tuples(st.booleans(), st.booleans()), speeds=st.tuples(st.floats(0.1, 2), st.floats(0.1, 2)),
       ranged=st.booleans())
def test_the_gear_s_candidate_turns_set_the_roots_all_six_set(ratios, rests, u, flips, speeds, ranged):
    """The half turns :func:`candidate_turns` leaves (one for a reference the others turn by whole ratios) set the
    roots every one of :data:`HALF_TURNS` would: those it drops set the wheels at headings an earlier one sets, or
    (the reference turned) on lines a kept even one holds, which wins."""
    from wmrkit.kinematics.gear_check import HALF_TURNS, NO_TURN, candidate_turns, steer_gears, steer_roots
    from wmrkit.kinematics.linkage_check import _plan
    from wmrkit.kinematics.linkage_law import LINKAGE_TOL

    around = [math.degrees(h) for h in rests]  # ranges hold the rest headings
    robot = geared([(0.3, 0.2), (-0.3, -0.2)], ratios, rests=rests,
                   ranges=((around[0] - 60, around[0] + 60), (around[1] - 120, around[1] + 30)) if ranged else (None,
                                                                                                          None))
    sg, links = steer_gears(robot), _plan(robot)
    full = np.full_like(sg.turns, NO_TURN)
    full[:, :len(HALF_TURNS)] = HALF_TURNS
    beta = np.array([h0 + k * u + (math.pi if f else 0.0) for h0, k, f in zip(sg.rest, ratios, flips, strict=True)])
    speed, free = np.array(speeds), np.ones(2, dtype=bool)
    x = speed  # turning in place about the origin, the axes on the x axis: their speeds (the reference the faster)
    got = []
    for table in (sg.turns, full):
        turn = np.zeros(2, dtype=bool)
        steer_roots(sg.table.joint, sg.table.ratio, 0, 2, sg.rest, x, np.zeros(2), 0.0, 0.0, 1.0, sg.rows, table, beta,
                    speed, 1e-9, LINKAGE_TOL, free, links.lo, links.width, links.offset, turn)
        got.append(turn.tolist())
    assert got[0] == got[1]
    assert (len(candidate_turns(np.array(ratios) / ratios[0])) == 1) == (ratios[1] / ratios[0] % 1 == 0)


FIXED = {ratios: geared([(0.3, 0.2), (-0.3, -0.2)], ratios, rests=(0.4, -0.7)) for ratios in ((1, 2), (2, -1))}


@settings(max_examples=60, deadline=None)
@given(ratios=st.sampled_from(sorted(FIXED)), u=st.floats(-3, 3),
       omega=st.floats(0.2, 3).flatmap(lambda w: st.sampled_from([w, -w])),
       current=st.tuples(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi)))
def test_the_compiled_ik_sets_the_roots_the_python_one_sets(ratios, u, omega, current):
    """The compiled path (``realtime(robot).ik``) on any twist of two geared robots (one kernel each)."""
    robot = FIXED[ratios]
    positions = [(0.3, 0.2), (-0.3, -0.2)]
    heading = [h0 + k * u for h0, k in zip((0.4, -0.7), ratios, strict=True)]
    assume(abs(math.sin(heading[0] - heading[1])) > 0.1)
    twist = twist_for(positions, heading, omega)
    speeds = [math.hypot(twist[0] - omega * y, twist[1] + omega * x) for x, y in positions]
    assume(min(speeds) > 1e-3 and abs(speeds[0] - speeds[1]) > 1e-9 * max(speeds) and max(abs(twist)) < 1e3)
    c, got = every_path(robot, twist, current)
    assert c.feasible and gear_turns(robot, got)
