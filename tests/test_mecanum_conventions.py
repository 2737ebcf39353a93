"""Mecanum roller conventions of the peers mapped onto the thesis's γ (docs/conventions.md, issue 8).

Modern Robotics (Lynch & Park, eq. 13.5) writes a Swedish wheel's driving speed as
``u_i = (1/r) [1, tan γ_MR] [[cos β, sin β], [-sin β, cos β]] [[-y_i, 1, 0], [x_i, 0, 1]] (ω, vx, vy)``, with β the
driving direction and γ_MR the sliding direction of the rollers measured from it; its Mecanum robot has
γ_MR = -45° at front-left. The thesis's γ (axle to contact-roller axis) is measured from the axle, 90° from the
driving direction, and to the roller's axis, 90° from its sliding direction: γ = γ_MR + 90° (mod 180°), which for
the ±45° of Mecanum rollers is γ = -γ_MR, and for omni wheels (γ_MR = 0) γ = 90°.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot, wheel_commands
from wmrkit.analysis.summary import analyze

CORNERS = {"fl": (0.3, 0.25), "fr": (0.3, -0.25), "rl": (-0.3, 0.25), "rr": (-0.3, -0.25)}
MR_GAMMA = {"fl": -45.0, "fr": 45.0, "rl": 45.0, "rr": -45.0}  # Modern Robotics' mecanum robot (Fig. 13.5)
R = 0.05


def _modern_robotics_speeds(twist: np.ndarray, gamma_mr: dict[str, float]) -> np.ndarray:
    omega, vx, vy = twist[2], twist[0], twist[1]
    out = []
    for name, (x, y) in CORNERS.items():
        g = math.radians(gamma_mr[name])
        out.append((1 / R) * np.array([1, math.tan(g)]) @ np.array([-y * omega + vx, x * omega + vy]))  # β = 0
    return np.array(out)


def _robot(wheels: list[dict]) -> Robot:
    return Robot.from_dict({"name": "m", "wheels": wheels})


@pytest.mark.parametrize("twist", [[0.4, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.7], [0.3, -0.2, 0.5]])
def test_modern_robotics_gamma_is_minus_the_thesis_gamma(twist):
    twist = np.array(twist)
    want = _modern_robotics_speeds(twist, MR_GAMMA)
    thesis = _robot([{"name": n, "type": "swedish", "position": list(p), "heading": 0, "r": R, "r_r": 0.01,
                      "gamma": f"{-MR_GAMMA[n]} deg"} for n, p in CORNERS.items()])
    np.testing.assert_allclose(wheel_commands(thesis, twist).spin, want, atol=1e-12)
    typed = _robot([{"name": n, "type": "mecanum", "position": list(p), "r": R} for n, p in CORNERS.items()])
    np.testing.assert_allclose(wheel_commands(typed, twist).spin, want, atol=1e-12)


def test_copying_modern_robotics_gamma_gives_the_mirrored_robot():
    """The silent mistake of the issue: the MR angles typed as the thesis's γ strafe the wrong way."""
    copied = _robot([{"name": n, "type": "swedish", "position": list(p), "heading": 0, "r": R, "r_r": 0.01,
                      "gamma": f"{MR_GAMMA[n]} deg"} for n, p in CORNERS.items()])
    strafe = np.array([0.0, 0.3, 0.0])
    np.testing.assert_allclose(wheel_commands(copied, strafe).spin, -_modern_robotics_speeds(strafe, MR_GAMMA),
                               atol=1e-12)


def test_mecanum_gamma_can_be_overridden_and_axis_wheels_need_it():
    w = {"name": "a", "type": "mecanum", "position": [0.3, 0.2], "r": R, "gamma": "-45 deg"}
    assert math.degrees(_robot([w]).wheels[0].gamma) == pytest.approx(-45)
    from wmrkit.errors import DescriptionError

    with pytest.raises(DescriptionError, match="no quadrant"):
        _robot([{"name": "a", "type": "mecanum", "position": [0.3, 0.0], "r": R}])


@pytest.mark.parametrize("gamma_mr", [0.0, 30.0, -45.0, 60.0, -80.0])
def test_modern_robotics_gamma_is_the_thesis_gamma_minus_90_deg(gamma_mr):
    """The general relation (audit of the doors): omni wheels have gamma_MR = 0 and the thesis's gamma = 90 deg, so
    gamma = -gamma_MR holds only at +-45 deg."""
    twist = np.array([0.3, -0.7, 1.1])
    want = _modern_robotics_speeds(twist, dict.fromkeys(CORNERS, gamma_mr))
    thesis = _robot([{"name": n, "type": "swedish", "position": list(p), "heading": 0, "r": R, "r_r": 0.01,
                      "gamma": f"{gamma_mr + 90.0} deg"} for n, p in CORNERS.items()])
    np.testing.assert_allclose(wheel_commands(thesis, twist).spin, want, atol=1e-9)


@pytest.mark.parametrize(("lx", "ly"), [(0.2, 0.15), (0.25, 0.1), (0.175, 0.175)])
def test_ros2_mecanum_drive_controller_wheel_speeds(lx, ly):
    """docs/conventions.md: ROS 2's mecanum_drive_controller commands (vx -+ vy -+ (lx + ly) omega) / r, in its
    order front-left, front-right, rear-right, rear-left; wmrkit's spins of a `type: mecanum` robot at (+-lx, +-ly)
    are those, for any split of the sum 0.35 m."""
    r, k = 0.05, lx + ly
    names = {"front_left_wheel_joint": (lx, ly), "front_right_wheel_joint": (lx, -ly),
             "rear_right_wheel_joint": (-lx, -ly), "rear_left_wheel_joint": (-lx, ly)}
    robot = _robot([{"name": n, "type": "mecanum", "position": list(p), "r": r} for n, p in names.items()])
    rng = np.random.default_rng(7)
    for vx, vy, w in rng.uniform(-1, 1, (20, 3)):
        ros = np.array([vx - vy - k * w, vx + vy + k * w, vx - vy + k * w, vx + vy - k * w]) / r
        np.testing.assert_allclose(wheel_commands(robot, [vx, vy, w]).spin, ros, rtol=1e-12, atol=1e-12)
    iso = analyze(robot).to_dict()  # the sum is the natural length: kappa 1 there
    assert iso["characteristic_length"] == pytest.approx(k, rel=1e-9) and iso["condition_number"] == pytest.approx(1)
