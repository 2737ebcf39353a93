"""The generated C forward model whose least squares is factored when the code is generated (robots without steering
angles, or whose steered rows are absorbed: kinematics._codegen_fixed), checked against the library's fk and the
generated Python, on every branch: determined, never determined, non-finite input, a reading with slip."""

from __future__ import annotations

import ctypes
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from test_codegen import GCC, _ptr, compile_c, load_module

from wmrkit import Robot, SingularError, catalog
from wmrkit.kinematics._codegen_fixed import _bound
from wmrkit.kinematics._codegen_plan import Plan
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.symbolic import sensed_rates
from wmrkit.kinematics.wheel_ik import forward_kinematics

pytestmark = pytest.mark.skipif(GCC is None, reason="gcc not installed")


def _forward(lib, ident: str, q: np.ndarray) -> tuple[int, np.ndarray, float]:
    forward = getattr(lib, f"{ident}_forward")
    forward.restype = ctypes.c_int
    tw, res = np.zeros(3), ctypes.c_double(-1.0)
    status = forward(_ptr(q), None, _ptr(tw), ctypes.byref(res))
    return status, tw, res.value


def _omni() -> Robot:
    """Three Swedish 90-deg wheels on a ring sensing their spins."""
    return Robot.from_dict({"name": "omni", "wheels": [
        {"name": f"w{i}", "type": "swedish", "position": [0.3 * np.cos(a), 0.3 * np.sin(a)], "heading": a + np.pi / 2,
         "r": 0.05, "gamma": "90 deg", "r_r": 0.01, "sensed": ["spin"]}
        for i, a in enumerate(np.radians([0.0, 120.0, 240.0]))]})


def test_mecanum_readings_with_slip_give_fks_twist_and_residual(tmp_path):
    """Wheel readings no rigid motion gives (one wheel 10 % fast): the least-squares twist and the slip |A q| of
    the library's fk, and of the generated Python (numpy's SVD at run time), from the factored map."""
    robot = catalog.load("mecanum-4")
    lib, ident = compile_c(robot, tmp_path)
    mod = load_module(write_code(robot, "python", tmp_path / "py")[0])
    q = np.array([10.0, 12.0, 9.0, 11.0]) * np.array([1.1, 1.0, 1.0, 1.0])
    status, tw, res = _forward(lib, ident, q)
    fk_twist, fk_slip = forward_kinematics(robot, dict(zip(sensed_rates(robot), q, strict=True)))
    py_twist, py_slip = mod.forward_with_residual(q)
    assert status == 0
    np.testing.assert_allclose(tw, fk_twist, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(tw, py_twist, rtol=1e-12, atol=1e-12)
    assert res > 0.01 and res == pytest.approx(float(py_slip), rel=1e-10)
    assert res == pytest.approx(float(fk_slip), rel=1e-9)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_reading_is_refused(tmp_path, bad):
    robot = _omni()
    lib, ident = compile_c(robot, tmp_path)
    status, tw, res = _forward(lib, ident, np.array([1.0, bad, 2.0]))
    assert status == -1 and np.isnan(tw).all() and np.isnan(res)
    status, tw, res = _forward(lib, ident, np.array([1.0, 3.0, 2.0]))
    assert status == 0 and np.isfinite(tw).all() and res == pytest.approx(0.0, abs=1e-12)


def test_huge_readings_keep_a_finite_residual(tmp_path):
    """Spins of 1e200 rad/s: the residual is scaled by its largest entry (a plain sum of squares overflowed)."""
    robot = catalog.load("mecanum-4")
    lib, ident = compile_c(robot, tmp_path)
    q = np.array([1.1, 1.0, 1.0, 1.0]) * 1e200
    status, tw, res = _forward(lib, ident, q)
    _, small_tw, small_res = _forward(lib, ident, q / 1e200)
    assert status == 0
    np.testing.assert_allclose(tw, small_tw * 1e200, rtol=1e-12)
    assert res == pytest.approx(small_res * 1e200, rel=1e-12)


def test_a_diff_drives_castor_rows_are_absorbed_at_every_heading(tmp_path):
    """The catalog diff-drive: its castor's steering and spin rates (not sensed) absorb the castor's rows, so the
    forward model is one map of the wheels' rows, whatever the castor's heading: fk's twist at random castor
    headings (fk solves the whole system), and -1 for a heading that is not finite, as the generated Python."""
    robot = catalog.load("diff-drive")
    _, source = write_code(robot, "c", tmp_path / "src")
    assert "the rows kept: 0, 1, 2, 3 of 6" in source.read_text()
    lib, ident = compile_c(robot, tmp_path)
    forward = getattr(lib, f"{ident}_forward")
    forward.restype = ctypes.c_int
    rng = np.random.default_rng(3)
    for heading, q in zip(rng.uniform(-np.pi, np.pi, 50), rng.normal(0, 10, (50, 2)), strict=True):
        tw, res = np.zeros(3), ctypes.c_double(-1.0)
        assert forward(_ptr(q), _ptr(np.array([heading])), _ptr(tw), ctypes.byref(res)) == 0
        fk_twist, fk_slip = forward_kinematics(robot, {"left.spin": q[0], "right.spin": q[1]}, heading=[heading])
        np.testing.assert_allclose(tw, fk_twist, rtol=1e-12, atol=1e-12)
        assert res.value == pytest.approx(float(fk_slip), abs=1e-12)
    tw = np.zeros(3)
    assert forward(_ptr(np.array([1.0, 2.0])), _ptr(np.array([np.nan])), _ptr(tw), None) == -1
    assert np.isnan(tw).all()


def test_a_castor_too_short_to_absorb_its_rows_is_left_to_the_run_time_svd(tmp_path):
    """A castor offset of 1 um on a 0.3 m robot: its block's least singular value (d over the robot's size, 3e-6)
    is too close to the rank rule's cut-off to prove every heading keeps it, so the Jacobi SVD decides at run time
    (and still gives fk's twist)."""
    base = catalog.load("diff-drive")
    robot = replace(base, name="short-castor", wheels=tuple(
        replace(w, d=1e-6) if w.type == "castor" else w for w in base.wheels))
    _, source = write_code(robot, "c", tmp_path / "src")
    assert "factored when" not in source.read_text() and "jacobi_rank" in source.read_text()
    lib, ident = compile_c(robot, tmp_path)
    status, tw, _ = _forward_at(lib, ident, np.array([4.0, 6.0]), np.array([0.4]))
    fk_twist, _ = forward_kinematics(robot, {"left.spin": 4.0, "right.spin": 6.0}, heading=[0.4])
    assert status == 0  # D's condition number is about 1 / 3e-6: the two SVDs agree to about 3e5 ulp
    np.testing.assert_allclose(tw, fk_twist, rtol=1e-9, atol=1e-10)


def _forward_at(lib, ident: str, q: np.ndarray, heading: np.ndarray) -> tuple[int, np.ndarray, float]:
    forward = getattr(lib, f"{ident}_forward")
    forward.restype = ctypes.c_int
    tw, res = np.zeros(3), ctypes.c_double(-1.0)
    return forward(_ptr(q), _ptr(heading), _ptr(tw), ctypes.byref(res)), tw, res.value


def test_the_least_singular_value_bound_of_absorbed_rows():
    """The lemma the absorption rests on: D = [[P, 0], [Q, B]] has least singular value at least
    s_P s_B / (s_P + s_B + |Q|) (random blocks, some nearly singular)."""
    rng = np.random.default_rng(5)
    for _ in range(2000):
        m, n, k = rng.integers(3, 7), 3, rng.integers(1, 4)
        p = rng.normal(size=(m, n)) * rng.choice([1.0, 1e-3], size=n)
        b = rng.normal(size=(k, k)) * rng.choice([1.0, 1e-2], size=k)
        q = rng.normal(size=(k, n)) * rng.choice([0.1, 1.0, 30.0])
        d = np.block([[p, np.zeros((m, k))], [q, b]])
        s_p, s_b = np.linalg.svd(p, compute_uv=False)[-1], np.linalg.svd(b, compute_uv=False)[-1]
        bound = s_p * s_b / (s_p + s_b + np.linalg.norm(q, 2))
        assert np.linalg.svd(d, compute_uv=False)[-1] >= bound * (1 - 1e-12)


@pytest.mark.parametrize("name", ["forklift", "swerve-4", "diff-drive"])
def test_the_entry_bound_holds_at_every_sampled_heading(name):
    """_bound(e) >= |e(heading)| for every entry of A_na (sines and cosines of the steering angles) at random
    steering angles: the q of the absorption's lower bound."""
    plan = Plan(catalog.load(name), None)
    a_na, _ = plan.forward_exprs()
    rng = np.random.default_rng(11)
    samples = rng.uniform(-np.pi, np.pi, (200, len(plan.beta)))
    for e in a_na:
        bound = _bound(e)
        assert bound is not None
        f = sp.lambdify(plan.beta, e, "numpy")
        values = np.abs(np.broadcast_to(f(*samples.T), (len(samples),)))
        assert values.max() <= bound + 1e-12


def _random_robot(rng: np.random.Generator, k: int) -> Robot:
    """2-5 wheels: fixed and Swedish wheels sensing their spins, castors sensing nothing (absorbed), steerable
    wheels sensing spin and steering (the Jacobi SVD at run time); random mounts, radii and offsets."""
    wheels = []
    for i in range(int(rng.integers(2, 6))):
        kind = rng.choice(["fixed", "swedish", "castor", "castor", "steerable"])
        w = {"name": f"w{i}", "type": str(kind), "position": rng.uniform(-0.5, 0.5, 2).tolist(),
             "heading": float(rng.uniform(-np.pi, np.pi)), "r": float(rng.uniform(0.02, 0.1))}
        if kind == "swedish":
            w |= {"gamma": float(rng.choice([-1, 1]) * rng.uniform(0.4, 1.57)), "r_r": 0.01, "sensed": ["spin"]}
        elif kind == "castor":
            w |= {"d": float(rng.choice([-1, 1]) * 10 ** rng.uniform(-3.3, -1)), "heading": 0.0}
        elif kind == "steerable":
            w |= {"sensed": ["spin", "steer"], "heading": 0.0}
        else:
            w |= {"sensed": ["spin"]}
        wheels.append(w)
    return Robot.from_dict({"name": f"random{k}", "wheels": wheels})


def test_random_robots_forward_models_are_fks(tmp_path):
    """16 random robots with castors (offsets from 0.5 mm to 10 cm, sensing nothing: absorbed), Swedish, fixed and
    steered wheels, all compiled into one library: each generated forward model gives fk's twist and slip at random
    headings and readings (or -1 where the library's twist_is_determined says no); both paths are met."""
    from wmrkit.kinematics.wheel_ik import twist_is_determined

    rng = np.random.default_rng(2026)
    robots, sources = [], []
    while len(robots) < 16:
        robot = _random_robot(rng, len(robots))
        try:
            _, source = write_code(robot, "c", tmp_path / robot.name)
        except SingularError:  # sensing that never determines the twist: refused, as tested elsewhere
            continue
        robots.append(robot)
        sources.append(str(source))
    lib_path = tmp_path / "librandom.so"
    subprocess.run([GCC, "-O2", "-shared", "-fPIC", "-std=c99", "-Wall", "-Wextra", "-Werror", "-o", str(lib_path),
                    *sources, "-lm"], check=True, capture_output=True, text=True)
    lib = ctypes.CDLL(str(lib_path))
    fast = sum("factored when" in Path(s).read_text() for s in sources)
    assert 3 <= fast <= len(robots) - 3  # both paths met
    for robot in robots:
        sensed = sensed_rates(robot)
        forward = getattr(lib, f"{robot.name}_forward")
        forward.restype = ctypes.c_int
        for _ in range(8):
            heading = rng.uniform(-np.pi, np.pi, len(robot.steer_names))
            q = rng.normal(0, 10, len(sensed))
            tw, res = np.zeros(3), ctypes.c_double(-1.0)
            status = forward(_ptr(q), _ptr(heading) if len(heading) else None, _ptr(tw), ctypes.byref(res))
            if not twist_is_determined(robot, sensed, heading=heading):
                assert status == -1, robot.name
                continue
            fk_twist, fk_slip = forward_kinematics(robot, dict(zip(sensed, q, strict=True)), heading=heading)
            assert status == 0, robot.name
            scale = 1.0 + float(np.abs(fk_twist).max())
            np.testing.assert_allclose(tw, fk_twist, rtol=1e-7, atol=1e-7 * scale, err_msg=robot.name)
            assert res.value == pytest.approx(float(fk_slip), rel=1e-7, abs=1e-7 * scale), robot.name
