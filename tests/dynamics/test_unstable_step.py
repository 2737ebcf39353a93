"""A fixed-step run that stops (a wheel "lifts off", the state diverges) is re-checked at a shorter step: the stop
is the integrator's when the shorter step does not reproduce it, and the error then says so instead of blaming the
torques; a lift-off that the shorter step and the adaptive integrator reproduce is still a lift-off.

The stops of a step too long are those of an unstable integration: their times depend on the floating point of the
CPU (numba compiles for the host), so no test pins one. Each expected stop is that of an independent run of the
same inputs at the same step without the re-check (:func:`coarse_stop`), and the examples are ones whose stop a
relative change of 1e-12 in the program's speed does not move (the forklift's rectangle at 2 m/s and 25 ms stops at
4.275 s for every one of nine such speeds, where at 20 ms it ran, stopped at 5.64 s or ran)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.dynamics import runs
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program, twist_program
from wmrkit.dynamics.runs import RECHECK_MAX_STEP, LiftOffError, recheck_step
from wmrkit.dynamics.simulate import Stepper, simulate
from wmrkit.errors import WmrkitError

#: (speed [m/s], step [s]) of the forklift's rectangle whose 'lift-off' the 1 ms step does not have.
STEP_STOPS = [(2.0, 0.025), (2.5, 0.02), (2.5, 0.033)]


def _error(capsys, *argv: str) -> str:
    assert main(list(argv)) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1 and err.startswith("wmrkit: error: "), err
    return err


def coarse_stop(model: DynamicModel, inputs, step: float) -> LiftOffError:
    """The lift-off of `inputs` through a Stepper at `step` [s] without the re-check (the run under test's own)."""
    stepper = Stepper(model, step=step, recheck=False)
    with pytest.raises(LiftOffError) as stop:
        stepper.advance(inputs, inputs.time[-1])
    return stop.value


@pytest.fixture(scope="module")
def forklift():
    return DynamicModel.of(catalog.load("forklift"))


@pytest.mark.parametrize(("speed", "step"), STEP_STOPS)
def test_a_lift_off_of_the_step_not_the_robot_is_called_the_step(forklift, speed, step, capsys):
    inputs, duration = path_program(forklift, "rectangle", speed=speed)
    stop = coarse_stop(forklift, inputs, step)
    err = _error(capsys, "simulate", "forklift", "--path", "rectangle", "--speed", f"{speed:g}", "--step", f"{step:g}")
    assert err == (f"wmrkit: error: contact '{stop.contact}' lost its load at t = {stop.t:.6g} s at step {step:g} s, "
                   f"but a run at step 0.001 s goes on to t = {round(duration / step) * step:.6g} s without it: the "
                   "step is too long for the tyres (the integration is unstable, not the robot); use a step of at "
                   "most 0.001 s (--step) or the adaptive method\n")


def test_the_refusal_under_json_is_one_error_object(capsys):
    assert main(["simulate", "forklift", "--path", "rectangle", "--step", "0.025", "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert "the step is too long for the tyres" in json.loads(err)["error"]


def test_the_premise_the_robot_keeps_its_wheels_down_by_two_other_integrators(forklift):
    """Independently of the re-check: the explicit rk4 at 0.1 ms and the semi-implicit method at 1 ms drive the
    rectangle at 2 m/s past the 25 ms run's stop with every wheel's load far from 0, where 25 ms 'lost' one (LSODA
    agrees, 0.84 of the load at rest at least, but takes 13 s for it)."""
    inputs, _ = path_program(forklift, "rectangle")
    stop = coarse_stop(forklift, inputs, 0.025)
    at_rest = forklift.normal_loads()
    for method, step in (("rk4", 1e-4), ("semi-implicit", 1e-3)):
        sim = simulate(forklift, inputs, stop.t + 0.5, method=method, step=step, record_step=0.01)
        assert (sim.loads.min(axis=0) > 0.5 * at_rest).all()
    coarse = simulate(forklift, inputs, stop.t, step=0.025, record_step=0.025, allow_lift_off=True)
    assert coarse.loads[:, forklift.contacts.index(stop.contact)].min() == 0.0  # its own lift-off


def test_a_real_lift_off_still_says_lift_off_at_any_step():
    """Braking the forklift from 1 m/s at the grip tips it onto its drive wheels: the adaptive integrator sees it
    too, so every fixed step (the default and coarser ones) still reports the lift-off, not the step."""
    model = DynamicModel.of(catalog.load("forklift"), "pacejka")
    brake = twist_program(model, [0.0], [(0.0, 0.0, 0.0)])
    with pytest.raises(WmrkitError, match="contact 'steer' lifts off the ground"):
        simulate(model, brake, 0.3, method="adaptive", initial_twist=(1.0, 0.0, 0.0))
    for step in (1e-3, 5e-3, 1e-2):
        with pytest.raises(WmrkitError, match=r"contact 'steer' lifts off the ground.*smaller torques or speeds"):
            simulate(model, brake, 0.3, step=step, initial_twist=(1.0, 0.0, 0.0))


def test_huge_torques_at_the_default_step_still_lift_off(tmp_path, capsys):
    hard = tmp_path / "hard.csv"
    hard.write_text("time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n"
                    "0,100,100,100,100\n0.05,100,100,100,100\n")
    for method in ("semi-implicit", "adaptive"):  # the adaptive integrator agrees: the robot's, not the step's
        err = _error(capsys, "simulate", "skid-steer-4", "--torques", str(hard), "--method", method)
        assert "contact 'front_left' lifts off the ground" in err and "smaller torques or speeds" in err


def test_rk4_too_long_a_step_is_called_the_step(capsys):
    err = _error(capsys, "simulate", "forklift", "--path", "turn", "--method", "rk4", "--step", "0.005")
    assert "lost its load" in err and "use a step of at most 0.0001 s (--step) or the adaptive method" in err


@pytest.mark.parametrize("step", [1e-5, 1e-3, 2e-3, 0.0035, 0.01, 0.02, 1 / 30, 0.033])
@pytest.mark.parametrize("method", [0, 1])
def test_the_recheck_step_is_a_whole_fraction_of_the_step_at_most_a_quarter_and_the_cap(step, method):
    fine = recheck_step(step, method)
    parts = step / fine
    assert abs(parts - round(parts)) < 1e-9 and round(parts) >= 4
    assert fine <= RECHECK_MAX_STEP[method] * (1 + 1e-12)
    assert fine > RECHECK_MAX_STEP[method] / 2 or round(parts) == 4  # not needlessly short
    assert np.isfinite(fine)


def test_a_robot_lift_off_the_shorter_step_reaches_late_is_not_blamed_on_the_step(forklift, capsys):
    """The forklift's figure-eight at 2.8 m/s 'loses' a drive wheel's load at 30 ms about 2 s in, and the robot
    loses it at 1 ms about 7.8 s in: the error is that later stop, naming both (each time that of a run without the
    re-check: at 1 ms, the re-check's step from t = 0, the same run)."""
    inputs, _ = path_program(forklift, "figure-eight", speed=2.8)
    coarse, fine = coarse_stop(forklift, inputs, 0.03), coarse_stop(forklift, inputs, 0.001)
    assert fine.t > runs.recheck_end(coarse.t, 0.03)  # the premise: the robot's stop, later
    err = _error(capsys, "simulate", "forklift", "--path", "figure-eight", "--speed", "2.8", "--step", "0.03")
    assert err == (f"wmrkit: error: contact '{coarse.contact}' lost its load at t = {coarse.t:.6g} s at step 0.03 s, "
                   f"but a run at step 0.001 s goes on without it until contact '{fine.contact}' lost its load at t = "
                   f"{fine.t:.6g} s: the robot's stop, which the step brought early; use smaller torques or speeds, "
                   "and a step of at most 0.001 s (--step) or the adaptive method\n")
    # independently, by the loads: the 1 ms run keeps that wheel loaded to just before its stop, and empties it
    sim = simulate(forklift, inputs, fine.t + 0.05, record_step=0.01, allow_lift_off=True)
    load = sim.loads[:, forklift.contacts.index(fine.contact)]
    assert load[sim.t <= fine.t - 0.05].min() > 0 and load[sim.t >= fine.t].min() == 0.0


def test_a_recheck_whose_budget_ends_before_the_run_does_says_so(forklift, monkeypatch):
    """The re-check of the rectangle's stop at 25 ms at 1 ms with a budget of 2 s of steps (from the last record
    before the stop) cannot reach the run's end: the verdict is not known."""
    monkeypatch.setattr(runs, "RECHECK_STEPS", 2000)
    inputs, duration = path_program(forklift, "rectangle")
    stop = coarse_stop(forklift, inputs, 0.025)
    with pytest.raises(WmrkitError) as err:
        simulate(forklift, inputs, duration, step=0.025)
    assert str(err.value) == (
        f"contact '{stop.contact}' lost its load at t = {stop.t:.6g} s at step 0.025 s; a run at step 0.001 s goes on "
        f"without it to t = {stop.t - 0.025 + 2:.6g} s, where the re-check's budget ends, short of the end at t = "
        f"{round(duration / 0.025) * 0.025:.6g} s: whether the step (the integration unstable) or the robot stops "
        "it is not known; use a step of at most 0.001 s (the step keyword) or method='adaptive' to tell, or smaller "
        "torques or speeds")
    assert not isinstance(err.value, LiftOffError)


def test_python_simulate_names_its_keyword_and_the_cli_its_option(forklift, capsys):
    """simulate() told Python callers "use a step of at most 0.001 s (--step) or the adaptive method", the CLI's
    option; now its keyword, and `wmrkit simulate` its option (the later stop's advice as well)."""
    for name, speed, step in (("rectangle", 2.0, 0.025), ("figure-eight", 2.8, 0.03)):
        inputs, duration = path_program(forklift, name, speed=speed)
        with pytest.raises(WmrkitError) as err:
            simulate(forklift, inputs, duration, step=step, record_step=step)
        assert str(err.value).endswith("a step of at most 0.001 s (the step keyword) or method='adaptive'")
        assert "--step" not in str(err.value)
        cli = _error(capsys, "simulate", "forklift", "--path", name, "--speed", str(speed), "--step", str(step))
        assert cli == f"wmrkit: error: {err.value}\n".replace("(the step keyword) or method='adaptive'",
                                                               "(--step) or the adaptive method")
