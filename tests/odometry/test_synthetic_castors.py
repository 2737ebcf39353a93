"""The castor angles of the synthetic generator: its fast slip rows against wheel_slip_rows, bit for bit."""

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry import synthetic
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.robot import Robot
from wmrkit.wheels import wheel_slip_rows

DOUBLE_CASTOR = {"name": "diff-and-double-castor", "wheels": [
    {"name": "left", "type": "fixed", "position": [0, 0.2], "heading": 0, "r": 0.05, "actuated": ["spin"],
     "sensed": ["spin"]},
    {"name": "right", "type": "fixed", "position": [0, -0.2], "heading": 0, "r": 0.05, "actuated": ["spin"],
     "sensed": ["spin"]},
    {"name": "trailer", "type": "double_castor", "position": [-0.3, 0], "beta": "100 deg", "d": 0.1, "b": 0.05,
     "r": 0.04, "sensed": ["steer", "spin1", "spin2"]}]}


def _robots() -> list[Robot]:
    return [catalog.load("thesis-omni-castor"), catalog.load("thesis-steer-castor"), Robot.from_dict(DOUBLE_CASTOR)]


@pytest.mark.parametrize("robot", _robots(), ids=lambda r: r.name)
def test_slip_rows_at_one_angle_are_wheel_slip_rows(robot):
    angles = np.random.default_rng(1).uniform(-10.0, 10.0, 200)
    for wheel in robot.wheels:
        rows = synthetic._slip_rows_at(wheel)
        for b in angles:
            np.testing.assert_array_equal(rows(np.float64(b)), wheel_slip_rows(wheel, b))


@pytest.mark.parametrize("robot", _robots(), ids=lambda r: r.name)
def test_castor_logs_are_those_of_wheel_slip_rows(robot, monkeypatch):
    """The whole log (castor angles from the ODE, turning by radians) is the one the ODE gave with
    wheel_slip_rows itself, bit for bit."""
    profile = TwistProfile.from_segments([(1.5, 0.3, 0.0, 0.4), (1.0, 0.3, 0.0, -0.5)])
    fast = simulate(robot, profile, 20.0).log
    monkeypatch.setattr(synthetic, "_slip_rows_at", lambda wheel: lambda b: wheel_slip_rows(wheel, b))
    slow = simulate(robot, profile, 20.0).log
    castors = [f"{w.name}.steer" for w in robot.wheels if w.type in ("castor", "double_castor")]
    turned = np.ptp(fast.positions[:, [fast.joints.index(j) for j in castors]], axis=0)
    assert fast.joints == slow.joints and (turned > 0.5).all()
    np.testing.assert_array_equal(fast.positions, slow.positions)
