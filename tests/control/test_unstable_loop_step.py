"""A closed loop through the dynamics (``track --dynamics``, ``simulate_dynamics``, ``simulate_slip_control``) that
stops at a step too long for the tyres is re-run at a shorter step: when the same loop goes on there, the error
blames the step, not the robot; a stop that the shorter step reproduces keeps its message."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.control import builtin_reference, control_point
from wmrkit.control.dynamic_plant import fast_law_controller, simulate_dynamics
from wmrkit.control.laws import PositionLaw
from wmrkit.control.slip_loop import simulate_slip_control
from wmrkit.control.track import initial_pose_on
from wmrkit.dynamics import runs
from wmrkit.dynamics.runs import LiftOffError
from wmrkit.errors import WmrkitError


def _loop(robot, reference):
    cp = control_point(robot)
    return fast_law_controller(cp, PositionLaw.uniform("p", 1.0), reference), initial_pose_on(cp, reference)


def test_a_loop_that_lifts_off_only_at_a_long_step_blames_the_step():
    """The skid steer on the square at a 20 ms step: its turns oscillate from the first corner on and 'lift off'
    a wheel at t = 36.24 s (it said "contact 'front_left' lifts off the ground ..."); the same loop at 1 ms drives
    the whole square with its wheels down."""
    robot, square = catalog.load("skid-steer-4"), builtin_reference("square")
    controller, pose0 = _loop(robot, square)
    with pytest.raises(WmrkitError) as err:
        simulate_dynamics(robot, controller, pose0, square.duration, period=0.02, step=0.02)
    assert not isinstance(err.value, LiftOffError)
    assert str(err.value) == (
        "contact 'front_left' lost its load at t = 36.24 s at step 0.02 s, but the same loop at step 0.001 s goes on "
        f"to t = {square.duration:g} s without it: the step is too long for the tyres (the integration is unstable, "
        "not the robot); use a step of at most 0.001 s (the step argument)")
    fine = simulate_dynamics(robot, controller, pose0, square.duration, period=0.02, step=0.001)  # independent
    assert fine["t"][-1] == pytest.approx(square.duration) and np.all(np.isfinite(fine["pose"]))


def test_the_slip_control_loop_blames_the_step_too():
    robot, square = catalog.load("skid-steer-4"), builtin_reference("square")
    controller, pose0 = _loop(robot, square)
    with pytest.raises(WmrkitError, match=r"lost its load at t = 13.6 s at step 0.04 s, but the same loop at step "
                                          r"0.001 s goes on to t = 15 s without it"):
        simulate_slip_control(robot, controller, pose0, 15.0, period=0.04, step=0.04, slip_model="mqe")


@pytest.mark.parametrize(("step", "last"), [(0.001, 1.51), (0.02, 1.53)])
def test_a_real_lift_off_in_the_loop_still_says_lift_off(step, last):
    """The forklift at 2 m/s takes the corner reference's corner at the grip and tips onto its drive wheels at
    t = 1.50 s at 1 ms and 1.52 s at 20 ms: the shorter step stops too, so the error is the lift-off."""
    robot, reference = catalog.load("forklift"), builtin_reference("corner", speed=2.0)
    controller, pose0 = _loop(robot, reference)
    with pytest.raises(LiftOffError, match="contact 'steer' lifts off the ground") as err:
        simulate_dynamics(robot, controller, pose0, reference.duration, period=0.02, step=step)
    assert 1.5 <= err.value.t <= last


def test_a_loop_whose_shorter_step_stops_later_names_both_stops(capsys):
    """The forklift on the arc-line at 2 m/s lifts its left drive wheel off at t = 2.401 s at 1 ms, and at 2.52 s at
    0.25 ms (and 0.0625 ms: the robot's, later). The loop's re-check ran to the loop's end and saw that later stop,
    but the error still gave only the 1 ms one ("contact 'left_drive' lifts off the ground at t = 2.401 s ...", t =
    2.401; `wmrkit track` the same). Now it is the later stop, at its time, naming both, as simulate's; each time
    checked against the loop run at that step without a re-check."""
    from wmrkit.cli.main import main
    from wmrkit.control.dynamic_plant import _dynamics_loop

    robot, reference = catalog.load("forklift"), builtin_reference("arc-line", speed=2.0)
    controller, pose0 = _loop(robot, reference)
    stops = []
    for step in (0.001, 0.00025):  # the loop itself, not re-checked, at the run's step and at the re-check's
        with pytest.raises(LiftOffError) as stop:
            _dynamics_loop(robot, controller, pose0, reference.duration, period=0.02, delay=0, tyre=None, step=step,
                           feedback="pose", policy="closest", until=None)
        assert stop.value.contact == "left_drive"
        stops.append(stop.value.t)
    coarse, fine = stops
    assert 2.4 <= coarse <= 2.41 and 2.52 <= fine <= 2.53
    with pytest.raises(LiftOffError) as err:
        simulate_dynamics(robot, controller, pose0, reference.duration, period=0.02, step=0.001)
    both = (f"contact 'left_drive' lost its load at t = {coarse:.6g} s at step 0.001 s, but the same loop at step "
            f"0.00025 s goes on without it until contact 'left_drive' lost its load at t = {fine:.6g} s: the robot's "
            "stop, which the step brought early")
    assert str(err.value) == (f"{both}; use smaller torques or speeds, and a step of at most 0.00025 s (the step "
                              "argument)")
    assert err.value.t == fine and err.value.contact == "left_drive"
    assert main(["track", "forklift", "--reference", "arc-line", "--speed", "2", "--dynamics"]) == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith(f"wmrkit: error: {both}; the servos follow ")
    assert main(["track", "forklift", "--reference", "arc-line", "--speed", "2", "--dynamics", "--slip-model",
                 "mqe"]) == 2  # the loop with slip-model commands (simulate_slip_control) is re-checked alike
    assert "at step 0.001 s, but the same loop at step 0.00025 s goes on without it until contact 'left_drive' lost " \
           "its load at t = 2.52" in capsys.readouterr().err


def test_a_loop_recheck_whose_budget_ends_before_the_loop_does_says_so(monkeypatch):
    """With a budget of 40 s of 1 ms steps the re-run of the skid steer's square (48 s) stops short of its end: it
    blamed the step ("goes on to t = 40 s without it: the step is too long ..."), and now says it is not known."""
    monkeypatch.setattr(runs, "RECHECK_STEPS", 40_000)
    robot, square = catalog.load("skid-steer-4"), builtin_reference("square")
    controller, pose0 = _loop(robot, square)
    with pytest.raises(WmrkitError) as err:
        simulate_dynamics(robot, controller, pose0, square.duration, period=0.02, step=0.02)
    assert str(err.value) == (
        "contact 'front_left' lost its load at t = 36.24 s at step 0.02 s; the same loop at step 0.001 s goes on "
        f"without it to t = 40 s, where the re-check's budget ends, short of the end at t = {square.duration:g} s: "
        "whether the step (the integration unstable) or the robot stops it is not known; use a step of at most "
        "0.001 s (the step argument) to tell, or smaller torques or speeds")


def test_track_names_no_step_option_when_the_step_is_to_blame(monkeypatch, capsys):
    """track integrates at DYNAMICS_STEP, which no option sets: a stop blamed on the step told its users "use a step
    of at most 0.001 s (the step argument)", which neither track() nor `wmrkit track` takes. With that step made
    20 ms (as simulate_dynamics at step=0.02 above), the error says what they can do instead."""
    import importlib

    from wmrkit.cli.main import main

    tracking = importlib.import_module("wmrkit.control.track")  # the module (wmrkit.control.track is the function)

    monkeypatch.setattr(tracking, "DYNAMICS_STEP", 0.02)
    advice = ("track integrates at 0.02 s, which no option changes; in Python, wmrkit.control.simulate_dynamics(..., "
              "step=0.001) runs the loop at the step that went on")
    with pytest.raises(WmrkitError) as err:
        tracking.track(catalog.load("skid-steer-4"), builtin_reference("square"), dynamics=True)
    assert str(err.value).startswith("contact 'front_left' lost its load at t = 36.24 s at step 0.02 s, but the "
                                     "same loop at step 0.001 s goes on to t = 48 s without it")
    assert str(err.value).endswith(f"(the integration is unstable, not the robot); {advice}")
    assert main(["track", "skid-steer-4", "--reference", "square", "--dynamics"]) == 2
    assert capsys.readouterr().err.endswith(f"; {advice}\n")
    monkeypatch.setattr(runs, "RECHECK_STEPS", 40_000)  # the verdict not known: no step option to tell it either
    with pytest.raises(WmrkitError, match=r"whether the step \(the integration unstable\) or the robot stops it is "
                                          r"not known; track integrates at 0.02 s, which no option changes; in "
                                          r"Python, .*step=0.001\) runs the loop at the step that would tell$"):
        tracking.track(catalog.load("skid-steer-4"), builtin_reference("square"), dynamics=True)
