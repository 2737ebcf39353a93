"""Pure pursuit and Stanley on robots whose steering couplings leave one steering degree of freedom
(control/coupled_arcs.py): examples/robots/geared.json (two double wheels at (0.3, 0.2) and (-0.3, -0.2) m geared
1:2, headings ``u`` and ``2 u``) and examples/robots/synchro.yaml (three wheels on a parallel linkage: it only
translates). Before, both laws steered these robots as a car about the virtual axle: a twist admissible to first order
in the turn only, the wheels held off its axles and reported (``held_off_axle``) on every run; the 3 m circle 54 mm
RMS cross-track under pure pursuit, 30 mm under Stanley, the figure-eight 146 mm and 44 mm. Every check here is
against geometry computed from the wheels' positions and headings, not from the laws' own solve."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.control import builtin_reference
from wmrkit.control.coupled_arcs import turn_of_curvature, turn_through
from wmrkit.control.points import control_point
from wmrkit.control.track import track
from wmrkit.control.trackers import EPS_FRACTION

ROBOTS = Path(__file__).parents[2] / "examples" / "robots"
GEARED = Robot.from_file(ROBOTS / "geared.json")
SYNCHRO = Robot.from_file(ROBOTS / "synchro.yaml")
R = 3.0  # the circle's radius [m]; its centre (0, R): it starts at the origin heading along +x


def _lateral(robot: Robot, twist: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """``(n, n_steer)``: each steered wheel's velocity across its heading under `twist` ``(n, 3)`` (rigid body, from
    its position), over the twist's scale (speed of the origin plus turn rate times the robot's reach)."""
    pos = np.array([robot.wheel(w).position for w in robot.steer_names])
    reach = float(np.hypot(*pos.T).max())
    vx = twist[:, :1] - twist[:, 2:] * pos[:, 1]
    vy = twist[:, 1:2] + twist[:, 2:] * pos[:, 0]
    scale = np.hypot(twist[:, 0], twist[:, 1]) + np.abs(twist[:, 2]) * reach
    return (-np.sin(heading) * vx + np.cos(heading) * vy) / np.maximum(scale, 1e-300)[:, None]


def _icr(heading: np.ndarray) -> np.ndarray:
    """The geared units' ICR [m, robot frame] at headings ``(front, rear)``: where their axle lines (through each
    unit, normal to its heading) meet."""
    p, q = np.array([0.3, 0.2]), np.array([-0.3, -0.2])
    a, b = np.array([-math.sin(heading[0]), math.cos(heading[0])]), np.array([-math.sin(heading[1]),
                                                                             math.cos(heading[1])])
    t = np.linalg.solve(np.column_stack([a, -b]), q - p)
    return p + t[0] * a


def _to_world(pose: np.ndarray, p: np.ndarray) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[:2] + np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])


@pytest.mark.parametrize("robot", [GEARED, SYNCHRO], ids=["geared", "synchro"])
@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
def test_the_followers_command_twists_the_coupled_headings_allow(robot, controller):
    """Every commanded twist rolls every steered wheel along its commanded heading (1e-9 relative), so no coupling
    holds a wheel off it: ``held_off_axle`` is empty (before, one report over the whole run)."""
    run = track(robot, builtin_reference("figure-eight", size=3.0), controller=controller, duration=12.0)
    assert np.abs(_lateral(robot, run.twist, run.commanded)).max() <= 1e-9
    assert run.held_off_axle() == [] and run.range_violations() == []


def test_on_the_circle_pure_pursuit_settles_the_geared_units_on_the_turn_whose_icr_is_its_centre():
    """Steady state on the 3 m circle: the turn ``u`` is constant, and the ICR where the units' axle lines meet (at
    the commanded headings ``u``, ``2 u``) is the circle's centre, the axle point 3 m from it (on the path)."""
    run = track(GEARED, builtin_reference("circle", size=R), controller="pure-pursuit", duration=30.0)
    last = run.t >= 25.0
    u = run.commanded[last]
    np.testing.assert_allclose(u[:, 1], 2 * u[:, 0], atol=1e-12)  # on the gear
    assert np.ptp(u[:, 0]) < 1e-5
    icr = _icr(u[-1])
    tracked = run.tracked[-1, :2]
    body = np.linalg.solve([[math.cos(run.pose[-1, 2]), -math.sin(run.pose[-1, 2])],
                            [math.sin(run.pose[-1, 2]), math.cos(run.pose[-1, 2])]], tracked - run.pose[-1, :2])
    assert float(np.hypot(*(body - icr))) == pytest.approx(R, abs=1e-4)
    np.testing.assert_allclose(_to_world(run.pose[-1], icr), [0.0, R], atol=1e-4)
    assert run.cross_track[last].max() < 1e-4


def test_pure_pursuit_drives_the_synchro_drive_straight_at_its_goal():
    """A synchro drive turns no way but its wheels: pure pursuit's circle about the ICR is then the line to the goal.
    On a circle of radius R, the point chasing the goal ``L`` further along it settles where that line is tangent to
    its own circle: radius ``R cos(L / R)``, cross-track ``R (1 - cos(L / R))`` = 6.66 mm at L = 0.2 m (its default
    lookahead, its wheelbase) and R = 3 m (before: 28.5 mm RMS, 115 mm at most)."""
    run = track(SYNCHRO, builtin_reference("circle", size=R), controller="pure-pursuit", duration=30.0,
                lookahead=0.2)
    settled = run.cross_track[run.t >= 10.0]
    assert settled == pytest.approx(R * (1 - math.cos(0.2 / R)), abs=2e-5)
    np.testing.assert_allclose(run.pose[:, 2], 0.0, atol=1e-12)  # it never turns


@pytest.mark.parametrize("robot", [GEARED, SYNCHRO], ids=["geared", "synchro"])
def test_stanley_steers_the_front_point_so_its_cross_track_error_obeys_hoffmanns_law(robot):
    """Stanley sets the direction of its front point's velocity, ``chi - atan(k e / (v + eps))``: on a line its
    cross-track error then obeys ``e' = -v sin(atan(k e / (v + eps)))`` exactly, whatever the coupling does to the
    heading (integrated here on its own, from 0.3 m off)."""
    ref = builtin_reference("line")
    v = float(np.hypot(*ref.velocity[0, :2]))
    eps = EPS_FRACTION * v
    run = track(robot, ref, controller="stanley", duration=8.0, initial_pose=[0.0, 0.3, 0.0])
    e0 = float(run.tracked[0, 1])
    ode = solve_ivp(lambda t, e: -v * np.sin(np.arctan2(e, v + eps)), (0.0, 8.0), [e0], t_eval=run.t, rtol=1e-10,
                    atol=1e-12)
    np.testing.assert_allclose(run.tracked[:, 1], ode.y[0], atol=1e-5)
    assert e0 > 0.2 and abs(run.tracked[-1, 1]) < 0.02


@pytest.mark.parametrize("goal", [(3.0, 0.5), (2.0, -1.0), (1.5, 0.05), (4.0, 2.5), (1.0, -0.6)])
def test_pure_pursuits_turn_puts_the_goal_on_the_circle_the_axle_point_drives(goal):
    """The turn's ICR (from the units' axle lines at ``u``, ``2 u``) is as far from the goal as from the axle point
    (0.9, 0), and the axle point moves towards the goal."""
    cs = control_point(GEARED).coupled
    a, g = np.array([0.9, 0.0]), np.array(goal)
    u = turn_through(cs, a, g)
    icr = _icr(np.array([u, 2 * u]))
    assert float(np.hypot(*(g - icr))) == pytest.approx(float(np.hypot(*(a - icr))), rel=1e-9)
    n = cs.twist_direction(u)[0]
    assert np.array([n[0], n[1] + a[0] * n[2]]) @ (g - a) > 0


@pytest.mark.parametrize("kappa", [0.8, -0.5, 0.1, -1e-3])
def test_a_turn_of_curvature_puts_the_icr_its_radius_from_the_axle_point(kappa):
    """Pure pursuit turning round to a goal behind: the axle point's circle about the ICR (from the axle lines) has
    radius ``1 / |kappa|``, on the side of its sign (left positive, driving forward)."""
    cs = control_point(GEARED).coupled
    a = np.array([0.9, 0.0])
    u = turn_of_curvature(cs, a, kappa)
    icr = _icr(np.array([u, 2 * u]))
    assert float(np.hypot(*(icr - a))) == pytest.approx(1 / abs(kappa), rel=1e-9)
    assert math.copysign(1.0, icr[1]) == math.copysign(1.0, kappa)


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
def test_the_followers_track_the_geared_units_closer_than_as_a_car(controller):
    """Whole runs of the 3 m circle and figure-eight: RMS cross-track below what steering them as a car about their
    virtual axle gave (54 and 146 mm under pure pursuit, 30 and 44 mm under Stanley), without a report."""
    before = {"pure-pursuit": (0.054, 0.146), "stanley": (0.030, 0.044)}[controller]
    for shape, was in zip(("circle", "figure-eight"), before, strict=True):
        run = track(GEARED, builtin_reference(shape, size=R), controller=controller)
        assert math.sqrt(float(np.mean(run.cross_track ** 2))) < was
        assert run.held_off_axle() == []


@pytest.mark.parametrize("controller", ["pure-pursuit", "stanley"])
def test_track_cli_drives_the_geared_units_with_the_followers_without_a_report(controller, capsys):
    assert main(["track", str(ROBOTS / "geared.json"), "--controller", controller, "--reference", "circle",
                 "--size", "3", "--duration", "5", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["held_off_axle"] == [] and not [w for w in answer["warnings"] if "held wheels" in w]
    assert answer["summary"]["max_cross_track"] < 0.02
