"""Bounded time of the closed forms (wmrkit.kinematics.symbolic): a least-squares form that couples many steering
angles is refused at once, and ``kinematics --symbolic`` says so instead of computing for hours."""

from __future__ import annotations

import math

import pytest
import sympy as sp
import yaml

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.symbolic import (
    MAX_LSQ_ANGLES,
    AssignmentError,
    ClosedFormTooLargeError,
    format_symbolic,
    sensed_rates,
    symbolic_model,
    twist_assignment,
)


def castors(n: int) -> dict:
    """`n` castors on a circle, every joint sensed (by default): the direct model is least squares over n angles."""
    return {"name": f"castors{n}", "wheels": [
        {"name": f"w{i}", "type": "castor", "d": 0.03, "r": 0.05,
         "position": [round(0.5 * math.cos(2 * math.pi * i / n) + 0.01 * i, 4),
                      round(0.5 * math.sin(2 * math.pi * i / n), 4)]} for i in range(n)]}


def test_a_least_squares_form_over_many_angles_is_refused_at_once(monkeypatch):
    """Six castors: the least-squares direct model couples six steering angles; its derivation took several minutes
    (twelve castors: hours), now ClosedFormTooLargeError names them at once: before any derivation (no wall-clock
    bound: the derivation is made to fail if it starts). The exact inverse model is still derived (one angle per
    wheel)."""
    from wmrkit.kinematics import _exact_linalg

    robot = Robot.from_dict(castors(6))

    def derivation(*args, **kwargs):
        raise AssertionError("the closed form was derived before the refusal")

    with monkeypatch.context() as patch:
        patch.setattr(_exact_linalg, "solve_exactly", derivation)
        with pytest.raises(ClosedFormTooLargeError, match=r"couples 6 steering angles \(beta_w0, beta_w1, beta_w2, "
                                                          r"beta_w3, beta_w4, beta_w5\), more than max_lsq_angles = 4"):
            symbolic_model(robot, sensed_rates(robot))
    assert twist_assignment(robot) == ("vx", "vy", "omega")
    assert symbolic_model(robot, ("vx", "vy", "omega")).exact
    assert MAX_LSQ_ANGLES == 4


def test_the_limit_is_a_keyword():
    robot = Robot.from_dict(castors(3))
    with pytest.raises(ClosedFormTooLargeError, match="couples 3 steering angles"):
        symbolic_model(robot, sensed_rates(robot), max_lsq_angles=2)
    with pytest.raises(AssignmentError, match="max_lsq_angles: expected a whole number >= 0, got -1"):
        symbolic_model(robot, sensed_rates(robot), max_lsq_angles=-1)


def test_format_and_cli_print_why_a_model_is_not_derived(tmp_path, capsys):
    data = castors(6)
    text = format_symbolic(Robot.from_dict(data))
    assert "  not derived: robot 'castors6': the least-squares closed form" in text
    assert "inverse model, assigned: vx, vy, omega" in text and "w0.spin = " in text
    path = tmp_path / "castors6.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["kinematics", str(path), "--symbolic"]) == 0
    assert "not derived: robot 'castors6'" in capsys.readouterr().out


def test_swedish_wheels_at_odd_angles_give_their_direct_model_in_seconds():
    """Eight Swedish wheels with axles at 7 + 45 k deg (sensed spins): sin(13 pi/45)... stayed unevaluated, each
    angle two more variables of the exact algebra, and `kinematics --symbolic` ran past 100 s; they are now floats
    taken exactly, as for a fixed axle at 0.3 rad, and the form still equals numeric least squares (4.11)."""
    import sympy as sp

    from wmrkit.kinematics.symbolic import symbolic_constraint_matrix

    robot = Robot.from_dict({"name": "sw8", "wheels": [
        {"name": f"m{i}", "type": "swedish", "l": 0.5, "alpha": f"{45 * i} deg", "beta": f"{45 * i + 7} deg",
         "gamma": "45 deg", "r": 0.03, "r_r": 0.01, "sensed": ["spin"]} for i in range(8)]})
    assert not symbolic_constraint_matrix(robot).atoms(sp.sin, sp.cos)
    _assert_direct_model_is_least_squares(robot)


def test_five_omni_wheels_give_their_direct_model_in_seconds():
    """Five omni wheels at 72 deg (sensed spins): sin(2 pi/5) came in as the nested root sqrt(5/8 + sqrt(5)/8),
    which no polynomial generator covers, so the least-squares direct model fell back to sympy expressions and
    `kinematics --symbolic` ran for minutes (stopped at 2 min). Nested roots are now floats taken exactly, as sin
    and cos of an angle that is no simple multiple of pi; the form still equals numeric least squares (4.11)."""
    import sympy as sp

    from wmrkit.kinematics.symbolic import symbolic_constraint_matrix

    robot = Robot.from_dict({"name": "omni5", "wheels": [
        {"name": f"o{i}", "type": "swedish", "l": 0.2, "alpha": f"{72 * i} deg", "beta": f"{72 * i} deg",
         "gamma": "90 deg", "r": 0.05, "r_r": 0.01, "sensed": ["spin"]} for i in range(5)]})
    nested = [p for p in symbolic_constraint_matrix(robot).atoms(sp.Pow) if not p.base.is_Rational]
    assert not nested, nested
    _assert_direct_model_is_least_squares(robot)


def _assert_direct_model_is_least_squares(robot: Robot) -> None:
    """The closed-form direct model of the sensed spins equals numeric least squares (4.11) on random rates."""
    import numpy as np

    from wmrkit.kinematics.linalg import solve_assigned

    model = symbolic_model(robot, sensed_rates(robot))
    cols = [robot.velocity_index(n) for n in model.assigned]
    q = np.random.default_rng(0).normal(size=len(cols))
    expected = solve_assigned(robot.constraint_matrix(), cols, q)[0]
    got = np.array(model.matrix.evalf(), dtype=float) @ q
    np.testing.assert_allclose(got, expected[[robot.velocity_index(n) for n in model.solved]], rtol=1e-9, atol=1e-12)


def test_the_relations_are_converted_once_per_ring(monkeypatch):
    """Each entry of a closed form is reduced modulo sin^2 + cos^2 = 1 of every angle; the relations were rebuilt as
    polynomials for every entry (6,720 entries x 33 relations for 32 double wheels: 221,760 conversions, most of the
    time; 64 double wheels' `kinematics --codegen` did not finish in 400 s). Now once per polynomial ring. The
    model is the same: its rates at rest, unit turning at s, are the sub-wheels' -+b s / r (3.24)."""
    from sympy.polys.rings import PolyRing

    n = 6
    robot = Robot.from_dict({"name": "doubles", "wheels": [
        {"name": f"u{i}", "type": "double", "b": 0.05, "r": 0.1, "alpha": 2 * math.pi * i / n, "l": 0.5}
        for i in range(n)]})
    calls = []
    original = PolyRing.from_expr
    monkeypatch.setattr(PolyRing, "from_expr", lambda ring, expr: calls.append(expr) or original(ring, expr))
    model = symbolic_model(robot, ("vx", "vy", "omega", *robot.free_steering))
    assert 0 < len(calls) <= 2 * n  # the 2 n relations s^2 + c^2 - 1, once (before: 2,268)
    rates = model.matrix[:, 3:]  # the steering rates' columns, at rest
    k = model.solved.index("u0.spin1")
    assert rates[k, 0] == sp.Rational(-1, 2) and rates[k + 1, 0] == sp.Rational(1, 2)  # -+b/r = -+0.05/0.1
