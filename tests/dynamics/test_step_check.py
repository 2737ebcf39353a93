"""A fixed-step run longer than the step the tyres' integration is checked at (1 ms semi-implicit, 0.1 ms rk4) is
re-run at that step, from Python as from the CLI (December 2026: only the CLI re-ran, and only runs off their path):
refused when the re-run stops (a long step can damp a real lift-off away) or is far from it; else it carries the
comparison (``Simulation.step_check``, the CLI's 'step check' line and JSON field)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program
from wmrkit.dynamics.simulate import simulate
from wmrkit.errors import WmrkitError

SKID_TORQUES = ("time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n"
                "0,{0},{1},{0},{1}\n10,{0},{1},{0},{1}\n")


@pytest.fixture(scope="module")
def forklift():
    return DynamicModel.of(catalog.load("forklift"))


def test_the_premise_a_5_ms_step_damps_away_the_figure_eights_lift_off(forklift):
    """Independently of the check: at 2.6 m/s the figure-eight loses its left drive wheel's load at about 8.35 s at
    1 ms and at 0.5 ms (the step converged), where the 5 ms run keeps every wheel down and on its path."""
    inputs, duration = path_program(forklift, "figure-eight", speed=2.6)
    for step in (1e-3, 5e-4):
        with pytest.raises(WmrkitError, match=r"contact 'left_drive' lifts off the ground at t = 8\.3[45]"):
            simulate(forklift, inputs, 8.5, step=step, record_step=0.01, check=False)
    coarse = simulate(forklift, inputs, duration, step=5e-3, record_step=0.01, check=False)
    assert coarse.loads.min() > 0 and not coarse.deviation().large and coarse.step_check is None


def test_a_long_step_that_misses_a_lift_off_is_refused_at_both_doors(forklift, capsys):
    inputs, duration = path_program(forklift, "figure-eight", speed=2.6)
    with pytest.raises(WmrkitError, match=r"the run at step 0\.005 s \(longer than the 0\.001 s at which the tyres' "
                                          r"integration is checked\) went on, and a run at step 0\.001 s to check it "
                                          r"stops: contact 'left_drive' lifts off the ground at t = 8\.351 s"):
        simulate(forklift, inputs, duration, step=5e-3, record_step=0.01)
    assert main(["simulate", "forklift", "--path", "figure-eight", "--speed", "2.6", "--step", "0.005"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "lifts off the ground at t = 8.351 s" in err


def test_torque_inputs_at_a_long_step_are_checked(tmp_path, capsys):
    """Torques program no path, so nothing compared these runs with anything: a 0.2 s step of this hard turn was
    printed 42.6 m from the 1 ms run, exit 0. A gentler one at 0.1 s passes, carrying the comparison, whose numbers
    are those of the two runs made here."""
    hard, gentle = tmp_path / "hard.csv", tmp_path / "gentle.csv"
    hard.write_text(SKID_TORQUES.format(3, 6))
    gentle.write_text(SKID_TORQUES.format(0.5, 1))
    assert main(["simulate", "skid-steer-4", "--torques", str(hard), "--step", "0.2"]) == 2
    err = capsys.readouterr().err
    assert "the run at step 0.2 s" in err and "the step is too long for the tyres" in err
    assert "use a step of at most 0.001 s (--step) or the adaptive method" in err
    assert main(["simulate", "skid-steer-4", "--torques", str(gentle), "--step", "0.1", "--json"]) == 0
    check = json.loads(capsys.readouterr().out)["step_check"]
    from wmrkit.dynamics.programs import read_torques

    model = DynamicModel.of(catalog.load("skid-steer-4"))
    inputs = read_torques(model, gentle)
    coarse = simulate(model, inputs, 10.0, step=0.1, check=False)
    fine = simulate(model, inputs, 10.0, step=1e-3, record_step=0.1)
    assert fine.step_check is None  # at the checked step: not re-run
    apart = np.hypot(*(coarse.pose[:, :2] - fine.pose[:, :2]).T)
    assert check["step"] == 1e-3 and check["until"] == 10.0
    assert check["max_position"] == pytest.approx(apart.max(), rel=1e-9) and 0.1 < apart.max() < 1.0
    heading = coarse.pose[:, 2] - fine.pose[:, 2]
    assert check["max_heading"] == pytest.approx(heading[np.argmax(np.abs(heading))], rel=1e-9)
    assert main(["simulate", "skid-steer-4", "--torques", str(gentle), "--step", "0.1"]) == 0
    assert (f"step check: a run at step 0.001 s to t = 10 s is within {apart.max():.3g} m"
            in capsys.readouterr().out)


def test_python_refuses_a_run_off_its_path_at_a_long_step_as_the_cli_does(tmp_path):
    """The flat forklift (no load transfer) crawls off its rectangle at 25 ms (tests/dynamics/
    test_unstable_path_step.py); simulate() returned that run, exit 0 from Python, where the CLI refused it."""
    text = catalog.source_text("forklift").replace("com_height: 0.7", "com_height: 0")
    path = tmp_path / "flat.yaml"
    path.write_text(text.replace("name: forklift", "name: flat"))
    model = DynamicModel.of(catalog.resolve(path))
    inputs, duration = path_program(model, "rectangle")
    with pytest.raises(WmrkitError, match=r"left the programmed path at step 0\.025 s .* too long for the tyres .* "
                                          r"\(the step keyword\) or method='adaptive'"):
        simulate(model, inputs, duration, step=0.025, record_step=0.025)
