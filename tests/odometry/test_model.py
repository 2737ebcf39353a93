"""The sensed direct model over samples: closed forms (002 (16)/(21), thesis (5.45)), peers, slip residual, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import Robot, catalog
from wmrkit.errors import UnknownNameError, WmrkitError
from wmrkit.kinematics.linalg import solve_assigned
from wmrkit.odometry.model import SensingError, odometry_model, wrap_angle

#: Catalog robots whose sensors determine the motion at the described configuration.
SENSED_OK = ["diff-drive", "line-follower", "mecanum-4", "omni-3", "omni-4", "swerve-4", "ackermann", "forklift",
             "skid-steer-4", "thesis-diff-castor", "thesis-tricycle"]


def test_differential_drive_is_the_classic_model_of_002():
    """002 (1), (6), (16)/(21): dS = r (dphi_r + dphi_l) / 2, dtheta = r (dphi_r - dphi_l) / (2 l)."""
    robot = catalog.load("diff-drive")  # r = 0.075 m, half track l = 0.20 m
    model = odometry_model(robot)
    assert model.constant and model.rate_joints == ("left.spin", "right.spin")
    rng = np.random.default_rng(0)
    dq = rng.normal(size=(20, 2))
    out = model.increments(dq)
    r, l = 0.075, 0.20
    np.testing.assert_allclose(out.increments_robot[:, 0], r * (dq[:, 0] + dq[:, 1]) / 2, rtol=0, atol=1e-15)
    np.testing.assert_allclose(out.increments_robot[:, 1], 0.0, atol=1e-15)
    np.testing.assert_allclose(out.increments_robot[:, 2], r * (dq[:, 1] - dq[:, 0]) / (2 * l), rtol=0, atol=1e-15)
    np.testing.assert_allclose(out.slip, 0.0, atol=1e-15)  # two sensors, two degrees of freedom: no redundancy


def test_thesis_frame_differential_model_5_45_matches_002():
    """Thesis (5.45) in its own frame (X along the axle): v_y = -(r1 phi1 + r2 phi2)/2, omega = (-r1 phi1 + r2 phi2)
    / (2 l12); with omega_d = -phi1, omega_i = -phi2 it is 002's (16) (digest C.7)."""
    robot = catalog.load("thesis-diff-castor")  # r = 0.1, l12 = 0.25
    model = odometry_model(robot, ["f1.spin", "f2.spin"])  # the castor unsensed: left out
    assert model.constant
    dq = np.array([[1.0, 0.5], [-0.3, 0.7], [2.0, 2.0]])
    inc = model.increments(dq).increments_robot
    np.testing.assert_allclose(inc[:, 0], 0.0, atol=1e-15)
    np.testing.assert_allclose(inc[:, 1], -(0.1 * dq[:, 0] + 0.1 * dq[:, 1]) / 2, atol=1e-15)
    np.testing.assert_allclose(inc[:, 2], (-0.1 * dq[:, 0] + 0.1 * dq[:, 1]) / (2 * 0.25), atol=1e-15)
    w_d, w_i = -dq[:, 0], -dq[:, 1]  # 002: forward speed r (w_d + w_i)/2 and turn r (w_d - w_i) / (2 l)
    np.testing.assert_allclose(inc[:, 1], 0.1 * (w_d + w_i) / 2, atol=1e-15)
    np.testing.assert_allclose(inc[:, 2], 0.1 * (w_d - w_i) / (2 * 0.25), atol=1e-15)


@pytest.mark.parametrize("name", SENSED_OK)
def test_no_slip_joint_increments_give_back_the_twist(name):
    """Alternative path: assign the twist and solve the rates (4.11), then feed the sensed ones to the model."""
    robot = catalog.load(name)
    model = odometry_model(robot)
    rng = np.random.default_rng(1)
    twists = np.vstack([rng.normal(size=(6, 3)) * [0.3, 0.3, 0.5], [0.3, 0.0, 0.0]])  # straight: any robot
    twists, beta = _compatible(robot, twists)  # steered so that the steerable wheels roll
    a = robot.constraint_matrix(beta) if robot.steer_names else robot.constraint_matrix()
    q, res = solve_assigned(a, [0, 1, 2], twists)
    consistent = np.max(np.abs(res), axis=-1) < 1e-12
    assert consistent.any()
    dq = q[:, [robot.velocity_index(j) for j in model.rate_joints]]
    b = beta[:, [robot.steer_names.index(j.split(".")[0]) for j in model.steer_joints]]
    out = model.increments(dq, b)
    np.testing.assert_allclose(out.increments_robot[consistent], twists[consistent], rtol=0, atol=1e-12)
    np.testing.assert_allclose(out.slip[consistent], 0.0, atol=1e-12)


def _compatible(robot: Robot, twists: np.ndarray):
    """Twists allowed by the fixed wheels, and the steering angles that make every steerable wheel roll."""
    # a fixed wheel's lateral constraint (3.11): (cos b, sin b) . (vx - w y, vy + w x) = 0; project onto its null space
    rows = [[math.cos(w.beta), math.sin(w.beta), w.position[0] * math.sin(w.beta) - w.position[1] * math.cos(w.beta)]
            for w in robot.wheels if w.type == "fixed"]
    if rows:
        _, sv, vt = np.linalg.svd(np.array(rows))
        null = vt[int(np.sum(sv > 1e-9)):]
        twists = twists @ null.T @ null
    beta = [np.zeros(len(twists))]
    for name in robot.steer_names:
        w = robot.wheel(name)
        x, y = w.position
        vx, vy = twists[:, 0] - twists[:, 2] * y, twists[:, 1] + twists[:, 2] * x
        beta.append(np.arctan2(vx, -vy))
    return twists, np.column_stack(beta)[:, 1:]


def test_mecanum_agrees_with_wpimath_forward_kinematics():
    kin = pytest.importorskip("wpimath.kinematics")
    geo = pytest.importorskip("wpimath.geometry")
    robot = catalog.load("mecanum-4")
    model = odometry_model(robot)
    positions = [geo.Translation2d(*robot.wheel(n).position) for n in ("front_left", "front_right", "rear_left",
                                                                      "rear_right")]
    wpi = kin.MecanumDriveKinematics(*positions)
    rng = np.random.default_rng(4)
    for dq in rng.normal(size=(10, 4)):
        deltas = kin.MecanumDriveWheelPositions()
        d = dq * 0.0762  # wheel distances = r * angle
        deltas.frontLeft, deltas.frontRight, deltas.rearLeft, deltas.rearRight = (float(v) for v in d)
        t = wpi.toTwist2d(deltas)
        np.testing.assert_allclose(model.increments(dq[None]).increments_robot[0], [t.dx, t.dy, t.dtheta],
                                   rtol=0, atol=1e-12)


def test_swerve_agrees_with_wpimath_forward_kinematics():
    kin = pytest.importorskip("wpimath.kinematics")
    geo = pytest.importorskip("wpimath.geometry")
    robot = catalog.load("swerve-4")
    model = odometry_model(robot)
    names = ("front_left", "front_right", "rear_left", "rear_right")
    wpi = kin.SwerveDrive4Kinematics(*[geo.Translation2d(*robot.wheel(n).position) for n in names])
    rng = np.random.default_rng(6)
    for _ in range(10):
        dq, beta = rng.normal(size=4), rng.uniform(-math.pi, math.pi, size=4)
        # wpimath's module angle is the direction of travel: the axle (beta) turned back by 90 deg
        mods = tuple(kin.SwerveModulePosition(float(0.0508 * q), geo.Rotation2d(float(b - math.pi / 2)))
                     for q, b in zip(dq, beta, strict=True))
        t = wpi.toTwist2d(mods)
        ours = model.increments(dq[None], beta[None]).increments_robot[0]
        np.testing.assert_allclose(ours, [t.dx, t.dy, t.dtheta], rtol=0, atol=1e-12)


def test_redundant_sensors_report_the_inconsistency_as_slip():
    """Mecanum: 4 spins, 3 DOF. Readings from a twist give zero residual; adding a reading outside the no-slip
    subspace (the wpimath-independent null vector of the forward map) gives it back as the residual."""
    robot = catalog.load("mecanum-4")
    model = odometry_model(robot)
    s = model.solution[:3]  # (3, 4) forward map
    null = np.linalg.svd(s)[2][-1]  # the reading pattern that no twist explains
    good = np.linalg.lstsq(s, [0.2, -0.1, 0.3], rcond=None)[0]
    bad = good + 0.01 * null
    out = model.increments(np.array([good, bad]))
    np.testing.assert_allclose(out.increments_robot[0], [0.2, -0.1, 0.3], atol=1e-12)
    np.testing.assert_allclose(out.increments_robot[1], out.increments_robot[0], atol=1e-12)
    assert out.slip[0] < 1e-14 and out.slip[1] > 1e-4


def test_increments_hand_out_read_only_columns_and_slip():
    """Columns and slip come from one cached pass: handed out read-only, so no caller can corrupt the others'."""
    out = odometry_model(catalog.load("mecanum-4")).increments(np.random.default_rng(2).normal(size=(9, 4)))
    for a in (out.column(0), out.column(2), out.slip):
        with pytest.raises(ValueError, match="read-only"):
            a[0] = 1.0
    body = out.increments_robot  # a private copy
    body[:] = 0.0
    assert np.any(out.increments_robot)


def test_forklift_steering_inconsistent_with_the_drive_wheels_is_slip():
    robot = catalog.load("forklift")
    model = odometry_model(robot)
    assert not model.constant and model.steer_joints == ("steer.steer",)
    # a right turn: wheel speeds u_r < u_l, omega = (u_r - u_l) / (2 * 0.45) at the drive axle midpoint (x = -1);
    # the fork tips (origin, 1 m ahead) move at (v, omega * 1); the steer wheel, 1.35 m behind, at (v, -1.35 omega)
    r, u_r, u_l = 0.23, 0.9, 1.1
    v, w = (u_r + u_l) / 2, (u_r - u_l) / 0.9
    beta_ok = math.atan2(v, w * 1.35)  # its axle normal to that velocity (3.11)
    out = model.increments(np.array([[u_r / r, u_l / r]] * 2), np.array([[beta_ok], [beta_ok + 0.1]]))
    np.testing.assert_allclose(out.increments_robot[0], [v, w * 1.0, w], atol=1e-12)  # origin at the fork tips
    assert out.slip[0] < 1e-12 and out.slip[1] > 1e-3


def test_unique_configuration_path_equals_per_sample_solves():
    robot = catalog.load("swerve-4")
    model = odometry_model(robot)
    rng = np.random.default_rng(8)
    beta = np.radians(np.round(rng.uniform(60, 120, size=(50, 4)) / 5) * 5)  # few distinct, like encoders
    dq = rng.normal(size=(50, 4))
    out = model.increments(dq, beta)
    rows = [robot.velocity_index(j) for j in model.rate_joints]
    for k in range(50):
        q, res = solve_assigned(robot.constraint_matrix(beta[k]), rows, dq[k])
        np.testing.assert_allclose(out.increments_robot[k], q[:3], atol=1e-12)
        np.testing.assert_allclose(out.slip[k], np.linalg.norm(res), atol=1e-12)


def test_from_positions_differences_and_midpoint_steering():
    robot = catalog.load("forklift")
    model = odometry_model(robot)
    assert model.joints == ("right_drive.spin", "left_drive.spin", "steer.steer")
    pos = np.array([[0.0, 0.0, math.pi - 0.01], [1.0, 1.2, -math.pi + 0.03], [2.0, 2.5, -math.pi + 0.05]])
    out = model.from_positions(pos)
    ref = model.increments(np.diff(pos[:, :2], axis=0), np.array([[math.pi + 0.01], [-math.pi + 0.04]]))
    np.testing.assert_allclose(out.increments_robot, ref.increments_robot, atol=1e-12)  # steering wraps across pi


@settings(max_examples=300)
@given(st.floats(-50, 50))
def test_wrap_angle(a):
    w = wrap_angle(a)
    assert -math.pi <= w < math.pi
    assert math.remainder(w - a, 2 * math.pi) == pytest.approx(0, abs=1e-9)


def test_sensing_errors_name_the_problem():
    # the angle as a heading (what log files hold): it printed the thesis's beta, 'front.steer=0 deg', for a
    # wheel turned sideways
    with pytest.raises(SensingError, match=r"interval 0: the sensed joints \(rear.spin, front.steer\) do not "
                                           r"determine the motion at steering headings front.steer=-90 deg"):
        odometry_model(catalog.load("bicycle")).increments(np.zeros((1, 1)), np.zeros((1, 1)))
    diff = catalog.load("diff-drive")
    with pytest.raises(SensingError, match=r"do not determine its motion"):
        odometry_model(diff, ["left.spin"])
    with pytest.raises(SensingError, match=r"wheel 'caster' steers but 'caster.steer' is not sensed, so caster.spin"):
        odometry_model(diff, ["left.spin", "right.spin", "caster.spin"])
    with pytest.raises(UnknownNameError, match=r"robot 'diff-drive' has no wheel 'lft'"):
        odometry_model(diff, ["lft.spin"])
    with pytest.raises(UnknownNameError, match=r"wheel 'left' of robot 'diff-drive' has no joint 'steer'"):
        odometry_model(diff, ["left.steer"])
    with pytest.raises(SensingError, match=r"listed twice: left\.spin"):
        odometry_model(diff, ["left.spin", "left.spin", "right.spin"])
    with pytest.raises(WmrkitError, match=r"rate_increments: expected shape \(N, 2\)"):
        odometry_model(diff).increments(np.zeros((3, 3)))
    with pytest.raises(WmrkitError, match="beta_mid: robot 'forklift' steers"):
        odometry_model(catalog.load("forklift")).increments(np.zeros((3, 2)))


def test_non_finite_joint_data_is_refused_by_name():
    """NaN or infinite joint increments, positions or steering angles gave NaN body increments silently."""
    diff, fork = odometry_model(catalog.load("diff-drive")), odometry_model(catalog.load("forklift"))
    with pytest.raises(WmrkitError, match="rate_increments: expected finite numbers, got nan"):
        diff.increments(np.array([[np.nan, 1.0]]))
    with pytest.raises(WmrkitError, match="positions: expected finite numbers, got inf"):
        diff.from_positions(np.array([[0.0, 0.0], [np.inf, 1.0]]))
    with pytest.raises(WmrkitError, match="previous: expected finite numbers"):
        diff.from_positions(np.array([[0.0, 0.0]]), previous=[np.nan, 0.0])
    with pytest.raises(WmrkitError, match="beta_mid: expected finite numbers"):
        fork.increments(np.zeros((1, len(fork.rate_joints))), np.full((1, len(fork.steer_joints)), np.nan))


def test_one_sensed_joint_as_a_string_and_weights_that_are_not_numbers():
    """sensed="left.spin" was split into letters ("no wheel 'l'"), a weight "1" failed with a TypeError."""
    diff = catalog.load("diff-drive")
    with pytest.raises(SensingError, match=r"^sensed: expected a sequence of 'wheel.joint' names, got the string "
                                            r"'left\.spin'$"):
        odometry_model(diff, "left.spin")  # as everywhere names are taken (trees.select_columns, symbolic_model)
    for bad in ("1", None, True):
        with pytest.raises(SensingError, match=f"weight of wheel 'left' must be a finite number > 0, got {bad}"):
            odometry_model(diff, weights={"left": bad})


def test_row_weights_give_the_weighted_least_squares():
    """Against numpy's lstsq on the weighted rows (an independent solver): min || W A q || with dq assigned."""
    robot = catalog.load("forklift")
    weights = {"steer": 0.05, "left_drive": 2.0}
    model = odometry_model(robot, weights=weights)
    dq, beta = np.array([[4.0, 4.6]]), np.array([[1.3]])
    out = model.increments(dq, beta)
    a = robot.constraint_matrix(beta[0])
    w = np.repeat([weights.get(n, 1.0) for n in robot.wheel_names], 2)
    assigned = [robot.velocity_index(j) for j in model.rate_joints]
    free = [c for c in range(a.shape[1]) if c not in assigned]
    q_free = np.linalg.lstsq(w[:, None] * a[:, free], -(w[:, None] * a[:, assigned]) @ dq[0], rcond=None)[0]
    np.testing.assert_allclose(out.increments_robot[0], q_free[:3], atol=1e-12)
    q = np.zeros(a.shape[1])
    q[free], q[assigned] = q_free, dq[0]
    np.testing.assert_allclose(out.slip[0], np.linalg.norm(a @ q), atol=1e-12)  # the residual is unweighted


def test_small_steering_weight_tends_to_differential_odometry():
    robot = catalog.load("forklift")
    diff = odometry_model(robot, ["right_drive.spin", "left_drive.spin"])  # the classic differential odometry
    dq, beta = np.array([[4.0, 4.6]]), np.array([[1.3]])  # steering inconsistent with the drive wheels
    ref = diff.increments(dq).increments_robot[0]
    errs = [np.abs(odometry_model(robot, weights={"steer": w}).increments(dq, beta).increments_robot[0] - ref).max()
            for w in (1.0, 0.1, 0.01)]
    assert errs[0] > 1e-2  # equal weights: the steering angle bends the estimate
    assert errs[1] < 0.1 * errs[0] and errs[2] < 0.02 * errs[1]  # the blend vanishes like w^2
    with pytest.raises(SensingError, match="weight of wheel 'steer' must be a finite number > 0"):
        odometry_model(robot, weights={"steer": 0.0})
    with pytest.raises(UnknownNameError, match="has no wheel 'ster'"):
        odometry_model(robot, weights={"ster": 1.0})
