"""The one-pass odometry of steering robots (the kept maps per steering configuration, the fused kernel) against a
plain per-sample reference: least squares of the weighted constraint rows at mid-interval steering, then the
exact SE(2) step written with the group's exponential (not the kernel's half-angle form)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import wmrkit._jit as jit
import wmrkit.odometry.model as model_module
from wmrkit import catalog
from wmrkit.odometry.logs import JointLog
from wmrkit.odometry.model import SensingError, odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.slip.weights import SlipWeights, wls_model


def reference(model, log: JointLog, pose0=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Poses ``(N, 3)`` and slip ``(N,)`` one sample at a time, from the model's rows, columns and weights only."""
    robot = model.robot
    p = log.select(model.joints).positions
    rate = [model.joints.index(j) for j in model.rate_joints]
    steer = [model.joints.index(j) for j in model.steer_joints]
    assigned = [robot.velocity_index(j) for j in model.rate_joints]
    free = [c for c in model.cols if c not in assigned]
    w = np.asarray(model.row_weights)[:, None]  # the rows of the least squares scaled (sqrt(mu) for WLS, (7.50))
    x, y, th = pose0
    poses, slip = [np.array(pose0, dtype=float)], [0.0]
    for k in range(1, len(p)):
        beta = np.array(robot.beta, dtype=float)
        step = (p[k, steer] - p[k - 1, steer] + math.pi) % (2 * math.pi) - math.pi
        beta[model.steer_index] = p[k - 1, steer] + 0.5 * step
        a = robot.constraint_matrix(beta)[model.rows]
        dq = p[k, rate] - p[k - 1, rate]
        sol = np.linalg.lstsq(w * a[:, free], -(w * a[:, assigned]) @ dq, rcond=None)[0]
        q = np.zeros(a.shape[1])
        q[free], q[assigned] = sol, dq
        dx, dy, dth = q[:3]
        if abs(dth) > 1e-9:
            s, c = math.sin(dth) / dth, (1 - math.cos(dth)) / dth
        else:
            s, c = 1 - dth**2 / 6, dth / 2 - dth**3 / 24
        u, v = s * dx - c * dy, c * dx + s * dy  # the exponential of SE(2): V(dth) (dx, dy)
        x, y = x + math.cos(th) * u - math.sin(th) * v, y + math.sin(th) * u + math.cos(th) * v
        th += dth
        poses.append(np.array([x, y, th]))
        slip.append(float(np.linalg.norm(a @ q)))
    return np.array(poses), np.array(slip)


def steering_log(robot, n: int, *, quantum: float | None, seed: int = 0) -> JointLog:
    """Random drive: spins with noise (so the sensors disagree a little), steering as a random walk, quantised to
    `quantum` [rad] (None: continuous), crossing +-pi."""
    model = odometry_model(robot)
    rng = np.random.default_rng(seed)
    cols = []
    for j in model.joints:
        if j.endswith(".steer"):
            walk = np.pi - 0.3 + np.cumsum(rng.normal(0.0, 0.02, n))
            cols.append(walk if quantum is None else quantum * np.round(walk / quantum))
        else:
            cols.append(np.cumsum(rng.normal(0.2, 0.01, n)))
    return JointLog(np.arange(n) * 0.01, model.joints, np.column_stack(cols))


@pytest.fixture(params=["python", "compiled"])
def kernels(request, monkeypatch):
    """Fresh kernels, run as Python (below the interpret budget) or compiled (budget 0)."""
    import importlib

    import wmrkit.odometry._kernels
    import wmrkit.odometry._steering_kernels

    monkeypatch.setattr(jit, "INTERPRET_BUDGET", 10**9 if request.param == "python" else 0)
    importlib.reload(wmrkit.odometry._steering_kernels)
    importlib.reload(wmrkit.odometry._kernels)
    return request.param


FORKLIFT_WLS = SlipWeights.of({"right_drive": (1.0, 3.2e-3), "left_drive": (1.0, 3.2e-3), "steer": (19.2, 1.0)})


@pytest.mark.parametrize("quantum", [math.radians(1.4118), None])
@pytest.mark.parametrize("chunk_size", [1, 37, 4096])
def test_forklift_wls_equals_the_per_sample_reference(kernels, quantum, chunk_size):
    fork = catalog.load("forklift")
    log = steering_log(fork, 600, quantum=quantum)
    model = wls_model(fork, FORKLIFT_WLS)
    poses, slip = reference(model, log)
    out = odometry(model, log, chunk_size=chunk_size)
    np.testing.assert_allclose(out.poses, poses, rtol=0, atol=1e-11)  # 600 steps of round-off over ~100 m
    np.testing.assert_allclose(out.slip, slip, rtol=0, atol=1e-14)
    assert slip.max() > 1e-4  # the sensors disagree: the residual is exercised
    from wmrkit.odometry import _kernels

    assert _kernels.steered_chunk.is_compiled() == (kernels == "compiled")
    plain = odometry(odometry_model(fork), log, chunk_size=chunk_size).poses
    assert np.abs(plain - poses).max() > 1e-3  # and the weights matter


@pytest.mark.parametrize("name", ["swerve-4", "thesis-steer-castor", "ackermann"])
def test_several_steering_joints_equal_the_reference(kernels, name):
    robot = catalog.load(name)
    log = steering_log(robot, 300, quantum=0.01, seed=3)
    model = odometry_model(robot)
    poses, slip = reference(model, log)
    out = odometry(model, log, chunk_size=50)
    np.testing.assert_allclose(out.poses, poses, rtol=0, atol=1e-10)
    np.testing.assert_allclose(out.slip, slip, rtol=0, atol=1e-13)


def test_the_kept_maps_serve_later_chunks_and_logs_with_the_same_numbers(monkeypatch):
    fork = catalog.load("forklift")
    log = steering_log(fork, 2000, quantum=math.radians(1.4118), seed=5)
    model = wls_model(fork, FORKLIFT_WLS)
    first = odometry(model, log, chunk_size=300)
    maps = model.configuration_maps()[0]
    steer = log.positions[:, 2]
    mid = steer[:-1] + 0.5 * ((np.diff(steer) + np.pi) % (2 * np.pi) - np.pi)
    assert len(maps.keys) == len(np.unique(mid))  # each configuration once, over all chunks
    assert np.all(np.diff(maps.keys[:, 0]) > 0)  # sorted, as the kernel's binary search needs
    again = odometry(model, log, chunk_size=1000)  # every configuration already known
    np.testing.assert_array_equal(again.poses, first.poses)
    monkeypatch.setattr(model_module, "CACHE_SIZE", 3)  # a cache that restarts at every chunk
    small = odometry(wls_model(fork, FORKLIFT_WLS), log, chunk_size=300)
    np.testing.assert_array_equal(small.poses, first.poses)
    other = wls_model(fork, SlipWeights.uniform())  # a model of other weights keeps other maps
    assert len(other.configuration_maps()[0].keys) == 0


def test_the_increments_path_shares_the_kept_maps():
    fork = catalog.load("forklift")
    log = steering_log(fork, 400, quantum=math.radians(1.4118), seed=7)
    model = wls_model(fork, FORKLIFT_WLS)
    inc = model.from_positions(log.positions)
    beta = log.positions[:-1, 2] + 0.5 * ((np.diff(log.positions[:, 2]) + np.pi) % (2 * np.pi) - np.pi)
    s, rm = model.matrices(beta[:, None])
    dq = np.diff(log.positions[:, :2], axis=0)
    np.testing.assert_allclose(inc.increments_robot, np.einsum("nij,nj->ni", s[:, :3], dq), rtol=0, atol=1e-15)
    np.testing.assert_allclose(inc.residual, np.einsum("nij,nj->ni", rm, dq), rtol=0, atol=1e-15)
    poses = odometry(model, log).poses
    np.testing.assert_allclose(poses, reference(model, log)[0], rtol=0, atol=1e-11)


def test_an_undetermined_configuration_names_its_interval():
    bike = catalog.load("bicycle")
    model = odometry_model(bike)
    n = 40
    steer = np.full(n, 0.5)
    steer[25:] = 0.0  # front.steer = 0 (beta): the rear spin no longer fixes the motion
    log = JointLog(np.arange(n) * 0.01, model.joints, np.column_stack([np.arange(n) * 0.1, steer]))
    with pytest.raises(SensingError, match=r"interval 25: the sensed joints \(rear.spin, front.steer\) do not "
                                           r"determine the motion at steering headings front.steer=-90 deg \(0 = "
                                           r"straight ahead\)"):  # interval 24 ends half-way: 0.25 rad
        odometry(model, log)


def test_a_full_cache_met_mid_chunk_starts_afresh_with_all_it_needs(monkeypatch):
    fork = catalog.load("forklift")
    quantum = math.radians(1.4118)
    steady = steering_log(fork, 200, quantum=None, seed=8)
    held = steady.positions.copy()
    held[:, 2] = 40 * quantum  # one configuration
    turning = held.copy()
    turning[100:, 2] = quantum * np.arange(40, 140)  # then a new one at every sample
    expected = reference(wls_model(fork, FORKLIFT_WLS), JointLog(steady.time, steady.joints, turning))
    monkeypatch.setattr(model_module, "CACHE_SIZE", 8)
    model = wls_model(fork, FORKLIFT_WLS)
    odometry(model, JointLog(steady.time, steady.joints, held))  # keeps the first configuration
    out = odometry(model, JointLog(steady.time, steady.joints, turning))  # known, then more than 8 new
    np.testing.assert_allclose(out.poses, expected[0], rtol=0, atol=1e-11)
    np.testing.assert_allclose(out.slip, expected[1], rtol=0, atol=1e-14)


def test_a_full_turn_in_a_sensed_castor_angle_is_no_motion(kernels):
    """A sensed castor's steering column that jumps by 2 pi (a ROS joint wrapped to one turn) gives the same poses:
    its step enters the model as a rate and at mid-interval, both wrapped (the increments path already was)."""
    from wmrkit.odometry.synthetic import TwistProfile, simulate

    robot = catalog.load("thesis-diff-castor")
    model = odometry_model(robot)
    log = simulate(robot, TwistProfile.from_segments([(4.0, 0.0, 0.3, 0.4), (3.0, 0.0, 0.2, -0.5)]), 50.0,
                   sensed=model.joints).log
    turned = log.positions.copy()
    turned[len(turned) // 2:, model.joints.index("c3.steer")] += 2 * np.pi
    jumped = JointLog(log.time, log.joints, turned)
    straight = odometry(model, log)
    np.testing.assert_allclose(odometry(model, jumped).poses, straight.poses, rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.from_positions(turned).rate_increments,  # the increments path wraps too
                               model.from_positions(log.positions).rate_increments, rtol=0, atol=1e-12)


@pytest.mark.parametrize("n_angles", [1, 2])
def test_the_configuration_lookup_finds_every_key_and_nothing_else(n_angles):
    from wmrkit.odometry._steering_kernels import _find

    rng = np.random.default_rng(n_angles)
    for size in (0, 1, 2, 3, 7, 64, 151):
        keys = np.unique(np.round(rng.normal(0, 1, (size, n_angles)), 2), axis=0)  # sorted lexicographically
        ids = rng.permutation(len(keys)).astype(np.int64)
        known = {tuple(k): i for k, i in zip(keys.tolist(), ids.tolist(), strict=True)}
        queries = [*keys, *np.round(rng.normal(0, 1, (50, n_angles)), 3), np.full(n_angles, np.nan),
                   np.full(n_angles, -1e300), np.full(n_angles, 1e300)]
        for q in queries:
            expected = known.get(tuple(q.tolist()), -1)
            for find in (_find, _find.py_func):
                assert find(keys, ids, q) == expected, (size, q)


@pytest.mark.parametrize("rows", [0, 1, 2])
def test_the_fused_two_rate_maps_give_the_row_by_row_numbers_bit_for_bit(rows):
    from wmrkit.odometry import _kernels as k

    rng = np.random.default_rng(rows)
    maps, residual = rng.normal(size=(5, 3, 2)), rng.normal(size=(5, rows, 2))
    cols = rng.normal(size=(2, k.BLOCK)) * rng.choice([0.0, -0.0, 1.0, 1e-300, 1e300], size=(2, k.BLOCK))
    cuts = np.unique(np.concatenate([[0, k.BLOCK], rng.choice(k.BLOCK, 40)]))  # runs of 1 to ~20 samples
    seg_start, seg_u = cuts.astype(np.int64), rng.integers(0, 5, len(cuts) - 1).astype(np.int64)
    count = len(seg_u)
    for with_dy in (False, True):
        fused, rowwise = np.full((10, k.BLOCK), 7.0), np.full((10, k.BLOCK), 7.0)
        k._maps_two_rates(maps, residual, seg_u, seg_start, count, cols, with_dy, fused)
        k._apply_row(maps, 0, seg_u, seg_start, count, cols, rowwise[0])
        if with_dy:
            k._apply_row(maps, 1, seg_u, seg_start, count, cols, rowwise[1])
        k._apply_row(maps, 2, seg_u, seg_start, count, cols, rowwise[2])
        if rows:
            k._norm_rows(residual, seg_u, seg_start, count, cols, False, rowwise[9], rowwise[3])
        np.testing.assert_array_equal(fused[:4], rowwise[:4])
        assert np.array_equal(np.signbit(fused[:4]), np.signbit(rowwise[:4]))  # zeros of the same sign too
