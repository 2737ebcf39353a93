"""Every door of ``ik`` judges the held linkages: the compiled single-call ``realtime`` ik and the generated code
(``kinematics --codegen``), as ``wheel_commands``' ``in_linkage`` (kinematics/linkage_check.py).

Before: only ``wheel_commands`` did; ``realtime(synchro).ik(1, 0, 0.5, ...)``, a synchro drive (one ``parallel``
linkage of its three wheels) asked to turn, returned True (feasible), as did the generated code. The reference for the
random twists is ``wheel_commands``, itself checked against brute force (tests/kinematics/test_linkage_ik.py).
"""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import wheel_commands

from .test_codegen import GCC, _ptr, compile_c, load_module
from .test_linkage_ik import ackermann_car, synchro


def linked_robots() -> list[Robot]:
    """The catalog car, synchro drives (one with rest headings apart), a random Ackermann car."""
    apart = Robot.from_dict({"name": "apart", "wheels": [
        {"name": f"w{k}", "type": "steerable", "position": list(p), "heading": h, "r": 0.05}
        for k, (p, h) in enumerate(zip([(0.3, 0.1), (-0.2, 0.25), (-0.1, -0.3)], [0.0, 0.5, -1.0], strict=True))],
        "couplings": [{"kind": "linkage", "joints": ["w0.steer", "w1.steer", "w2.steer"], "law": "parallel"}]})
    return [catalog.load("ackermann"), synchro(), synchro([(0.0, 0.2), (0.0, -0.2)]), apart,
            ackermann_car(1.7, 1.1, -0.4, 0.3)]


def twists(robot: Robot, rng) -> np.ndarray:
    """Random twists, translations, the ICR at each steering axis, on the fixed axle line, tiny turns."""
    out = [rng.uniform(-1, 1, (40, 3)), np.c_[rng.uniform(-1, 1, (10, 2)), np.zeros(10)], np.zeros((1, 3)),
           [[0.0, 0.0, 1e-10], [0.0, 0.0, 1e-8]]]
    for w in robot.wheels:
        if w.kind.steers:
            x, y = w.position
            out.append([[y, -x, 1.0], [-0.5 * y, 0.5 * x, -0.5]])
    if robot.name == "ackermann":  # the catalog car's fixed axle is x = 0: ICRs on it
        out.append(np.c_[rng.uniform(-1, 1, (10, 1)), np.zeros((10, 1)), rng.uniform(-1, 1, (10, 1))])
    return np.concatenate([np.asarray(t, dtype=float) for t in out])


def test_the_realtime_ik_says_a_synchro_drive_cannot_turn():
    robot = synchro()
    rt = realtime(robot)
    rates, out = np.empty(len(robot.rate_names)), np.empty(3)
    assert not rt.ik(1.0, 0.0, 0.5, np.zeros(3), rates, out)
    assert rt.ik(1.0, 0.3, 0.0, np.zeros(3), rates, out)
    np.testing.assert_allclose(out, math.atan2(0.3, 1.0))  # all three wheels along the translation


@pytest.mark.parametrize("index", range(5))
def test_the_realtime_ik_s_verdicts_are_wheel_commands(index):
    robot = linked_robots()[index]
    rt = realtime(robot)
    rng = np.random.default_rng(index)
    rates, out = np.empty(len(robot.rate_names)), np.empty(len(robot.steer_names))
    verdicts = []
    for twist in twists(robot, rng):
        heading = rng.uniform(-math.pi, math.pi, len(robot.steer_names))
        ref = wheel_commands(robot, twist, heading=heading)
        got = rt.ik(*map(float, twist), heading, rates, out)
        assert got == bool(ref.feasible), twist
        verdicts.append(bool(ref.in_linkage.all()))
    assert any(verdicts) and not all(verdicts)


def ik_cases(robot: Robot, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Twists, ``wmrkit ik``'s headings for them (from random current ones) and its ``in_linkage`` of the linkages."""
    rng = np.random.default_rng(seed)
    twist = twists(robot, rng)
    heading = rng.uniform(-math.pi, math.pi, (len(twist), len(robot.steer_names)))
    ref = wheel_commands(robot, twist, heading=heading)
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    linked = [i for i, c in enumerate(robot.couplings) if c.kind == "linkage"]
    return twist, ref.heading[:, steer], ref.in_linkage[:, linked]


@pytest.mark.parametrize("index", range(5))
def test_the_generated_python_in_linkage_is_ik_s(index, tmp_path):
    robot = linked_robots()[index]
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    twist, heading, want = ik_cases(robot, index)
    assert mod.LINKAGE_NAMES == tuple(c.channel_name for c in robot.couplings if c.kind == "linkage")
    np.testing.assert_array_equal(mod.in_linkage(twist, heading), want)
    assert want.any() and not want.all()
    assert not mod.in_linkage([math.nan, 0.0, 0.0], heading[0]).any()


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
@pytest.mark.parametrize("index", range(5))
def test_the_generated_c_in_linkage_is_ik_s(index, tmp_path):
    robot = linked_robots()[index]
    lib, ident = compile_c(robot, tmp_path)
    check = getattr(lib, f"{ident}_in_linkage")
    check.restype = ctypes.c_int
    twist, heading, want = ik_cases(robot, index)
    for t, h, w in zip(twist, heading, want, strict=True):
        flags = np.full(len(w), 7, dtype=np.intc)
        assert check(_ptr(t), _ptr(h), flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int))) == int(w.all())
        np.testing.assert_array_equal(flags, w.astype(np.intc))
    flags = np.zeros(len(want[0]), dtype=np.intc)
    assert check(_ptr([0.0, math.inf, 0.0]), _ptr(heading[0]), flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int))) == 0


def test_the_synchro_drive_asked_to_turn_is_refused_by_the_generated_code(tmp_path):
    robot = synchro()
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    turn = wheel_commands(robot, [1.0, 0.0, 0.5])
    assert mod.in_linkage([1.0, 0.0, 0.5], turn.heading).tolist() == [False]
    assert mod.in_linkage([1.0, 0.3, 0.0], np.full(3, math.atan2(0.3, 1.0))).tolist() == [True]


def test_robots_without_a_held_linkage_get_the_code_they_got(tmp_path):
    """No ``in_linkage`` without a law to hold: the 4WS pair (no fixed wheel, no law) as a diff drive."""
    free = Robot.from_dict({"name": "4ws", "wheels": [
        {"name": f"w{k}", "type": "steerable", "position": list(p), "heading": 0, "r": 0.1}
        for k, p in enumerate([(0.5, 0.3), (0.5, -0.3), (-0.5, 0.3), (-0.5, -0.3)])],
        "couplings": [{"kind": "linkage", "joints": ["w0.steer", "w1.steer"]}]})
    for robot in (free, catalog.load("diff-drive")):
        for lang in ("python", "c"):
            text = "".join(p.read_text() for p in write_code(robot, lang, tmp_path / robot.name / lang))
            assert "in_linkage" not in text and "np = numpy" not in text
