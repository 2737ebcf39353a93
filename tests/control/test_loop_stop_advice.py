"""A loop through the dynamics that stops at both steps of its re-check (``simulate_dynamics``, ``track --dynamics``)
says what the user of that door can change: the Python arguments from Python, the options of ``wmrkit track`` (which
has no step option) from the command line; one line and exit 2 from the CLI, JSON under --json."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from cli_options import options
from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control import builtin_reference, control_point
from wmrkit.control.dynamic_plant import _dynamics_loop, fast_law_controller, simulate_dynamics
from wmrkit.control.laws import PositionLaw
from wmrkit.control.points import StoppedRun
from wmrkit.control.track import initial_pose_on
from wmrkit.dynamics.runs import DivergedError, recheck_step
from wmrkit.dynamics.simulate import Stepper
from wmrkit.errors import WmrkitError

TRACK_OPTIONS = {o for words, a in options() if words == ("track",) for o in a.option_strings}


def _named_options(message: str) -> set[str]:
    """The command-line options a message names."""
    return set(re.findall(r"--[a-z][a-z-]*", message))


def _flat_skid_steer(tmp_path) -> str:
    """The catalog skid steer with its centre of mass on the ground: no load transfer, so no wheel lifts off and a
    loop of too high a gain runs until its law diverges."""
    text = catalog.source_text("skid-steer-4")
    assert "com_height: 0.2" in text
    path = tmp_path / "flat.yaml"
    path.write_text(text.replace("com_height: 0.2", "com_height: 0"))
    return str(path)


def _cli_error(argv: list[str], capsys) -> str:
    """The one error line of `argv` (exit 2), the same as its JSON answer's error."""
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[-1].startswith("wmrkit: error: ") and all(line.startswith("wmrkit: warning: ") for line in lines[:-1])
    assert main([*argv, "--json"]) == 2
    answer = json.loads(capsys.readouterr().err.strip().splitlines()[-1])
    assert answer["error"] == lines[-1].removeprefix("wmrkit: error: ")
    return answer["error"]


def test_a_law_that_diverges_later_at_the_shorter_step_names_no_step_option(tmp_path, capsys):
    """The flat skid steer on the circle at a = 4000 1/s (a T = 80: the sampled law diverges) commands beyond
    1000 m/s at t = 1.70 s at the 1 ms step, and at 2.16 s at 0.25 ms (December 2026; the time of a divergence does
    not converge with the step: 2.38 s at 62.5 us, 2.12 s at 31.25 us. At 5000 1/s, this test's gain before the step
    took the loads of its own acceleration, 1.88 s and 2.24 s became 1.88 s and 1.90 s, within the re-check's
    margin; 1.92 s at 62.5 us, 2.22 s at 31.25 us). `wmrkit track` said "...: the robot's stop,
    which the step brought early; use smaller torques or speeds, and a step of at most 0.00025 s (the step argument)":
    no step option, and torques it does not take; it is the law's stop, and its advice is the law's (the gain, the
    period: options of track). Each time checked against the loop run at that step without a re-check."""
    from wmrkit.description import load_robot_file

    path = _flat_skid_steer(tmp_path)
    robot, reference = load_robot_file(path), builtin_reference("circle")
    cp = control_point(robot)
    controller = fast_law_controller(cp, PositionLaw.uniform("p", 4000.0), reference)
    pose0 = initial_pose_on(cp, reference)
    stops = []
    for step in (1e-3, recheck_step(1e-3, 0)):  # independently: the loop at each step, not re-checked
        with pytest.raises(StoppedRun) as stop:
            _dynamics_loop(robot, controller, pose0, reference.duration, period=0.02, delay=0, tyre=None, step=step,
                           feedback="pose", policy="closest", until=None)
        stops.append(stop.value.t)
    coarse, fine = stops
    assert fine > coarse + 0.1  # later than the re-check's margin: the later stop is the error
    head = (f"the loop diverged at t = {coarse:.6g} s at step 0.001 s, but the same loop at step 0.00025 s goes on "
            f"without it until the loop diverged at t = {fine:.6g} s: the loop's stop, which the step brought early")
    with pytest.raises(StoppedRun) as err:
        simulate_dynamics(robot, controller, pose0, reference.duration, period=0.02, step=1e-3)
    assert str(err.value) == f"{head}; lower the gain or the period"
    assert err.value.t == fine
    message = _cli_error(["track", path, "--reference", "circle", "--dynamics", "--gain", "4000"], capsys)
    assert message.startswith(f"{head}; lower the gain or the period")
    assert "step argument" not in message and "torques" not in message
    assert _named_options(message) <= TRACK_OPTIONS


@pytest.fixture
def diverging(monkeypatch):
    """A Stepper whose state overflows once it has reached t = 1 s, at any step: the loop's divergence, which its
    re-run at the shorter step reproduces (as a state no step keeps finite would)."""
    advance = Stepper.advance

    def overflowing(self, inputs=None, duration=0.0):
        if self.t >= 1.0 - 1e-9:
            self.state[3] = math.inf
        return advance(self, inputs, duration)

    monkeypatch.setattr(Stepper, "advance", overflowing)


def test_a_state_divergence_both_steps_reproduce_names_no_step_option(diverging, capsys):
    """The stepper's own error, "the simulation diverged before t = 1.02 s; use a smaller step", came out of
    simulate_dynamics and `wmrkit track --dynamics` unchanged: a shorter step diverged too, and track has no step
    option. Python now says both steps; the CLI names what track's user can change."""
    robot, reference = catalog.load("skid-steer-4"), builtin_reference("circle")
    cp = control_point(robot)
    controller = fast_law_controller(cp, PositionLaw.uniform("p", 1.0), reference)
    with pytest.raises(DivergedError) as err:
        simulate_dynamics(robot, controller, initial_pose_on(cp, reference), 3.0, period=0.02, step=1e-3)
    assert str(err.value) == ("the simulation diverged before t = 1.02 s at step 0.001 s, and the same loop at step "
                              "0.00025 s diverges too: lower the speeds or the gain, or use a step below 0.00025 s "
                              "(the step argument)")
    assert err.value.t == pytest.approx(1.02)
    message = _cli_error(["track", "skid-steer-4", "--reference", "circle", "--dynamics", "--duration", "3"], capsys)
    assert message.startswith("the simulation diverged before t = 1.02 s at step 0.001 s, and the same loop at "
                              "step 0.00025 s diverges too")
    assert "step argument" not in message and "smaller step" not in message
    assert "track integrates at 0.001 s, which no option changes" in message
    assert _named_options(message) <= TRACK_OPTIONS


def test_a_state_divergence_the_shorter_step_brings_later_names_no_step_option(monkeypatch, capsys):
    """The state overflowing from t = 1 s at the 1 ms step and from 1.5 s at the re-check's: judge()'s "the robot's
    stop, which the step brought early; use smaller torques or speeds, and a step of at most 0.00025 s (the step
    argument)" came out of `wmrkit track` as it was."""
    advance = Stepper.advance

    def overflowing(self, inputs=None, duration=0.0):
        if self.t >= (1.0 if self.step == 1e-3 else 1.5) - 1e-9:
            self.state[3] = math.inf
        return advance(self, inputs, duration)

    monkeypatch.setattr(Stepper, "advance", overflowing)
    robot, reference = catalog.load("skid-steer-4"), builtin_reference("circle")
    cp = control_point(robot)
    controller = fast_law_controller(cp, PositionLaw.uniform("p", 1.0), reference)
    head = ("the simulation diverged before t = 1.02 s at step 0.001 s, but the same loop at step 0.00025 s goes on "
            "without it until the simulation diverged before t = 1.52 s: the robot's stop, which the step brought "
            "early")
    with pytest.raises(DivergedError) as err:
        simulate_dynamics(robot, controller, initial_pose_on(cp, reference), 3.0, period=0.02, step=1e-3)
    assert str(err.value) == (f"{head}; use smaller torques or speeds, and a step of at most 0.00025 s (the step "
                              "argument)")  # Python: simulate_dynamics takes a step
    message = _cli_error(["track", "skid-steer-4", "--reference", "circle", "--dynamics", "--duration", "3"], capsys)
    assert message.startswith(f"{head}; lower the speed or the gain; track integrates at 0.001 s, which no option "
                              "changes")
    assert "step argument" not in message and _named_options(message) <= TRACK_OPTIONS


def test_track_from_python_names_the_loop_that_takes_a_step(diverging):
    """track() has no step argument either: it names the Python loop that has one."""
    from wmrkit.control import track

    with pytest.raises(WmrkitError) as err:
        track(catalog.load("skid-steer-4"), builtin_reference("circle"), dynamics=True, duration=3.0)
    assert "step argument" not in str(err.value) and "smaller step" not in str(err.value)
    assert "in Python, wmrkit.control.simulate_dynamics(..., step=...)" in str(err.value)


@pytest.mark.parametrize("period", [None, 0.05])
def test_a_diverged_kinematic_law_advises_a_period_only_when_the_loop_has_one(period):
    """A continuous loop (``period=None``) whose law's command passes 1e6 m/s said "lower the gain or the period":
    it has no period. Its twist grows as exp(t / 0.01 s) from t = 0.5 s (a law of ours, independent of the loop);
    the continuous loop says "lower the gain", the sampled one the period too."""
    from wmrkit.control.loop import simulate

    def exploding(t, pose, integral):
        return np.array([math.exp(max(0.0, t - 0.5) / 0.01), 0.0, 0.0]), np.zeros(3)

    with pytest.raises(StoppedRun) as err:
        simulate(catalog.load("diff-drive"), exploding, np.zeros(3), 1.0, period=period)
    assert 0.5 + 0.01 * math.log(1e6) - 0.05 <= err.value.t <= 0.5 + 0.01 * math.log(1e6) + 0.05  # where it passes
    assert str(err.value).endswith("lower the gain" if period is None else "lower the gain or the period")
