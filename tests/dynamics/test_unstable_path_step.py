"""A fixed-step --path run that leaves its program's path only because its step is too long (it neither lifts off
nor diverges) is refused naming the step, after a re-run at a shorter step; a deviation that the shorter step
reproduces is the robot's and keeps its warning."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.dynamics.deviation import check_step
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program
from wmrkit.dynamics.simulate import simulate
from wmrkit.errors import WmrkitError


def _flat_forklift(tmp_path):
    """The forklift without load transfer (com_height 0): nothing lifts off at any step."""
    text = catalog.source_text("forklift")
    assert "com_height: 0.7" in text
    path = tmp_path / "flat.yaml"
    path.write_text(text.replace("com_height: 0.7", "com_height: 0").replace("name: forklift", "name: flat"))
    return path


def _refused(capsys, *argv: str) -> str:
    assert main(list(argv)) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1 and err.startswith("wmrkit: error: "), err
    assert "the step is too long for the tyres" in err and "or the adaptive method" in err
    return err


def test_rk4_turn_off_its_path_at_a_long_step_is_refused(capsys):
    # before: exit 0, "the robot left the programmed path: up to 4.31 m from it ...; its tyres slip"
    err = _refused(capsys, "simulate", "forklift", "--path", "turn", "--method", "rk4", "--step", "0.0333")
    assert "at step 0.0333 s (up to 4.31 m from it)" in err and "use a step of at most 0.0001 s" in err
    assert main(["simulate", "forklift", "--path", "turn", "--method", "rk4", "--step", "0.0333", "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert "the step is too long for the tyres" in json.loads(err)["error"]


def test_the_premise_lsoda_drives_the_turn_on_its_path():
    """Independently of the re-check: over the turn's first second the adaptive integrator (error-controlled) keeps
    the forklift within 0.05 m of the program, where rk4 at 0.0333 s is already 0.97 m off (4.31 m at 3 s)."""
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, _ = path_program(model, "turn")
    good = simulate(model, inputs, 0.999, method="adaptive", record_step=0.0333).deviation()
    assert not good.large and good.max_position < 0.05
    bad = simulate(model, inputs, 0.999, method="rk4", step=0.0333).deviation()
    assert bad.large and bad.max_position > 0.9


def test_a_robot_without_load_transfer_off_its_path_at_20_ms_is_refused(tmp_path, capsys):
    # before: exit 0 with the deviation warning (12.4 m); at 20 ms it drove 0.78 m/s at t = 5 s instead of 2
    flat = _flat_forklift(tmp_path)
    err = _refused(capsys, "simulate", str(flat), "--path", "rectangle", "--step", "0.02")
    assert "at step 0.02 s (up to 12.4 m from it)" in err and "use a step of at most 0.001 s" in err
    model = DynamicModel.of(catalog.resolve(flat))
    inputs, _ = path_program(model, "rectangle")
    coarse = simulate(model, inputs, 1.0, step=0.02)
    exact = simulate(model, inputs, 1.0, method="adaptive", record_step=0.02)  # the premise, by LSODA
    assert exact.twist[-1, 0] > 1.9 and coarse.twist[-1, 0] < 1.8  # 1.94 and 1.77 m/s; the program asks 2
    assert np.hypot(*(exact.pose[-1, :2] - exact.nominal_pose[-1, :2])) < 0.1


def test_a_step_that_doubles_a_real_deviation_is_refused(capsys):
    """The skid steer leaves the rectangle at any step (24.2 m at 1 ms: its wheels slip to turn), but at 20 ms it
    is 42.4 m off, 44.8 m from the 1 ms run: the answer is the step's."""
    err = _refused(capsys, "simulate", "skid-steer-4", "--path", "rectangle", "--step", "0.02")
    assert "keeps within 24.2 m of the path and is up to 44.8 m" in err


@pytest.mark.parametrize("argv", [("--path", "rectangle"), ("--path", "figure-eight", "--step", "0.004")])
def test_a_real_deviation_at_a_stable_step_still_warns(argv, capsys):
    """The skid steer cannot follow the turns of a program (its fixed wheels must slip): at 1 ms and 4 ms the
    shorter step leaves the path as far, so the warning stays, exit 0."""
    assert main(["simulate", "skid-steer-4", *argv, "--json"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    assert len(data["warnings"]) == 1 and err.count("\n") == 1
    assert data["warnings"][0].startswith("the robot left the programmed path") and data["deviation"]["large"]
    model = DynamicModel.of(catalog.load("skid-steer-4"))
    inputs, duration = path_program(model, argv[1])
    step = float(argv[3]) if len(argv) > 2 else 1e-3
    run = simulate(model, inputs, duration, step=step, record_step=0.02)
    fine = simulate(model, inputs, duration, step=step / 4, record_step=0.02)
    apart = np.hypot(*(run.pose[:, :2] - fine.pose[:, :2]).T).max()
    assert apart < 0.1 * run.deviation().max_position  # the two steps agree: the deviation is the robot's
    check_step(model, inputs, run)  # passes


def test_check_step_passes_runs_on_their_path_and_adaptive_runs():
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, _ = path_program(model, "turn")
    check_step(model, inputs, simulate(model, inputs, 1.0, step=0.005))  # on its path: nothing re-run
    with pytest.raises(WmrkitError, match=r"at step 0\.0333 s .* use a step of at most 0\.0001 s"):
        check_step(model, inputs, simulate(model, inputs, 2.997, method="rk4", step=0.0333))


def test_check_step_names_the_step_keyword_and_the_cli_its_option(capsys):
    """check_step() told Python callers "use a step of at most 0.0001 s (--step) or the adaptive method", the CLI's
    option; now simulate()'s keyword, and `wmrkit simulate` its option, as simulate()'s own stops do."""
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, duration = path_program(model, "turn")
    with pytest.raises(WmrkitError) as err:
        check_step(model, inputs, simulate(model, inputs, duration, method="rk4", step=0.0333, record_step=0.0333))
    assert str(err.value).endswith("use a step of at most 0.0001 s (the step keyword) or method='adaptive'")
    assert "--step" not in str(err.value)
    cli = _refused(capsys, "simulate", "forklift", "--path", "turn", "--method", "rk4", "--step", "0.0333")
    assert cli == f"wmrkit: error: {err.value}\n".replace("(the step keyword) or method='adaptive'",
                                                           "(--step) or the adaptive method")


def test_a_stop_of_check_steps_rerun_says_the_step_as_each_door_sets_it(monkeypatch, capsys):
    """A re-run that stops is quoted in check_step's error: its advice (simulate()'s keyword) is said by the CLI as
    its option, as simulate()'s own stops."""
    import wmrkit.dynamics.simulate as simulate_module
    from wmrkit.dynamics.runs import SIMULATE_STEP

    real = simulate_module.simulate

    def stopping(model, inputs, duration, **kwargs):
        if kwargs.get("step") == 0.0001:  # the re-run of check_step
            err = WmrkitError(f"the re-run stopped; use a step of at most 1e-05 s {SIMULATE_STEP}")
            err.where = SIMULATE_STEP
            raise err
        return real(model, inputs, duration, **kwargs)

    monkeypatch.setattr(simulate_module, "simulate", stopping)
    model = DynamicModel.of(catalog.load("forklift"))
    inputs, duration = path_program(model, "turn")
    with pytest.raises(WmrkitError, match=r"to check it stops: the re-run stopped; .* \(the step keyword\) or"):
        check_step(model, inputs, real(model, inputs, duration, method="rk4", step=0.0333, record_step=0.0333))
    assert main(["simulate", "forklift", "--path", "turn", "--method", "rk4", "--step", "0.0333"]) == 2
    err = capsys.readouterr().err
    assert err.endswith("to check it stops: the re-run stopped; use a step of at most 1e-05 s (--step) or the adaptive "
                        "method\n") and "keyword" not in err
