"""The generated C forward model of robots without steering angles: the least squares factored when the code is
generated (kinematics._codegen_fixed), checked against the library's fk and twist_is_determined, and the generated
Python, on every branch: determined, never determined, non-finite input, a reading with slip."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest
from test_codegen import GCC, _ptr, compile_c, load_module

from wmrkit import Robot, catalog
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
