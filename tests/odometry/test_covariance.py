"""Pose covariance: Crowley's model (003 (17), oracles B.4), Jacobians, closed-form propagation, Monte Carlo."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.errors import ShapeError, WmrkitError
from wmrkit.odometry.covariance import CrowleyNoise, JointNoise, propagate_covariance, step_jacobians
from wmrkit.odometry.integrators import METHODS, integrate_exact, integrate_increments, step
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate, square_path


@pytest.mark.parametrize(("dd", "dth", "var_d", "var_th", "sd_th_deg"), [
    (1.0, 0.0, 0.001, 0.003, 3.14),  # B.4 rows: sigma_D = 3.162 cm in all three with dD = 1 m
    (1.0, math.pi / 2, 0.001, 0.0045708, 3.87),
    (0.0, math.pi / 2, 0.0, 0.0015708, 2.27),
])
def test_crowley_oracles_of_b4(dd, dth, var_d, var_th, sd_th_deg):
    q = CrowleyNoise().input_covariance(dd, dth)
    assert q[0, 0] == pytest.approx(var_d, abs=1e-12)
    assert q[1, 1] == pytest.approx(var_th, abs=5e-8)
    assert q[0, 1] == q[1, 0] == 0.0  # "errors not collinear, so cross terms are ignored"
    assert math.degrees(math.sqrt(q[1, 1])) == pytest.approx(sd_th_deg, abs=5e-3)
    if dd:
        assert math.sqrt(q[0, 0]) == pytest.approx(0.03162, abs=5e-6)


def test_crowley_increment_covariance_generalises_17():
    noise = CrowleyNoise(0.002, 0.004, 0.0005)
    q = noise.increment_covariance([[-0.7, 0.0, 0.3]])[0]  # differential drive: dy = 0, backwards
    np.testing.assert_allclose(q, np.diag([0.002 * 0.7, 0.0, 0.004 * 0.7 + 0.0005 * 0.3]), atol=1e-18)
    q = noise.increment_covariance([[0.3, 0.4, 0.0]])[0]  # omnidirectional: along the direction of travel
    u = np.array([0.6, 0.8])
    np.testing.assert_allclose(q[:2, :2], 0.002 * 0.5 * np.outer(u, u), atol=1e-18)
    np.testing.assert_allclose(noise.increment_covariance(np.zeros((2, 3))), 0.0)


@pytest.mark.parametrize("method", METHODS)
def test_step_jacobians_against_central_differences(method):
    rng = np.random.default_rng(2)
    for _ in range(10):
        pose, inc = rng.normal(size=3), rng.normal(size=3) * [0.3, 0.2, 0.8]
        inc[2] = inc[2] if rng.random() > 0.3 else 1e-7  # also near the straight line
        j_pp, j_pi = step_jacobians(pose, inc, method)
        e = 1e-6
        num_pp = np.stack([(step(pose + e * d, inc, method) - step(pose - e * d, inc, method)) / (2 * e)
                           for d in np.eye(3)], axis=-1)
        num_pi = np.stack([(step(pose, inc + e * d, method) - step(pose, inc - e * d, method)) / (2 * e)
                           for d in np.eye(3)], axis=-1)
        np.testing.assert_allclose(j_pp, num_pp, rtol=0, atol=1e-9)
        np.testing.assert_allclose(j_pi, num_pi, rtol=0, atol=1e-9)


def test_euler_jacobians_agree_with_roboticstoolbox():
    mobile = pytest.importorskip("roboticstoolbox.mobile")
    veh = mobile.Bicycle()
    x, odo = np.array([0.4, -1.0, 0.9]), np.array([0.3, 0.2])
    j_pp, j_pi = step_jacobians(x, [odo[0], 0.0, odo[1]], "euler")
    np.testing.assert_allclose(j_pp, veh.Fx(x, odo), atol=1e-15)
    np.testing.assert_allclose(j_pi[:, [0, 2]], veh.Fv(x, odo), atol=1e-15)


def _recursion(poses, inc, q, method, p0):
    p, out = p0.copy(), []
    for k in range(len(inc)):
        f, g = step_jacobians(poses[k], inc[k], method)
        p = f @ p @ f.T + g @ q[k] @ g.T
        out.append(p)
    return np.array(out)


@settings(max_examples=100)
@given(st.integers(1, 40), st.sampled_from(METHODS), st.integers(0, 2**32 - 1), st.floats(-50, 50))
def test_closed_form_propagation_equals_the_recursion(n, method, seed, offset):
    rng = np.random.default_rng(seed)
    inc = rng.normal(size=(n, 3)) * [0.3, 0.1, 0.4]
    pose0 = np.array([offset, -offset, rng.normal()])
    poses = np.vstack([pose0, integrate_increments(pose0, inc, method)])
    a = rng.normal(size=(n, 3, 3)) * 0.01
    q = a @ np.swapaxes(a, -1, -2)  # any symmetric positive semi-definite increment covariance
    b = rng.normal(size=(3, 3)) * 0.1
    p0 = b @ b.T
    got = propagate_covariance(poses, inc, q, method, initial=p0)
    ref = _recursion(poses, inc, q, method, p0)
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12 * (1 + offset**2))


def test_propagated_covariance_matches_monte_carlo():
    """Noise drawn from Crowley's Q on every increment; 4000 trajectories integrated at once (batch axis)."""
    rng = np.random.default_rng(11)
    n, trials = 60, 4000
    inc = np.column_stack([np.full(n, 0.05), np.zeros(n), np.full(n, 0.02)])
    noise = CrowleyNoise(1e-4, 3e-4, 1e-4)  # small, so first order holds
    q = noise.increment_covariance(inc)
    poses = np.vstack([[0, 0, 0], integrate_increments([0, 0, 0], inc, "exact")])
    p = propagate_covariance(poses, inc, q, "exact")[-1]
    noisy = inc + rng.normal(size=(trials, n, 3)) * np.sqrt(np.diagonal(q, axis1=-2, axis2=-1))
    ends = integrate_increments(np.zeros((trials, 3)), noisy, "exact")[:, -1]
    sample = np.cov(ends.T)
    np.testing.assert_allclose(np.sqrt(np.diag(sample)), np.sqrt(np.diag(p)), rtol=0.05)
    corr = lambda c: c[0, 2] / math.sqrt(c[0, 0] * c[2, 2])  # noqa: E731
    assert corr(sample) == pytest.approx(corr(p), abs=0.05)


def test_joint_noise_through_the_differential_drive_is_the_closed_form():
    robot = catalog.load("diff-drive")
    model = odometry_model(robot)
    r, l, k = 0.075, 0.2, 1e-4
    dq = np.array([[2.0, 3.0]])
    q = JointNoise(per_rad=k).increment_covariance(model.solution[:3], dq)[0]
    var_l, var_r = k * 2.0, k * 3.0
    expected = np.array([[r * r / 4 * (var_l + var_r), 0, r * r / (4 * l) * (var_r - var_l)],
                         [0, 0, 0],
                         [r * r / (4 * l) * (var_r - var_l), 0, r * r / (4 * l * l) * (var_l + var_r)]])
    np.testing.assert_allclose(q, expected, rtol=1e-12, atol=1e-20)


def test_joint_noise_covariance_matches_simulated_encoder_noise():
    """End to end: the synthetic generator's random-walk spin noise (variance per_rad |dq|) against the pose
    covariance the pipeline propagates with JointNoise(per_rad) through the robot's kinematics."""
    robot = catalog.load("diff-drive")
    profile = TwistProfile.from_segments([(4.0, 0.5, 0.0, 0.3)])
    k = 2e-5
    ends = np.array([odometry(robot, simulate(robot, profile, 20.0, spin_noise_per_rad=k, oversample=1,
                                              seed=s).log).final_pose for s in range(300)])
    truth_run = simulate(robot, profile, 20.0)
    traj = odometry(robot, truth_run.log, noise=JointNoise(per_rad=k))
    p = traj.covariance[-1]
    sample = np.cov(ends.T)
    np.testing.assert_allclose(np.sqrt(np.diag(sample)), np.sqrt(np.diag(p)), rtol=0.12)
    assert np.all(np.abs(ends.mean(axis=0) - traj.final_pose) < 4 * np.sqrt(np.diag(p) / 300))  # unbiased


def test_shape_errors():
    with pytest.raises(WmrkitError, match="expected shapes"):
        propagate_covariance(np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3, 3)))
    with pytest.raises(WmrkitError, match=r"initial: expected a finite \(3, 3\) matrix"):
        propagate_covariance(np.zeros((4, 3)), np.zeros((3, 3)), np.zeros((3, 3, 3)), initial=np.eye(2))


def test_noise_and_covariances_that_cannot_be_are_refused_by_name():
    """A negative noise coefficient or initial covariance gave negative variances, and an asymmetric initial
    covariance was averaged into a symmetric one, silently."""
    from wmrkit.odometry.covariance import NoiseError

    with pytest.raises(NoiseError, match=r"CrowleyNoise\.k_d: a noise coefficient must be finite and >= 0, got -1"):
        CrowleyNoise(-1, 1, 1)
    with pytest.raises(NoiseError, match=r"JointNoise\.per_sample: a noise coefficient"):
        JointNoise(0.1, float("nan"))
    poses, inc = np.zeros((4, 3)), np.zeros((3, 3))
    q = np.tile(np.eye(3), (3, 1, 1))
    with pytest.raises(NoiseError, match="initial: a covariance must be positive semi-definite"):
        propagate_covariance(poses, inc, q, initial=-np.eye(3))
    with pytest.raises(NoiseError, match="increment_covariance: every matrix must be finite and symmetric"):
        propagate_covariance(poses, inc, -q)
    indefinite = q.copy()
    indefinite[1, 0, 1] = indefinite[1, 1, 0] = 2.0  # variances >= 0, but eigenvalue -1: gave negative variances
    with pytest.raises(NoiseError, match="increment_covariance: matrix 1 is not positive semi-definite"):
        propagate_covariance(poses, inc, indefinite)
    robot = catalog.load("diff-drive")
    log = simulate(robot, square_path(1.0), 50.0).log
    with pytest.raises(NoiseError, match="initial_covariance: a covariance must be positive semi-definite"):
        odometry(robot, log, noise=CrowleyNoise(), initial_covariance=-np.eye(3))
    with pytest.raises(NoiseError, match="initial_covariance: a covariance is symmetric"):
        odometry(robot, log, noise=CrowleyNoise(), initial_covariance=[[1, 5, 0], [0, 1, 0], [0, 0, 1]])
    assert np.isfinite(odometry(robot, log, noise=CrowleyNoise(), initial_covariance=np.eye(3) * 1e-4)
                       .covariance).all()


def test_initial_covariance_without_noise_is_refused():
    """odometry(..., initial_covariance=P0) without a noise model returned no covariance, P0 silently ignored."""
    from wmrkit.odometry.covariance import NoiseError

    robot = catalog.load("diff-drive")
    log = simulate(robot, square_path(1.0), 10.0).log
    with pytest.raises(NoiseError, match="initial_covariance: needs a noise model"):
        odometry(robot, log, initial_covariance=np.eye(3) * 1e-4)


@pytest.mark.parametrize("noise", [CrowleyNoise, "crowley", (0.001, 0.003, 0.001)])
def test_a_noise_that_is_no_noise_model_is_refused(noise):
    """The class instead of an instance failed with a misleading shape error, a string with an AttributeError."""
    from wmrkit.odometry.covariance import NoiseError

    robot = catalog.load("diff-drive")
    log = simulate(robot, square_path(1.0), 10.0).log
    with pytest.raises(NoiseError, match="noise: expected a CrowleyNoise or JointNoise instance"):
        odometry(robot, log, noise=noise)


def test_non_finite_poses_and_increments_are_refused_by_name():
    """NaN or infinite poses or increments went through as NaN covariances (step() refused them already)."""
    poses, inc = np.zeros((3, 3)), np.full((2, 3), 0.1)
    q = np.tile(np.eye(3) * 1e-3, (2, 1, 1))
    bad_poses, bad_inc = poses.copy(), inc.copy()
    bad_poses[1, 0], bad_inc[0, 2] = np.nan, np.inf
    with pytest.raises(WmrkitError, match="poses_world_robot: expected finite numbers, got nan"):
        propagate_covariance(bad_poses, inc, q)
    with pytest.raises(WmrkitError, match="increments_robot: expected finite numbers, got inf"):
        propagate_covariance(poses, bad_inc, q)
    with pytest.raises(WmrkitError, match="pose_world_robot: expected finite numbers"):
        step_jacobians([0.0, 0.0, np.nan], [1.0, 0.0, 0.0])
    with pytest.raises(WmrkitError, match="increments_robot: expected finite numbers"):
        CrowleyNoise().increment_covariance([np.nan, 0.0, 0.0])
    with pytest.raises(WmrkitError, match="delta_d: expected finite numbers"):
        CrowleyNoise().input_covariance(np.nan, 0.0)


@pytest.mark.parametrize(("call", "message"), [
    # numpy's "shape mismatch: objects cannot be broadcast to a single shape" named neither argument
    (lambda: step(np.zeros((4, 3)), np.ones((5, 3))), r"^pose_world_robot \(4, 3\) and increment_robot \(5, 3\): "
                                                      r"their batch shapes"),
    (lambda: step_jacobians(np.zeros((4, 3)), np.ones((5, 3))), r"^pose_world_robot \(4, 3\) and increment_robot"),
    (lambda: CrowleyNoise().input_covariance([1.0, 2.0], [1.0, 2.0, 3.0]), r"^delta_d \(2,\) and delta_theta \(3,\)"),
    (lambda: integrate_exact([0, 0, 0], [[1.0, 0, 1.0]] * 3, [0.1, 0.2]), r"^twist_robot \(3, 3\) and dt \(2, 1\)"),
    # text was read as a number: integrate_exact(..., '0.1') stepped 0.1 s
    (lambda: integrate_exact([0, 0, 0], [1.0, 0, 1.0], "0.1"), r"^dt: got the text '0\.1'"),
    (lambda: CrowleyNoise().input_covariance("1", 0.5), r"^delta_d: got the text '1'"),
])
def test_steps_refuse_batches_that_do_not_broadcast_and_text_by_name(call, message):
    with pytest.raises(ShapeError, match=message):
        call()


def test_first_order_covariance_matches_a_monte_carlo_of_the_steps():
    """Independent check of propagate_covariance: small Crowley noise drawn on every body increment of a curving,
    sideways-drifting path, each run integrated step by step; the sample covariance of the final poses (2e4 runs,
    fixed seed: 0.9 % of the largest entry off at most) equals the first-order propagation for every scheme. (The
    schemes' covariances differ by 2.5 % here, the accumulated heading noise dominating: this checks the
    propagation, the Jacobians of each scheme are checked against central differences above.)"""
    rng = np.random.default_rng(7)
    n, runs, scale = 40, 20_000, 0.01  # noise scaled down: first order is exact to O(scale^2)
    inc = np.column_stack([np.full(n, 0.05), np.full(n, 0.01), np.linspace(0.02, 0.08, n)])
    q = CrowleyNoise(1e-4, 3e-4, 1e-4).increment_covariance(inc)
    w, v = np.linalg.eigh(q)
    root = v * np.sqrt(np.clip(w, 0.0, None))[:, None, :]
    pose0 = np.array([0.3, -0.2, 0.7])
    drawn = inc + scale * (root @ rng.standard_normal((runs, n, 3, 1)))[..., 0]
    for method in METHODS:
        poses = np.vstack([pose0, integrate_increments(pose0, inc, method)])
        expected = propagate_covariance(poses, inc, q, method)[-1]
        x = np.tile(pose0, (runs, 1))
        for k in range(n):  # step by step, not through the compiled composition
            x = step(x, drawn[:, k], method)
        np.testing.assert_allclose(np.cov(x.T) / scale**2, expected, atol=0.02 * np.abs(expected).max())
