"""Extended solutions (thesis §4.5) judge the held linkages as ``ik`` and ``fk`` do (kinematics/linkage_check.py).

Before: ``no_slip_extended_solution`` gave each steerable wheel its own angle and ignored linkages, so a synchro
drive (one ``parallel`` linkage of all its wheels) assigned the turn (vx, vy, omega) = (1, 0, 0.5) came back with
three different headings, zero slip and every ``in_gear`` True (consistent), silently; and ``extended_solution`` at
headings off a car's Ackermann law with the rear spins at rest said slip 0, consistent. Angles found for the assigned
velocities are judged as ``ik`` judges its angles for a twist; given angles as ``fk`` judges given headings. The
references: brute force (the steering axes' velocities parallel), the ICR geometry, ``wheel_commands``' verdict on
random twists and ``forward_kinematics_check``'s on random headings.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.kinematics.extended import extended_solution, no_slip_extended_solution, solve_steering
from wmrkit.kinematics.linkage_check import LinkageAngleWarning
from wmrkit.kinematics.wheel_ik import forward_kinematics_check, wheel_commands

from .test_linkage_doors import linked_robots, twists
from .test_linkage_ik import TRIANGLE, all_parallel, synchro

TWIST = ["vx", "vy", "omega"]


def said(call):
    """`call`'s result and the messages of its LinkageAngleWarnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = call()
    return out, [str(w.message) for w in caught if issubclass(w.category, LinkageAngleWarning)]


def test_a_synchro_drive_assigned_a_turn_breaks_its_linkage_and_the_linkage_is_named():
    robot = synchro()
    assert not all_parallel(TRIANGLE, (1.0, 0.0, 0.5), 1e-3)  # brute force: the wheels cannot all be parallel
    sol, msgs = said(lambda: no_slip_extended_solution(robot, TWIST, [1.0, 0.0, 0.5]))
    assert float(sol.slip) < 1e-9 and sol.in_gear.all()  # each wheel its own angle: no slip, as before
    assert sol.in_linkage.tolist() == [False] and sol.as_dict()["in_linkage"] == [False]
    assert len(msgs) == 1 and msgs[0].startswith(
        "a steering linkage cannot set these headings: the steering linkage of wheels 'w0', 'w1' and 'w2' (law "
        "parallel) sets w0 at heading -2.63485 deg with w2 at -2.63485 deg, not 5.71059 deg")
    assert said(lambda: solve_steering(robot, TWIST, [1.0, 0.0, 0.5]))[1] == msgs  # the angles alone say it too
    straight, msgs = said(lambda: no_slip_extended_solution(robot, TWIST, [1.0, 0.3, 0.0]))
    assert all_parallel(TRIANGLE, (1.0, 0.3, 0.0), 1e-12)
    assert straight.in_linkage.tolist() == [True] and msgs == []


def ackermann_headings(front_left_deg: float) -> tuple[float, float]:
    """The catalog car (wheelbase 2.70 m, track 1.55 m, rear axle x = 0): front_right's heading [deg] whose axle meets
    front_left's on the rear axle line, from the ICR (not from the law's formula)."""
    icr = 0.775 + 2.70 / math.tan(math.radians(front_left_deg))
    return front_left_deg, math.degrees(math.atan(2.70 / (icr + 0.775)))  # a wheel points ahead: mod 180 deg


def test_a_car_at_headings_off_its_ackermann_law_is_not_consistent_though_nothing_slips():
    robot = catalog.load("ackermann")
    fl, fr = ackermann_headings(20.0)
    rear = ["rear_left.spin", "rear_right.spin"]
    sol, msgs = said(lambda: extended_solution(robot, rear, [0.0, 0.0], heading=np.radians([fl, fr + 5.0])))
    assert float(sol.slip) == 0.0 and sol.in_gear.all()  # at rest nothing slips: before, this was consistent
    assert sol.in_linkage.tolist() == [True, False]  # the differential, the linkage
    assert len(msgs) == 1 and msgs[0].startswith(
        "the headings break a steering linkage: the steering linkage of wheels 'front_left' and 'front_right' (law "
        f"ackermann) sets front_right at heading {fr:.6g} deg with front_left at 20 deg, not {fr + 5.0:.6g} deg")
    sol, msgs = said(lambda: extended_solution(robot, rear, [0.0, 0.0], heading=np.radians([fl, fr])))
    assert sol.in_linkage.tolist() == [True, True] and msgs == []


def test_given_angles_are_judged_as_fk_judges_them_on_random_headings():
    """A batch of headings: front_right off the Ackermann angle by up to 3 deg; broken iff more than asin(0.02)."""
    robot = catalog.load("ackermann")
    rng = np.random.default_rng(3)
    left = rng.uniform(-40.0, 40.0, 60)
    left = left[np.abs(left) > 1.0]
    off = rng.uniform(-3.0, 3.0, len(left))
    keep = np.abs(np.abs(off) - math.degrees(math.asin(0.02))) > 1e-3  # not at the tolerance itself
    heads = np.array([[a, ackermann_headings(a)[1] + e] for a, e in zip(left[keep], off[keep], strict=True)])
    rates = rng.uniform(-5.0, 5.0, (len(heads), 2))
    sol, msgs = said(lambda: extended_solution(robot, ["rear_left.spin", "rear_right.spin"], rates,
                                               heading=np.radians(heads)))
    expected = np.abs(off[keep]) > math.degrees(math.asin(0.02))
    assert expected.any() and not expected.all()
    np.testing.assert_array_equal(sol.in_linkage, np.c_[np.ones_like(expected), ~expected])
    assert len(msgs) == 1  # the first row that breaks it, as a gear's warning
    for h, r, ok in zip(heads, rates, sol.in_linkage[:, 1], strict=True):
        fk, _ = said(lambda h=h, r=r: forward_kinematics_check(
            robot, {"rear_left.spin": r[0], "rear_right.spin": r[1]}, heading=np.radians(h)))
        assert (fk.out_of_linkage == ()) == ok


@pytest.mark.parametrize("index", range(5))
def test_found_angles_are_judged_as_ik_judges_its_angles_on_random_twists(index):
    """The catalog car, synchro drives (one with rest headings apart), a random car: for every twist the fixed wheels
    roll with, the extended solution assigned it (its velocities among vx, vy, omega: as many as extended_dof)
    says in_linkage as wheel_commands does."""
    robot = linked_robots()[index]
    rng = np.random.default_rng(index)
    asked = twists(robot, rng)
    ik = wheel_commands(robot, asked)
    rolls = np.all(ik.slip == 0.0, axis=-1)
    asked = asked[rolls]
    assigned = TWIST if not any(w.type == "fixed" for w in robot.wheels) else ["vx", "omega"]
    sol, _ = said(lambda: no_slip_extended_solution(robot, assigned, asked[:, [TWIST.index(n) for n in assigned]]))
    np.testing.assert_allclose(sol.q_dot[:, :3], asked, atol=1e-9)  # the solution is the asked twist
    assert np.all(sol.slip < 1e-9)
    np.testing.assert_array_equal(sol.in_linkage, ik.in_linkage[rolls])
    if robot.name == "synchro" and len(robot.wheels) == 3:
        assert not sol.in_linkage.all() and sol.in_linkage.any()
