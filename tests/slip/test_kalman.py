"""FK1 / FK2 (7.68)-(7.77): the recursion as printed, its limits, and the corrected covariance update (7.75)."""

from __future__ import annotations

import numpy as np
import pytest
from slip_helpers import L3, L12, R, forklift_at_axle, thesis_twist_to_rep

from wmrkit import catalog
from wmrkit.errors import ShapeError, WmrkitError
from wmrkit.odometry.logs import JointLog
from wmrkit.slip.kalman import KalmanNoise, fk1_noise, fk2_noise, kalman_filter, kalman_model, kalman_odometry
from wmrkit.slip.models import wls
from wmrkit.slip.weights import SlipWeights

JOINTS = ("right_drive.spin", "left_drive.spin", "steer.steer")


def forklift_log(u1, u2, beta3_thesis, dt=0.05):
    """A log of the forklift at axle origin from forward wheel speeds ``(N,)`` and thesis steering at the
    samples: ``(N,)`` constant over each interval, or ``(N + 1,)`` (the filter uses the interval's mid-angle)."""
    u1, u2 = np.broadcast_arrays(np.asarray(u1, dtype=float), np.asarray(u2, dtype=float))
    n = len(u1)
    b = np.asarray(beta3_thesis, dtype=float)
    pos = np.zeros((n + 1, 3))
    pos[1:, 0] = np.cumsum(u1 / R * dt)
    pos[1:, 1] = np.cumsum(u2 / R * dt)
    pos[:, 2] = (b if len(b) == n + 1 else np.concatenate([b[:1], b])) + np.pi / 2
    return JointLog(np.arange(n + 1) * dt, JOINTS, pos)


def literal_kf(c_seq, y_seq, q, r_diag, x0, p0, double_q):
    """(7.71)-(7.75) literally, with the gain (7.73) and an m x m inverse: the reference."""
    x, p = np.array(x0, float), np.array(p0, float)
    out = []
    for c, y in zip(c_seq, y_seq, strict=True):
        p = p + q * np.eye(3)
        k = p @ c.T @ np.linalg.inv(c @ p @ c.T + np.diag(r_diag))
        x = x + k @ (y - c @ x)
        p = (np.eye(3) - k @ c) @ p + (q * np.eye(3) if double_q else 0.0)
        out.append(x)
    return np.array(out), p


@pytest.mark.parametrize("double_q", [False, True])
def test_kernel_is_the_printed_recursion(double_q):
    """The compiled information-form filter equals (7.71)-(7.75) evaluated literally (thesis frame, (7.70))."""
    rng = np.random.default_rng(3)
    n = 60
    u1, u2 = 2 + 0.3 * rng.normal(size=n), 1.8 + 0.3 * rng.normal(size=n)
    nodes = np.radians(-10) + 0.05 * rng.normal(size=n + 1)
    b = 0.5 * (nodes[1:] + nodes[:-1])
    k16, k17, k18 = 0.28, 3.57, 0.28
    model = kalman_model(forklift_at_axle(), "fk2", fk2_noise(k16, k17, k18, k13=0.7), thesis_double_q=double_q)
    x0, p0 = np.array([0.1, 2.0, 0.2]), np.diag([0.3, 0.2, 0.1])
    run = kalman_filter(model, forklift_log(u1, u2, nodes), x0=thesis_twist_to_rep(x0), p0=p0)
    # thesis FK2 output equation (7.70) in its own frame; state (vx, vy, omega) with x to the right
    cs = [np.array([[1, 0, 0], [0, -1, -L12], [0, -1, L12], [np.cos(bk), np.sin(bk), L3 * np.cos(bk)]]) for bk in b]
    ys = [np.array([0, -u1[k], -u2[k], 0]) for k in range(n)]  # phi_dot r = -u
    p0_thesis = np.diag([0.2, 0.3, 0.1])  # (x, y) swapped: vx_thesis = -vy_rep, vy_thesis = vx_rep
    want, p_end = literal_kf(cs, ys, 0.49, [k16**2, k17**2, k17**2, k18**2], x0, p0_thesis, double_q)
    assert np.allclose(run.twist, thesis_twist_to_rep(want), atol=1e-9)
    perm = [1, 0, 2]
    sign = np.array([1, -1, 1])
    assert np.allclose(run.covariance, (p_end[np.ix_(perm, perm)] * np.outer(sign, sign)), atol=1e-10)


def test_fk1_without_filtering_is_the_inverse_of_c1():
    """R << Q: FK1 reduces to x = C1^-1 y (7.76); the spec's value (-0.405, 2, 0.3) at (2.135, 1.865, 0 deg).
    (Variances 1e10 apart; a spread of the standard deviations beyond 1e6 is refused, MAX_SPREAD.)"""
    model = kalman_model(forklift_at_axle(), "fk1", fk1_noise(1e-3, 1e-3, k13=1e2))
    run = kalman_filter(model, forklift_log([2.135] * 3, [1.865] * 3, [0.0] * 3))
    assert np.allclose(run.twist[-1], thesis_twist_to_rep([-0.405, 2.0, 0.3]), atol=1e-6)


def test_fk2_without_memory_is_wls():
    """Q >> R: each update is the weighted least squares with mu = 1 / sigma^2 (spec §6.3)."""
    rng = np.random.default_rng(4)
    u1, u2, b = 2 + rng.normal(size=20), 2 + rng.normal(size=20), np.full(20, 0.2)
    noise = KalmanNoise(1e4, 0.3, 0.3, (("right_drive", 0.1, 2.0), ("left_drive", 0.1, 2.0)))
    run = kalman_filter(kalman_model(forklift_at_axle(), "fk2", noise), forklift_log(u1, u2, b))
    w = SlipWeights.of({"right_drive": (100.0, 0.25), "left_drive": (100.0, 0.25), "steer": (1 / 0.09, 1.0)})
    want = wls(forklift_at_axle(), JOINTS[:2], np.stack([u1, u2], -1) / R, b[:, None] + np.pi / 2, w).twist
    assert np.allclose(run.twist, want, atol=1e-6)


def test_standard_update_is_the_batch_estimate_and_the_printed_one_is_not():
    """Erratum (7.75): the filtered state and covariance equal the batch least-squares (MAP) estimate of the
    random walk (7.68) with all measurements so far, an independent formulation; the printed update, which adds
    Q after the measurement as well, does not (its covariance is too large)."""
    rng = np.random.default_rng(5)
    n = 8
    u1, u2, b = 2 + rng.normal(size=n), 2 + rng.normal(size=n), np.full(n, -0.15)
    k13 = 0.5
    noise = fk2_noise(0.3, 0.8, 0.4, k13)
    log = forklift_log(u1, u2, b)
    x0, p0 = np.array([2.0, 0.0, 0.0]), np.eye(3) * 0.2
    model = kalman_model(forklift_at_axle(), "fk2", noise)
    _, _, c, aa = model.matrices(b[:, None] + np.pi / 2)
    rates = np.stack([u1, u2], -1) / R
    # batch: unknowns x_1..x_n; prior x_1 ~ N(x0, p0 + Q), x_{k+1} - x_k ~ N(0, Q), rows C x_k = -A_a qdot_k
    blocks, rhs = [], []
    lp = np.linalg.cholesky(np.linalg.inv(p0 + k13**2 * np.eye(3))).T
    e = np.zeros((3, 3 * n))
    e[:, :3] = lp
    blocks.append(e)
    rhs.append(lp @ x0)
    for k in range(n - 1):
        e = np.zeros((3, 3 * n))
        e[:, 3 * k:3 * k + 3], e[:, 3 * k + 3:3 * k + 6] = -np.eye(3) / k13, np.eye(3) / k13
        blocks.append(e)
        rhs.append(np.zeros(3))
    for k in range(n):
        e = np.zeros((len(model.sigma), 3 * n))
        e[:, 3 * k:3 * k + 3] = c[k] / model.sigma[:, None]
        blocks.append(e)
        rhs.append(-(aa[k] @ rates[k]) / model.sigma)
    big, y = np.vstack(blocks), np.concatenate(rhs)
    sol = np.linalg.lstsq(big, y, rcond=None)[0]
    cov_last = np.linalg.inv(big.T @ big)[-3:, -3:]
    run = kalman_filter(model, log, x0=x0, p0=p0)
    assert np.allclose(run.twist[-1], sol[-3:], atol=1e-9)
    assert np.allclose(run.covariance, cov_last, atol=1e-12)
    printed = kalman_filter(kalman_model(forklift_at_axle(), "fk2", noise, thesis_double_q=True), log, x0=x0, p0=p0)
    assert not np.allclose(printed.covariance, cov_last, atol=1e-3)
    assert np.all(np.linalg.eigvalsh(printed.covariance - cov_last) > 0)


@pytest.mark.parametrize(("options", "message"), [
    ({"p0": -np.eye(3)}, "p0: a covariance must be positive definite, its least eigenvalue is -1"),
    ({"p0": np.zeros((3, 3))}, "p0: a covariance must be positive definite"),
    ({"p0": [[1.0, 5.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]}, "p0: a covariance is symmetric"),
    ({"p0": np.full((3, 3), np.nan)}, r"p0: expected a finite \(3, 3\) matrix"),
    ({"x0": [np.nan, 0.0, 0.0]}, r"x0: expected a twist \(vx, vy, omega\), finite"),
    ({"x0": [0.0, 0.0]}, r"x0: expected a twist"),  # a bare reshape error
])
def test_the_filter_refuses_a_start_that_is_not_a_twist_and_a_covariance(options, message):
    """p0 = -I (or NaN, or x0 NaN) gave every twist, increment and covariance NaN, without an error."""
    model = kalman_model(forklift_at_axle(), "fk2", fk2_noise(0.5, 0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match=message):
        kalman_filter(model, forklift_log([2.0] * 3, [1.9] * 3, [0.0] * 3), **options)


@pytest.mark.parametrize(("time", "spin", "call", "message"), [
    ([0.0, 0.1, 0.1, 0.2], [0.0, 0.1, 0.2, 0.3], "filter", r"sample 2: time 0.1 s repeats"),
    ([0.0, 0.1, 0.05, 0.2], [0.0, 0.1, 0.2, 0.3], "odometry", r"sample 2: time 0.05 s goes backwards"),
    ([0.0, 0.1, 0.2, 0.3], [0.0, 0.1, np.nan, 0.3], "odometry", r"sample 2: right_drive.spin: value nan"),
    ([0.0, 0.1, 0.2, 0.3], [0.0, 0.1, 0.2, 0.3], {"pose0": [0.0, 0.0, np.nan]}, r"pose0: must be finite"),
    ([0.0, 0.1, 0.2, 0.3], [0.0, 0.1, 0.2, 0.3], {"pose0": [0.0, 0.0]}, r"pose0: expected shape .*got \(2,\)"),
    ([0.0, 0.1, 0.2, 0.3], [0.0, 0.1, 0.2, 0.3], {"pose0": [1e300, 0.0, 0.0]}, r"pose0: a position beyond"),
])
def test_the_filter_refuses_a_log_or_start_pose_that_odometry_refuses(time, spin, call, message):
    """kalman_filter and kalman_odometry (Python) gave NaN twists and poses for a repeated time or a NaN reading,
    wrong numbers for time going backwards and a NaN path for a NaN start pose (a (2,) pose: numpy's broadcast error),
    where odometry() and the CLI refuse them."""
    model = kalman_model(catalog.load("forklift"), "fk2")
    spin = np.array(spin)
    log = JointLog(np.array(time), ("right_drive.spin", "left_drive.spin", "steer.steer"),
                   np.column_stack([spin, spin, np.full(4, np.pi / 2)]))
    with pytest.raises(WmrkitError, match=message):
        if call == "filter":
            kalman_filter(model, log)
        else:
            kalman_odometry(model, log, **({} if call == "odometry" else call))


@pytest.mark.parametrize(("call", "message"), [
    # a mapping raised AttributeError "'dict' object has no attribute 'wheels'"
    (lambda: kalman_model(catalog.load("forklift"), "fk2", {"process": 1.0}),
     r"noise: expected KalmanNoise or None \(KalmanNoise\(process, lateral, longitudinal\)"),
    # a string raised ValueError "not enough values to unpack (expected 3, got 1)"
    (lambda: KalmanNoise(wheels="steer"), r"Kalman noise wheels: expected \(\(wheel name, lateral, longitudinal\)"),
    (lambda: KalmanNoise(wheels=(("steer", 1.0),)), "Kalman noise wheels: expected"),
    # text was printed bare ("got 1", as if 1 were refused); a boolean was read as 1
    (lambda: KalmanNoise("1"), r"Kalman noise process: must be a finite number in \[1e-150, 1e\+150\], got '1'"),
    (lambda: KalmanNoise(True), "Kalman noise process: must be a finite number .*, got True"),
    # fk2_noise's merged lateral noise raised numpy's TypeError "can't multiply sequence by non-int" for text
    (lambda: fk2_noise("1", 1.0, 1.0), r"Kalman noise right_drive \(lateral\): .*, got '1'"),
    (lambda: fk2_noise(True, 1.0, 1.0), r"Kalman noise right_drive \(lateral\): .*, got True"),
    (lambda: KalmanNoise(lateral=-1.0), r"Kalman noise lateral: must be a finite number in .*, got -1.0"),
    (lambda: KalmanNoise(1e-4, 1e4), r"Kalman noise process \(0.0001\) and lateral \(10000\) differ by more"),
    (lambda: KalmanNoise(period=0.0), r"Kalman noise period: the nominal sample period must be a finite number"),
])
def test_the_filters_python_doors_refuse_what_is_not_their_noise(call, message):
    """A ShapeError (a ValueError) naming the argument, as every keyword door of the Python API (docs/conventions.md):
    these raised a bare WmrkitError, which ``except ValueError`` did not catch."""
    with pytest.raises(ShapeError, match=message):
        call()
