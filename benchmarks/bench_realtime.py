"""Single-call kinematics against WPILib, per call from Python (issue 11, item 4): the controller's tick.

wmrkit: :func:`wmrkit.kinematics.realtime.realtime`, outputs written into caller-owned arrays. WPILib (robotpy-wpimath):
``SwerveDrive4Kinematics.toSwerveModuleStates`` + ``SwerveModuleState.optimize`` per module, ``MecanumDriveKinematics
.toWheelSpeeds``, ``DifferentialDriveOdometry.update``. Target: no slower than WPILib per call (ratio >= 1). Also
the IK of two units whose steering is geared 1:2 (no peer): the root its gear sets, then its check.
"""

from __future__ import annotations

import time

import numpy as np

from wmrkit import Robot, catalog
from wmrkit.kinematics.realtime import realtime

from ._harness import Result, peer


def _per_call(fn, n: int) -> float:
    fn()  # warm
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def _geared_units() -> Robot:
    """Two double wheels at (0.3, 0.2), (-0.3, -0.2) m whose steering a gear turns 1:2 (docs/wheel-ik.md)."""
    unit = {"type": "double", "heading": 0, "b": 0.06, "r": 0.08, "actuated": ["steer", "spin1", "spin2"]}
    return Robot.from_dict({"name": "geared-units", "wheels": [
        {**unit, "name": "front", "position": [0.3, 0.2]}, {**unit, "name": "rear", "position": [-0.3, -0.2]}],
        "couplings": [{"kind": "gear", "joints": ["front.steer", "rear.steer"], "ratios": [1, 2]}]})


def run(quick: bool) -> list[Result]:
    n = 2_000 if quick else 50_000
    kin, geo = peer("wpimath.kinematics"), peer("wpimath.geometry")
    out = []

    swerve = catalog.load("swerve-4")
    rt = realtime(swerve)
    heading, rates, heading_out = np.zeros(4), np.empty(4), np.empty(4)
    ours = _per_call(lambda: rt.ik(1.0, 0.5, 0.3, heading, rates, heading_out), n)
    theirs = None
    if kin is not None:
        k = kin.SwerveDrive4Kinematics(*[geo.Translation2d(*w.position) for w in swerve.wheels])
        current = [geo.Rotation2d(0.0)] * 4

        def wpilib_swerve():
            for state, c in zip(k.toSwerveModuleStates(kin.ChassisSpeeds(1.0, 0.5, 0.3)), current, strict=True):
                state.optimize(c)

        theirs = _per_call(wpilib_swerve, n)
    out.append(Result("single call: swerve-4 IK + closest angle", 1, ours, "WPILib", theirs, "ratio >= 1"))

    geared = _geared_units()  # a gear between steering joints: the root its gear sets, then its check
    rtg, gear_rates, gear_heading = realtime(geared), np.empty(len(geared.rate_names)), np.empty(2)
    ours = _per_call(lambda: rtg.ik(1.0, 0.5, 0.3, heading[:2], gear_rates, gear_heading), n)
    out.append(Result("single call: units geared 1:2, IK + gear roots", 1, ours, "none (no geared peer)", None))

    mecanum = catalog.load("mecanum-4")
    rtm, spins, none = realtime(mecanum), np.empty(8), np.empty(0)
    ours = _per_call(lambda: rtm.ik(1.0, 0.5, 0.3, none, spins, none), n)
    theirs = None
    if kin is not None:
        km = kin.MecanumDriveKinematics(*[geo.Translation2d(*w.position) for w in mecanum.wheels])
        theirs = _per_call(lambda: km.toWheelSpeeds(kin.ChassisSpeeds(1.0, 0.5, 0.3)), n)
    out.append(Result("single call: mecanum-4 IK", 1, ours, "WPILib", theirs, "ratio >= 1"))

    diff = catalog.load("diff-drive")
    rtd = realtime(diff, ("left.spin", "right.spin"))
    pose, previous, positions = np.zeros(3), np.zeros(2), np.array([0.01, 0.012])
    ours = _per_call(lambda: rtd.odometry_step(pose, previous, positions, none), n)
    theirs = None
    if kin is not None:
        odo = kin.DifferentialDriveOdometry(geo.Rotation2d(0.0), 0.0, 0.0)
        gyro = geo.Rotation2d(0.1)
        theirs = _per_call(lambda: odo.update(gyro, 0.01, 0.012), n)
    out.append(Result("single call: diff-drive odometry step", 1, ours, "WPILib", theirs, "ratio >= 1"))
    return out
