"""Agreement with WPILib's kinematics (robotpy-wpimath) on random twists: differential, Mecanum, swerve.

Conventions mapped explicitly:
- WPILib wheel speeds are linear [m/s] at the rim: ``speed = spin * r`` (our spin in rad/s, positive forward for
  wheels whose axle points left, beta = 90 deg).
- A WPILib swerve module angle is the direction the wheel rolls when its speed is positive; ours is the axle angle:
  ``beta = module_angle + 90 deg`` (a positive spin about an axle at beta drives along beta - 90 deg).
- ``SwerveModuleState.optimize(current)`` reverses the speed rather than turning more than 90 deg, as our
  closest-angle policy does; WPILib's ``ChassisSpeeds`` is (vx, vy, omega) in REP-103 like ours.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.kinematics.wheel_ik import forward_kinematics, wheel_commands, wrap_angle

kin = pytest.importorskip("wpimath.kinematics")
geo = pytest.importorskip("wpimath.geometry")

R = 0.05  # wheel radius [m] of the test robots
CORNERS = [(0.31, 0.27), (0.31, -0.27), (-0.29, 0.27), (-0.29, -0.27)]  # fl, fr, rl, rr (not symmetric on purpose)
NAMES = ["fl", "fr", "rl", "rr"]


def _twists(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, 3)) * [1.0, 1.0, 2.0]


def _translations():
    return [geo.Translation2d(x, y) for x, y in CORNERS]


def test_differential_drive_inverse_and_forward():
    track = 0.53
    diff = Robot.from_dict({"name": "diff", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, track / 2], "beta": "90 deg", "r": R},
        {"name": "right", "type": "fixed", "position": [0, -track / 2], "beta": "90 deg", "r": R},
    ]})
    peer = kin.DifferentialDriveKinematics(track)
    twists = _twists(50, 0)
    twists[:, 1] = 0.0  # WPILib drops vy; ours reports it as slip, tested elsewhere
    ours = wheel_commands(diff, twists)
    assert ours.feasible.all()
    for twist, spin in zip(twists, ours.spin, strict=True):
        speeds = peer.toWheelSpeeds(kin.ChassisSpeeds(*twist))
        np.testing.assert_allclose(spin * R, [speeds.left, speeds.right], rtol=1e-12, atol=1e-12)
        back = peer.toChassisSpeeds(kin.DifferentialDriveWheelSpeeds(*(spin * R)))
        fk, residual = forward_kinematics(diff, {"left": spin[0], "right": spin[1]})
        np.testing.assert_allclose(fk, [back.vx, back.vy, back.omega], rtol=1e-12, atol=1e-12)
        assert residual < 1e-12


def _mecanum() -> Robot:
    # WPILib's X roller layout: seen from above the rollers form an X; fl and rr at +45 deg to the axle.
    gammas = [45, -45, -45, 45]
    return Robot.from_dict({"name": "mec", "wheels": [
        {"name": n, "type": "swedish", "position": list(p), "beta": "90 deg", "gamma": f"{g} deg", "r": R,
         "r_r": 0.01} for n, p, g in zip(NAMES, CORNERS, gammas, strict=True)]})


def _mecanum_type() -> Robot:
    """The same robot written as users write it: ``type: mecanum``, no roller angle, no axle angle."""
    return Robot.from_dict({"name": "mec", "wheels": [
        {"name": n, "type": "mecanum", "position": list(p), "r": R, "r_r": 0.01} for n, p in zip(NAMES, CORNERS,
                                                                                              strict=True)]})


def test_type_mecanum_is_wpilibs_layout():
    assert _mecanum_type() == _mecanum()


@pytest.mark.parametrize("build", [_mecanum, _mecanum_type])
def test_mecanum_inverse_and_forward(build):
    mec = build()
    peer = kin.MecanumDriveKinematics(*_translations())
    twists = _twists(50, 1)
    ours = wheel_commands(mec, twists)
    for twist, spin in zip(twists, ours.spin, strict=True):
        s = peer.toWheelSpeeds(kin.ChassisSpeeds(*twist))
        np.testing.assert_allclose(spin * R, [s.frontLeft, s.frontRight, s.rearLeft, s.rearRight], rtol=1e-10,
                                   atol=1e-12)
    rng = np.random.default_rng(2)
    for spin in rng.normal(size=(30, 4)) * 10:  # arbitrary (inconsistent) wheel speeds: both least squares
        back = peer.toChassisSpeeds(kin.MecanumDriveWheelSpeeds(*(spin * R)))
        fk, _ = forward_kinematics(mec, dict(zip(NAMES, spin, strict=True)))
        np.testing.assert_allclose(fk, [back.vx, back.vy, back.omega], rtol=1e-9, atol=1e-12)


def _swerve() -> Robot:
    return Robot.from_dict({"name": "swerve", "wheels": [
        {"name": n, "type": "steerable", "position": list(p), "heading": 0, "r": R}
        for n, p in zip(NAMES, CORNERS, strict=True)]})


def test_swerve_inverse_with_optimize_matches_closest_angle_policy():
    swerve = _swerve()
    peer = kin.SwerveDrive4Kinematics(*_translations())
    rng = np.random.default_rng(3)
    twists = _twists(60, 3)
    current_module = rng.uniform(-math.pi, math.pi, (60, 4))  # WPILib module angles, current
    ours = wheel_commands(swerve, twists, heading=current_module)  # WPILib's module angle is our heading
    for i, twist in enumerate(twists):
        states = peer.toSwerveModuleStates(kin.ChassisSpeeds(*twist))
        for k, state in enumerate(states):
            state.optimize(geo.Rotation2d(current_module[i, k]))
            assert ours.spin[i, k] * R == pytest.approx(state.speed, rel=1e-10, abs=1e-12)
            assert abs(wrap_angle(ours.heading[i, k] - state.angle.radians())) < 1e-10
            assert abs(wrap_angle(ours.steer[i, k] - (state.angle.radians() + math.pi / 2))) < 1e-10  # thesis β


@pytest.mark.parametrize("twist", [(0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)])
def test_swerve_ties_are_broken_as_wpilibs_optimize(twist):
    """From heading 0, strafing left asks for +-90 deg, both 90 deg away: WPILib keeps +90 rolling forward; the IK
    took -90 rolling backward (the same motion, the other root). The compiled single-call IK agrees."""
    from wmrkit.kinematics.realtime import realtime

    swerve = _swerve()
    ours = wheel_commands(swerve, twist, heading=np.zeros(4))
    rt = realtime(swerve)
    rates, heading = np.zeros(4), np.zeros(4)
    rt.ik(*twist, np.zeros(4), rates, heading)
    for k, state in enumerate(kin.SwerveDrive4Kinematics(*_translations()).toSwerveModuleStates(
            kin.ChassisSpeeds(*twist))):
        state.optimize(geo.Rotation2d(0.0))
        assert ours.spin[k] * R == pytest.approx(state.speed, rel=1e-10, abs=1e-12)
        assert abs(wrap_angle(ours.heading[k] - state.angle.radians())) < 1e-10
        assert rates[k] * R == pytest.approx(state.speed, rel=1e-10, abs=1e-12)
        assert abs(wrap_angle(heading[k] - state.angle.radians())) < 1e-10


def test_swerve_forward_matches_to_chassis_speeds():
    swerve = _swerve()
    peer = kin.SwerveDrive4Kinematics(*_translations())
    rng = np.random.default_rng(4)
    for _ in range(30):  # arbitrary module states, generally inconsistent: both least squares
        speeds, angles = rng.normal(size=4), rng.uniform(-math.pi, math.pi, 4)
        back = peer.toChassisSpeeds(tuple(kin.SwerveModuleState(s, geo.Rotation2d(a))
                                          for s, a in zip(speeds, angles, strict=True)))
        fk, residual = forward_kinematics(swerve, dict(zip(NAMES, speeds / R, strict=True)), heading=angles)
        np.testing.assert_allclose(fk, [back.vx, back.vy, back.omega], rtol=1e-9, atol=1e-12)
    # consistent states: our residual vanishes
    twist = np.array([0.7, -0.4, 1.1])
    states = peer.toSwerveModuleStates(kin.ChassisSpeeds(*twist))
    speeds = np.array([s.speed for s in states])
    angles = np.array([s.angle.radians() for s in states])
    fk, residual = forward_kinematics(swerve, dict(zip(NAMES, speeds / R, strict=True)), heading=angles)
    np.testing.assert_allclose(fk, twist, rtol=1e-12)
    assert residual < 1e-12


def test_field_relative_speeds_as_the_docs_rotate_them():
    """docs/wheel-ik.md, 'Coming from WPILib': the field-relative twist rotated by -theta as written there equals
    ChassisSpeeds.fromFieldRelativeSpeeds, and wmrkit's swerve IK of it WPILib's module states (speed = spin * r)."""
    swerve = Robot.from_dict({"name": "sw", "wheels": [
        {"name": n, "type": "steerable", "position": list(p), "r": R} for n, p in zip(NAMES, CORNERS, strict=True)]})
    swerve_kin = kin.SwerveDrive4Kinematics(*_translations())
    rng = np.random.default_rng(11)
    for (vx_f, vy_f, omega), theta in zip(_twists(50, 5), rng.uniform(-4, 4, 50), strict=True):
        vx = math.cos(theta) * vx_f + math.sin(theta) * vy_f  # the docs' formula
        vy = -math.sin(theta) * vx_f + math.cos(theta) * vy_f
        speeds = kin.ChassisSpeeds.fromFieldRelativeSpeeds(vx_f, vy_f, omega, geo.Rotation2d(theta))
        np.testing.assert_allclose([vx, vy, omega], [speeds.vx, speeds.vy, speeds.omega], rtol=1e-12, atol=1e-12)
        c = wheel_commands(swerve, [vx, vy, omega], heading=np.zeros(4))
        for k, state in enumerate(swerve_kin.toSwerveModuleStates(speeds)):
            wpi = state.speed * np.array([math.cos(state.angle.radians()), math.sin(state.angle.radians())])
            ours = c.spin[k] * R * np.array([math.cos(c.heading[k]), math.sin(c.heading[k])])
            np.testing.assert_allclose(ours, wpi, atol=1e-12)
