"""Geared double wheels in the closed forms and the generated code: the same inputs as the numeric inverse model.

A double wheel whose two spins a gear holds at a ratio other than -1 cannot turn on the spot: its steering turns
with the twist and is not an input (``models._free_steering``); a gear of several steering rates is one input.
Before, ``kinematics --symbolic`` assigned every double wheel's steering rate (least squares, gears not held) and
the generated inverse took them all as ``steer_rate``. References: ``inverse_model`` at random steering (the ranks
method on the numeric matrix) and ``linalg.geared_solve`` (numeric least squares with the gears substituted).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from test_codegen import GCC, _ptr, compile_c, load_module

from wmrkit import Robot
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.linalg import geared_solve
from wmrkit.kinematics.models import inverse_model
from wmrkit.kinematics.symbolic import steering_symbols, symbolic_model, twist_assignment

TWIST = ("vx", "vy", "omega")


def random_robot(seed: int) -> Robot:
    """Two double wheels at random places (the body keeps one degree of freedom), one or both with their spins
    geared at a random ratio other than -1; for odd seeds a castor (its spin geared to w0.spin1 when seed % 4 == 1),
    and for seeds divisible by 3 the two steering rates on a gear."""
    rng = np.random.default_rng(seed)
    wheels = [{"name": f"w{i}", "type": "double", "position": np.round(rng.uniform(-0.6, 0.6, 2), 2).tolist(),
               "heading": round(float(rng.uniform(-3, 3)), 2), "b": round(float(rng.uniform(0.03, 0.1)), 2),
               "r": round(float(rng.uniform(0.03, 0.1)), 2)} for i in range(2)]
    held = [i for i in range(2) if rng.uniform() < 0.6] or [seed % 2]
    gears = [{"kind": "gear", "joints": [f"w{i}.spin1", f"w{i}.spin2"],
              "ratios": [1, float(rng.choice([2.0, 3.0, 0.5, -2.0]))]} for i in held]
    if seed % 2:
        wheels.append({"name": "c", "type": "castor", "position": [-0.4, 0.1], "d": 0.04, "r": 0.05})
        if seed % 4 == 1:
            gears.append({"kind": "gear", "joints": ["w0.spin1", "c.spin"], "ratios": [1, 1.5]})
    if seed % 3 == 0:
        gears.append({"kind": "gear", "joints": ["w0.steer", "w1.steer"], "ratios": [1, 2]})
    return Robot.from_dict({"name": f"dbl{seed}", "wheels": wheels, "couplings": gears})


SEEDS = range(8)


def _beta(robot: Robot, seed: int) -> np.ndarray:
    return np.random.default_rng(100 + seed).uniform(-math.pi, math.pi, len(robot.steer_names))


@pytest.mark.parametrize("seed", SEEDS)
def test_the_closed_form_inverse_assigns_the_numeric_models_inputs_and_holds_the_gears(seed):
    """The symbolic default inverse set is the numeric one at random steering, and its closed form there gives the
    numeric model's velocities (which hold every gear: A q = 0 with the gear rows)."""
    robot = random_robot(seed)
    beta = _beta(robot, seed)
    numeric = inverse_model(robot, beta=beta)
    names = twist_assignment(robot)
    if not numeric.assigned:  # m = 0 (seed 3: both units' spins and their steering geared): the twist by least
        assert names == TWIST  # squares, as a controller computes it (the closed forms' fallback)
        return
    assert names == numeric.assigned
    model = symbolic_model(robot, names)
    assert model.exact
    at = dict(zip(steering_symbols(robot), beta.tolist(), strict=True))
    matrix = np.array(model.matrix.xreplace({s: sp.Float(v, 30) for s, v in at.items()}).evalf(), dtype=float)
    q_a = np.random.default_rng(seed).normal(size=len(names))
    expect = numeric.velocities(q_a)
    got = matrix @ q_a
    np.testing.assert_allclose(got, expect[[robot.velocity_index(n) for n in model.solved]], rtol=1e-9, atol=1e-12)


def _held(robot: Robot, inputs: tuple[str, ...]) -> tuple:
    """The gears turning a joint of a double wheel whose steering rate is not an input."""
    steered = {n.rpartition(".")[0] for n in robot.free_steering if n not in inputs}
    return tuple(c for c in robot.couplings if c.kind == "gear" and
                 any(j.rpartition(".")[0] in steered for j in c.joints))


@pytest.mark.parametrize("seed", SEEDS)
def test_the_generated_inverse_takes_the_numeric_models_inputs(seed, tmp_path):
    """``FREE_STEER_NAMES`` are the numeric model's steering inputs; for the twist and steering rates of a motion of
    the numeric model the generated rates are that motion's, and for any twist they are numeric least squares with
    the gears of the non-input double wheels substituted (``geared_solve``), those gears held exactly."""
    robot = random_robot(seed)
    beta = _beta(robot, seed)
    numeric = inverse_model(robot, beta=beta)
    inputs = tuple(n for n in numeric.assigned if n not in TWIST)
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    assert mod.FREE_STEER_NAMES == inputs
    heading = robot.heading_of_beta(beta)
    rng = np.random.default_rng(seed)
    names = robot.velocity_names
    cols = [names.index(n) for n in TWIST + inputs]
    rate_cols = [names.index(n) for n in mod.RATE_NAMES]
    q = numeric.velocities(rng.normal(size=len(numeric.assigned)))
    given = np.concatenate([rng.normal(size=3), rng.normal(size=len(inputs))])
    a = robot.constraint_matrix(beta)
    ref = geared_solve(a, _held(robot, inputs), names, cols, given)[0]
    for u, expect in ((q[cols], q), (given, ref)):
        args = (u[:3], u[3:], heading) if inputs else (u[:3], heading)
        np.testing.assert_allclose(mod.inverse(*args), expect[rate_cols], rtol=1e-9, atol=1e-12)
    if GCC is not None and seed < 3:
        lib, ident = compile_c(robot, tmp_path / "c")
        for u, expect in ((q[cols], q), (given, ref)):
            out = np.zeros(len(rate_cols))
            steer = (_ptr(u[3:]),) if inputs else ()
            getattr(lib, f"{ident}_inverse")(_ptr(u[:3]), *steer, _ptr(heading), _ptr(out))
            np.testing.assert_allclose(out, expect[rate_cols], rtol=1e-9, atol=1e-12)


def test_a_least_squares_form_holds_the_gears_that_set_steering_and_names_the_others():
    """Two units spin-geared 1:2 and two castors whose spins turn together: (vx, vy, omega) is no exact set, so
    the closed form is least squares holding the units' gears by substitution and names the castors' gear as not
    held; at random steering it is numeric least squares with those two gears substituted (``geared_solve``)."""
    from wmrkit.kinematics.symbolic import held_model

    d = random_robot(2).to_dict()
    d["wheels"] += [{"name": f"c{i}", "type": "castor", "position": [0, y], "d": 0.04, "r": 0.03}
                    for i, y in ((1, 0.3), (2, -0.3))]
    d["couplings"] = [*d["couplings"], {"kind": "gear", "joints": ["c1.spin", "c2.spin"]}]
    robot = Robot.from_dict(d)
    model, unheld = held_model(robot, TWIST)
    assert unheld == ("gear(c1.spin, c2.spin)",) and not model.exact
    beta = _beta(robot, 2)
    at = {s: sp.Float(v, 30) for s, v in zip(steering_symbols(robot), beta.tolist(), strict=True)}
    matrix = np.array(model.matrix.xreplace(at).evalf(), dtype=float)
    twist = np.array([0.4, -0.2, 0.7])
    ref = geared_solve(robot.constraint_matrix(beta), robot.couplings[:-1], robot.velocity_names, [0, 1, 2], twist)[0]
    np.testing.assert_allclose(matrix @ twist, ref[[robot.velocity_index(n) for n in model.solved]], rtol=1e-9,
                               atol=1e-12)
