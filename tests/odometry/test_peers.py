"""Agreement with peers' odometry on the same inputs: WPILib (robotpy-wpimath) and the Robotics Toolbox."""

from __future__ import annotations

import itertools
import math

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


def _wpilib_poses(twists) -> np.ndarray:
    """WPILib's odometry without a gyro: Pose2d.exp of each Twist2d its kinematics gives, heading summed."""
    pose, theta, out = geo.Pose2d(), 0.0, [[0.0, 0.0, 0.0]]
    for t in twists:
        pose, theta = pose.exp(t), theta + t.dtheta
        out.append([pose.X(), pose.Y(), theta])
    return np.array(out)


def _csv(path, names, time, spin, steer=None) -> None:
    """A log as a WPILib user exports it: cumulative wheel angles [rad] (distance / r), module angles [rad]."""
    cols = [f"{n}.spin" for n in names] + ([f"{n}.steer" for n in names] if steer is not None else [])
    data = np.column_stack([time, spin] + ([steer] if steer is not None else []))
    np.savetxt(path, data, delimiter=",", header=",".join(["time", *cols]), comments="", fmt="%.17g")


def _ours(robot, path) -> np.ndarray:
    from wmrkit.odometry.logs import load_csv

    return odometry(robot, load_csv(path, odometry_model(robot).joints, robot=robot)).poses


def test_differential_and_mecanum_logs_match_wpilibs_own_heading(tmp_path):
    """Arbitrary wheel logs (not made by wmrkit), read from CSV: every pose, heading included, equals WPILib's
    Pose2d.exp of its kinematics' Twist2d (the other test feeds WPILib our heading as its gyro, so a wrong track or
    roller sign that turns both models alike would pass it)."""
    rng = np.random.default_rng(11)
    time = np.arange(301) * 0.02
    diff = catalog.load("diff-drive")
    left, right = diff.wheel("left"), diff.wheel("right")
    dist = np.cumsum(np.vstack([[0, 0], rng.normal(0.01, 0.01, (300, 2)) * [1.0, 1.3]]), axis=0)
    _csv(tmp_path / "diff.csv", ["left", "right"], time, dist / left.r)
    peer = kin.DifferentialDriveKinematics(left.position[1] - right.position[1])
    want = _wpilib_poses(peer.toTwist2d(*map(float, d)) for d in np.diff(dist, axis=0))
    np.testing.assert_allclose(_ours(diff, tmp_path / "diff.csv"), want, rtol=0, atol=1e-12)

    mec = catalog.load("mecanum-4")
    names = ("front_left", "front_right", "rear_left", "rear_right")
    peer = kin.MecanumDriveKinematics(*[geo.Translation2d(*mec.wheel(n).position) for n in names])
    dist = np.cumsum(np.vstack([np.zeros(4), rng.normal(0.0, 0.01, (300, 4))]), axis=0)  # inconsistent: slip
    _csv(tmp_path / "mec.csv", names, time, dist / mec.wheel("front_left").r)
    def deltas(d):
        w = kin.MecanumDriveWheelPositions()
        w.frontLeft, w.frontRight, w.rearLeft, w.rearRight = (float(v) for v in d)
        return w

    want = _wpilib_poses(peer.toTwist2d(deltas(d)) for d in np.diff(dist, axis=0))
    np.testing.assert_allclose(_ours(mec, tmp_path / "mec.csv"), want, rtol=0, atol=1e-12)


def test_swerve_log_in_module_angles_matches_wpilib_odometry(tmp_path, capsys):
    """A swerve log made by WPILib: random chassis speeds, module states optimised from random current angles
    (reversed wheels, angles anywhere in (-180, 180] deg), the modules turned while stopped, then driven; last,
    backwards with the modules at 180 deg written +pi and -pi in turn. Written
    as WPILib reports it (the module angle is the log's steering heading), read through the CSV door and the
    CLI, every pose equals SwerveDrive4Odometry's (its gyro fed its own kinematics' dtheta)."""
    import json

    from wmrkit.cli.main import main

    robot = catalog.load("swerve-4")
    names = ("front_left", "front_right", "rear_left", "rear_right")
    peer = kin.SwerveDrive4Kinematics(*[geo.Translation2d(*robot.wheel(n).position) for n in names])
    rng = np.random.default_rng(7)
    dist, angle, rows = np.zeros(4), np.zeros(4), [np.zeros(8)]
    for _ in range(12):
        states = peer.toSwerveModuleStates(kin.ChassisSpeeds(*(rng.normal(size=3) * [1.0, 1.0, 2.0])))
        for k, s in enumerate(states):
            s.optimize(geo.Rotation2d(angle[k] + rng.uniform(-2.0, 2.0)))
        speed, angle = np.array([s.speed for s in states]), np.array([s.angle.radians() for s in states])
        rows.append(np.concatenate([dist, angle]))  # stopped while the modules turn
        for _ in range(rng.integers(5, 30)):
            dist = dist + 0.02 * speed
            rows.append(np.concatenate([dist, angle]))
    states = peer.toSwerveModuleStates(kin.ChassisSpeeds(-0.5, 0.0, 0.0))  # backwards, the modules at 180 deg
    for s in states:
        s.optimize(geo.Rotation2d(math.pi))
    speed, angle = np.array([s.speed for s in states]), np.array([s.angle.radians() for s in states])
    rows.append(np.concatenate([dist, angle]))
    for i in range(20):  # 180 deg written +pi and -pi in turn (both WPILib's Rotation2d(pi)): no turn between
        dist = dist + 0.02 * speed
        rows.append(np.concatenate([dist, angle * (-1) ** i]))
    rows = np.array(rows)
    assert np.abs(rows[:, 4:]).max() > 3.0 and (rows[:, :4] < rows[0, :4]).any()  # near +-pi; some backwards
    _csv(tmp_path / "swerve.csv", names, np.arange(len(rows)) * 0.02, rows[:, :4] / robot.wheel("front_left").r,
         rows[:, 4:])

    def positions(row):
        return tuple(kin.SwerveModulePosition(float(row[k]), geo.Rotation2d(float(row[4 + k]))) for k in range(4))

    want = _wpilib_poses(peer.toTwist2d(positions(a), positions(b)) for a, b in itertools.pairwise(rows))
    wpi = kin.SwerveDrive4Odometry(peer, geo.Rotation2d(0.0), positions(rows[0]))
    wpi_poses = np.array([_pose(wpi.update(geo.Rotation2d(th), positions(row)))
                          for th, row in zip(want[1:, 2].tolist(), rows[1:], strict=True)])
    np.testing.assert_allclose(wpi_poses[:, :2], want[1:, :2], atol=1e-12)
    ours = _ours(robot, tmp_path / "swerve.csv")
    np.testing.assert_allclose(ours, want, rtol=0, atol=1e-12)
    assert main(["odometry", "swerve-4", str(tmp_path / "swerve.csv"), "--json", "--out",
                 str(tmp_path / "path.csv")]) == 0
    np.testing.assert_allclose(json.loads(capsys.readouterr().out)["final_pose"], want[-1], rtol=0, atol=1e-12)
    from wmrkit.odometry.trajectories import read_trajectory_csv

    np.testing.assert_allclose(read_trajectory_csv(tmp_path / "path.csv").poses, want, rtol=0, atol=1e-9)


@pytest.mark.parametrize("ratio", [1.0, 0.8])
def test_skid_steer_odometry_is_wpilibs_differential_drive_at_the_effective_track(tmp_path, ratio):
    """A four-wheel skid steer (wheels at (+-a, +-b)) read by wmrkit's least squares (ratio 1) or WLS with
    mu_lateral / mu_longitudinal = k is WPILib's (and ROS diff_drive_controller's) differential drive whose track is
    the wheels' 2 b times wheel_separation_multiplier m = 1 + k (a / b)^2 (docs/slip.md): on the square catalog
    robot, no-slip odometry turns half as much as the geometric track says (m = 2), pose by pose."""
    from wmrkit.odometry.logs import load_csv
    from wmrkit.slip.weights import SlipWeights, wls_model

    robot = catalog.load("skid-steer-4")
    names = ("front_left", "front_right", "rear_left", "rear_right")
    a, b = robot.wheel("front_left").position
    rng = np.random.default_rng(5)
    time = np.arange(401) * 0.02
    sides = np.cumsum(np.vstack([[0, 0], rng.normal([0.008, 0.012], 0.004, (400, 2))]), axis=0)  # left, right [m]
    _csv(tmp_path / "skid.csv", names, time, sides[:, [0, 1, 0, 1]] / robot.wheel("front_left").r)
    peer = kin.DifferentialDriveKinematics(2 * b * (1 + ratio * (a / b) ** 2))
    want = _wpilib_poses(peer.toTwist2d(*map(float, d)) for d in np.diff(sides, axis=0))
    model = wls_model(robot, SlipWeights.uniform(ratio, 1.0)) if ratio != 1.0 else odometry_model(robot)
    got = odometry(model, load_csv(tmp_path / "skid.csv", model.joints, robot=robot)).poses
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    assert abs(want[-1, 2]) > 1.0  # it turned
