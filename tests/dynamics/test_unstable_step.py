"""A fixed-step run that stops (a wheel "lifts off", the state diverges) is re-checked at a shorter step: the stop
is the integrator's when the shorter step does not reproduce it, and the error then says so instead of blaming the
torques; a lift-off that the shorter step and the adaptive integrator reproduce is still a lift-off."""

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
from wmrkit.dynamics.simulate import simulate
from wmrkit.errors import WmrkitError


def _error(capsys, *argv: str) -> str:
    assert main(list(argv)) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1 and err.startswith("wmrkit: error: "), err
    return err


@pytest.mark.parametrize("step", ["0.01", "0.02", "0.033"])
def test_a_lift_off_of_the_step_not_the_robot_is_called_the_step(step, capsys):
    # before: "contact 'steer' lifts off the ground at t = 0.22 s ...; use smaller torques or speeds"
    err = _error(capsys, "simulate", "forklift", "--path", "rectangle", "--step", step)
    assert "contact 'steer' lost its load" in err and f"at step {step} s" in err
    assert "the step is too long for the tyres" in err and "torques" not in err
    assert "use a step of at most 0.001 s (--step) or the adaptive method" in err


def test_the_refusal_under_json_is_one_error_object(capsys):
    assert main(["simulate", "forklift", "--path", "rectangle", "--step", "0.01", "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert "the step is too long for the tyres" in json.loads(err)["error"]


def test_the_premise_the_robot_keeps_its_wheels_down_by_two_other_integrators():
    """Independently of the re-check: LSODA (adaptive, error-controlled) and the semi-implicit method at a tenth of
    the step drive the same start of the rectangle with the steered wheel's load far from 0, where 10 ms 'lost' it."""
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, _ = path_program(model, "rectangle")
    steer = model.contacts.index("steer")
    at_rest = model.normal_loads()[steer]
    for method, step in (("adaptive", 1e-3), ("semi-implicit", 1e-3)):
        sim = simulate(model, inputs, 0.5, method=method, step=step, record_step=1e-3)
        assert sim.loads[:, steer].min() > 0.7 * at_rest
    coarse = simulate(model, inputs, 0.5, step=0.01, record_step=0.01, allow_lift_off=True)
    assert coarse.loads[:, steer].min() == 0.0  # the 10 ms run's own lift-off, which the others do not have


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


def test_a_robot_lift_off_the_shorter_step_reaches_late_is_not_blamed_on_the_step(capsys):
    """The forklift's figure-eight at 2.8 m/s 'loses' a drive wheel's load at t = 1.41 s at 10 ms, and the robot
    loses it at t = 7.81 s: the re-check ran only to 0.1 s past the stop and said "... goes on to t = 1.51 s without
    it: the step is too long for the tyres (the integration is unstable, not the robot)"; it runs to the end now."""
    err = _error(capsys, "simulate", "forklift", "--path", "figure-eight", "--speed", "2.8", "--step", "0.01")
    assert err == ("wmrkit: error: contact 'left_drive' lost its load at t = 1.41 s at step 0.01 s, but a run at step "
                   "0.001 s goes on without it until contact 'left_drive' lost its load at t = 7.809 s: the robot's "
                   "stop, which the step brought early; use smaller torques or speeds, and a step of at most 0.001 s "
                   "(--step) or the adaptive method\n")
    # independently, without the re-check: the 1 ms run keeps the wheel loaded past 1.51 s and empties it by 7.81 s
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, _ = path_program(model, "figure-eight", speed=2.8)
    sim = simulate(model, inputs, 7.85, record_step=0.01, allow_lift_off=True)
    load = sim.loads[:, model.contacts.index("left_drive")]
    assert load[sim.t <= 7.75].min() > 0 and load[sim.t >= 7.82].min() == 0.0


def test_a_recheck_whose_budget_ends_before_the_run_does_says_so(monkeypatch):
    """The re-check of the rectangle's stop at 10 ms (t = 0.22 s) at 1 ms with a budget of 2 s of steps cannot
    reach the run's end: it blamed the step ("goes on to t = 0.32 s"), and now says the verdict is not known."""
    monkeypatch.setattr(runs, "RECHECK_STEPS", 2000)
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, duration = path_program(model, "rectangle")
    with pytest.raises(WmrkitError) as err:
        simulate(model, inputs, duration, step=0.01)
    assert str(err.value) == (
        f"contact 'steer' lost its load at t = 0.22 s at step 0.01 s; a run at step 0.001 s goes on without it to "
        f"t = 2.21 s, where the re-check's budget ends, short of the end at t = {round(duration / 0.01) * 0.01:.6g} s: "
        "whether the step (the integration unstable) or the robot stops it is not known; use a step of at most "
        "0.001 s (the step keyword) or method='adaptive' to tell, or smaller torques or speeds")
    assert not isinstance(err.value, LiftOffError)


def test_python_simulate_names_its_keyword_and_the_cli_its_option(capsys):
    """simulate() told Python callers "use a step of at most 0.001 s (--step) or the adaptive method", the CLI's
    option; now its keyword, and `wmrkit simulate` its option (the later stop's advice as well)."""
    model = DynamicModel.of(catalog.load("forklift"))
    for name, speed in (("rectangle", 2.0), ("figure-eight", 2.8)):
        inputs, duration = path_program(model, name, speed=speed)
        with pytest.raises(WmrkitError) as err:
            simulate(model, inputs, duration, step=0.01, record_step=0.01)
        assert str(err.value).endswith("a step of at most 0.001 s (the step keyword) or method='adaptive'")
        assert "--step" not in str(err.value)
        cli = _error(capsys, "simulate", "forklift", "--path", name, "--speed", str(speed), "--step", "0.01")
        assert cli == f"wmrkit: error: {err.value}\n".replace("(the step keyword) or method='adaptive'",
                                                               "(--step) or the adaptive method")
