"""Generated code holds a description's gears as ``fk`` and ``ik`` do (``kinematics --codegen``).

The forward model (sensed rates -> twist) fills a gear's joints from its sensed ones and takes a gear with none of
them sensed as one unknown, its turn: the generated Python and C give ``wmrkit.forward_kinematics``'s twist and
slip at random rates and headings. The inverse model gives ``wheel_commands``' rates, and its ``in_gear`` check the
same verdict as its ``in_gear``. Robots: tests/geared.py's cart at ratios 1, 2, -1 (one encoder on left.spin: the
wheels alone leave right.spin free, so the forward model was refused) and the synchro drive.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pytest
import yaml
from test_codegen import GCC, _ptr, compile_c, load_module

from geared import SYNCHRO, TWO_ENCODERS, cart_yaml
from wmrkit import Robot
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.symbolic import sensed_rates
from wmrkit.kinematics.wheel_ik import forward_kinematics, wheel_commands

ROBOTS = {"cart 1:1": cart_yaml(1.0), "cart 1:2": cart_yaml(2.0), "cart 1:-1": cart_yaml(-1.0),
          "synchro": SYNCHRO, "two encoders": TWO_ENCODERS}
N = 8


def load(text: str) -> Robot:
    return Robot.from_dict(yaml.safe_load(text))


def samples(robot: Robot, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Random sensed rates ``(N, s)`` [rad/s] and headings ``(N, n_steer)`` [rad]."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(N, len(sensed_rates(robot)))), rng.uniform(-np.pi, np.pi, (N, len(robot.steer_names)))


def reference(robot: Robot, q_s: np.ndarray, heading: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``fk``'s twist ``(N, 3)`` and slip norm ``(N,)``, one sample at a time."""
    out = [forward_kinematics(robot, dict(zip(sensed_rates(robot), q, strict=True)), heading=h)
           for q, h in zip(q_s, heading, strict=True)]
    return np.array([t for t, _ in out]), np.array([float(r) for _, r in out])


@pytest.mark.parametrize("name", list(ROBOTS))
def test_python_forward_is_fk_with_the_gear(name, tmp_path):
    robot = load(ROBOTS[name])
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    q_s, heading = samples(robot, 1)
    twist, slip = reference(robot, q_s, heading)
    got_twist, got_slip = mod.forward_with_residual(q_s, heading)
    np.testing.assert_allclose(got_twist, twist, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(got_slip, slip, rtol=1e-8, atol=1e-9)


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
@pytest.mark.parametrize("name", list(ROBOTS))
def test_c_forward_is_fk_with_the_gear(name, tmp_path):
    robot = load(ROBOTS[name])
    lib, ident = compile_c(robot, tmp_path)
    forward = getattr(lib, f"{ident}_forward")
    forward.restype = ctypes.c_int
    q_s, heading = samples(robot, 2)
    twist, slip = reference(robot, q_s, heading)
    for k in range(N):
        out, res = np.zeros(3), ctypes.c_double(-1.0)
        assert forward(_ptr(q_s[k]), _ptr(heading[k]) if heading.shape[1] else None, _ptr(out), ctypes.byref(res)) == 0
        np.testing.assert_allclose(out, twist[k], rtol=1e-8, atol=1e-9)
        assert res.value == pytest.approx(slip[k], rel=1e-8, abs=1e-9)


@pytest.mark.parametrize("ratio", [1.0, 2.0, -1.0])
def test_the_carts_one_encoder_gives_the_geared_motion(ratio, tmp_path):
    """Closed form: the axle turns at ``(l, ratio l)``, so ``vx = r l (1 + ratio) / 2``, ``omega = r l (ratio - 1) /
    (2 b)`` (wheels at y = +-b, r = 0.075 m, b = 0.2 m), no slip."""
    mod = load_module(write_code(load(cart_yaml(ratio)), "python", tmp_path)[0])
    left = np.array([[1.0], [-2.5]])
    twist, slip = mod.forward_with_residual(left, np.array([[0.3], [-1.2]]))
    r, b = 0.075, 0.2
    expect = np.column_stack([r * left[:, 0] * (1 + ratio) / 2, 0 * left[:, 0], r * left[:, 0] * (ratio - 1) / (2 * b)])
    np.testing.assert_allclose(twist, expect, atol=1e-12)
    np.testing.assert_allclose(slip, 0.0, atol=1e-12)


R, B = 0.075, 0.2  # the cart's wheel radius and half track [m]


def twists(robot: Robot, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Twists ``(N, 3)`` and headings ``(N, n_steer)`` for the inverse model, half of them in the gear's ratios:
    the cart's geared motion (axle at ``(l, ratio l)``) and any twist; the synchro's translations along its wheels'
    common heading (where ``ik`` keeps the given headings), which its gear turns."""
    rng = np.random.default_rng(seed)
    heading = rng.uniform(-np.pi, np.pi, (N, len(robot.steer_names)))
    if robot.name == "synchro-3":
        heading[:] = heading[:, :1]
        v = rng.normal(size=N)
        return np.column_stack([v * np.cos(heading[:, 0]), v * np.sin(heading[:, 0]), 0 * v]), heading
    k = robot.couplings[0].ratios[1]
    left = rng.normal(size=N)
    geared = np.column_stack([R * left * (1 + k) / 2, 0 * left, R * left * (k - 1) / (2 * B)])
    return np.where((np.arange(N) % 2 == 0)[:, None], geared, rng.normal(size=(N, 3))), heading


def ik_reference(robot: Robot, rate_names: tuple[str, ...], twist: np.ndarray, heading: np.ndarray):
    """``ik``'s rates in the generated code's order ``(N, n)`` and its verdict on each gear ``(N, n_gears)``."""
    ik = wheel_commands(robot, twist, heading=heading)
    gears = [i for i, c in enumerate(robot.couplings) if c.kind == "gear"]
    return ik.rates[..., [robot.rate_names.index(n) for n in rate_names]], ik.in_gear[..., gears]


GEARED = {k: v for k, v in ROBOTS.items() if k != "two encoders"}


@pytest.mark.parametrize("name", list(GEARED))
def test_python_inverse_and_in_gear_are_iks(name, tmp_path):
    robot = load(GEARED[name])
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    twist, heading = twists(robot, 3)
    rates, in_gear = ik_reference(robot, mod.RATE_NAMES, twist, heading)
    got = mod.inverse(twist, heading)
    np.testing.assert_allclose(got, rates, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(mod.in_gear(got), in_gear)
    assert mod.GEAR_NAMES == tuple(c.channel_name for c in robot.couplings if c.kind == "gear")
    if name != "synchro":
        assert in_gear[::2].all() and not in_gear[1::2].any()  # the geared half, and random twists


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
@pytest.mark.parametrize("name", list(GEARED))
def test_c_inverse_and_in_gear_are_iks(name, tmp_path):
    robot = load(GEARED[name])
    lib, ident = compile_c(robot, tmp_path)
    mod = load_module(write_code(robot, "python", tmp_path / "py")[0])
    twist, heading = twists(robot, 4)
    rates, in_gear = ik_reference(robot, mod.RATE_NAMES, twist, heading)
    check = getattr(lib, f"{ident}_in_gear")
    check.restype = ctypes.c_int
    for k in range(N):
        out, flags = np.zeros(rates.shape[1]), np.zeros(in_gear.shape[1], dtype=np.intc)
        getattr(lib, f"{ident}_inverse")(_ptr(twist[k]), _ptr(heading[k]), _ptr(out))
        np.testing.assert_allclose(out, rates[k], rtol=1e-9, atol=1e-12)
        assert check(_ptr(out), flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int))) == int(in_gear[k].all())
        np.testing.assert_array_equal(flags.astype(bool), in_gear[k])


@pytest.mark.parametrize("name", list(GEARED))
def test_in_gear_of_rates_in_and_out_of_the_ratios(name, tmp_path):
    """Rates ``q_j = ratio_j u`` are in gear; one joint off by 1e-6 of them is not; NaN is not."""
    robot = load(GEARED[name])
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    gear = next(c for c in robot.couplings if c.kind == "gear")
    q = np.zeros(len(mod.RATE_NAMES))
    for j, k in zip(gear.joints, gear.ratios, strict=True):
        q[mod.RATE_NAMES.index(j)] = 3.7 * k
    off, bad = q.copy(), q.copy()
    off[mod.RATE_NAMES.index(gear.joints[-1])] *= 1 + 1e-6
    bad[0] = np.nan
    assert mod.in_gear(np.array([q, off, bad])).tolist() == [[True], [False], [False]]


def test_a_gear_on_double_wheels_steering_rates_is_one_input(tmp_path):
    """A gear turning two double wheels' steering rates is one input of the inverse, as the numeric inverse model's
    (``drive.steer``); the gear sets the other (``rear.steer = 2 drive.steer``, a rate) and ``in_gear`` checks it.
    Before, both were inputs (``FREE_STEER_NAMES == ("drive.steer", "rear.steer")``). The forward model is ``fk``'s."""
    from test_codegen import ROBOTS as PLAIN

    from wmrkit.kinematics.models import inverse_model

    d = PLAIN["double units"].to_dict()
    d["couplings"] = [{"kind": "gear", "joints": ["drive.steer", "rear.steer"], "ratios": [1, 2]}]
    robot = Robot.from_dict(d)
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    assert mod.FREE_STEER_NAMES == ("drive.steer",) == inverse_model(robot).assigned[-1:]  # after ("vx",)
    rates = mod.inverse([0.3, 0.1, -0.2], [0.5], [0.2, -0.4, 1.0])
    assert rates[mod.RATE_NAMES.index("rear.steer")] == pytest.approx(1.0, abs=1e-15)
    off = rates.copy()
    off[mod.RATE_NAMES.index("rear.steer")] = -1.0
    assert mod.in_gear(np.array([rates, off]), [0.5]).tolist() == [[True], [False]]
    q_s, heading = samples(robot, 5)
    twist, slip = reference(robot, q_s, heading)
    got_twist, got_slip = mod.forward_with_residual(q_s, heading)
    np.testing.assert_allclose(got_twist, twist, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(got_slip, slip, rtol=1e-8, atol=1e-9)
    if GCC is not None:
        lib, ident = compile_c(robot, tmp_path / "c")
        check = getattr(lib, f"{ident}_in_gear")
        flags = np.zeros(1, dtype=np.intc)
        for r, expect in ((rates, 1), (off, 0)):
            assert check(_ptr(r), _ptr(np.array([0.5])), flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int))) == expect
            assert flags[0] == expect
