"""A fixed wheel's lateral slip at the edges of the envelope (1 km robots, twists of 1e6 rad/s): round-off is no slip.

The slip (8.14) is a sum of products of the twist with entries of at most 1, 1 and l; at l = 1 km and omega = 1e6
rad/s the round-off of cos(pi/2) left 1.2e-7 m/s on a wheel rolling exactly along its path, over slip_tol (1e-9 m/s):
``wmrkit ik`` printed "feasible: NO (a fixed wheel would slip sideways)" and exited 1 for a rotation every wheel rolls
along. Checked here on twists feasible by construction (every fixed wheel's axle through the ICR)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import wheel_commands


def _rolling_about(icr: tuple[float, float], points: list[tuple[float, float]]) -> Robot:
    """Fixed wheels at `points` rolling about `icr`: each heading perpendicular to its radius from the ICR."""
    return Robot.from_dict({"name": "icr", "wheels": [
        {"name": f"w{i}", "type": "fixed", "position": [x, y], "r": 0.1,
         "heading": math.atan2(x - icr[0], -(y - icr[1]))} for i, (x, y) in enumerate(points)]})


size = st.floats(1e-3, 1e3)
unit = st.floats(-1.0, 1.0)


@settings(max_examples=60, deadline=None)
@given(scale=size, icr=st.tuples(unit, unit), points=st.lists(st.tuples(unit, unit), min_size=2, max_size=4),
       omega=st.sampled_from([1.0, -1e3, 1e6, -1e6]))
@example(scale=708.0, icr=(0.0, 0.0), points=[(0.0, 1.0), (1.0, 1.0)], omega=1.0)  # a wheel 1001 m out, refused
def test_a_rotation_every_fixed_wheel_rolls_along_is_feasible_at_any_scale(scale, icr, points, omega):
    _check_rolling(scale, icr, points, omega, compiled=False)


@pytest.mark.parametrize(("scale", "icr", "points", "omega"), [
    (1e3, (0.0, 0.0), [(0.9, 0.0), (-0.9, 0.0), (0.0, 0.9)], 1e6),  # 600 m out at 1e6 rad/s: 6e8 m/s at the wheels
    (1e3, (0.5, -0.3), [(-0.8, 0.6), (0.7, 0.9)], -1e3),
    (1e-3, (0.2, 0.1), [(0.9, -0.4), (-0.6, -0.7), (0.1, 0.95), (-0.9, 0.3)], 1e6)])
def test_the_compiled_ik_finds_the_same_rotations_feasible(scale, icr, points, omega):
    """The single-call ik of three robots at the envelope's corners (compiled per robot: seconds each, so not for
    each of the random robots above)."""
    _check_rolling(scale, icr, points, omega, compiled=True)


def _check_rolling(scale, icr, points, omega, compiled: bool) -> None:
    scale /= 1.5  # the unit square's corners within 1 km of the origin (MAX_SIZE) at scale 1e3: 0.94 of it
    icr = (icr[0] * scale, icr[1] * scale)
    points = [(x * scale, y * scale) for x, y in points]
    if min(math.dist(p, icr) for p in points) < 1e-2 * scale:  # a wheel on the ICR has no rolling direction
        assert not compiled, "a fixed case must be a real one"
        return
    robot = _rolling_about(icr, points)
    twist = np.array([omega * icr[1], -omega * icr[0], omega])  # v = omega z x (0 - icr)
    if np.abs(twist).max() > 1e6:
        assert not compiled, "a fixed case must be a real one"
        return
    commands = wheel_commands(robot, twist)
    assert bool(commands.feasible), commands.slip
    if compiled:
        ik = realtime(robot).ik
        assert ik(*twist.tolist(), np.zeros(0), np.zeros(len(robot.rate_names)), np.zeros(0))
    # the same twist plus a motion along the first wheel's axle of 1e-6 of the wheel speeds (far above round-off)
    speed = max(abs(omega) * math.dist(p, icr) for p in points)
    heading = math.atan2(points[0][0] - icr[0], -(points[0][1] - icr[1]))
    pushed = twist + (1e-6 * speed + 1e-8) * np.array([-math.sin(heading), math.cos(heading), 0.0])
    assert not bool(wheel_commands(robot, pushed).feasible)


def test_a_kilometre_robot_turning_at_a_million_rad_per_s_is_feasible_on_the_command_line(tmp_path, capsys):
    """Before: exit 1, 'feasible: NO (a fixed wheel would slip sideways)', wheel 'r' slips at +1.22465e-07 m/s."""
    path = tmp_path / "km.yaml"
    path.write_text("name: km\nwheels:\n"
                    "  - {name: l, type: fixed, position: [0, 1000], heading: 0, r: 0.1}\n"
                    "  - {name: r, type: fixed, position: [0, -1000], heading: 0, r: 0.1}\n"
                    "  - {name: c, type: castor, position: [-500, 0], d: 0.1, r: 0.1}\n")
    assert main(["ik", str(path), "--twist", "0", "0", "1e6"]) == 0
    out = capsys.readouterr()
    assert out.out.rstrip().endswith("feasible: yes") and "warning" not in out.err
    assert main(["ik", str(path), "--twist", "0", "1e-3", "1e6"]) == 1  # a real lateral motion still slips
