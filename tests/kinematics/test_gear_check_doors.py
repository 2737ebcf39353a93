"""One gear check at every door: ``wheel_commands``' ``in_gear`` (``wmrkit ik``), the compiled ``realtime`` ik and
the generated Python and C ``in_gear`` judge a gear by ``gear_check.gears_hold``'s rule, whose absolute floor is the
slip check's (``slip_tol`` [m/s] at the contacts).

Before, the gear check was relative only (1e-9 of the command's largest rate): ``wmrkit ik CART --twist 0 0 1e-320``
said "feasible: NO" while ``0 1e-320 0`` said "yes" (CART: two fixed wheels on one axle, spins geared 1:1, and a
castor). The floor is checked against the closed form of the cart (a turn at omega spins its wheels at -+ omega b / r,
the gear's common turn is 0, so each contact departs by omega b), at robot scales 1e-3, 1 and 1e3; the compiled and
generated checks agree with ``wheel_commands`` on random twists from 1e-320 to 1e6 in size.
"""

from __future__ import annotations

import ctypes
import dataclasses

import numpy as np
import pytest
import yaml
from test_codegen import GCC, _ptr, compile_c, load_module

from geared import SYNCHRO, cart_yaml
from wmrkit import Robot, catalog
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.gear_check import gear_table, gears_hold
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import SLIP_TOL, wheel_commands

SCALES = [1e-3, 1.0, 1e3]
B = 0.2  # the cart's half track [m] at scale 1


def scaled(robot: Robot, s: float) -> Robot:
    """`robot` with every length times `s`."""
    wheels = tuple(dataclasses.replace(w, l=w.l * s, d=w.d * s, b=w.b * s, r=w.r * s, r_r=w.r_r * s)
                   for w in robot.wheels)
    return dataclasses.replace(robot, wheels=wheels)


def castor_gear() -> Robot:
    """A castor's swivel geared to its spin (1:1): the gear's levers are the castor's offset d and radius r."""
    robot = catalog.load("thesis-diff-castor")
    castor = next(w for w in robot.wheels if w.type == "castor")
    return dataclasses.replace(robot, couplings=(Coupling("gear", (f"{castor.name}.steer", f"{castor.name}.spin"),
                                                          (1.0, 1.0)),))


def double_gear() -> Robot:
    """Two double wheels whose steering rates a gear turns 1:2 (levers: their half spacings b)."""
    from test_codegen import ROBOTS as PLAIN

    d = PLAIN["double units"].to_dict()
    d["couplings"] = [{"kind": "gear", "joints": ["drive.steer", "rear.steer"], "ratios": [1, 2]}]
    return Robot.from_dict(d)


def cart(ratio: float = 1.0) -> Robot:
    return Robot.from_dict(yaml.safe_load(cart_yaml(ratio)))


ROBOTS = {"cart 1:1": lambda: cart(1.0), "cart 1:2": lambda: cart(2.0), "cart 1:-1": lambda: cart(-1.0),
          "synchro": lambda: Robot.from_dict(yaml.safe_load(SYNCHRO)), "castor gear": castor_gear,
          "double gear": double_gear}


def floor_twists(s: float) -> np.ndarray:
    """Turns of the scale-`s` cart whose contacts depart from the gear by 0.5, 0.9, 1.1 and 2 ``SLIP_TOL``, then
    1e-320 rad/s and 1 rad/s (a real turn: b s m/s off the gear)."""
    f = np.array([0.5, 0.9, 1.1, 2.0])
    omega = np.concatenate([f * SLIP_TOL / (B * s), [1e-320, 1.0]])
    return np.column_stack([0 * omega, 0 * omega, omega])


EXPECTED = [True, True, False, False, True, False]


@pytest.mark.parametrize("s", SCALES)
def test_wheel_commands_floor_is_the_contact_speed(s):
    robot = scaled(cart(), s)
    c = wheel_commands(robot, floor_twists(s))
    assert c.in_gear[:, 0].tolist() == EXPECTED == c.feasible.tolist()
    # the same floor as the slip check's: a side speed of 0.9 / 1.1 SLIP_TOL, and 1e-320 m/s
    side = wheel_commands(robot, [[0, 0.9 * SLIP_TOL, 0], [0, 1.1 * SLIP_TOL, 0], [0, 1e-320, 0]])
    assert side.feasible.tolist() == [True, False, True]


@pytest.mark.parametrize("s", SCALES)
def test_realtime_ik_has_the_floor(s):
    robot = scaled(cart(), s)
    rt = realtime(robot)
    got = []
    for twist in floor_twists(s):
        rates, heading = np.empty(len(robot.rate_names)), np.empty(len(robot.steer_names))
        got.append(rt.ik(*map(float, twist), robot.heading.copy(), rates, heading))
    assert got == EXPECTED


def _rates(robot: Robot, mod, twists: np.ndarray) -> np.ndarray:
    """``wheel_commands``' rates in the generated code's order (rates, then the free steering rates)."""
    names = (*mod.RATE_NAMES, *mod.FREE_STEER_NAMES)
    return wheel_commands(robot, twists).rates[..., [robot.rate_names.index(n) for n in names]]


@pytest.mark.parametrize("s", SCALES)
def test_generated_python_and_c_have_the_floor(s, tmp_path):
    robot = scaled(cart(), s)
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    q = _rates(robot, mod, floor_twists(s))
    assert mod.in_gear(q)[:, 0].tolist() == EXPECTED
    if GCC is not None:
        assert _c_in_gear(robot, tmp_path / "c", q) == EXPECTED


def _c_in_gear(robot: Robot, directory, q: np.ndarray, steer: int = 0) -> list[bool]:
    """The generated C's verdicts on rates `q` ``(K, n)`` (the last `steer` the double wheels' steering rates)."""
    lib, ident = compile_c(robot, directory)
    check = getattr(lib, f"{ident}_in_gear")
    check.restype = ctypes.c_int
    out = []
    for row in q:
        flags = np.zeros(1, dtype=np.intc)
        args = (_ptr(row[:len(row) - steer]), _ptr(row[len(row) - steer:])) if steer else (_ptr(row),)
        verdict = check(*args, flags.ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
        assert verdict == flags[0]
        out.append(bool(verdict))
    return out


def sizes(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    """Numbers 0 or of random sign and size 10^U(-20, 6), one in five 10^U(-320, -20) (subnormal ones too)."""
    exponent = np.where(rng.random(shape) < 0.2, rng.uniform(-320, -20, shape), rng.uniform(-20, 6, shape))
    return 10.0 ** exponent * rng.choice([-1.0, 0.0, 1.0], shape)


def random_twists(seed: int, n: int = 40) -> np.ndarray:
    """Twists of random :func:`sizes`, then as many straight ahead (which the carts' and the synchro's gears allow,
    at the described headings)."""
    size = sizes(np.random.default_rng(seed), (n, 3))
    return np.vstack([size, size * [1, 0, 0]])


def random_rates(robot: Robot, names: tuple[str, ...], seed: int, n: int = 40) -> np.ndarray:
    """Rates ``(2 n, len(names))`` of random :func:`sizes`; then every gear's joints in its ratios at a turn of such a
    size, one of them off by 10^U(-15, -5) rad/s (about the floor over the levers)."""
    rng = np.random.default_rng(seed)
    q = sizes(rng, (2 * n, len(names)))
    for c in (c for c in robot.couplings if c.kind == "gear"):
        cols = [names.index(j) for j in c.joints]
        q[n:, cols] = q[n:, cols[:1]] * np.array(c.ratios) / c.ratios[0]
        off = rng.integers(len(cols), size=n)
        q[n + np.arange(n), np.array(cols)[off]] += 10.0 ** rng.uniform(-15, -5, n) * rng.choice([-1.0, 1.0], n)
    return q


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("name", list(ROBOTS))
def test_every_door_agrees_with_wheel_commands(name, s, tmp_path):
    robot = scaled(ROBOTS[name](), s)
    twists = random_twists(11)
    if name.startswith("cart"):
        twists = np.vstack([twists, floor_twists(s)])
    ref = wheel_commands(robot, twists)
    rt = realtime(robot)
    for twist, feasible in zip(twists, ref.feasible.tolist(), strict=True):
        rates, heading = np.empty(len(robot.rate_names)), np.empty(len(robot.steer_names))
        assert rt.ik(*map(float, twist), robot.heading.copy(), rates, heading) == feasible, twist
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    names = (*mod.RATE_NAMES, *mod.FREE_STEER_NAMES)
    q = np.vstack([_rates(robot, mod, twists), random_rates(robot, names, 12)])
    # wheel_commands' own check (gears_hold) on the same rates: the IK's, and any
    in_gear = gears_hold(gear_table(robot, names), q, SLIP_TOL)
    np.testing.assert_array_equal(in_gear[:len(twists)], ref.in_gear[:, list(gear_table(robot, names).coupling)])
    assert in_gear.any() and not in_gear.all()  # both verdicts are tried
    steer = len(mod.FREE_STEER_NAMES)
    got = mod.in_gear(q[:, :len(q[0]) - steer], q[:, len(q[0]) - steer:]) if steer else mod.in_gear(q)
    np.testing.assert_array_equal(got, in_gear)
    if GCC is not None:
        assert _c_in_gear(robot, tmp_path / "c", q, steer) == in_gear.all(axis=1).tolist()


@pytest.mark.parametrize("twist", [["0", "0", "1e-320"], ["0", "1e-320", "0"], ["0", "0", "1e-9"]])
def test_ik_says_a_tiny_twist_is_feasible_whichever_component_holds_it(twist, tmp_path, capsys):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(1.0))
    code = main(["ik", str(path), "--twist", *twist])
    out, err = capsys.readouterr()
    assert code == 0 and "feasible: yes" in out and err == ""


def test_ik_still_refuses_a_real_turn_of_the_solid_axle(tmp_path, capsys):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(1.0))
    code = main(["ik", str(path), "--twist", "0", "0", "1e-8"])  # the contacts 2e-9 m/s off the gear
    assert code == 1 and "feasible: NO (a gear coupling cannot turn its joints so)" in capsys.readouterr().out
