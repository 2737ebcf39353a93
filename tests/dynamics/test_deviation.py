"""``wmrkit simulate --path`` compares the run with the path its program commands (dynamics.deviation)."""

from __future__ import annotations

import dataclasses
import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.dynamics.deviation import nominal_poses
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program, twist_program
from wmrkit.dynamics.simulate import Inputs, simulate
from wmrkit.errors import ShapeError, WmrkitError


def rk4_poses(time: np.ndarray, twists: np.ndarray, t_out: np.ndarray, h: float = 1e-3) -> np.ndarray:
    """The pose ODE x' = R(theta) (vx, vy), theta' = omega, twists linear between knots, by classical RK4 at a
    step `h` that divides the output times' spacing (written here, independent of the library)."""
    def rate(t, s):
        vx, vy, om = (np.interp(t, time, twists[:, k]) for k in range(3))
        c, sn = np.cos(s[2]), np.sin(s[2])
        return np.array([c * vx - sn * vy, sn * vx + c * vy, om])

    s, t, out = np.zeros(3), 0.0, []
    for target in t_out:
        while t < target - 1e-12:
            k1 = rate(t, s)
            k2 = rate(t + h / 2, s + h / 2 * k1)
            k3 = rate(t + h / 2, s + h / 2 * k2)
            k4 = rate(t + h, s + h * k3)
            s, t = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), t + h
        out.append(s.copy())
    return np.array(out)


def test_nominal_poses_are_the_integrated_twists():
    """A circle in closed form (x = v/w sin wt, y = v/w (1 - cos wt)), and a program's ramps and turns against
    RK4 written here; knots between the samples and outside them (held) included."""
    t = np.linspace(0.0, 10.0, 41)
    circle = nominal_poses(np.array([0.0]), np.array([[2.0, 0.0, 0.5]]), t)
    assert circle == pytest.approx(np.column_stack([4 * np.sin(0.5 * t), 4 * (1 - np.cos(0.5 * t)), 0.5 * t]),
                                   abs=1e-12)
    time = np.array([0.3, 1.0, 1.25, 4.0, 4.7])
    twists = np.array([[0.0, 0.0, 0.0], [1.5, 0.2, 0.0], [1.5, 0.2, 0.8], [1.0, -0.3, -1.1], [0.5, 0.0, 0.4]])
    t = np.arange(0.0, 6.01, 0.05)
    assert nominal_poses(time, twists, t) == pytest.approx(rk4_poses(time, twists, t), abs=1e-9)


@pytest.fixture(scope="module")
def skid():
    return DynamicModel.of(catalog.load("skid-steer-4"))


def test_simulation_deviation_is_from_the_commanded_twists(skid):
    """Simulation.nominal_pose is the program's twists integrated (RK4 here) at the records' times, and
    deviation() compares the simulated poses with it; torque inputs program no path."""
    inputs, duration = path_program(skid, "turn", speed=1.0)
    sim = simulate(skid, inputs, duration, record_step=0.01)
    assert inputs.twist_time == pytest.approx(inputs.time)
    nominal = rk4_poses(inputs.twist_time, inputs.twist, sim.t)
    assert sim.nominal_pose == pytest.approx(nominal, abs=1e-8)
    distance = np.hypot(*(sim.pose[:, :2] - nominal[:, :2]).T)
    dev = sim.deviation()
    assert dev.max_position == pytest.approx(distance.max(), abs=1e-8)
    assert dev.end_position == pytest.approx(distance[-1], abs=1e-8)
    assert dev.end_heading == pytest.approx(sim.pose[-1, 2] - nominal[-1, 2], abs=1e-8)
    assert dev.end_heading < -0.1  # the skid steer turns less than commanded (docs/dynamics.md: 0.2 for 1/3 rad/s)
    torques = Inputs.torques_only(skid, [0.0], {})
    assert simulate(skid, torques, 0.1).deviation() is None
    with pytest.raises(ShapeError, match=r"twist: expected finite body twists of shape \(2, 3\)"):
        dataclasses.replace(inputs, twist=np.zeros((3, 3)), twist_time=np.array([0.0, 1.0]))
    with pytest.raises(WmrkitError, match="give both"):
        dataclasses.replace(inputs, twist=None)
    # new knots (a closed loop's held references) keep the program's twists on their own knots
    held = dataclasses.replace(inputs, time=np.array([0.5]), torques=inputs.torques[:1],
                               rate_reference=inputs.rate_reference[:1], heading_reference=inputs.heading_reference[:1])
    assert held.twist is inputs.twist and held.twist_time is inputs.twist_time


def test_twist_program_keeps_a_copy_of_the_twists(skid):
    twists = np.array([[1.0, 0.0, 0.0]])
    inputs = twist_program(skid, [0.0], twists)
    assert twists.flags.writeable and inputs.twist == pytest.approx(twists) and not inputs.twist.flags.writeable


def test_skid_steer_rectangle_warns_that_it_left_the_path(capsys, tmp_path):
    """The skid steer driven by the no-slip wheel rates of the rectangle turns about 2/3 of each corner: it ended
    23.8 m from the programmed end, 2.7 rad short, with exit 0 and no word of it. The deviation is the simulated
    poses (--out) against the program's twists integrated here."""
    out = tmp_path / "run.csv"
    code = main(["simulate", "skid-steer-4", "--path", "rectangle", "--out", str(out), "--json"])
    text, err = capsys.readouterr()
    data = json.loads(text)
    assert code == 0
    assert len(data["warnings"]) == 1 and err.count("\n") == 2 and err.startswith(f"wmrkit: samples written to {out}\n")
    warning = data["warnings"][0]
    assert warning.startswith("the robot left the programmed path: up to 24.2 m from it")
    assert "no no-slip motion" in warning and "wmrkit calibrate" in warning and "docs/slip.md" in warning
    run = np.loadtxt(out, delimiter=",", skiprows=1)
    inputs, _ = path_program(DynamicModel.of(catalog.load("skid-steer-4")), "rectangle")
    nominal = rk4_poses(inputs.twist_time, inputs.twist, run[:, 0])
    distance = np.hypot(*(run[:, 1:3] - nominal[:, :2]).T)
    dev = data["deviation"]
    assert dev["large"] is True
    assert dev["max_position"] == pytest.approx(distance.max(), abs=1e-6)  # the CSV's 9 digits
    assert dev["end_position"] == pytest.approx(distance[-1], abs=1e-6)
    assert dev["end_heading"] == pytest.approx(run[-1, 3] - nominal[-1, 2], abs=1e-6)
    assert dev["max_time"] == pytest.approx(run[np.argmax(distance), 0])
    assert dev["end_heading"] < -2.0 and dev["path_turn"] == pytest.approx(nominal[-1, 2], abs=1e-6)
    code = main(["simulate", "skid-steer-4", "--path", "rectangle"])
    text, err = capsys.readouterr()
    assert code == 0 and "from the programmed path: 24.2 m at most" in text
    assert err.startswith("wmrkit: warning: the robot left the programmed path") and err.count("\n") == 1


def test_forklift_rectangle_stays_near_its_path_and_silent(capsys):
    code = main(["simulate", "forklift", "--path", "rectangle", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["warnings"] == []
    dev = data["deviation"]
    assert dev["large"] is False and dev["max_position"] < 0.1 * dev["path_size"] and dev["end_position"] < 0.2
    assert abs(dev["end_heading"]) < 0.1


def test_simulate_errors_stay_json_objects(capsys, tmp_path):
    code = main(["simulate", "skid-steer-4", "--path", "rectangle", "--speed", "nan", "--json"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and json.loads(err)["error"].startswith("--speed: cannot read 'nan'")
    torques = tmp_path / "t.csv"
    torques.write_text("time,front_left.spin\n0,1\n0.01,1\n", encoding="utf-8")
    code = main(["simulate", "skid-steer-4", "--torques", str(torques), "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["deviation"] is None


def _rk4_through_knots(time, twists, t_out, pose0, h=2e-3):
    """The pose ODE by classical RK4 from ``t_out[0]``, stepping onto every knot and output time (the twist is
    smooth within each step, so the error is O(h^4)); written here, independent of the library."""
    def rate(t, s):
        vx, vy, om = (np.interp(t, time, twists[:, k]) for k in range(3))
        c, sn = math.cos(s[2]), math.sin(s[2])
        return np.array([c * vx - sn * vy, sn * vx + c * vy, om])

    stops = np.union1d(t_out, time[(time > t_out[0]) & (time < t_out[-1])])
    s, out = np.array(pose0, dtype=float), [np.array(pose0, dtype=float)]
    for a, b in itertools.pairwise(stops):
        n = max(1, math.ceil((b - a) / h))
        dt = (b - a) / n
        for i in range(n):
            t = a + i * dt
            k1 = rate(t, s)
            k2 = rate(t + dt / 2, s + dt / 2 * k1)
            k3 = rate(t + dt / 2, s + dt / 2 * k2)
            k4 = rate(t + dt, s + dt * k3)
            s = s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if np.isin(b, t_out):
            out.append(s.copy())
    return np.array(out)


_knot = st.tuples(st.floats(-2, 2), st.floats(-1, 1), st.floats(-3, 3))


@settings(max_examples=75)
@given(st.lists(st.tuples(st.floats(-1, 3.5), _knot), min_size=1, max_size=5, unique_by=lambda k: round(k[0], 3)),
       st.sampled_from([0.05, 0.1, 0.3, 0.7]), st.floats(-0.5, 0.5), st.floats(0.5, 3.0),
       st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(-4, 4)), st.booleans())
def test_nominal_poses_of_random_twist_programs_are_rk4s(knots, dt, t0, duration, pose0, spin):
    """Random piecewise-linear twist programs (reversing, sideways, turning either way; knots before, between and
    after the samples; or a pure rotation) from a random pose: the poses are RK4's through the knots (written
    here), and a pure rotation stays where it is with the exact heading (the integral of the rate)."""
    knots = sorted(knots)
    time = np.array([k for k, _ in knots])
    twists = np.array([tw for _, tw in knots])
    if spin:
        twists[:, :2] = 0.0
    t = t0 + np.arange(0.0, duration + dt / 2, dt)
    got = nominal_poses(time, twists, t, pose0)
    assert got == pytest.approx(_rk4_through_knots(time, twists, t, pose0), abs=1e-8)
    if spin:
        assert np.all(got[:, :2] == np.asarray(pose0[:2]))
        fine = np.linspace(t[0], t[-1], 200_001)
        heading = pose0[2] + np.trapezoid(np.interp(fine, time, twists[:, 2]), fine)
        assert got[-1, 2] == pytest.approx(heading, abs=1e-6)
