"""The public stepping API of the simulator: ``Stepper`` and ``advance`` continue a run from its full state."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import feasible_twists, path_program, twist_program
from wmrkit.dynamics.simulate import Stepper, advance, initial_state, simulate
from wmrkit.errors import ShapeError, WmrkitError


@pytest.fixture(scope="module")
def forklift():
    model = DynamicModel.of(catalog.load("forklift"), "pacejka")
    inputs, _ = path_program(model, "turn", speed=2.0)
    return model, inputs


def _final_state(sim) -> np.ndarray:
    """The full state (pose, joint positions, velocities) of a Simulation's last sample."""
    return np.concatenate([sim.pose[-1], sim.joint_positions[-1], sim.twist[-1], sim.joint_rates[-1]])


@pytest.mark.parametrize(("pieces", "jac_every"), [((0.137, 0.25, 0.613, 0.5, 0.5), 20),
                                                    ((0.001, 0.019, 0.98, 0.2, 0.3, 0.5), 7)])
def test_stepper_pieces_equal_simulate(forklift, pieces, jac_every):
    model, inputs = forklift
    duration = sum(pieces)
    whole = simulate(model, inputs, duration, step=1e-3, record_step=0.1, jac_every=jac_every)
    stepper = Stepper(model, step=1e-3, jac_every=jac_every)
    for piece in pieces:
        stepper.advance(inputs, piece)
    assert stepper.t == pytest.approx(duration, abs=1e-12)
    np.testing.assert_array_equal(stepper.state, _final_state(whole))  # bit for bit


def test_stepper_rk4_pieces_equal_simulate(forklift):
    model, inputs = forklift
    whole = simulate(model, inputs, 0.3, step=1e-4, method="rk4", record_step=0.1)
    stepper = Stepper(model, step=1e-4, method="rk4")
    for piece in (0.1, 0.05, 0.15):
        stepper.advance(inputs, piece)
    np.testing.assert_array_equal(stepper.state, _final_state(whole))


def test_advance_is_pure_and_equals_a_fresh_simulation(forklift):
    model, _ = forklift  # a program that starts at the initial speed (braking from it at the grip would tip the truck)
    twists = feasible_twists(model, [(1.0, 0.0, 0.0), (1.0, 0.0, 0.1), (1.2, 0.0, 0.2)])
    inputs = twist_program(model, [0.0, 0.5, 1.0], twists)
    s0 = initial_state(model, (1.0, 0.0, 0.0), (1.0, -2.0, 0.3))
    before = s0.copy()
    out = advance(model, s0, inputs, 0.8)
    np.testing.assert_array_equal(s0, before)
    whole = simulate(model, inputs, 0.8, initial_twist=(1.0, 0.0, 0.0), initial_pose=(1.0, -2.0, 0.3))
    np.testing.assert_array_equal(out, _final_state(whole))


def test_stepper_writes_into_the_callers_state_and_held_inputs(forklift):
    model, _ = forklift
    state = initial_state(model)
    stepper = Stepper(model, state)
    assert stepper.state is state
    stepper.advance(twist_program(model, [0.0], [(1.0, 0.0, 0.0)]), 2.0)  # one knot: held
    assert stepper.state is state and stepper.t == pytest.approx(2.0)
    assert state[model.n] == pytest.approx(1.0, abs=0.05)  # the rate servos brought it to about 1 m/s
    stepper.advance(None, 0.5)  # the same inputs again
    assert stepper.t == pytest.approx(2.5)
    copied = Stepper(model, list(state))
    assert copied.state is not state


def test_stepper_refuses_bad_arguments(forklift):
    model, inputs = forklift
    with pytest.raises(WmrkitError, match="state"):
        Stepper(model, np.zeros(3))
    with pytest.raises(ShapeError, match="finite"):
        Stepper(model, np.full(2 * model.n, np.nan))
    with pytest.raises(WmrkitError, match="no inputs"):
        Stepper(model).advance(None, 0.1)
    with pytest.raises(ShapeError, match="duration"):
        Stepper(model).advance(inputs, -1.0)
    with pytest.raises(WmrkitError, match="method"):
        Stepper(model, method="adaptive")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="jac_every"):
        Stepper(model, jac_every=0)


def test_hold_equals_advancing_with_the_held_inputs(forklift):
    model, inputs = forklift  # several knots: hold() keeps their gains and holds new references
    a, b = Stepper(model), Stepper(model)
    a.advance(inputs, 1.0)
    b.advance(inputs, 1.0)
    program = twist_program(model, [0.0], [(2.0, 0.0, 0.0)])  # near its speed: a hard brake would tip the truck
    a.advance(program, 0.5)
    b.hold(program.rate_reference[0], program.heading_reference[0], program.torques[0])
    b.advance(None, 0.5)
    np.testing.assert_array_equal(a.state, b.state)
    with pytest.raises(ShapeError, match="heading_reference"):
        b.hold(heading_reference=np.zeros(5))
    with pytest.raises(WmrkitError, match="first"):
        Stepper(model).hold(torques=np.zeros(model.n))


def test_hold_without_steering_keeps_the_programs_values_at_the_current_time():
    model = DynamicModel.of(catalog.load("skid-steer-4"), "dugoff")
    inputs, _ = path_program(model, "turn", speed=1.0)
    a, b = Stepper(model), Stepper(model)
    a.advance(inputs, 1.5)
    b.advance(inputs, 1.5)
    b.hold()  # nothing new: the references at t = 1.5 s, held from now on
    t = np.asarray(inputs.time)
    held = [np.interp(1.5, t, col) for col in np.asarray(inputs.rate_reference).T]
    a.advance(twist_program(model, [0.0], [(0.0, 0.0, 0.0)]), 0.0)
    a.hold(np.array(held))
    a.advance(None, 0.3)
    b.advance(None, 0.3)
    np.testing.assert_array_equal(a.state, b.state)
