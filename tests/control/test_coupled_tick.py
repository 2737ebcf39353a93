"""The single-call tick (control/tick.py) of robots whose steering couplings leave one steering degree of freedom:
the law of control/coupled_point.py, its Newton solve compiled from control/coupled_solve.py (the functions the
Python path runs). Before, ``control_tick`` refused them ("not compiled") unless reduced=False (blind to the
couplings). The geared units (examples/robots/geared.json: double wheels steered 1:2) and the synchro drive."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq
from test_coupled_point import _icr

from wmrkit import Robot
from wmrkit.control import builtin_reference
from wmrkit.control.laws import PositionLaw
from wmrkit.control.points import control_point, point_pose
from wmrkit.control.tick import control_tick, scalar_law
from wmrkit.control.track import initial_pose_on
from wmrkit.kinematics.wheel_ik import wheel_commands

ROBOTS = Path(__file__).parents[2] / "examples" / "robots"
GEARED = Robot.from_file(ROBOTS / "geared.json")
SYNCHRO = Robot.from_file(ROBOTS / "synchro.yaml")


def _cases(rng: np.random.Generator) -> list[tuple[float, ...]]:
    """Poses, references and their velocities: at rest on the reference, a reference behind the robot (driven
    backwards), far to its side (beyond the branch's arc: its end held), and random ones."""
    cases = [(0.0,) * 9, (0.5, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, -0.1, 3.0, 0.0, 0.0, 0.0, 0.0)]
    for _ in range(30):
        pose, ref = rng.normal(0.0, 1.0, 3), rng.normal(0.0, 1.0, 3)
        cases.append((*pose, *ref, *rng.normal(0.0, 0.5, 3)))
    return cases


@pytest.mark.parametrize("robot", [GEARED, SYNCHRO], ids=["geared", "synchro"])
def test_the_compiled_tick_gives_the_python_law_and_its_wheel_commands(robot):
    """Same inputs, same twist to 1e-12 as the Python law (``scalar_law``, :class:`CoupledSteering`), and the rates
    ``wheel_commands`` gives for it: a feasible command (the twist rolls every wheel at the coupled headings)."""
    cp = control_point(robot)
    law = PositionLaw.uniform("p", 0.8, gate=0.5)
    tick, python = control_tick(robot, law).tick, scalar_law(cp, law)
    twist, rates = np.zeros(3), np.zeros(len(robot.rate_names))
    heading, out = np.array(robot.heading, dtype=float), np.zeros(len(robot.steer_names))
    for case in _cases(np.random.default_rng(5)):
        assert tick(*case, heading, twist, rates, out)
        want = np.array(python(*case, 0.0, 0.0, 0.0)[:3], dtype=float)
        np.testing.assert_allclose(twist, want, atol=1e-12, rtol=0)
        np.testing.assert_allclose(twist, cp.coupled.twist(_point_velocity(cp, case, law)), atol=1e-12, rtol=0)
        batched = wheel_commands(robot, want, robot.beta_of_heading(heading))
        np.testing.assert_allclose(rates, batched.rates, atol=1e-9)
        assert bool(batched.feasible)


def _point_velocity(cp, case, law) -> np.ndarray:
    """The law (8.2)/(8.53) written out: the reference's velocity (within the gate) plus ``a e``, in the robot frame."""
    x, y, theta, xr, yr, _, vxr, vyr, _ = case
    e = np.array([xr, yr]) - point_pose(cp, [x, y, theta])[:2]
    v = np.array(law.a[:2]) * e + (np.array([vxr, vyr]) if np.hypot(*e) <= law.gate else 0.0)
    c, s = math.cos(theta), math.sin(theta)
    return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])


def _run(robot: Robot, pose: np.ndarray, duration: float, dt: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """A closed loop on the 3 m circle through the tick every `dt`, each twist held over its period (the pose moved
    along its arc exactly): the point's error at each tick and the last pose."""
    cp, tick, ref = control_point(robot), control_tick(robot).tick, builtin_reference("circle", size=3.0)
    twist, rates = np.zeros(3), np.zeros(len(robot.rate_names))
    heading, out = np.array(robot.heading, dtype=float), np.zeros(len(robot.steer_names))
    errors = []
    for k in range(round(duration / dt)):
        p, v = ref.at(k * dt)
        tick(*pose.tolist(), *p.tolist(), *v.tolist(), heading, twist, rates, out)
        heading[:] = out
        errors.append(float(np.hypot(*(point_pose(cp, pose)[:2] - p[:2]))))
        vx, vy, w = (twist * dt).tolist()
        a, b = (math.sin(w) / w, (1.0 - math.cos(w)) / w) if w else (1.0, 0.0)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        dx, dy = a * vx - b * vy, b * vx + a * vy
        pose = pose + np.array([c * dx - s * dy, s * dx + c * dy, w])
    return np.array(errors), pose


def test_a_closed_loop_through_the_tick_tracks_the_circle():
    """From 4 m off the 3 m circle the point's error decays as the sampled P law sets it, ``e(0) (1 - dt)^k`` (the
    twist gives the point the law's velocity exactly) to 1e-3 relative over 4 s; from on it, the heading settles
    where the circle's centre is the gear's ICR, 0.17306 rad behind the tangent (closed form of
    test_coupled_point), to 1e-5 rad after 14 s."""
    errors, _ = _run(GEARED, np.array([3.3, 0.4, 1.2]), 4.0)
    assert errors[0] > 4.0
    np.testing.assert_allclose(errors, errors[0] * (1 - 1e-3) ** np.arange(len(errors)), rtol=1e-3)
    cp, ref = control_point(GEARED), builtin_reference("circle", size=3.0)
    _, pose = _run(GEARED, np.array(initial_pose_on(cp, ref), dtype=float), 14.0)
    r = cp.point - _icr(brentq(lambda v: float(np.hypot(*(cp.point - _icr(v)))) - 3.0, -0.2, -0.1))
    lag = math.remainder(float(ref.at(14.0)[0][2] - pose[2]), 2 * math.pi)
    assert lag == pytest.approx(math.atan2(r[0], -r[1]), abs=1e-5)
