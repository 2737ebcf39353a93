"""A ``Stepper`` (the single-step API: closed loops, the slip studies' drivetrain) that stops (a wheel "lifts off",
the state diverges) is re-checked as ``simulate`` is: the inputs it was given, logged, are run again at a shorter
step over the stretch that led to the stop; when that run goes on, the error blames the step, not the robot.

No expected stop time is pinned (an unstable integration's depends on the CPU's floating point): each is that of a
run of the same inputs at the same step without the re-check (test_unstable_step.coarse_stop), on examples whose stop
a 1e-12 change of the program's speed does not move (test_unstable_step.py)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from test_unstable_step import coarse_stop

from wmrkit import catalog
from wmrkit.dynamics import runs
from wmrkit.dynamics._integrate import model_work_arrays, run
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program, twist_program
from wmrkit.dynamics.runs import LiftOffError, recheck_step, records
from wmrkit.dynamics.simulate import Stepper, advance, initial_state
from wmrkit.errors import WmrkitError

#: The forklift's rectangle at 2 m/s 'lifts off' at this step [s] (9.875 s in), not at 1 ms (it did at 25 ms, 4.3 s
#: in, until the step's Newton iterations searched along their direction, December 2026; 20 to 50 ms now run on).
STEP = 0.125


@pytest.fixture(scope="module")
def rectangle():
    model = DynamicModel.of(catalog.load("forklift"))
    inputs = path_program(model, "rectangle")[0]
    return model, inputs, coarse_stop(model, inputs, STEP)


@pytest.mark.parametrize("piece", [0.125, 0.5, 1.0])
def test_a_stepper_lift_off_of_the_step_is_called_the_step(rectangle, piece):
    """A Stepper said "lifts off the ground ...; use smaller torques or speeds" where only its step stopped it,
    whatever its pieces; it blames the step, at the stop of the same inputs without the re-check."""
    model, inputs, stop = rectangle
    stepper = Stepper(model, step=STEP)
    with pytest.raises(WmrkitError) as err:
        for _ in range(round((stop.t + 0.5) / piece)):
            stepper.advance(inputs, piece)
    assert not isinstance(err.value, LiftOffError)
    message = str(err.value)
    assert message.startswith(f"contact '{stop.contact}' lost its load at t = {stop.t:.6g} s at step {STEP:g} s, but a "
                              "run of its inputs at step 0.001 s goes on to t = ")
    assert message.endswith("the step is too long for the tyres (the integration is unstable, not the robot); use a "
                            "step of at most 0.001 s (the step argument)")
    # independently: the same inputs at that step, through the Stepper, run past the stop with the wheels loaded
    fine = Stepper(model, step=recheck_step(STEP, 0))
    fine.advance(inputs, stop.t + 0.5)
    assert fine.t == pytest.approx(stop.t + 0.5)


def test_advance_blames_the_step_too(rectangle):
    model, inputs, stop = rectangle
    with pytest.raises(WmrkitError, match=r"at step 0\.125 s, but a run of its inputs at step 0\.001 s goes on"):
        advance(model, initial_state(model), inputs, stop.t + 0.5, step=STEP)


@pytest.mark.parametrize("step", [1e-3, 5e-3, 1e-2])
def test_a_real_lift_off_through_the_stepper_still_says_lift_off(step):
    """Braking the forklift from 1 m/s at the grip tips it (the adaptive integrator sees it too:
    test_unstable_step.py): the re-check at the shorter step stops as well, so the error stays the lift-off."""
    model = DynamicModel.of(catalog.load("forklift"), "pacejka")
    stepper = Stepper(model, initial_state(model, (1.0, 0.0, 0.0)), step=step)
    with pytest.raises(LiftOffError, match=r"contact 'steer' lifts off the ground.*smaller torques or speeds"):
        for _ in range(30):
            stepper.advance(twist_program(model, [0.0], [(0.0, 0.0, 0.0)]), 0.01)


def test_the_log_replays_the_held_inputs_bit_for_bit(rectangle):
    """The log keeps each piece's inputs as the stepper advanced with them (hold() writes new rows, not the logged
    ones): run again at the same step from the first piece, they give the stepper's state bit for bit."""
    model, inputs, _ = rectangle
    stepper = Stepper(model, step=1e-3)
    stepper.advance(inputs, 0.02)
    rates = np.zeros(model.n)
    for k in range(40):
        rates[3:] = 2.0 + 0.1 * k
        stepper.hold(rates, np.full(len(model.steer_columns), 0.01 * k))
        stepper.advance(None, 0.005)
    pieces = list(stepper._log.pieces)
    s, acc, w = pieces[0][2].copy(), np.zeros(model.n), model_work_arrays(model)
    for k0, steps, _, inp in pieces:
        run(s, k0, 1e-3, steps, 1 << 62, 0, 20, acc, model.pack, inp, w, records(model, 0), 0)
    np.testing.assert_array_equal(s, stepper.state)
    assert len({id(p[3]) for p in pieces[1:]}) == 40  # one set of inputs a hold


def test_the_log_is_bounded_by_the_recheck_budget():
    model = DynamicModel.of(catalog.load("skid-steer-4"))
    stepper = Stepper(model, step=0.02, method="rk4")  # re-checked at 1e-4 s: 1250 of its steps
    stepper.advance(twist_program(model, [0.0], [(0.3, 0.0, 0.0)]), 0.0)
    for _ in range(3000):
        stepper.advance(None, 0.02)
    log = stepper._log
    assert log.span == 1250 and len(log.pieces) <= log.span + 1
    assert stepper._k - log.pieces[0][0] <= log.span + 1


def test_without_a_log_a_stop_is_not_rechecked(rectangle):
    model, inputs, stop = rectangle
    with pytest.raises(LiftOffError, match=f"contact '{stop.contact}' lifts off the ground at t = {stop.t:.6g} s"):
        Stepper(model, step=STEP, recheck=False).advance(inputs, stop.t + 0.5)


def test_a_robot_lift_off_the_shorter_step_reaches_late_is_not_blamed_on_the_step():
    """The figure-eight program at 2.8 m/s through a Stepper at 100 ms 'loses' a drive wheel's load 6.5 s in (at 30
    ms, 2 s in, before the step's line search; 30 to 50 ms now run on); the robot loses it about 7.8 s in (the same
    inputs at 1 ms from t = 0, without the re-check). The re-check runs the logged inputs to their end: the error is
    that later stop, naming both."""
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, duration = path_program(model, "figure-eight", speed=2.8)
    coarse, fine = coarse_stop(model, inputs, 0.1), coarse_stop(model, inputs, 0.001)
    stepper = Stepper(model, step=0.1)
    with pytest.raises(LiftOffError) as err:
        for _ in range(round(duration / 0.3)):
            stepper.advance(inputs, 0.3)
    assert str(err.value) == (
        f"contact '{coarse.contact}' lost its load at t = {coarse.t:.6g} s at step 0.1 s, but a run of its inputs at "
        f"step 0.001 s goes on without it until contact '{fine.contact}' lost its load at t = {fine.t:.6g} s: the "
        "robot's stop, which the step brought early; use smaller torques or speeds, and a step of at most 0.001 s "
        "(the step argument)")
    assert err.value.t == fine.t and err.value.contact == fine.contact


def test_a_recheck_whose_budget_ends_before_the_inputs_do_says_so(rectangle, monkeypatch):
    """With a budget of 2 s of 1 ms steps, the re-check of the rectangle's stop at 200 ms (3.6 s; from 125 ms's
    state 2 s before its stop, 1 ms reaches the robot's own stop within the budget) cannot reach the program's
    end (its last knot, 22.4 s): the verdict is not known."""
    monkeypatch.setattr(runs, "RECHECK_STEPS", 2000)
    model, inputs, _ = rectangle
    stop = coarse_stop(model, inputs, 0.2)
    stepper = Stepper(model, step=0.2)
    with pytest.raises(WmrkitError) as err:
        stepper.advance(inputs, stop.t + 0.5)
    assert re.fullmatch(
        f"contact '{stop.contact}' lost its load at t = {stop.t:.6g} s at step 0.2 s; a run of its inputs at step "
        r"0\.001 s goes on without it to t = ([\d.]+) s, where the re-check's budget ends, short of the end at t = "
        f"{inputs.time[-1]:.6g} s: whether the step \\(the integration unstable\\) or the robot stops it is not "
        r"known; use a step of at most 0\.001 s \(the step argument\) to tell, or smaller torques or speeds",
        str(err.value)), str(err.value)
    reached = float(re.search(r"to t = ([\d.]+) s, where", str(err.value))[1])
    assert stop.t < reached <= stop.t + 2.0 + 0.2  # the log's 2 s span, from at most a step before the stop
