"""A ``gear`` holds its joints together even when none of them is read or actuated (``couplings.gear_free``: its turn
is one unknown): the minimal actuator sets judge each set as ``actuation_analysis`` does (brute force), one encoder on
the castor of a solid-axle cart is a sensor set, and ``fk``, ``odometry``, the sensing analysis and the slip models
(WLS, MCD, MQE) give the cart's closed form: 1:1 axle spins, so ``vx = r q`` for either spin and ``vx = r_c q_c`` for
the castor's (rolling straight behind), ``vy = omega = 0``."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.cli.main import main
from wmrkit.description import robot_from_dict
from wmrkit.dynamics.mass import Body
from wmrkit.kinematics.actuation import actuation_analysis, minimal_actuator_sets, selectable_rates
from wmrkit.kinematics.sensing import minimal_sensor_sets, sensing_analysis
from wmrkit.kinematics.trees import jacobian_names
from wmrkit.kinematics.wheel_ik import forward_kinematics, twist_is_determined
from wmrkit.slip.models import LinearFriction, mcd, mqe, wls
from wmrkit.slip.weights import SlipWeights

R, RC = 0.075, 0.025
WHEELS = [{"name": "left", "type": "fixed", "position": [0, 0.2], "heading": 0, "r": R},
          {"name": "right", "type": "fixed", "position": [0, -0.2], "heading": 0, "r": R}]
CASTOR = {"name": "caster", "type": "castor", "position": [-0.25, 0], "heading": 0, "d": 0.04, "r": RC}
# ratio 2: vx = 1.5 r q, omega = 2.5 r q; the front wheel at x = 0.6 rolls along (vx, 0.6 omega): heading pi/4
STEERED = {"name": "front", "type": "steerable", "position": [0.6, 0], "heading": math.pi / 4, "r": 0.1}


def cart(kind: str = "gear", ratio: float = 1.0, front: dict = CASTOR) -> Robot:
    """The solid-axle cart of tests/kinematics/test_gear_fill.py (left.spin actuated and sensed)."""
    wheels = [dict(WHEELS[0], actuated=["spin"], sensed=["spin"]), WHEELS[1], front]
    return robot_from_dict({"name": "cart", "wheels": wheels,
                            "couplings": [{"kind": kind, "joints": ["left.spin", "right.spin"], "ratios": [1, ratio]}]})


SYNCHRO = {"name": "synchro-3", "wheels": [
    {"name": n, "type": "steerable", "position": p, "heading": 0.4, "r": 0.05}
    for n, p in (("a", [0.2, 0]), ("b", [-0.1, 0.1732]), ("c", [-0.1, -0.1732]))],
    "couplings": [{"kind": "gear", "joints": ["a.spin", "b.spin", "c.spin"], "ratios": [1, 1, 1]},
                  {"kind": "linkage", "joints": ["a.steer", "b.steer", "c.steer"], "ratios": [1, 1, 1]}]}
ROBOTS = {"cart-1": lambda: cart(), "cart-2": lambda: cart(ratio=2.0), "cart-minus-1": lambda: cart(ratio=-1.0),
          "cart-steered": lambda: cart(ratio=2.0, front=STEERED), "cart-differential": lambda: cart("differential"),
          "synchro-3": lambda: robot_from_dict(SYNCHRO), "diff-drive": lambda: catalog.load("diff-drive")}


def brute_force_actuators(robot: Robot) -> list[tuple[str, ...]]:
    """Every set of m selectable rates (m: actuation_analysis's) that actuation_analysis calls consistent and
    sufficient (determined, nothing undriven)."""
    names, steer = jacobian_names(robot), []
    for w in (w for w in robot.wheels if w.type == "steerable"):  # one steering actuator per linkage: its first joint
        link = next((c.joints for c in robot.couplings if c.kind == "linkage" and f"{w.name}.steer" in c.joints),
                    (f"{w.name}.steer",))
        steer += [] if link[0] in steer else [link[0]]
    steer = tuple(steer)
    m = int(actuation_analysis(robot).mobility)
    out = []
    for s in itertools.combinations(selectable_rates(robot), m):
        a = actuation_analysis(robot, actuated=tuple(names[c] for c in s) + steer)
        if bool(a.leaf == "determined") and int(a.undriven) == 0:
            out.append(tuple(names[c] for c in s) + steer)
    return out


@pytest.mark.parametrize("name", list(ROBOTS))
def test_minimal_actuator_sets_are_the_sets_the_actuation_analysis_accepts(name):
    """Before: the cart listed 6 pairs under m = 2, next to 'actuation [gear(...)]: ... m = 1'."""
    robot = ROBOTS[name]()
    found = minimal_actuator_sets(robot)
    assert found.complete and list(found) == brute_force_actuators(robot) != []


def test_kinematics_lists_the_actuator_and_sensor_sets_of_the_cart(tmp_path, capsys):
    path = tmp_path / "cart.yaml"
    path.write_text(json.dumps({"name": "cart", "wheels": [dict(WHEELS[0], actuated=["spin"], sensed=["spin"]),
                                                           WHEELS[1], CASTOR],
                                "couplings": [{"kind": "gear", "joints": ["left.spin", "right.spin"]}]}))
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    assert "  minimal actuator sets (3):\n    (left.spin)  (right.spin)  (caster.spin)\n" in out
    assert "  minimal sensor sets (3):\n    (left.spin)  (right.spin)  (caster.spin)\n" in out


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_the_castor_encoder_alone_senses_the_geared_cart(ratio):
    """The gear's q_r = ratio q_l holds with neither joint sensed: the cart has one motion, which the castor's spin
    reads. Independent twist: left.spin = 10 gives the differential drive's closed form (q_r = ratio q_l); the
    castor's spin for that twist (least squares of its own rows) alone, given to fk, gives it back."""
    robot = cart(ratio=ratio)
    s = sensing_analysis(robot, sensed=["caster.spin"])
    assert bool(s.sufficient) and s.leaf == "determined"
    assert "gear(left.spin, right.spin)" in s.full_names
    assert bool(twist_is_determined(robot, ["caster.spin"]))  # before: False (fk warned: not determined)
    twist_left = np.array([R * 10 * (1 + ratio) / 2, 0, R * 10 * (ratio - 1) / 0.4])
    np.testing.assert_allclose(forward_kinematics(robot, {"left.spin": 10.0})[0], twist_left, atol=1e-12)
    a, names = robot.constraint_matrix(), robot.velocity_names
    castor = [names.index("caster.spin"), names.index("caster.steer")]
    spin, _ = np.linalg.lstsq(a[:, castor], -a[:, :3] @ twist_left, rcond=None)[0]
    twist, residual = forward_kinematics(robot, {"caster.spin": spin})
    np.testing.assert_allclose(twist, twist_left, atol=1e-12)
    assert residual < 1e-12
    np.testing.assert_allclose(s.twist([spin]), twist_left, atol=1e-12)


def test_the_castor_spin_does_not_sense_a_turn_on_the_spot():
    """Ratio -1: the axle turns the cart about its centre; the castor (heading 0) only steers, its spin reads 0."""
    assert not bool(sensing_analysis(cart(ratio=-1.0), sensed=["caster.spin"]).sufficient)


def test_minimal_sensor_sets_of_the_cart_include_the_castor_spin():
    """Before: (left.spin) and (right.spin) only; the castor's spin was left with two free axle spins."""
    assert list(minimal_sensor_sets(cart())) == [("left.spin",), ("right.spin",), ("caster.spin",)]


@pytest.mark.parametrize("ratio", [1.0, 2.0, -1.0, 0.5])
def test_slip_models_hold_the_gear(ratio):
    """Before: wls(cart, ['left.spin'], [10]).twist was (0.348, 0, -2.01) (right.spin free); with no slip WLS must
    equal the exact odometry (fk), and MCD with the linear law WLS (the theorem of §7.4.4)."""
    robot = cart(ratio=ratio)
    exact = np.array([R * 10 * (1 + ratio) / 2, 0, R * 10 * (ratio - 1) / 0.4])
    w = wls(robot, ["left.spin"], [10.0])
    np.testing.assert_allclose(w.twist, exact, atol=1e-12)
    np.testing.assert_allclose(w.q_dot[robot.velocity_index("right.spin")], 10 * ratio, rtol=1e-12)
    assert np.abs(w.slip).max() < 1e-12
    law = LinearFriction.from_weights(robot, SlipWeights())
    c = mcd(robot, ["left.spin"], [10.0], law)
    assert bool(c.converged)
    np.testing.assert_allclose(c.q_dot, w.q_dot, atol=1e-9)
    q = mqe(robot, ["left.spin"], [10.0], law, body=Body(mass=20.0, inertia=1.0, com=(0.0, 0.0), com_height=0.1))
    assert bool(q.converged)
    np.testing.assert_allclose(q.q_dot[robot.velocity_index("right.spin")], 10 * ratio, rtol=1e-9)


def test_slip_models_with_no_joint_of_the_gear_assigned():
    """The gear's turn is one unknown of the slip models: the castor's spin alone drives the cart (ratio 2: a turn),
    with the twist of the castor test above; before, WLS gave the minimum-norm answer of the free axle spins."""
    robot = cart(ratio=2.0)
    twist = np.array([R * 10 * 3 / 2, 0, R * 10 / 0.4])  # left.spin = 10, right.spin = 20
    a, names = robot.constraint_matrix(), robot.velocity_names
    castor = [names.index("caster.spin"), names.index("caster.steer")]
    spin = np.linalg.lstsq(a[:, castor], -a[:, :3] @ twist, rcond=None)[0][0]
    w = wls(robot, ["caster.spin"], [spin])
    np.testing.assert_allclose(w.twist, twist, atol=1e-12)
    np.testing.assert_allclose([w.q_dot[names.index("left.spin")], w.q_dot[names.index("right.spin")]], [10, 20],
                               rtol=1e-12)
    c = mcd(robot, ["caster.spin"], [spin], LinearFriction.from_weights(robot, SlipWeights()))
    assert bool(c.converged)
    np.testing.assert_allclose(c.q_dot, w.q_dot, atol=1e-9)
