"""A fixed-step run that stops (a wheel "lifts off", the state diverges) is re-checked at a shorter step: the stop
is the integrator's when the shorter step does not reproduce it, and the error then says so instead of blaming the
torques; a lift-off that the shorter step and the adaptive integrator reproduce is still a lift-off.

The stops of a step too long are those of an unstable integration: their times depend on the floating point of the
CPU (numba compiles for the host), so no test pins one. Each expected stop is that of an independent run of the
same inputs at the same step without the re-check (:func:`coarse_stop`), and the examples are ones whose stop a
relative change of 1e-12 in the program's speed does not move (the forklift's rectangle at 2 m/s and 80 ms stops at
6.72 s for every one of nine such speeds, where at 62.5 ms it stopped between 6.81 and 17.4 s). Since the step's
Newton iterations search along their direction (``_newton.line_search``, December 2026) the rectangle at 2 and 2.5
m/s runs at every step up to 50 ms, which 'lifted off' at 20 to 33 ms before."""

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

#: Steps [s] of the forklift's rectangle at 2 m/s whose 'lift-off' the 1 ms step does not have (at 6.72, 9.875 and
#: 3.6 s). `wmrkit simulate --path` refuses steps longer than its servos' time constant (1/30 s), where the rectangle
#: now runs at every step: these are Python calls, and the command's door is shown on rk4's stop (RK4_TURN).
STEP_STOPS = [0.08, 0.125, 0.2]
#: The rectangle's step [s] of the tests below, and the figure-eight's at 2.8 m/s ('left_drive' at 6.5 s, where the
#: 1 ms step loses it at 7.81 s).
STEP, EIGHT_STEP = 0.125, 0.1
#: A stop of rk4's step that `wmrkit simulate` takes (the forklift's turn, rk4 at 5 ms).
RK4_TURN = ("simulate", "forklift", "--path", "turn", "--method", "rk4", "--step", "0.005")


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


@pytest.mark.parametrize("step", STEP_STOPS)
def test_a_lift_off_of_the_step_not_the_robot_is_called_the_step(forklift, step):
    inputs, duration = path_program(forklift, "rectangle")
    stop = coarse_stop(forklift, inputs, step)
    with pytest.raises(WmrkitError) as err:
        simulate(forklift, inputs, duration, step=step)
    assert str(err.value) == (
        f"contact '{stop.contact}' lost its load at t = {stop.t:.6g} s at step {step:g} s, but a run at step 0.001 s "
        f"goes on to t = {round(duration / step) * step:.6g} s without it: the step is too long for the tyres (the "
        "integration is unstable, not the robot); use a step of at most 0.001 s (the step keyword) or "
        "method='adaptive'")


def test_the_refusal_under_json_is_one_error_object(capsys):
    assert main([*RK4_TURN, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert "the step is too long for the tyres" in json.loads(err)["error"]


def test_the_premise_the_robot_keeps_its_wheels_down_by_two_other_integrators(forklift):
    """Independently of the re-check: the explicit rk4 at 0.1 ms and the semi-implicit method at 1 ms drive the
    rectangle at 2 m/s past the 80 ms run's stop with every wheel's load far from 0, where 80 ms 'lost' one (LSODA
    agrees, 0.84 of the load at rest at least, but takes 13 s for it)."""
    inputs, _ = path_program(forklift, "rectangle")
    stop = coarse_stop(forklift, inputs, STEP_STOPS[0])
    at_rest = forklift.normal_loads()
    for method, step in (("rk4", 1e-4), ("semi-implicit", 1e-3)):
        sim = simulate(forklift, inputs, stop.t + 0.5, method=method, step=step, record_step=0.01)
        assert (sim.loads.min(axis=0) > 0.5 * at_rest).all()
    coarse = simulate(forklift, inputs, stop.t, step=STEP_STOPS[0], record_step=STEP_STOPS[0], allow_lift_off=True,
                      check=False)
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
    """The forklift's figure-eight at 2.8 m/s 'loses' a drive wheel's load at 100 ms 6.5 s in (at 30 ms 2 s in
    before the step's line search; 30 to 50 ms now run on), and the robot loses it at 1 ms about 7.8 s in: the error
    is that later stop, naming both (each time that of a run without the re-check: at 1 ms, the re-check's step from
    t = 0, the same run)."""
    inputs, _ = path_program(forklift, "figure-eight", speed=2.8)
    coarse, fine = coarse_stop(forklift, inputs, EIGHT_STEP), coarse_stop(forklift, inputs, 0.001)
    assert fine.t > runs.recheck_end(coarse.t, EIGHT_STEP)  # the premise: the robot's stop, later
    with pytest.raises(LiftOffError) as err:
        simulate(forklift, inputs, inputs.time[-1], step=EIGHT_STEP)
    assert str(err.value) == (
        f"contact '{coarse.contact}' lost its load at t = {coarse.t:.6g} s at step 0.1 s, but a run at step 0.001 s "
        f"goes on without it until contact '{fine.contact}' lost its load at t = {fine.t:.6g} s: the robot's stop, "
        "which the step brought early; use smaller torques or speeds, and a step of at most 0.001 s (the step "
        "keyword) or method='adaptive'")
    # independently, by the loads: the 1 ms run keeps that wheel loaded to just before its stop, and empties it
    sim = simulate(forklift, inputs, fine.t + 0.05, record_step=0.01, allow_lift_off=True)
    load = sim.loads[:, forklift.contacts.index(fine.contact)]
    assert load[sim.t <= fine.t - 0.05].min() > 0 and load[sim.t >= fine.t].min() == 0.0


def test_a_recheck_whose_budget_ends_before_the_run_does_says_so(forklift, monkeypatch):
    """The re-check of the rectangle's stop at 125 ms at 1 ms with a budget of 2 s of steps (from the last record
    before the stop) cannot reach the run's end: the verdict is not known."""
    monkeypatch.setattr(runs, "RECHECK_STEPS", 2000)
    inputs, duration = path_program(forklift, "rectangle")
    stop = coarse_stop(forklift, inputs, STEP)
    with pytest.raises(WmrkitError) as err:
        simulate(forklift, inputs, duration, step=STEP)
    assert str(err.value) == (
        f"contact '{stop.contact}' lost its load at t = {stop.t:.6g} s at step {STEP:g} s; a run at step 0.001 s goes "
        f"on without it to t = {stop.t - STEP + 2:.6g} s, where the re-check's budget ends, short of the end at t = "
        f"{round(duration / STEP) * STEP:.6g} s: whether the step (the integration unstable) or the robot stops "
        "it is not known; use a step of at most 0.001 s (the step keyword) or method='adaptive' to tell, or smaller "
        "torques or speeds")
    assert not isinstance(err.value, LiftOffError)


def test_python_simulate_names_its_keyword_and_the_cli_its_option(forklift, capsys):
    """simulate() told Python callers "use a step of at most 0.001 s (--step) or the adaptive method", the CLI's
    option; now its keyword (the later stop's advice as well: the test above), and `wmrkit simulate` its option."""
    for name, speed, step in (("rectangle", 2.0, STEP), ("figure-eight", 2.8, EIGHT_STEP)):
        inputs, duration = path_program(forklift, name, speed=speed)
        with pytest.raises(WmrkitError) as err:
            simulate(forklift, inputs, duration, step=step, record_step=step)
        assert str(err.value).endswith("a step of at most 0.001 s (the step keyword) or method='adaptive'")
        assert "--step" not in str(err.value)
    inputs, duration = path_program(forklift, "turn")
    with pytest.raises(WmrkitError) as err:
        simulate(forklift, inputs, duration, method="rk4", step=0.005)
    assert str(err.value).endswith("a step of at most 0.0001 s (the step keyword) or method='adaptive'")
    assert _error(capsys, *RK4_TURN) == f"wmrkit: error: {err.value}\n".replace(
        "(the step keyword) or method='adaptive'", "(--step) or the adaptive method")
