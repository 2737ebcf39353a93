"""The one-pass Kalman filters FK1/FK2 against a textbook covariance-form Kalman filter in numpy, and the reuse of
the covariance at a fixed point against the plain recursion, bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

import wmrkit._jit as jit
from wmrkit import catalog
from wmrkit.odometry.logs import JointLog
from wmrkit.odometry.model import odometry_model
from wmrkit.slip import _kalman_kernel
from wmrkit.slip.kalman import KalmanNoise, fk1_noise, fk2_noise, kalman_filter, kalman_model, kalman_odometry


def drive(robot, n: int, *, quantum: float, seed: int = 0, hold: int = 1) -> JointLog:
    """Spins with noise at 100 Hz (jittered steps), steering a random walk quantised to `quantum` [rad], changing
    at most every `hold` samples."""
    model = odometry_model(robot)
    rng = np.random.default_rng(seed)
    cols = []
    for j in model.joints:
        if j.endswith(".steer"):
            walk = np.repeat(np.pi / 2 + 0.2 + np.cumsum(rng.normal(0.0, 0.03, -(-n // hold))), hold)[:n]
            cols.append(quantum * np.round(walk / quantum))
        else:
            cols.append(np.cumsum(rng.normal(0.05, 0.004, n)))
    time = np.cumsum(rng.uniform(0.009, 0.011, n))
    return JointLog(time, model.joints, np.column_stack(cols))


def periods(dt: float, period: float | None) -> int:
    """The nominal periods in a step of `dt` [s]: the nearest whole number, at least 1 (1 without a period)."""
    return 1 if period is None else max(1, math.floor(dt / period + 0.5))


def textbook(model, log: JointLog, x0, p0, period=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Twists ``(N, 3)``, slip ``(N,)`` and the final covariance: predict ``P + n Q`` (`n` the `period`s in the
    step), gain ``K = P C^T (C P C^T + R)^-1``, update ``x + K (y - C x)``, ``(I - K C) P`` (Joseph's form; ``+ n Q``
    again with the model's ``thesis_double_q``, (7.75) as printed), with ``y = -A_a qdot``."""
    om = model.odometry
    robot = om.robot
    p = log.select(om.joints).positions
    t = np.asarray(log.time)
    rate = [om.joints.index(j) for j in om.rate_joints]
    steer = [om.joints.index(j) for j in om.steer_joints]
    cols = [robot.velocity_index(j) for j in om.rate_joints]
    x, cov = np.array(x0, dtype=float), np.array(p0, dtype=float)
    q, r = model.process * np.eye(3), np.diag(model.sigma**2)
    twists, slip = [], []
    for k in range(1, len(t)):
        dt = t[k] - t[k - 1]
        beta = np.array(robot.beta, dtype=float)
        step = (p[k, steer] - p[k - 1, steer] + math.pi) % (2 * math.pi) - math.pi
        beta[om.steer_index] = p[k - 1, steer] + 0.5 * step
        a = robot.constraint_matrix(beta)[model.rows]
        c, aa = a[:, :3], a[:, cols]
        qdot = (p[k, rate] - p[k - 1, rate]) / dt
        y = -aa @ qdot
        n = periods(dt, period)
        cov = cov + q * n
        gain = cov @ c.T @ np.linalg.inv(c @ cov @ c.T + r)
        x = x + gain @ (y - c @ x)
        keep = np.eye(3) - gain @ c
        cov = keep @ cov @ keep.T + gain @ r @ gain.T  # Joseph's form: (I - K C) P, symmetric and stable
        cov = cov + q * n if model.thesis_double_q else cov
        twists.append(x)
        slip.append(np.linalg.norm(c @ x - y) * dt)
    return np.array(twists), np.array(slip), cov


@pytest.fixture(params=["python", "compiled"])
def kernels(request, monkeypatch):
    """The filter's kernel, fresh, run as Python (below the interpret budget) or compiled (budget 0)."""
    import importlib

    monkeypatch.setattr(jit, "INTERPRET_BUDGET", 10**9 if request.param == "python" else 0)
    importlib.reload(_kalman_kernel)
    return request.param


CASES = [("forklift", "fk2", fk2_noise(0.28, 3.57, 0.28)), ("forklift", "fk1", fk1_noise(0.5, 0.3)),
         ("skid-steer-4", "fk2", KalmanNoise(0.5, 0.05, 2.0)), ("swerve-4", "fk2", KalmanNoise(2.0, 0.1, 0.3))]


@pytest.mark.parametrize(("name", "kind", "noise"), CASES)
def test_filter_equals_the_textbook_kalman_filter(kernels, name, kind, noise):
    robot = catalog.load(name)
    model = kalman_model(robot, kind, noise)
    log = drive(robot, 400, quantum=math.radians(1.4118), seed=1)
    x0, p0 = [0.1, 0.0, 0.0], np.diag([0.5, 0.2, 0.3])
    twists, slip, cov = textbook(model, log, x0, p0)
    run = kalman_filter(model, log, x0=x0, p0=p0)
    scale = np.abs(twists).max()
    np.testing.assert_allclose(run.twist, twists, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(run.slip, slip, rtol=0, atol=1e-12 * scale * 0.011)
    np.testing.assert_allclose(run.covariance, cov, rtol=0, atol=1e-12 * np.abs(cov).max())
    poses = kalman_odometry(model, log, x0=x0, p0=p0).poses  # composed in the same pass: the exact SE(2) step
    x, y, th = 0.0, 0.0, 0.0
    for dx, dy, dth in run.increments:
        s, c = (math.sin(dth) / dth, 2 * math.sin(dth / 2) ** 2 / dth) if dth else (1.0, 0.0)
        u, v = s * dx - c * dy, c * dx + s * dy
        x, y, th = x + math.cos(th) * u - math.sin(th) * v, y + math.sin(th) * u + math.cos(th) * v, th + dth
    np.testing.assert_allclose(poses[-1], [x, y, th], rtol=0, atol=1e-12 * len(log))


def plain_recursion(model, log: JointLog, x0, p0, period=None) -> tuple[np.ndarray, int]:
    """The information-form recursion of :mod:`wmrkit.slip._kalman_kernel` with both inverses computed at every
    step (no reuse), in Python floats with the kernel's own 3x3 inverse, ``n Q`` over a step of `n` periods: the
    twists ``(N, 3)``, and how many steps of one period gave back the covariance they started from (bit for bit)."""
    inverse = _kalman_kernel._inverse_sym.py_func
    om = model.odometry
    p = log.select(om.joints).positions
    t = np.asarray(log.time)
    rate = [om.joints.index(j) for j in om.rate_joints]
    steer = [om.joints.index(j) for j in om.steer_joints]
    maps = model.configuration_maps()
    x = [float(v) for v in x0]
    cov = [float(p0[0][0]), float(p0[0][1]), float(p0[0][2]), float(p0[1][1]), float(p0[1][2]), float(p0[2][2])]
    q, out, fixed = model.process, [], 0
    for k in range(1, len(t)):
        d = t[k] - t[k - 1]
        step = (p[k, steer] - p[k - 1, steer] + math.pi) % (2 * math.pi) - math.pi
        u = maps.find((p[k - 1, steer] + 0.5 * step)[None])[0]
        h, m = maps.arrays[0][u], maps.arrays[1][u]
        rates = [(p[k, j] - p[k - 1, j]) / d for j in rate]
        n = periods(d, period)
        i00, i01, i02, i11, i12, i22 = inverse(cov[0] + q * n, cov[1], cov[2], cov[3] + q * n, cov[4], cov[5] + q * n)
        before, cov = cov, list(inverse(i00 + h[0, 0], i01 + h[0, 1], i02 + h[0, 2], i11 + h[1, 1],
                                        i12 + h[1, 2], i22 + h[2, 2]))
        at_fixed_point = cov == before and n == 1
        fixed += at_fixed_point
        u00, u01, u02, u11, u12, u22 = cov
        pu = ((u00, u01, u02), (u01, u11, u12), (u02, u12, u22))
        pi = ((i00, i01, i02), (i01, i11, i12), (i02, i12, i22))
        if at_fixed_point:  # a fixed point: x+ = A x + G qdot with A = P+ P-^-1, G = P+ M
            a = [[pr[0] * pi[0][col] + pr[1] * pi[1][col] + pr[2] * pi[2][col] for col in range(3)] for pr in pu]
            g = [[pr[0] * m[0, col] + pr[1] * m[1, col] + pr[2] * m[2, col] for col in range(len(rates))] for pr in pu]
            c = [sum((g[r][col] * rates[col] for col in range(len(rates))), 0.0) for r in range(3)]
            x = [(c[r] + a[r][0] * x[0]) + (a[r][1] * x[1] + a[r][2] * x[2]) for r in range(3)]
        else:  # x+ = P+ (P-^-1 x + M qdot)
            c = [sum((m[r, col] * rates[col] for col in range(len(rates))), 0.0) for r in range(3)]
            b = [(c[r] + pi[r][0] * x[0]) + (pi[r][1] * x[1] + pi[r][2] * x[2]) for r in range(3)]
            x = [pr[0] * b[0] + pr[1] * b[1] + pr[2] * b[2] for pr in pu]
        out.append(x)
    return np.array(out), fixed


def test_the_covariance_kept_at_its_fixed_point_changes_no_bit(kernels):
    fork = catalog.load("forklift")
    model = kalman_model(fork, "fk2", fk2_noise(0.28, 3.57, 0.28))
    log = drive(fork, 1500, quantum=math.radians(1.4118), seed=2, hold=300)  # runs long enough to reach it
    x0, p0 = [0.2, 0.0, 0.0], np.eye(3)
    run = kalman_filter(model, log, x0=x0, p0=p0)
    reference, fixed = plain_recursion(model, log, x0, p0)
    assert fixed > 1000  # most steps start at the fixed point: the kernel skips their inverses
    np.testing.assert_array_equal(run.increments, reference * np.diff(log.time)[:, None])
    assert _kalman_kernel.kalman_chunk.is_compiled() == (kernels == "compiled")


def with_gaps(log: JointLog, count: int, seed: int) -> JointLog:
    """`log` with `count` of its steps (not the first ten) made 0.02 to 3 s long: 2 to 300 periods."""
    rng = np.random.default_rng(seed)
    steps = np.diff(log.time)
    steps[rng.choice(np.arange(10, len(steps)), count, replace=False)] = rng.uniform(0.02, 3.0, count)
    return JointLog(np.concatenate([log.time[:1], log.time[0] + np.cumsum(steps)]), log.joints, log.positions)


@pytest.mark.parametrize(("name", "kind", "noise", "double_q"), [(*c, False) for c in CASES[:3]] + [(*CASES[0], True)])
def test_long_steps_add_their_periods_of_process_noise(name, kind, noise, double_q):
    """A step of n nominal periods predicts ``P + n Q`` (the textbook filter with that Q; (7.75) as printed adds it
    again), the period the median of the log's steps (0.01 s, jittered by 10%)."""
    robot = catalog.load(name)
    model = kalman_model(robot, kind, noise, thesis_double_q=double_q)
    log = with_gaps(drive(robot, 400, quantum=math.radians(1.4118), seed=1), 20, seed=2)
    x0, p0 = [0.1, 0.0, 0.0], np.diag([0.5, 0.2, 0.3])
    run = kalman_filter(model, log, x0=x0, p0=p0)
    assert run.period == np.median(np.diff(log.time)) and abs(run.period - 0.01) < 1e-4
    twists, slip, cov = textbook(model, log, x0, p0, run.period)
    scale = np.abs(twists).max()
    np.testing.assert_allclose(run.twist, twists, rtol=0, atol=1e-12 * scale)
    assert np.all(np.abs(run.slip - slip) <= 1e-12 * scale * np.diff(log.time))  # [m]: over each step
    np.testing.assert_allclose(run.covariance, cov, rtol=0, atol=1e-12 * np.abs(cov).max())


def test_a_long_step_leaves_the_fixed_point_and_the_recursion_finds_it_again_bit_for_bit(kernels):
    fork = catalog.load("forklift")
    model = kalman_model(fork, "fk2", fk2_noise(0.28, 3.57, 0.28))
    log = with_gaps(drive(fork, 1500, quantum=math.radians(1.4118), seed=2, hold=300), 12, seed=3)
    x0, p0 = [0.2, 0.0, 0.0], np.eye(3)
    run = kalman_filter(model, log, x0=x0, p0=p0)
    reference, fixed = plain_recursion(model, log, x0, p0, run.period)
    assert fixed > 600  # the fixed point found again after each of the 12 long steps
    np.testing.assert_array_equal(run.increments, reference * np.diff(log.time)[:, None])


def test_new_configurations_met_mid_run_give_the_same_numbers():
    fork = catalog.load("forklift")
    log = drive(fork, 3000, quantum=math.radians(1.4118), seed=4)
    fresh = kalman_model(fork, "fk2", fk2_noise(0.28, 3.57, 0.28))
    first = kalman_odometry(fresh, log)  # every configuration new: the pass stops, adds them, resumes
    known = len(fresh.configuration_maps().keys)
    again = kalman_odometry(fresh, log)  # all known
    np.testing.assert_array_equal(again.poses, first.poses)
    np.testing.assert_array_equal(again.slip, first.slip)
    assert known == len(fresh.configuration_maps().keys) > 10


def test_a_full_cache_met_mid_run_starts_afresh_with_all_it_needs(monkeypatch):
    import wmrkit.odometry.model as model_module

    fork = catalog.load("forklift")
    quantum = math.radians(1.4118)
    held = drive(fork, 200, quantum=quantum, seed=6)
    held.positions[:, 2] = 40 * quantum  # one configuration
    turning = JointLog(held.time, held.joints, held.positions.copy())
    turning.positions[100:, 2] = quantum * np.arange(40, 140)  # then a new one at every sample
    noise = fk2_noise(0.28, 3.57, 0.28)
    expected = kalman_odometry(kalman_model(fork, "fk2", noise), turning)
    monkeypatch.setattr(model_module, "CACHE_SIZE", 8)
    model = kalman_model(fork, "fk2", noise)
    kalman_odometry(model, held)  # keeps the first configuration
    out = kalman_odometry(model, turning)  # known, then more than 8 new
    np.testing.assert_array_equal(out.poses, expected.poses)


def test_a_log_filtered_in_pieces_gives_the_same_bits():
    fork = catalog.load("forklift")
    model = kalman_model(fork, "fk2", fk2_noise(0.28, 3.57, 0.28))
    log = drive(fork, 1500, quantum=math.radians(1.4118), seed=3, hold=200)  # pieces cut inside fixed-point runs
    whole = kalman_filter(model, log, x0=[0.2, 0.0, 0.0], p0=np.eye(3))
    x, p, increments = [0.2, 0.0, 0.0], np.eye(3), []
    for a, b in ((0, 450), (449, 1130), (1129, 1500)):  # each piece starts at the sample the one before ended on
        run = kalman_filter(model, log.slice(a, b), x0=x, p0=p)
        x, p = run.twist[-1], run.covariance
        increments.append(run.increments)
    np.testing.assert_array_equal(np.concatenate(increments), whole.increments)


@pytest.mark.parametrize("scale", [1e100, 1e-100, 3.7])
def test_only_the_ratios_of_the_noises_matter(scale):
    """Scaling every standard deviation scales the covariance by its square and leaves the twists: the filter runs
    on their ratios. Before, k13 = 1e100 (a valid noise) overflowed the 3x3 inverses and odometry printed a pose of
    NaN (null in JSON) with exit 0."""
    fork = catalog.load("forklift")
    log = drive(fork, 300, quantum=math.radians(1.4118), seed=5)
    base = kalman_model(fork, "fk2", fk2_noise(0.28, 3.57, 0.28))
    scaled = kalman_model(fork, "fk2", fk2_noise(0.28 * scale, 3.57 * scale, 0.28 * scale, scale))
    x0, p0 = [0.1, 0.0, 0.0], np.diag([0.5, 0.2, 0.3])
    want = kalman_filter(base, log, x0=x0, p0=p0)
    got = kalman_filter(scaled, log, x0=x0, p0=p0 * scale**2)
    np.testing.assert_allclose(got.twist, want.twist, rtol=0, atol=1e-13 * np.abs(want.twist).max())
    np.testing.assert_allclose(got.covariance / scale**2, want.covariance, rtol=1e-13)
    poses = kalman_odometry(scaled, log).poses
    np.testing.assert_allclose(poses, kalman_odometry(base, log).poses, rtol=0, atol=1e-12)


def test_a_result_that_is_not_finite_is_refused_not_printed():
    """The summary every odometry run returns refuses non-finite numbers (an overflow inside wmrkit): the CLI says
    so in one line instead of printing null with exit 0."""
    from wmrkit.errors import WmrkitError
    from wmrkit.odometry.pipeline import OdometrySummary

    good = OdometrySummary("forklift", "fk2", 3, 0.0, 1.0, (1.0, 2.0, 0.5), 3.0, 0.5, 0.0, 0.0, 0.01)
    assert good.to_dict()["final_pose"] == [1.0, 2.0, 0.5]
    with pytest.raises(WmrkitError, match="not finite"):
        OdometrySummary("forklift", "fk2", 3, 0.0, 1.0, (math.nan, 2.0, 0.5), 3.0, 0.5, 0.0, 0.0, 0.01)
    with pytest.raises(WmrkitError, match="not finite"):
        OdometrySummary("forklift", "fk2", 3, 0.0, 1.0, (1.0, 2.0, 0.5), 3.0, 0.5, 0.0, math.inf, 0.01)


@pytest.mark.parametrize(("rows", "cols"), [(0, 5), (1, 5), (2, 5), (3, 5), (4, 5), (5, 5), (4, 6)])
def test_the_slip_norms_of_two_rates_are_the_generic_ones_bit_for_bit(rows, cols):
    """The slip indicator's one-loop form for five columns (two sensed rates) against the generic loops per row and
    column (:func:`_norm_rows`, same sums in the same order: equal bits) and against numpy (round-off); six
    columns take the generic loops. Runs of every length, the short ones of a quantised steering angle first."""
    from wmrkit.odometry._kernels import BLOCK, _norm_rows

    rng = np.random.default_rng(rows)
    ca = np.triu(rng.normal(size=(3, rows, cols)))
    z = rng.normal(size=(cols, BLOCK)) * 10.0 ** rng.integers(-3, 4, size=(cols, 1))
    lengths = [1, 2, 3, 4, 5, 1, 8, 1, 17, 2, 60]
    seg_start = np.cumsum([0, *lengths, BLOCK - sum(lengths)])
    seg_u = np.arange(len(seg_start) - 1) % 3
    count = len(seg_u)
    want, got, acc = np.empty(BLOCK), np.full(BLOCK, np.nan), np.empty(BLOCK)
    _norm_rows.py_func(ca, seg_u, seg_start, count, z, True, acc, want)
    for fn in (_kalman_kernel._slip_norms, _kalman_kernel._slip_norms.py_func):
        fn(ca, seg_u, seg_start, count, z, acc, got)
        np.testing.assert_array_equal(got, want)
    u = np.repeat(seg_u, np.diff(seg_start))
    np.testing.assert_allclose(got, np.linalg.norm(np.einsum("jrc,cj->jr", ca[u], z), axis=1), rtol=1e-13, atol=0)
