"""Agreement with peers' odometry on the same inputs: WPILib (robotpy-wpimath) and the Robotics Toolbox."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry.integrators import integrate_increments
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate

kin = pytest.importorskip("wpimath.kinematics")
geo = pytest.importorskip("wpimath.geometry")


def _pose(p):
    return [p.X(), p.Y(), p.rotation().radians()]


def test_differential_drive_odometry_matches_wpilib():
    """WPILib integrates (dS, dtheta_gyro) with Pose2d.exp; fed our wheel heading as its gyro, it must agree with
    our exact scheme sample by sample (and so with the truth)."""
    robot = catalog.load("diff-drive")
    profile = TwistProfile.from_segments([(3.0, 0.5, 0.0, 0.8), (2.0, 0.4, 0.0, -1.2), (3.0, -0.3, 0.0, 0.1)])
    run = simulate(robot, profile, 50.0)
    ours = odometry(robot, run.log)
    dist = run.log.positions * 0.075  # left, right wheel distances
    wpi = kin.DifferentialDriveOdometry(geo.Rotation2d(0.0), dist[0, 0], dist[0, 1])
    got = np.array([_pose(wpi.update(geo.Rotation2d(th), d[0], d[1]))
                    for th, d in zip(ours.poses[:, 2].tolist(), dist.tolist(), strict=True)])
    np.testing.assert_allclose(got[:, :2], ours.poses[:, :2], atol=1e-9)
    np.testing.assert_allclose(np.unwrap(got[:, 2]), ours.poses[:, 2], atol=1e-9)
    np.testing.assert_allclose(got[-1, :2], run.truth[-1, :2], atol=1e-8)


def test_mecanum_odometry_matches_wpilib():
    robot = catalog.load("mecanum-4")
    names = ("front_left", "front_right", "rear_left", "rear_right")
    profile = TwistProfile.from_segments([(2.0, 0.4, -0.3, 0.5), (2.0, -0.2, 0.4, -0.7)])
    run = simulate(robot, profile, 50.0)
    ours = odometry(robot, run.log)
    wpik = kin.MecanumDriveKinematics(*[geo.Translation2d(*robot.wheel(n).position) for n in names])
    cols = [run.log.joints.index(f"{n}.spin") for n in names]

    def positions(row):
        p = kin.MecanumDriveWheelPositions()
        p.frontLeft, p.frontRight, p.rearLeft, p.rearRight = (float(v) * 0.0762 for v in row[cols])
        return p

    wpi = kin.MecanumDriveOdometry(wpik, geo.Rotation2d(0.0), positions(run.log.positions[0]))
    got = np.array([_pose(wpi.update(geo.Rotation2d(float(th)), positions(row)))
                    for th, row in zip(ours.poses[:, 2], run.log.positions, strict=True)])
    np.testing.assert_allclose(got[:, :2], ours.poses[:, :2], atol=1e-9)


def test_euler_trajectory_matches_the_robotics_toolbox():
    """RTB's vehicle update f(x, (dd, dth)) is forward Euler (003 (20)); feed it our model's increments."""
    mobile = pytest.importorskip("roboticstoolbox.mobile")
    robot = catalog.load("diff-drive")
    run = simulate(robot, TwistProfile.from_segments([(4.0, 0.5, 0.0, 0.6)]), 10.0)
    inc = odometry_model(robot).from_positions(run.log.positions).increments_robot
    veh = mobile.Unicycle()
    x = np.zeros(3)
    for dd, _, dth in inc:
        x = veh.f(x, [dd, dth])
    np.testing.assert_allclose(integrate_increments([0, 0, 0], inc, "euler")[-1], x, atol=1e-12)
    np.testing.assert_allclose(odometry(robot, run.log, method="euler").final_pose, x, atol=1e-12)
