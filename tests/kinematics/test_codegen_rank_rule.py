"""The generated forward model decides "twist not determined" with the library's rank rule (linalg.RANK_RTOL,
``twist_is_determined``) and solves as ``forward_kinematics``, on both sides of the cut-off. The generated code had
its own rule (the least singular value of unit columns above 1e-9 rows): three castors 1e-7 rad off parallel axles
were "determined" there, and got a twist of round-off, where the library says the sensed spins do not fix it."""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
from test_codegen import GCC, _ptr, compile_c, load_module

from wmrkit import Robot, catalog
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.linalg import RANK_RTOL
from wmrkit.kinematics.symbolic import sensed_rates
from wmrkit.kinematics.wheel_ik import forward_kinematics, twist_is_determined

CASTORS = Robot.from_dict({"name": "castors", "wheels": [
    {"name": f"c{i}", "type": "castor", "l": 0.3, "alpha": f"{a} deg", "d": 0.05, "r": 0.03, "sensed": ["spin"]}
    for i, a in enumerate((0, 120, 240))]})


def _ackermann_law(robot: Robot, radius: float) -> np.ndarray:
    """The front headings of the Ackermann car turning about a point on its rear axle, `radius` to the left."""
    rear = robot.wheel("rear_left").position[0]
    return np.array([math.atan2(robot.wheel(n).position[0] - rear, radius - robot.wheel(n).position[1])
                     for n in robot.steer_names])


# (robot, headings, whether the library finds the twist determined); the off-law headings move one wheel
ACKERMANN = catalog.load("ackermann")
CASES = {
    "castors parallel, 1e-7 rad off": (CASTORS, np.array([1e-7, 0.0, 0.0]), False),
    "castors parallel, 1e-2 rad off": (CASTORS, np.array([1e-2, 0.0, 0.0]), True),
    "ackermann 1e-7 rad off the law": (ACKERMANN, _ackermann_law(ACKERMANN, 2.0) + np.array([0.0, 1e-7]), True),
    "ackermann 1e-2 rad off the law": (ACKERMANN, _ackermann_law(ACKERMANN, 2.0) + np.array([0.0, 1e-2]), True),
}
SPINS = np.array([1.0, -0.5, 2.0, 0.7])


def _library(robot, heading):
    sensed = sensed_rates(robot)
    q = SPINS[:len(sensed)]
    determined = bool(twist_is_determined(robot, sensed, heading=heading))
    twist, residual = forward_kinematics(robot, dict(zip(sensed, q, strict=True)), heading=heading)
    return q, determined, twist, float(residual)


def test_the_cases_straddle_the_cut_off():
    """The castors' case is the library's (not the generated code's old) call: not determined at 1e-7 rad."""
    assert RANK_RTOL == 1e-6
    assert [_library(r, h)[1] for r, h, _ in CASES.values()] == [d for _, _, d in CASES.values()]


@pytest.mark.parametrize("case", list(CASES))
def test_generated_python_decides_as_the_library(case, tmp_path):
    robot, heading, determined = CASES[case]
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    assert mod.RANK_RTOL == RANK_RTOL
    q, _, twist, residual = _library(robot, heading)
    got, got_residual = mod.forward_with_residual(q, heading)
    assert bool(np.isfinite(got).all()) == determined
    if determined:
        np.testing.assert_allclose(got, twist, rtol=1e-8, atol=1e-10)
        assert got_residual == pytest.approx(residual, rel=1e-7, abs=1e-12)
    else:
        assert math.isnan(got_residual)


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
@pytest.mark.parametrize("case", list(CASES))
def test_generated_c_decides_as_the_library(case, tmp_path):
    robot, heading, determined = CASES[case]
    lib, ident = compile_c(robot, tmp_path)
    q, _, twist, residual = _library(robot, heading)
    forward = getattr(lib, f"{ident}_forward")
    forward.restype = ctypes.c_int
    tw, res = np.zeros(3), ctypes.c_double(0.0)
    status = forward(_ptr(q), _ptr(heading), _ptr(tw), ctypes.byref(res))
    assert status == (0 if determined else -1)
    if determined:
        np.testing.assert_allclose(tw, twist, rtol=1e-8, atol=1e-10)
        assert res.value == pytest.approx(residual, rel=1e-7, abs=1e-12)
    else:
        assert np.isnan(tw).all() and math.isnan(res.value)
