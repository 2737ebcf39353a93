"""Control through the slip models in closed loop through the chapter-7 dynamics: the commands against the dynamic
model, tracking with and without them, the feedback options, and ``wmrkit track --slip-model``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.control.points import ControlError
from wmrkit.control.references import builtin_reference, reference_from_samples
from wmrkit.control.slip_control import slip_commands, slip_inverse
from wmrkit.control.slip_loop import simulate_slip_control
from wmrkit.control.track import track
from wmrkit.dynamics.model import DynamicModel
from wmrkit.kinematics.wheel_ik import wheel_commands
from wmrkit.slip.models import mqe, tyre_friction

FORK = catalog.load("forklift")
SKID = catalog.load("skid-steer-4")


@pytest.mark.parametrize("name, twist", [("forklift", (1.0, 0.2, 0.2)), ("forklift", (1.5, 0.45, 0.45)),
                                         ("skid-steer-4", (1.0, 0.0, 0.6))])
def test_commands_make_the_twist_a_steady_state_of_the_dynamic_model(name, twist):
    """The Lagrange model (Tables 7.1-7.2, its own mass matrix, bias terms, loads and tyres) at the slip model's
    velocities for the commands: the body does not accelerate and the free joints neither (7.37)."""
    robot = catalog.load(name)
    inv = slip_inverse(robot)
    c = slip_commands(inv, twist)
    model = DynamicModel.of(robot)
    q = mqe(robot, inv.assigned, c.rates, tyre_friction(robot), c.beta if len(c.beta) else None).q_dot
    np.testing.assert_allclose(inv.weights @ q[:3], inv.weights @ twist, atol=1e-7)  # the controlled point
    nu = np.zeros(model.n)
    nu[[model.names.index(v) for v in robot.velocity_names]] = q
    beta = c.beta if len(c.beta) else None
    forces = model.contact_forces(beta, nu, model.normal_loads(beta, nu))
    acc = model.accelerations(beta, nu, forces=forces)
    free = [model.names.index(v) for v in robot.velocity_names[3:] if v not in inv.assigned]
    np.testing.assert_allclose(acc[:3], 0.0, atol=1e-6)
    np.testing.assert_allclose(acc[free], 0.0, atol=1e-6)


def _hold(twist):
    return lambda t, pose, integral: (np.asarray(twist, dtype=float), np.zeros(3))


def test_skid_steer_open_loop_turns_as_asked_only_with_slip_model_commands():
    twist = (1.0, 0.0, 0.6)
    turn = {}
    whole = slip_inverse(SKID, weights=np.eye(3))  # the whole twist asked, not only the point's velocity
    for sm in ("none", "mqe"):
        out = simulate_slip_control(SKID, _hold(twist), np.zeros(3), 4.0, period=0.1, slip_model=sm, inverse=whole)
        turn[sm] = (out["pose"][-1, 2] - out["pose"][-11, 2]) / 1.0
    assert turn["mqe"] == pytest.approx(0.6, rel=0.03)  # the rate servos' proportional error: about 2 %
    assert turn["none"] < 0.4  # the no-slip IK's commands turn about half as fast


@pytest.mark.parametrize("name, speed, radius, settle, factor", [("skid-steer-4", 1.0, 2.0, 3.0, 0.2),
                                                                ("forklift", 2.0, 4.0, 4.0, 0.6)])
def test_slip_model_commands_track_with_less_error_through_the_dynamics(name, speed, radius, settle, factor):
    robot = catalog.load(name)
    ref = builtin_reference("circle", speed=speed, size=radius)
    runs = {sm: track(robot, ref, dynamics=True, period=0.05, duration=6.0, slip_model=sm) for sm in ("none", "mqe")}
    rms = {sm: run.summary(settle)["rms_error"] for sm, run in runs.items()}
    assert rms["mqe"] < factor * rms["none"]
    assert runs["mqe"].slip_model == "mqe" and runs["mqe"].to_dict()["slip_model"] == "mqe"
    # the JSON's per-wheel spins are the commanded (slip-model) rates, not the no-slip IK's of the same twists
    spin = np.array(runs["mqe"].to_dict()["wheels"][robot.wheel_names[0]]["spin"])
    ik = np.asarray(wheel_commands(robot, runs["mqe"].twist).spin)[:, 0]
    assert np.all(np.isfinite(spin)) and np.max(np.abs(spin - ik)) > 1e-2


def test_feedback_options():
    ref = builtin_reference("circle", speed=1.0, size=2.0)
    runs = {fb: track(SKID, ref, dynamics=True, period=0.1, duration=4.0, slip_model="mqe", feedback=fb)
            for fb in ("odometry", "wls", "mqe")}
    # WLS with unit friction coefficients is the least-squares odometry (7.52 with mu = 1)
    np.testing.assert_allclose(runs["wls"].estimate, runs["odometry"].estimate, atol=1e-9)
    drift = {fb: np.hypot(*(r.estimate[:, :2] - r.pose[:, :2]).T).max() for fb, r in runs.items()}
    # slip-model commands slip on purpose: a kinematic estimator reads that as motion, the same model does not
    assert drift["mqe"] < 0.2 * drift["odometry"]
    assert runs["mqe"].summary(2.0)["rms_error"] < 0.2 * runs["odometry"].summary(2.0)["rms_error"]


@pytest.mark.parametrize("feedback", ["fk2", "mqe"])
def test_forklift_feedback_runs_and_follows_the_truck(feedback):
    run = track(FORK, builtin_reference("circle", speed=1.0, size=3.0), dynamics=True, period=0.05, duration=3.0,
                feedback=feedback, slip_model="mqe")
    assert run.estimate is not None and np.all(np.isfinite(run.estimate))
    assert np.hypot(*(run.estimate[:, :2] - run.pose[:, :2]).T).max() < 0.5


def test_refusals():
    ref = builtin_reference("circle")
    with pytest.raises(ControlError, match="dynamic plant"):
        track(SKID, ref, slip_model="mqe")
    with pytest.raises(ControlError, match="slip model"):
        track(SKID, ref, dynamics=True, slip_model="magic", duration=0.2)
    with pytest.raises(ControlError, match="feedback"):
        track(SKID, ref, dynamics=True, slip_model="mqe", feedback="gps", duration=0.2)
    with pytest.raises(ControlError, match="ramp"):
        track(SKID, ref, ramp=True)


def test_cli_track_with_the_slip_model(capsys):
    code = main(["track", "skid-steer-4", "--reference", "circle", "--size", "2", "--speed", "1", "--dynamics",
                 "--period", "0.1", "--slip-model", "mqe", "--feedback", "mqe", "--duration", "2", "--json"])
    assert code == 0
    d = json.loads(capsys.readouterr().out)
    assert d["slip_model"] == "mqe" and d["feedback"] == "mqe"
    assert len(d["tracking_error"]) == len(d["t"]) == len(d["estimate"]) == 21
    assert d["summary"]["rms_error"] < 0.1
    assert main(["track", "skid-steer-4", "--reference", "circle", "--slip-model", "mqe"]) == 2
    assert "needs --dynamics" in capsys.readouterr().err
    assert main(["track", "diff-drive", "--reference", "circle", "--dynamics", "--slip-model", "mqe"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wmrkit: error:") and "mass" in err and len(err.strip().splitlines()) == 1


def test_forklift_mqe_odometry_does_not_drift_held_or_ramped():
    """The forklift's drive wheels share one servo through its open differential (twist_program), so they no longer
    fight within a period when the commands are held: the MQE odometry's heading error stays constant after the
    launch, held or ramped over the period (first-order hold). With a servo per drive wheel it grew 0.013 rad/s."""
    base = builtin_reference("circle", speed=2.0, size=4.0, duration=8.0)
    t = np.arange(0.0, 8.0, 0.01)
    ref = reference_from_samples("circle from rest", t, base.sample(np.where(t < 2.0, t * t / 4.0, t - 1.0)))
    growth = {}
    for ramp in (False, True):
        run = track(FORK, ref, dynamics=True, period=0.05, duration=6.0, slip_model="mqe", feedback="mqe", ramp=ramp)
        heading_error = run.estimate[:, 2] - run.pose[:, 2]
        growth[ramp] = abs(heading_error[-1] - heading_error[-31])  # over the last 1.5 s
    assert growth[True] < 1e-3 and growth[False] < 1e-3
