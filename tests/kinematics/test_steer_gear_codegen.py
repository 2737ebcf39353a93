"""The generated code (``kinematics --codegen``) checks a ``gear`` between steering joints as ``ik`` does
(``out_of_steer_gear``, kinematics/gear_check.py): ``in_steer_gear``.

Before: it had no such check; for two double wheels whose steering a gear turns 1:2 (tests/kinematics/
test_steer_gear_ik.py) asked for (1, 0, 1), ``wmrkit ik`` said ``feasible: NO`` while the generated code had nothing to
say it with. The reference is ``wheel_commands``' ``in_steer_gear`` at ``ik``'s headings, and the judge
(``steer_gears_hold``) at random headings, each checked against brute force in test_steer_gear_ik.py.
"""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.gear_check import steer_gears_hold
from wmrkit.kinematics.wheel_ik import SLIP_TOL, wheel_commands

from .test_codegen import GCC, _ptr, compile_c, load_module
from .test_linkage_ik import TRIANGLE, synchro
from .test_steer_gear_ik import _geared, _twist_for


def geared_synchro() -> Robot:
    """Three double wheels (a steerable wheel's angle is not a rate a gear can couple) at a synchro drive's points,
    their steering turned 1:1:1 by one gear."""
    unit = {"type": "double", "heading": 0, "b": 0.04, "r": 0.05}
    return Robot.from_dict({"name": "synchro-gear", "wheels": [
        {**unit, "name": f"w{k}", "position": list(p)} for k, p in enumerate(TRIANGLE)], "couplings": [
        {"kind": "gear", "joints": ["w0.steer", "w1.steer", "w2.steer"]}]})


def robots() -> list[Robot]:
    return [_geared(), _geared((1.0, -1.5)), geared_synchro()]


def cases(robot: Robot, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Twists ``(N, 3)``, headings ``(N, n_steer)`` and ``ik``'s verdicts ``(N, n_steer_gears)``: at ``ik``'s
    headings (random twists, twists the gear rolls, 1e-3 rad off it) and at random headings (the judge's)."""
    rng = np.random.default_rng(seed)
    n = len(robot.steer_names)
    geared = [i for i, c in enumerate(robot.couplings) if c.kind == "gear"]
    if robot.name == "synchro-gear":
        rolled = np.c_[rng.normal(size=(20, 2)), np.zeros(20)]  # translations: all wheels parallel
    else:
        k = robot.couplings[0].ratios[1]
        fronts = rng.uniform(-1.0, 1.0, 20) / max(1.0, abs(k))
        rolled = np.array([_twist_for(f, k * f) for f in fronts] + [_twist_for(f, k * f + 1e-3) for f in fronts])
    twist = np.concatenate([rng.normal(size=(30, 3)), rolled])
    ik = wheel_commands(robot, twist, heading=rng.uniform(-math.pi, math.pi, (len(twist), n)))
    steer = [robot.wheel_names.index(w) for w in robot.steer_names]
    random_twist = rng.normal(size=(30, 3))
    random_heading = rng.uniform(-math.pi, math.pi, (30, n))
    judged = steer_gears_hold(robot, random_twist, robot.beta_of_heading(random_heading), SLIP_TOL)[..., geared]
    return (np.concatenate([twist, random_twist]), np.concatenate([ik.heading[:, steer], random_heading]),
            np.concatenate([ik.in_steer_gear[..., geared], judged]))


@pytest.mark.parametrize("index", range(3))
def test_the_generated_python_in_steer_gear_is_ik_s(index, tmp_path):
    robot = robots()[index]
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    twist, heading, want = cases(robot, index)
    assert mod.STEER_GEAR_NAMES == tuple(c.channel_name for c in robot.couplings if c.kind == "gear")
    np.testing.assert_array_equal(mod.in_steer_gear(twist, heading), want)
    assert want.any() and not want.all()
    assert not mod.in_steer_gear([0.0, math.nan, 0.0], heading[0]).any()


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
@pytest.mark.parametrize("index", range(3))
def test_the_generated_c_in_steer_gear_is_ik_s(index, tmp_path):
    robot = robots()[index]
    lib, ident = compile_c(robot, tmp_path)
    check = getattr(lib, f"{ident}_in_steer_gear")
    check.restype = ctypes.c_int
    twist, heading, want = cases(robot, index)
    for t, h, w in zip(twist, heading, want, strict=True):
        flags = np.full(len(w), 7, dtype=np.intc)
        assert check(_ptr(t), _ptr(h), flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int))) == int(w.all())
        np.testing.assert_array_equal(flags, w.astype(np.intc))
    flags = np.zeros(len(want[0]), dtype=np.intc)
    assert check(_ptr([math.inf, 0.0, 0.0]), _ptr(heading[0]), flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int))) == 0


def test_the_geared_units_asked_for_1_0_1_are_refused_by_the_generated_code(tmp_path):
    robot = _geared()
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    c = wheel_commands(robot, [1.0, 0.0, 1.0])
    assert not c.in_steer_gear[0]
    assert mod.in_steer_gear([1.0, 0.0, 1.0], c.heading).tolist() == [False]
    rolled = _twist_for(0.3, 0.6)
    assert mod.in_steer_gear(rolled, wheel_commands(robot, rolled).heading).tolist() == [True]


def test_robots_without_a_steering_gear_get_no_in_steer_gear(tmp_path):
    for lang in ("python", "c"):
        text = "".join(p.read_text() for p in write_code(synchro(), lang, tmp_path / lang))
        assert "steer_gear" not in text.lower()
