"""The reduced control point of a robot whose steering couplings leave one steering degree of freedom
(control/coupled_point.py): examples/robots/geared.json, two double wheels at (0.3, 0.2) and (-0.3, -0.2) whose
steering a gear turns 1:2 (headings ``u`` and ``2 u``), and the synchro drive (three wheels on a parallel linkage).
Before, the law commanded a full twist the geared headings do not allow: the 3 m circle ended 0.457 m off, the
corner 0.38 m off, each with "held off axle"."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from wmrkit import Robot, catalog
from wmrkit.analysis.lines import constraint_lines
from wmrkit.control import builtin_reference
from wmrkit.control.points import ControlError, control_point
from wmrkit.control.tick import control_tick
from wmrkit.control.track import track

ROBOTS = Path(__file__).parents[2] / "examples" / "robots"
GEARED = Robot.from_file(ROBOTS / "geared.json")
FRONT, REAR = np.array([0.3, 0.2]), np.array([-0.3, -0.2])


def _wheel_velocity(twist: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Rigid body: ``v + omega z x p``."""
    return np.array([twist[0] - twist[2] * p[1], twist[1] + twist[2] * p[0]])


def test_the_geared_units_reduce_to_a_point_ahead_of_their_virtual_axle():
    """Near straight driving (u -> 0) the twist is ``(1, 3u/2, -5u/3)`` to first order (the cross product of the
    two lateral rows ``(-sin h, cos h, x cos h + y sin h)`` at ``h = u`` and ``2 u``), so the ICR ``(-vy / omega, vx
    / omega)`` tends to the line x = 0.9: the virtual axle. The default point is ahead of it by the robot's size,
    the wheels' distance sqrt(0.13) m."""
    cp = control_point(GEARED)
    assert cp.reduced and cp.coupled is not None and cp.gain is None
    np.testing.assert_allclose(cp.point, [0.9 + math.sqrt(0.13), 0.0], atol=1e-12)
    np.testing.assert_allclose(cp.axle_point, [0.9, 0.0], atol=1e-12)
    assert cp.forward == pytest.approx(0.0, abs=1e-12)
    for u in (1e-4, -1e-4):
        n = cp.coupled.twist_direction(u)[0]
        assert -n[1] / n[2] == pytest.approx(0.9, abs=1e-3) and n[2] / n[0] == pytest.approx(-5 * u / 3, rel=1e-3)


@pytest.mark.parametrize("speed", [0.7, 1e-3])
def test_the_commanded_twist_is_admissible_and_moves_the_point_as_asked(speed):
    """Any wanted velocity of the point (24 directions): the twist rolls both units along their geared headings
    (``u`` and ``2 u``: lateral velocity 0 to 1e-9) and moves the point with the wanted velocity."""
    cs = control_point(GEARED).coupled
    for a in np.linspace(-math.pi, math.pi, 24, endpoint=False):
        want = speed * np.array([math.cos(a), math.sin(a)])
        s, u, _ = cs.solve(want)
        twist = cs.twist(want)
        for p, h in ((FRONT, u), (REAR, 2 * u)):
            lateral = _wheel_velocity(twist, p) @ np.array([-math.sin(h), math.cos(h)])
            assert abs(lateral) <= 1e-9 * speed
        np.testing.assert_allclose(_wheel_velocity(twist, cs.point), want, atol=1e-9 * speed)
        assert (s < 0) == (abs(a) > math.radians(100))  # behind the branch's arc: backwards


def test_the_point_velocity_map_has_its_jacobian():
    """``point_velocity(s, u)``'s Jacobian against central differences (step 1e-6)."""
    cs = control_point(GEARED).coupled
    h = 1e-6
    for s, u in ((1.0, 0.0), (0.5, 0.4), (-1.2, -0.6), (2.0, 1.1)):
        _, jac = cs.point_velocity(s, u)
        ds = (cs.point_velocity(s + h, u)[0] - cs.point_velocity(s - h, u)[0]) / (2 * h)
        du = (cs.point_velocity(s, u + h)[0] - cs.point_velocity(s, u - h)[0]) / (2 * h)
        np.testing.assert_allclose(jac, np.column_stack([ds, du]), atol=1e-8)


def test_the_point_error_decays_as_the_p_law_sets_it():
    """From 4 m off the 3 m circle: the point's error is ``e(0) exp(-t)`` (gain 1) to 1e-7 m, since the twist gives
    it the law's velocity exactly (backwards where the law asks, as it does at first)."""
    run = track(GEARED, builtin_reference("circle", size=3.0), initial_pose=[3.3, 0.4, 1.2], duration=8.0)
    assert run.error[0] > 4.0
    np.testing.assert_allclose(run.error, run.error[0] * np.exp(-run.t), atol=1e-7, rtol=0)


def _icr(u: float) -> np.ndarray:
    """Where the units' axles at headings ``u`` and ``2 u`` meet."""
    d1, d2 = np.array([-math.sin(u), math.cos(u)]), np.array([-math.sin(2 * u), math.cos(2 * u)])
    a, _ = np.linalg.solve(np.column_stack([d1, -d2]), REAR - FRONT)
    return FRONT + a * d1


def test_the_heading_settles_where_the_circle_centre_is_the_gears_icr():
    """The heading (the zero dynamics) is stable ahead of the virtual axle. Once settled on the circle (radius 3 m),
    the robot turns about its centre, so the centre is the ICR of the gear's turn at which the point is 3 m from it
    (closed form from the axles' intersection), and the robot's heading lags the circle's tangent by the angle of the
    point's velocity ``z x (P - ICR)`` in the robot: 0.17306 rad. It settles there within 14 s from the tangent."""
    cp = control_point(GEARED)
    u = brentq(lambda v: float(np.hypot(*(cp.point - _icr(v)))) - 3.0, -0.2, -0.1)
    r = cp.point - _icr(u)
    lag = math.atan2(r[0], -r[1])
    reference = builtin_reference("circle", size=3.0)
    run = track(GEARED, reference, duration=14.0)
    assert math.remainder(float(reference.sample(run.t[-1:])[0, 2] - run.pose[-1, 2]), 2 * math.pi) == pytest.approx(
        lag, abs=1e-4)
    assert lag == pytest.approx(0.17306, abs=1e-5)


def test_the_corner_is_tracked_and_the_synchro_drive_follows_a_circle():
    """The corner (3 m legs): before 0.38 m off at its end, now within 1e-8 m throughout; the synchro drive (it only
    translates: P's velocity is ``s (cos u, sin u)``) tracks a circle with its heading fixed (before 0.065 m off)."""
    run = track(GEARED, builtin_reference("corner", size=3.0))
    assert run.summary()["max_error"] < 1e-8 and run.held_off_axle() == []
    synchro = Robot.from_file(ROBOTS / "synchro.yaml")
    run = track(synchro, builtin_reference("circle", size=3.0), duration=5.0)
    assert run.summary()["max_error"] < 1e-8 and np.ptp(run.pose[:, 2]) < 1e-12


def test_the_car_and_the_full_pose_robots_keep_their_control_points():
    for name in ("ackermann", "forklift", "swerve-4", "mecanum-4"):
        assert control_point(catalog.load(name)).coupled is None


def test_a_point_on_the_virtual_axle_is_refused():
    with pytest.raises(ControlError, match="lies on the virtual axle"):
        track(GEARED, builtin_reference("line"), point=(0.9, 0.0), duration=1.0)
    with pytest.raises(ControlError, match="lies on the virtual axle"):
        control_tick(GEARED, point=(0.9, 0.0))


def test_a_turn_beyond_the_steering_ranges_is_held_at_their_end_and_reported():
    """Units geared 1:2 within +-0.3 rad each (the front within +-0.15 rad, where the rear fits): the 3 m circle needs
    the front at -0.160 rad (closed form above), so the keeper holds it at -0.15 rad and reports it, as the car's
    wheels at their stops; the law is not cut at the ranges (it would miss the circle without a word)."""
    data = GEARED.to_dict()
    for wheel in data["wheels"]:
        wheel["steer_range"] = [-0.3, 0.3]
    robot = Robot.from_dict(data)
    run = track(robot, builtin_reference("circle", size=3.0), duration=5.0)
    front = run.range_violations()[0]
    assert front["wheel"] == "front" and front["held_by"] == "gear(front.steer, rear.steer)"
    assert front["headings"] == pytest.approx([-0.15, -0.15], abs=1e-12) and front["to"] == 5.0


@pytest.mark.parametrize("path", ["geared.json", "synchro.yaml"])
def test_the_lines_turned_about_their_pivots_are_the_constraint_lines_at_the_coupled_headings(path):
    """The solver turns the lines at u = 0 about their wheels' pivots by ``ratio u`` (control/coupled_solve.py);
    the constraint lines (6.18) computed from the coupled headings (``wheel rows`` at each turn) are the same."""
    robot = Robot.from_file(ROBOTS / path)
    cs = control_point(robot).coupled
    lines = constraint_lines(robot)
    for u in (-2.5, -0.7, 0.0, 0.3, 1.1, 3.0):
        np.testing.assert_allclose(cs.lines(u), lines.lines(robot.steering(heading=cs.headings(u))), atol=1e-14)


def test_two_steered_wheels_on_a_linkage_give_their_two_lines_a_null_twist():
    """Two steerable wheels on a parallel linkage (a two-wheel synchro drive) have two constraint lines: their
    one-dimensional null space was missed (the SVD of two rows has two singular values, both nonzero), so the
    robot kept the full pose its wheels cannot give (0.28 m off the 3 m circle); now its point tracks it."""
    unit = {"type": "steerable", "heading": 0.0, "r": 0.08}
    robot = Robot.from_dict({"name": "two", "wheels": [{**unit, "name": "f", "position": [0.3, 0.2]},
                                                        {**unit, "name": "b", "position": [-0.3, -0.2]}],
                             "couplings": [{"kind": "linkage", "joints": ["f.steer", "b.steer"]}]})
    assert control_point(robot).coupled is not None
    run = track(robot, builtin_reference("circle", size=3.0), duration=5.0)
    assert run.summary()["max_error"] < 1e-8 and np.ptp(run.pose[:, 2]) < 1e-12
