"""Forward kinematics by least squares (4.11): closed forms, residual as slip indicator, names, batching."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot, ShapeError, UnknownNameError, catalog
from wmrkit.kinematics.wheel_ik import forward_kinematics, resolve_rate_name, twist_is_determined, wheel_commands

DIFF = Robot.from_dict({"name": "diff", "wheels": [
    {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.05},
    {"name": "right", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.05},
]})


def test_differential_drive_closed_form():
    rng = np.random.default_rng(0)
    left, right = rng.normal(size=(2, 30))
    twist, residual = forward_kinematics(DIFF, {"left": left, "right.spin": right})
    np.testing.assert_allclose(twist[:, 0], 0.05 * (left + right) / 2, rtol=1e-12)
    np.testing.assert_allclose(twist[:, 1], 0.0, atol=1e-14)
    np.testing.assert_allclose(twist[:, 2], 0.05 * (right - left) / 0.4, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(residual, 0.0, atol=1e-13)


def test_mecanum_is_the_pseudo_inverse_of_modern_robotics_h():
    """Lynch & Park eq. (13.5)-(13.10): wheel speeds u = H(0) twist, F = pinv(H(0)) (4 Mecanum, l = 0.25, w = 0.275)."""
    mec = catalog.load("mecanum-4")  # WPILib roller layout: fl, rr at +45 deg, fr, rl at -45 deg
    r, l, w = 0.0762, 0.25, 0.275
    # r u = (vx -+ vy -+ (l + w) omega) per wheel, in our twist order (vx, vy, omega)
    h = np.array([[1, -1, -(l + w)], [1, 1, l + w], [1, 1, -(l + w)], [1, -1, l + w]]) / r
    rng = np.random.default_rng(1)
    spins = rng.normal(size=(25, 4))
    twist, residual = forward_kinematics(mec, dict(zip(mec.wheel_names, spins.T, strict=True)))
    np.testing.assert_allclose(twist, spins @ np.linalg.pinv(h).T, rtol=1e-10, atol=1e-12)
    consistent = spins @ np.linalg.pinv(h).T @ h.T  # projected onto the range of H: no slip left
    _, res_ok = forward_kinematics(mec, dict(zip(mec.wheel_names, consistent.T, strict=True)))
    np.testing.assert_allclose(res_ok, 0.0, atol=1e-12)
    assert np.all(residual[np.linalg.norm(spins - consistent, axis=1) > 1e-3] > 1e-5)


def test_residual_is_the_slip_norm_of_the_least_squares_solution():
    """Independent least squares on the robot-frame rows (3.5): same twist and same residual norm (A.9)."""
    rng = np.random.default_rng(2)
    fork = catalog.load("forklift")
    beta = rng.uniform(-1, 1, (10, 1)) + math.pi / 2
    spins = rng.normal(size=(10, 3))
    twist, residual = forward_kinematics(fork, dict(zip(fork.wheel_names, spins.T, strict=True)), beta)
    a = fork.constraint_matrix(beta, frame="robot")  # columns vx, vy, omega, 3 spins
    for i in range(10):
        x, *_ = np.linalg.lstsq(a[i, :, :3], -a[i, :, 3:] @ spins[i], rcond=None)
        np.testing.assert_allclose(twist[i], x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(residual[i], np.linalg.norm(a[i, :, :3] @ x + a[i, :, 3:] @ spins[i]), rtol=1e-9)


def test_ik_rates_give_back_the_twist_with_zero_residual():
    rng = np.random.default_rng(3)
    for name in ("swerve-4", "mecanum-4", "omni-3", "omni-4", "forklift", "bicycle"):
        robot = catalog.load(name)
        twist = rng.normal(size=(8, 3))
        if name == "forklift":  # feasible: omega from the fixed axle behind R (8.47), case B of (8.16)
            twist[:, 2] = twist[:, 1] / 1.0
        if name == "bicycle":  # R on the fixed axle: no lateral velocity, omega free (8.15), case A
            twist[:, 1] = 0.0
        c = wheel_commands(robot, twist)
        spins = {n: c.rates[:, robot.rate_names.index(n)] for n in robot.rate_names if n.endswith(".spin")}
        got, residual = forward_kinematics(robot, spins, c.beta)
        np.testing.assert_allclose(got, twist, rtol=1e-9, atol=1e-11, err_msg=name)
        np.testing.assert_allclose(residual, 0.0, atol=1e-11, err_msg=name)


def test_twist_components_may_be_assigned_and_determinacy_is_reported():
    assert not twist_is_determined(DIFF, ["left"])
    assert twist_is_determined(DIFF, ["left", "right"])
    assert twist_is_determined(DIFF, ["left", "omega"])  # e.g. a gyro
    twist, residual = forward_kinematics(DIFF, {"left": 10.0, "omega": 1.0})
    np.testing.assert_allclose(twist, [0.05 * 10 + 0.2 * 1.0, 0.0, 1.0], atol=1e-14)
    assert residual < 1e-14
    castor = catalog.load("diff-drive")
    assert not twist_is_determined(castor, ["caster"])  # a castor's spin alone: 2 of 3 directions free


def test_batched_rates_and_angles_broadcast_like_a_loop():
    rng = np.random.default_rng(4)
    swerve = catalog.load("swerve-4")
    spins = rng.normal(size=(3, 1, 4))
    beta = rng.uniform(-3, 3, (1, 5, 4))
    twist, residual = forward_kinematics(swerve, dict(zip(swerve.wheel_names, np.moveaxis(spins, -1, 0),
                                                          strict=True)), beta)
    assert twist.shape == (3, 5, 3) and residual.shape == (3, 5)
    for i, j in np.ndindex(3, 5):
        t, res = forward_kinematics(swerve, dict(zip(swerve.wheel_names, spins[i, 0], strict=True)), beta[0, j])
        np.testing.assert_allclose(twist[i, j], t, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(residual[i, j], res, rtol=1e-9, atol=1e-14)
    with pytest.raises(ValueError, match="read-only"):
        twist[...] = 0


def test_names_resolve_and_bad_names_list_the_valid_ones():
    diff = catalog.load("diff-drive")
    assert resolve_rate_name(diff, "left") == diff.velocity_names.index("left.spin")
    assert resolve_rate_name(diff, "caster.steer") == diff.velocity_names.index("caster.steer")
    assert resolve_rate_name(diff, "omega") == 2
    with pytest.raises(UnknownNameError, match=r"no joint rate 'lefft' \(valid: left, right, caster, .*left\.spin"):
        forward_kinematics(diff, {"lefft": 1.0})
    with pytest.raises(UnknownNameError, match=r"'left\.spin' given twice"):
        forward_kinematics(diff, {"left": 1.0, "left.spin": 1.0})
    with pytest.raises(ShapeError, match="at least one joint rate"):
        forward_kinematics(diff, {})
    with pytest.raises(ShapeError, match=r"rates: left: got the text 'fast', but the Python API reads no units"):
        forward_kinematics(diff, {"left": "fast"})
    zoo = Robot.from_dict({"name": "z", "wheels": [{"name": "d", "type": "double", "position": [0, 0], "b": 0.1,
                                                    "r": 0.05}]})
    with pytest.raises(UnknownNameError, match=r"no joint rate 'd'"):  # a double wheel has spin1 and spin2
        forward_kinematics(zoo, {"d": 1.0})
