"""The closed loop through the dynamics (issue 11 item 7) on its fast path: the scalar law equals law_controller,
and simulate_dynamics equals a plain loop over the public stepping API of the simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control import builtin_reference, control_point, track
from wmrkit.control.dynamic_plant import fast_law_controller, simulate_dynamics
from wmrkit.control.laws import PositionLaw
from wmrkit.control.loop import law_controller
from wmrkit.control.track import initial_pose_on
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import twist_program
from wmrkit.dynamics.simulate import Stepper, initial_state

LAWS = [PositionLaw.uniform("p", 0.7), PositionLaw.uniform("p", 0.7, gate=0.2),
        PositionLaw("pi", (0.5, 0.6, 0.7), (0.06, 0.09, 0.1)), PositionLaw.uniform("point", 0.4)]


@pytest.mark.parametrize("name", ["forklift", "swerve-4", "diff-drive"])  # reduced, full, reduced (skid-free)
@settings(max_examples=100, deadline=None)
@given(k=st.integers(0, 10_000), dx=st.floats(-2, 2), dy=st.floats(-2, 2), dth=st.floats(-7, 7),
       integral=st.lists(st.floats(-3, 3), min_size=3, max_size=3), law=st.sampled_from(LAWS))
def test_fast_law_controller_equals_law_controller(name, k, dx, dy, dth, integral, law):
    robot = catalog.load(name)
    ref = builtin_reference("figure-eight")
    cp = control_point(robot)
    t = float(ref.t[k % len(ref.t)]) * 0.999 + 0.003 * (k % 7)  # between samples too
    pose = ref.pose[k % len(ref.t)] + np.array([dx, dy, dth])
    want_twist, want_e = law_controller(cp, law, ref)(t, pose, np.array(integral))
    twist, e = fast_law_controller(cp, law, ref)(t, pose, np.array(integral))
    np.testing.assert_allclose(twist, want_twist, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(e[:2], want_e[:2], rtol=1e-12, atol=1e-12)
    assert math.remainder(e[2] - want_e[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


def _plain_loop(robot, controller, pose0, duration, period, delay):
    """The reference: the loop written with the public API only (twist_program + Stepper.advance each period),
    starting at `pose0` rolling at the law's first command."""
    model = DynamicModel.of(robot)
    stepper = Stepper(model, initial_state(model, controller(0.0, pose0.copy(), np.zeros(3))[0], pose0), step=1e-3)
    n = math.floor(duration / period + 1e-9) + 1
    history, integral, poses, twists, betas, targets = [pose0.copy()], np.zeros(3), [], [], [], []
    steer = list(model.steer_columns)
    for k in range(n):
        twist, de = controller(k * period, history[max(0, k - delay)], integral)
        integral = integral + period * de
        inputs = twist_program(model, [k * period], [twist])
        poses.append(stepper.state[:3].copy())
        twists.append(twist)
        betas.append(stepper.state[steer].copy())
        targets.append(robot.beta_of_heading(inputs.heading_reference[0]))
        if k < n - 1:
            stepper.advance(inputs, period)
            history.append(stepper.state[:3].copy())
    return {"pose": np.array(poses), "twist": np.array(twists), "beta": np.array(betas), "target": np.array(targets)}


@pytest.mark.parametrize(("law", "delay"), [(PositionLaw.uniform("p", 0.5), 0), (PositionLaw("pi", (0.5,) * 3,
                                                                                             (0.06,) * 3), 1)])
def test_simulate_dynamics_equals_a_plain_loop_over_the_stepping_api(law, delay):
    fork = catalog.load("forklift")
    ref = builtin_reference("figure-eight")
    cp = control_point(fork)
    pose0 = initial_pose_on(cp, ref) + np.array([0.0, 0.2, 0.05])
    want = _plain_loop(fork, law_controller(cp, law, ref), pose0, 4.0, 0.02, delay)
    got = simulate_dynamics(fork, fast_law_controller(cp, law, ref), pose0, 4.0, period=0.02, delay=delay)
    assert len(got["t"]) == len(want["pose"]) == 201
    for key in ("pose", "twist", "beta", "target"):
        np.testing.assert_allclose(got[key], want[key], rtol=0, atol=1e-9, err_msg=key)
    assert np.abs(got["pose"][-1] - got["pose"][0]).max() > 1.0  # it went somewhere


def test_track_with_dynamics_runs_the_fast_law_and_the_generic_controller_alike():
    """``track(..., dynamics=True)`` (what ``wmrkit track --dynamics`` calls) gives the run of the generic
    controller closure; pure pursuit goes through the same loop."""
    fork = catalog.load("forklift")
    ref = builtin_reference("circle")
    run = track(fork, ref, initial_pose=[0.0, 0.3, 0.0], duration=3.0, dynamics=True, gain=0.6)
    cp = control_point(fork)
    generic = simulate_dynamics(fork, law_controller(cp, PositionLaw.uniform("p", 0.6), ref),
                                np.array([0.0, 0.3, 0.0]), 3.0, period=0.02)
    np.testing.assert_allclose(run.pose, generic["pose"], rtol=0, atol=1e-9)
    pp = track(fork, ref, controller="pure-pursuit", duration=3.0, dynamics=True)
    kin = track(fork, ref, controller="pure-pursuit", duration=3.0, period=0.02)
    assert np.abs(pp.cross_track - kin.cross_track).max() < 0.05  # close to the ideal kinematic loop


def test_simulate_dynamics_refuses_bad_arguments():
    from wmrkit.control.points import ControlError

    fork = catalog.load("forklift")
    ctrl = fast_law_controller(control_point(fork), PositionLaw(), builtin_reference("line"))
    with pytest.raises(ControlError, match="period"):
        simulate_dynamics(fork, ctrl, np.zeros(3), 1.0, period=1e-4)
    with pytest.raises(ControlError, match="delay"):
        simulate_dynamics(fork, ctrl, np.zeros(3), 1.0, period=0.02, delay=-1)
