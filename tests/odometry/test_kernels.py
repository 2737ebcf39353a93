"""The compiled kernels: inlined sine, cosine and sinc against mpmath, libm fallbacks, the fused pipeline path
against the model-then-integration path, and a read-only installation (no cache directory)."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import mpmath
import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry import _kernels
from wmrkit.odometry.covariance import CrowleyNoise
from wmrkit.odometry.integrators import integrate_increments, step
from wmrkit.odometry.logs import JointLog, LogError
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import Slip, TwistProfile, simulate


def _ulps(got: np.ndarray, exact: list) -> np.ndarray:
    """|got - exact| in units of the last place of the exact value rounded to double."""
    ref = np.array([float(e) for e in exact])
    err = np.array([abs(mpmath.mpf(float(g)) - e) for g, e in zip(got, exact, strict=True)], dtype=float)
    return err / np.spacing(np.abs(ref))


def _angles() -> np.ndarray:
    rng = np.random.default_rng(4)
    k = rng.integers(1, 2**20, 40).astype(float)
    return np.concatenate([
        [0.0, -0.0, 5e-324, 1e-300, 1e-9, math.pi / 4, math.pi / 2, math.pi, 1e5, -2.0**20],
        rng.uniform(-1, 1, 300), rng.uniform(-100, 100, 300), rng.uniform(-1e4, 1e4, 200),
        rng.uniform(-2.0**20, 2.0**20, 200),
        np.nextafter(k * (math.pi / 2), 0.0), np.nextafter(k * (math.pi / 2), 1e9),  # hard cases of the reduction
        [2.0**20 + 0.5, -3e6, 1e12, 1e300]])  # beyond TRIG_MAX: libm


def test_inlined_cosine_and_sine_are_faithful():
    """Euler steps of (1, 0, 0) from heading theta give (cos theta, sin theta): error below 1 ulp (mpmath)."""
    theta = _angles()
    pose0 = np.column_stack([np.zeros_like(theta), np.zeros_like(theta), theta])
    got = integrate_increments(pose0, np.tile([1.0, 0.0, 0.0], (len(theta), 1, 1)), "euler")[:, 0]
    mpmath.mp.dps = 40
    exact = [(mpmath.cos(mpmath.mpf(t)), mpmath.sin(mpmath.mpf(t))) for t in theta]
    assert _ulps(got[:, 0], [c for c, _ in exact]).max() < 1.0
    nonzero = theta != 0  # sin(+-0) = +-0 exactly
    assert _ulps(got[nonzero, 1], [s for (_, s), nz in zip(exact, nonzero, strict=True) if nz]).max() < 1.0
    assert np.all(got[~nonzero, 1] == 0.0)


def test_chord_factor_is_sinc_to_the_last_bit():
    """An exact step turning 2h from heading -h moves sinc(h) along x; polynomial up to pi/4, then libm."""
    h = np.concatenate([[1e-300, 1e-8, 1e-4, 0.01], np.linspace(0.02, math.pi / 4, 40), [0.8, 1.5, 3.0]])
    poses = np.column_stack([np.zeros_like(h), np.zeros_like(h), -h])
    got = step(poses, np.column_stack([np.ones_like(h), np.zeros_like(h), 2 * h]), "exact")
    mpmath.mp.dps = 40
    exact = np.array([float(mpmath.sin(mpmath.mpf(v)) / mpmath.mpf(v)) for v in h])
    np.testing.assert_allclose(got[:, 0], exact, rtol=2.3e-16, atol=0)
    np.testing.assert_array_equal(got[:, 1], 0.0)
    np.testing.assert_array_equal(got[:, 2], h)


def test_a_block_crossing_the_inlined_range_matches_libm():
    """Headings crossing TRIG_MAX inside a block: every step still matches math.cos / math.sin."""
    n = 3 * _kernels.BLOCK
    inc = np.column_stack([np.full(n, 0.01), np.full(n, 0.002), np.full(n, 0.01)])
    theta0 = _kernels.TRIG_MAX - 0.01 * (n // 2)
    poses = integrate_increments([0.0, 0.0, theta0], inc, "euler")
    x = y = 0.0
    th = theta0
    for k in range(n):
        c, s = math.cos(th), math.sin(th)
        x, y, th = x + c * inc[k, 0] - s * inc[k, 1], y + s * inc[k, 0] + c * inc[k, 1], th + inc[k, 2]
        np.testing.assert_allclose(poses[k], [x, y, th], rtol=0, atol=1e-15 * (k + 1))


@pytest.mark.parametrize("name", ["diff-drive", "mecanum-4", "forklift"])
def test_fused_pipeline_equals_model_then_integration(name):
    """odometry() (one compiled pass; positions differenced in the kernel for robots that do not steer) against
    the sensed model's increments integrated by integrate_increments, and its summary against numpy sums."""
    robot = catalog.load(name)
    profile = TwistProfile.from_segments([(2.0, 0.4, 0.0, 0.3), (1.0, 0.3, 0.0, -0.5)])
    profile = profile.about((-1.0, 0.0)) if name == "forklift" else profile  # its rear axle
    slips = [Slip(f"{robot.wheel_names[0]}.spin", 0.5, 1.0, 0.3)]
    run = simulate(robot, profile, 100.0, slips=slips, steer_noise=1e-3 if name == "forklift" else 0.0)
    model = odometry_model(robot)
    traj = odometry(model, run.log, chunk_size=77)
    inc = model.from_positions(run.log.positions)
    expected = integrate_increments(traj.poses[0], inc.increments_robot)
    np.testing.assert_allclose(traj.poses[1:], expected, rtol=0, atol=1e-13)
    np.testing.assert_allclose(traj.slip[1:], inc.slip, rtol=0, atol=1e-15)
    assert traj.slip[0] == 0
    if name == "mecanum-4":
        assert inc.slip.max() > 1e-4  # the slip shows: the residual path is exercised


def test_the_covariance_path_gives_the_same_poses(diff_run):
    """With noise the pipeline builds the model's increments (numpy differences); without, the kernel differences
    the positions itself: the same subtractions, so the same poses to the bit. External heading too."""
    robot = catalog.load("diff-drive")
    for log in (diff_run.log, replace(diff_run.log, heading_world=diff_run.truth[:, 2] + 0.3)):
        plain = odometry(robot, log, chunk_size=50)
        with_cov = odometry(robot, log, chunk_size=50, noise=CrowleyNoise())
        np.testing.assert_array_equal(plain.poses, with_cov.poses)
        np.testing.assert_array_equal(plain.slip, with_cov.slip)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("noise", [None, CrowleyNoise()], ids=["fused", "model"])
def test_a_bad_position_after_the_first_chunk_is_named(bad, noise):
    """The fused path checks positions through the kernel's path length (non-finite exactly when a position
    is); the message is the same as on the model path."""
    robot = catalog.load("mecanum-4")
    joints = odometry_model(robot).joints
    positions = np.zeros((9, 4))
    positions[6, 2] = bad
    log = JointLog(np.arange(9) * 0.1, joints, positions)
    with pytest.raises(LogError, match=rf"<log>: sample 6: {joints[2]}: value {bad!r} is not a finite number"):
        odometry(robot, log, chunk_size=4, noise=noise)


def test_time_steps_counts_bad_steps_and_finds_the_largest():
    t = np.array([0.0, 0.1, 0.3, 0.3, np.nan, 1.0, 0.9, 1.5])
    assert _kernels.time_steps(t, np.empty(0)) == (4, 0.6)  # repeat, NaN twice, backwards
    assert _kernels.time_steps(t[:3], np.array([-1.0])) == (0, 1.0)
    assert _kernels.time_steps(t[:1], np.empty(0)) == (0, 0.0)


def test_a_read_only_installation_compiles_in_memory(tmp_path):
    """No writable cache directory (not next to the sources, not in the user's cache): numba cannot cache, the
    kernels compile in memory and give the same poses; nothing is written."""
    src = Path(_kernels.__file__).parents[2]
    copy = tmp_path / "site"
    shutil.copytree(src / "wmrkit", copy / "wmrkit", ignore=shutil.ignore_patterns("__pycache__"))
    blockers = [copy / "wmrkit" / d / "__pycache__" for d in ("", "odometry")]
    for b in blockers:
        b.write_text("a file where numba would make its cache directory")
    env = {**os.environ, "PYTHONPATH": str(copy), "PYTHONDONTWRITEBYTECODE": "1",
           "XDG_CACHE_HOME": str(blockers[1] / "cache"), "HOME": str(blockers[1] / "home")}
    env.pop("NUMBA_CACHE_DIR", None)
    code = ("import json, wmrkit.odometry.integrators as m; print(m.__file__); "
            "print(json.dumps(m.integrate_increments([0, 0, 0.5], [[0.1, 0.0, 0.04]] * 3)[-1].tolist()))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True,
                         timeout=120)
    where, last = out.stdout.splitlines()
    assert Path(where).is_relative_to(copy)
    np.testing.assert_allclose(json.loads(last), integrate_increments([0, 0, 0.5], [[0.1, 0.0, 0.04]] * 3)[-1],
                               rtol=0, atol=1e-15)
    assert sorted(p.name for p in copy.rglob("*") if p.suffix in (".nbi", ".nbc")) == []
