"""``kinematics --symbolic`` derives each closed form once: the inverse model's ranks were taken by deriving its
whole form (a cache key without ``gears`` missed the one that had it), and a geared robot's least-squares form was
derived only to be refused (``GearedLeastSquaresError``) and derived again of the wheels alone; 64 double wheels
with 96 gears took 66 s of processor time for ``--symbolic``. A geared ring's least squares holds its gears by
substitution (they set the steering rates of half its double wheels)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.kinematics import _exact_linalg, symbolic
from wmrkit.kinematics.linalg import geared_solve


def _ring(n: int, gears: bool) -> Robot:
    """`n` radial double wheels on a 0.5 m ring; with `gears`, neighbours' spins 1:1 and steering rates in pairs."""
    angles = [2 * math.pi * i / n for i in range(n)]
    wheels = [{"name": f"w{i}", "type": "double", "b": 0.05, "r": 0.05, "heading": a,
               "position": [round(0.5 * math.cos(a), 6), round(0.5 * math.sin(a), 6)],
               "actuated": ["spin1"], "sensed": ["spin1", "steer"]} for i, a in enumerate(angles)]
    couplings = [{"kind": "gear", "joints": [f"w{i}.{j}", f"w{i + 1}.{j}"]}
                 for i in range(0, n, 2) for j in ("spin1", "spin2", "steer")] if gears else []
    return Robot.from_dict({"name": f"ring{n}", "wheels": wheels, "couplings": couplings})


@pytest.mark.parametrize("gears", [False, True])
def test_each_closed_form_is_derived_once(monkeypatch, gears):
    robot = _ring(6, gears)
    calls = []
    original = _exact_linalg.solve_exactly
    monkeypatch.setattr(_exact_linalg, "solve_exactly", lambda *a, **k: calls.append(a[3]) or original(*a, **k))
    text = symbolic.format_symbolic(robot)
    assert "direct model (sensed)" in text and "not derived" in text  # six angles coupled: refused, never derived
    # one form derived: the inverse model's least squares; before: 2, 3 derivations. Geared, every gear turns a
    # double wheel whose steering rate the gears set (w1, w3, w5: one input per steering pair), so the least squares
    # holds them all by substitution (before: of the wheels alone, every steering rate an input, the gears not held)
    assert calls == [False]
    assert "not held" not in text
    names = symbolic.twist_assignment(robot)
    assert names == ("vx", "vy", "omega", *((f"w{i}.steer" for i in (0, 2, 4)) if gears else robot.free_steering))
    model = symbolic.held_model(robot, names)[0]
    cols = [robot.velocity_index(n) for n in model.assigned]
    q = np.random.default_rng(1).normal(size=len(cols))
    # numeric least squares (4.11), the gears substituted as fk's (none without them)
    expected = geared_solve(robot.constraint_matrix(), robot.couplings, robot.velocity_names, cols, q)[0]
    at = dict(zip(symbolic.steering_symbols(robot), robot.beta, strict=True))  # the described steering angles
    got = np.array(model.matrix.evalf(subs=at), dtype=float) @ q
    np.testing.assert_allclose(got, expected[[robot.velocity_index(n) for n in model.solved]], rtol=1e-9, atol=1e-12)
