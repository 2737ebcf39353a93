"""The continuous loop's fast paths (the compiled nearest-segment search, the plain-float steering targets and castor
rates) against closed forms and another method: Stanley's cross-track error on a line obeys its scalar ODE, pure
pursuit holds a circle it starts on and reaches one it starts off (its steady state is the path's radius), and the
castors' steering rates are the batched IK's. (The P law's ``e(0) exp(-a t)`` on the diff-drive with its castor and
the forklift: ``test_loop.py``.)"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wmrkit import catalog
from wmrkit.control import builtin_reference, control_point, track
from wmrkit.control.trackers import EPS_FRACTION, default_wheelbase
from wmrkit.kinematics import _ik_fast
from wmrkit.kinematics.loop_ik import checked_castor_rates
from wmrkit.kinematics.wheel_ik import wheel_commands


def test_stanley_s_cross_track_error_on_a_line_obeys_its_ode():
    """Stanley drives its front point ``F`` at the path's speed ``v`` in the direction ``chi - atan(k e / (v +
    eps))`` (unclipped), so on the x axis ``e' = -v sin(atan(k e / (v + eps)))``: the run's ``y_F`` against that ODE
    integrated to 1e-12 (1.9e-8 m apart; the loop's tolerance is rtol 1e-5), until ``F`` is within its stopping
    length of the end (where it slows); it ends at the end, on the line."""
    robot, ref, k, v = catalog.load("diff-drive"), builtin_reference("line"), 1.0, 0.5
    run = track(robot, ref, controller="stanley", stanley_gain=k, initial_pose=[0.0, 0.3, 0.0])
    eps = EPS_FRACTION * v
    ode = solve_ivp(lambda _t, e: [-v * math.sin(math.atan(k * e[0] / (v + eps)))], (0.0, float(run.t[-1])),
                    [float(run.tracked[0, 1])], rtol=1e-12, atol=1e-14, dense_output=True)
    stopping = max(default_wheelbase(control_point(robot)), 2.0 * v)  # min_length: 2 s at the top speed
    before = run.tracked[:, 0] < 10.0 - stopping
    assert before.sum() > 300
    assert np.max(np.abs(run.tracked[before, 1] - ode.sol(run.t[before])[0])) < 1e-6
    assert abs(run.tracked[-1, 0] - 10.0) < 0.1 * stopping and abs(run.tracked[-1, 1]) < 1e-6


@pytest.mark.parametrize("offset", [0.0, -0.3])
def test_pure_pursuit_holds_and_reaches_a_circle(offset):
    """On a circle of radius ``R``, an axle point at radius ``r`` aiming at the path point a lookahead ``L`` ahead
    turns at ``2 y_g / L_g^2``, which is ``1 / r`` only at ``r = R``: started on the circle (the default pose) its
    radius stays ``R`` (to 1e-5 m: the path is a polyline of 5 mm chords), started 0.3 m inside it ends on it."""
    robot, ref = catalog.load("diff-drive"), builtin_reference("circle")  # radius 3 m about (0, 3)
    run = track(robot, ref, controller="pure-pursuit", initial_pose=None if offset == 0 else [0.0, -offset, 0.0])
    radius = np.hypot(run.tracked[:, 0], run.tracked[:, 1] - 3.0)
    if offset == 0:
        assert np.max(np.abs(radius - 3.0)) < 1e-5
    else:
        assert abs(radius[0] - 3.0) == pytest.approx(0.3) and np.max(np.abs(radius[-40:] - 3.0)) < 1e-5


@pytest.mark.parametrize("name", ["diff-drive", "thesis-omni-castor", "thesis-two-steer-castor"])
def test_castor_rates_in_plain_floats_are_the_batched_ik_s(name):
    """:func:`checked_castor_rates` against :func:`wheel_commands` (its numpy batch) on random twists and angles."""
    robot = catalog.load(name)
    p = _ik_fast.plan(robot)
    castors = [n for n in robot.steer_names if robot.wheel(n).type in ("castor", "double_castor")]
    columns = [robot.rate_names.index(f"{n}.steer") for n in castors]
    elements = [p.element_steer_col.tolist().index(c) for c in columns]
    rng = np.random.default_rng(3)
    twist, beta = rng.normal(size=(50, 3)), rng.uniform(-4, 4, size=(50, len(robot.steer_names)))
    expected = np.asarray(wheel_commands(robot, twist, beta).rates)[:, columns]
    got = np.array([checked_castor_rates(robot, t, b, elements) for t, b in zip(twist, beta, strict=True)])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
