"""``ik`` judges a ``gear`` between steering joints on the angles it sets (``beta_j - beta_j0 = ratio_j u``), as it
judges a linkage's law. Before, two double wheels whose steering a gear turns 1:2 were given headings 20.6 and -14.0
deg for the twist (1, 0, 1) and ``feasible: yes`` by ``wheel_commands``, ``wmrkit ik`` and the compiled
``realtime(robot).ik`` (so ``control_tick``): the gear sets the rear at twice the front's turn."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.control.tick import control_tick
from wmrkit.kinematics.gear_check import steer_breaches
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import wheel_commands

GEAR = "gear(front.steer, rear.steer)"
FRONT, REAR = np.array([0.3, 0.2]), np.array([-0.3, -0.2])


def _geared(ratios=(1.0, 2.0)) -> Robot:
    unit = {"type": "double", "heading": 0, "b": 0.06, "r": 0.08, "actuated": ["steer", "spin1", "spin2"]}
    return Robot.from_dict({
        "name": "geared-units", "wheels": [{**unit, "name": "front", "position": FRONT.tolist()},
                                           {**unit, "name": "rear", "position": REAR.tolist()}],
        "couplings": [{"kind": "gear", "joints": ["front.steer", "rear.steer"], "ratios": list(ratios)}]})


def _twist_for(front: float, rear: float, omega: float = 0.7) -> np.ndarray:
    """The twist rolling both wheels at headings `front`, `rear` [rad]: the ICR where their axles meet."""
    rows = np.array([[math.cos(front), math.sin(front)], [math.cos(rear), math.sin(rear)]])  # rolling directions
    icr = np.linalg.solve(rows, [rows[0] @ FRONT, rows[1] @ REAR])  # on both axles: (icr - p) . rolling = 0
    return np.array([omega * icr[1], -omega * icr[0], omega])


def _rolls(twist: np.ndarray, heading: np.ndarray) -> bool:
    """Brute force: each wheel's heading along its steering axis's velocity, mod pi."""
    for p, h in ((FRONT, heading[0]), (REAR, heading[1])):
        v = np.array([twist[0] - twist[2] * p[1], twist[1] + twist[2] * p[0]])
        if abs(v[0] * math.sin(h) - v[1] * math.cos(h)) > 1e-9:
            return False
    return True


def test_headings_out_of_a_steering_gears_ratio_are_not_feasible():
    robot = _geared()
    c = wheel_commands(robot, [1.0, 0.0, 1.0])
    np.testing.assert_allclose(np.degrees(c.heading), [20.556045, -14.036243], atol=1e-5)
    assert c.in_gear.all() and not c.in_steer_gear[0] and not c.feasible
    assert c.to_dict()["out_of_steer_gear"] == [GEAR]
    (b,) = steer_breaches(robot, np.array([1.0, 0.0, 1.0]), c.beta, 1e-9)
    # the rear moves faster: it sets u = -14.04 deg, so the front at -7.02 deg, 27.6 deg off its 20.56
    assert (b.coupling, b.column, b.reference) == (0, 0, 1)
    front, rear = math.atan2(0.3, 1.0 - 0.2), math.atan2(-0.3, 1.0 + 0.2)  # the axes' velocities' directions
    assert b.want - b.beta == pytest.approx(rear / 2 - front, abs=1e-12)
    assert b.slip == pytest.approx(math.hypot(1.0 - 0.2, 0.3) * math.sin(front - rear / 2), rel=1e-12)


@pytest.mark.parametrize("front", [0.3, -0.5, 1.2, 1.5, -1.4])
def test_a_twist_the_gear_can_roll_is_feasible_and_one_off_it_is_not(front):
    """Twists whose axles meet with the rear at twice the front's heading are feasible (also when ik keeps the
    rear's other root, current heading near 180 deg); 1e-4 rad off the ratio they are not."""
    robot = _geared()
    for rear, ok in ((2 * front, True), (2 * front + 1e-4, False)):
        twist = _twist_for(front, rear)
        for current in ([0.0, 0.0], [0.0, 3.0], [2.9, -0.1]):
            c = wheel_commands(robot, twist, heading=current)
            assert _rolls(twist, c.heading)
            assert bool(c.in_steer_gear[0]) == bool(c.feasible) == ok, (rear, current)


def test_the_realtime_ik_and_the_control_tick_agree_with_wheel_commands():
    robot = _geared()
    rt, rng = realtime(robot), np.random.default_rng(3)
    fronts = rng.uniform(-1.4, 1.4, 40)
    twists = np.concatenate([rng.normal(size=(40, 3)), [_twist_for(f, 2 * f) for f in fronts],
                             [_twist_for(f, 2 * f + 1e-3) for f in fronts]])
    batch = wheel_commands(robot, twists)  # >= 64 twists: the compiled batch
    assert 0 < batch.feasible.sum() < len(twists)
    rates, out = np.empty(len(robot.rate_names)), np.empty(2)
    for i, t in enumerate(twists):
        one = wheel_commands(robot, t)
        assert bool(one.feasible) == bool(batch.feasible[i])
        assert rt.ik(*t.tolist(), np.zeros(2), rates, out) == bool(one.feasible)
    tick = control_tick(robot, reduced=False).tick  # the full pose's law, blind to the gear (reduced=False)
    twist = np.empty(3)
    # the reference's velocity (1, 0, 1) is the twist: the robot on its reference
    assert not tick(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, np.zeros(2), twist, rates, out)
    assert tick(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, np.zeros(2), twist, rates, out)


def test_ik_names_the_steering_gear_and_how_far_off(tmp_path, capsys):
    path = tmp_path / "geared.json"
    path.write_text(json.dumps(_geared().to_dict()))
    assert main(["ik", str(path), "--twist", "1", "0", "1", "--json"]) == 1
    answer = json.loads(capsys.readouterr().out)
    assert answer["out_of_steer_gear"] == [GEAR] and answer["feasible"] is False
    (said,) = answer["warnings"]
    assert ("a steering gear cannot set these headings: the steering gear of wheels 'front' and 'rear' (ratios 1, 2) "
            "sets front at heading -7.01812 deg with "
            "rear at -14.0362 deg, not 20.556 deg, which the twist needs (27.6 deg off") in said
    assert main(["ik", str(path), "--twist", "1", "0", "0"]) == 0
    assert "feasible: yes" in capsys.readouterr().out
