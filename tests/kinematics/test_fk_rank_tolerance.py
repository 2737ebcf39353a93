"""forward_kinematics decides what the rates determine with the rank tests' one tolerance (linalg.rank_cutoff), on
the robot's nondimensional matrix of the centroid's twist: two fixed wheels on one axle 3e-12 m apart (the turn rate
undetermined to the rank tests) gave a turn rate from round-off, 1e-5 rad/s off, and another in the mirrored or moved
robot."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strategies import mirrored, moved, moved_twist
from wmrkit import Robot, Wheel, forward_kinematics, wheel_commands
from wmrkit.errors import ShapeError
from wmrkit.kinematics.wheel_ik import forward_kinematics_check, twist_is_determined

TWIST = np.array([0.7, 0.0, 0.3])
C, PHI = np.array([0.3, -0.2]), 0.4


def _pair(gap: float, k: float = 1.0) -> Robot:
    """Two fixed wheels rolling along x on the line x = 0, at y = 0.5 and 0.5 + gap [m], every length times k."""
    return Robot(name="pair", wheels=tuple(
        Wheel(name=f"w{i}", type="fixed", l=k * (0.5 + i * gap), alpha=math.pi / 2, beta=math.pi / 2, r=k * 0.1)
        for i in range(2)))


def _fk(robot: Robot, twist: np.ndarray) -> np.ndarray:
    c = wheel_commands(robot, twist)
    return forward_kinematics(robot, dict(zip(robot.rate_names, c.rates.tolist(), strict=True)))[0]


@pytest.mark.parametrize("gap", [3e-12, 1e-10, 1e-6])
def test_the_twist_of_a_mirrored_and_a_moved_robot_is_the_mirrored_and_moved_twist(gap):
    robot = _pair(gap)
    got = _fk(robot, TWIST)
    flip = np.array([1.0, -1.0, -1.0])
    np.testing.assert_allclose(_fk(mirrored(robot), TWIST * flip) * flip, got, atol=1e-12)
    np.testing.assert_allclose(_fk(moved(robot, C, PHI), moved_twist(TWIST, C, PHI)), moved_twist(got, C, PHI),
                               atol=1e-9)


@pytest.mark.parametrize("gap", [3e-12, 1e-10])
def test_a_turn_rate_the_rank_tests_call_undetermined_is_not_solved_from_round_off(gap):
    robot = _pair(gap)
    assert not twist_is_determined(robot, list(robot.rate_names))
    vx, _, omega = _fk(robot, TWIST)
    # the minimum-norm twist of the centroid (y = 0.5 + gap / 2 m) with its speed: no turn, whatever the gap
    assert omega == pytest.approx(0.0, abs=1e-12) and vx == pytest.approx(0.7 - 0.3 * (0.5 + gap / 2), abs=1e-12)


@pytest.mark.parametrize("k", [1e-6, 1e3])
def test_a_determined_twist_is_found_at_any_scale(k):
    robot = _pair(1e-3, k)
    assert twist_is_determined(robot, list(robot.rate_names))
    np.testing.assert_allclose(_fk(robot, TWIST * [k, k, 1]), TWIST * [k, k, 1], rtol=1e-6, atol=1e-12 * k)


@pytest.mark.parametrize("rtol", [-0.1, float("nan"), float("inf"), 1.5, "0.1", None, True])
def test_forward_kinematics_check_refuses_an_rtol_that_is_not_a_fraction(rtol):
    robot = _pair(1e-3)
    with pytest.raises(ShapeError, match=r"^rtol: expected a fraction .* in \[0, 1\], got "):
        forward_kinematics_check(robot, {"w0": 1.0, "w1": 1.0}, rtol=rtol)


@pytest.mark.parametrize("rtol", [0, 0.0, 0.02, 1])
def test_forward_kinematics_check_takes_a_fraction(rtol):
    assert forward_kinematics_check(_pair(1e-3), {"w0": 1.0, "w1": 1.0}, rtol=rtol).consistent
