"""Symbolic models (wmrkit.kinematics.symbolic): the constraint matrix against the numeric one, the ranks method done
exactly against numeric least squares, and the tricycle tables (4.80)-(4.84) against the digest's corrected forms
(spec/ch3-4-wheels-and-kinematic-models.md PART C), which were derived independently of wmrkit.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings

from strategies import robots
from wmrkit import Robot, SingularError, UnknownNameError, Wheel, catalog
from wmrkit.kinematics.linalg import solve_assigned, velocity_scale
from wmrkit.kinematics.symbolic import (
    AssignmentError,
    exact_number,
    format_symbolic,
    geometry_symbols,
    sensed_rates,
    steering_symbols,
    symbolic_constraint_matrix,
    symbolic_model,
    twist_assignment,
)

r, l12, l3 = sp.symbols("r l12 l3", positive=True)
b3 = sp.Symbol("beta3", real=True)
c, s = sp.cos(b3), sp.sin(b3)
vx, vy, om, p1, p2, p3 = sp.symbols("vx vy omega w1.spin w2.spin w3.spin", real=True)
TRICYCLE = Robot("tricycle", (  # table C.1; the numbers are those of the oracles C.5/C.6
    Wheel("w1", "fixed", 0.5, 0.0, 0.0, 0.1, sensed=("spin",)),
    Wheel("w2", "fixed", 0.5, math.pi, 0.0, 0.1, sensed=("spin",)),
    Wheel("w3", "steerable", 1.2, -math.pi / 2, 0.4, 0.1),
))
TRICYCLE_CATALOG = catalog.load("thesis-tricycle")
GEOMETRY = {"w1.l": l12, "w2.l": l12, "w3.l": l3, "w1.r": r, "w2.r": r, "w3.r": r}
NUMBERS = {r: 0.1, l12: 0.5, l3: 1.2}


def tri(assigned):
    return symbolic_model(TRICYCLE, assigned, [b3], geometry=GEOMETRY)


def is_zero(expr) -> bool:
    """Exact zero test independent of wmrkit's reduction: tan half-angle substitution, then cancel."""
    t = sp.Symbol("t", real=True)
    e = sp.expand_trig(sp.sympify(expr)).xreplace({s: 2 * t / (1 + t**2), c: (1 - t**2) / (1 + t**2)})
    return sp.cancel(sp.together(e)) == 0


def column(model, expected: dict) -> bool:
    """The closed form equals `expected` ({velocity name: expression in the assigned symbols})."""
    sol = dict(zip(model.solved, model.solution(), strict=True))
    return all(is_zero(sol[name] - value) for name, value in expected.items()) and set(sol) == set(expected)


# ---- the constraint matrix -------------------------------------------------------------------------------
def test_exact_numbers():
    assert exact_number(0.45, "length") == sp.Rational(9, 20)
    assert exact_number(math.radians(90), "angle") == sp.pi / 2
    assert exact_number(math.radians(-90), "angle") == -sp.pi / 2
    assert exact_number(0.4, "angle") == sp.Rational(2, 5)
    assert exact_number(2.35, "length") == sp.Rational(47, 20)
    assert exact_number(0.123456789, "length") == sp.Rational(123456789, 10**9)


@settings(max_examples=40)
@given(robots(max_wheels=3))
def test_symbolic_matrix_is_the_numeric_one(robot):
    """Built from the same kernel: equal to Robot.constraint_matrix at random steering angles."""
    a = symbolic_constraint_matrix(robot)
    betas = np.random.default_rng(1).uniform(-math.pi, math.pi, (2, len(robot.steer_names)))
    for beta in betas:
        values = a.xreplace({sym: sp.Float(v) for sym, v in zip(steering_symbols(robot), beta, strict=True)})
        np.testing.assert_allclose(np.array(values.evalf(), dtype=float), robot.constraint_matrix(beta),
                                   rtol=0, atol=1e-12)


@settings(max_examples=40)
@given(robots(max_wheels=3))
def test_symbolic_geometry_evaluates_to_the_numeric_matrix(robot):
    """geometry="symbolic" for every wheel type: substituting the wheels' numbers gives Robot.constraint_matrix."""
    a = symbolic_constraint_matrix(robot, geometry="symbolic")
    beta = np.random.default_rng(3).uniform(-math.pi, math.pi, len(robot.steer_names))
    values = {sym: sp.Float(getattr(robot.wheel(key.split(".")[0]), key.split(".")[1]))
              for key, sym in geometry_symbols(robot).items()}
    values.update({sym: sp.Float(v) for sym, v in zip(steering_symbols(robot), beta, strict=True)})
    np.testing.assert_allclose(np.array(a.xreplace(values).evalf(), dtype=float), robot.constraint_matrix(beta),
                               rtol=0, atol=1e-12)


def test_symbolic_geometry_gives_every_field_its_own_symbol():
    """A Swedish wheel 'a' and a wheel 'r_a': the roller radius of one and the radius of the other were both the
    symbol r_r_a, one parameter in the closed forms (their numbers substituted into one symbol, the other lost)."""
    robot = Robot("two", (Wheel("a", "swedish", 0.3, 0.0, 0.0, 0.05, gamma=0.7, r_r=0.01),
                          Wheel("r_a", "fixed", 0.3, math.pi, 0.0, 0.08)))
    g = geometry_symbols(robot)
    assert len(set(g.values())) == len(g) and g["r_a.r"].name == "r_r_a" and g["a.r_r"].name == "rr_a"
    values = {sym: getattr(robot.wheel(key.split(".")[0]), key.split(".")[1]) for key, sym in g.items()}
    a = symbolic_constraint_matrix(robot, geometry="symbolic").xreplace(values)
    np.testing.assert_allclose(np.array(a.evalf(), dtype=float), robot.constraint_matrix(), rtol=0, atol=1e-12)


def test_catalog_forklift_entries_are_exact():
    """Positions [-1, +-0.45], [-2.35, 0] and r = 0.23 appear as exact rationals (3.11), beta 90 deg as pi/2."""
    from wmrkit import catalog

    a = symbolic_constraint_matrix(catalog.load("forklift"), [sp.Symbol("b")])
    bb = sp.Symbol("b")
    # right drive wheel: l sin(beta - alpha) with (x, y) = (-1, -0.45) and beta = pi/2 is x sin(beta) - y cos(beta)
    assert list(a.row(0)) == [0, 1, -1, 0, 0, 0]
    assert list(a.row(1)) == [-1, 0, sp.Rational(-9, 20), sp.Rational(23, 100), 0, 0]
    assert list(a.row(4)) == [sp.cos(bb), sp.sin(bb), sp.Rational(-47, 20) * sp.sin(bb), 0, 0, 0]


def test_symbolic_geometry_gives_the_general_formulas():
    """Castor (3.12) and Swedish (3.13) rows with symbols l, alpha, d, delta, gamma, r, r_r."""
    robot = Robot("two", (Wheel("c", "castor", 0.3, 0.2, 0.1, 0.05, d=0.04, delta=0.2),
                          Wheel("s", "swedish", 0.3, 1.0, 0.5, 0.05, gamma=0.7, r_r=0.01)))
    g = geometry_symbols(robot)
    a = symbolic_constraint_matrix(robot, geometry="symbolic")
    (bc,) = steering_symbols(robot)
    lc, ac, d, dl, rc = (g[f"c.{k}"] for k in ("l", "alpha", "d", "delta", "r"))
    ls, as_, bs, gm, rs, rr = (g[f"s.{k}"] for k in ("l", "alpha", "beta", "gamma", "r", "r_r"))
    th = bc + dl
    castor = sp.Matrix([[sp.cos(th), sp.sin(th), lc * sp.sin(th - ac) - d * sp.cos(dl), -d * sp.cos(dl), 0],
                        [-sp.sin(th), sp.cos(th), lc * sp.cos(th - ac) + d * sp.sin(dl), d * sp.sin(dl), rc]])
    ts = bs + gm
    swedish = sp.Matrix([[sp.cos(ts), sp.sin(ts), ls * sp.sin(ts - as_), rs * sp.sin(gm), 0],
                         [-sp.sin(ts), sp.cos(ts), ls * sp.cos(ts - as_), rs * sp.cos(gm), rr]])
    diff = (a[:2, :5] - castor).col_join(a[2:, [0, 1, 2, 5, 6]] - swedish)
    assert diff.applyfunc(lambda e: sp.simplify(sp.expand_trig(e))) == sp.zeros(4, 5)


# ---- the ranks method, exactly ---------------------------------------------------------------------------
def millimetres(robot: Robot) -> Robot:
    """Geometry rounded to mm and mrad, as robots are drawn (random 17-digit floats make huge exact rationals)."""
    fields = ("l", "alpha", "beta", "r", "d", "delta", "gamma", "r_r", "b")
    return replace(robot, wheels=tuple(replace(w, **{f: round(getattr(w, f), 3) for f in fields})
                                       for w in robot.wheels))


@settings(max_examples=30)
@given(robots(max_wheels=3).map(millimetres))
def test_closed_form_is_the_numeric_least_squares(robot):
    """M(beta) q_a equals solve_assigned (4.11) for the sensed rates and for the twist, when determined."""
    rng = np.random.default_rng(2)
    for assigned in (sensed_rates(robot), ("vx", "vy", "omega")):
        try:
            model = symbolic_model(robot, assigned)
        except SingularError:
            continue
        beta = rng.uniform(-math.pi, math.pi, len(robot.steer_names))
        q_a = rng.normal(size=len(assigned))
        sub = {sym: sp.Float(v) for sym, v in zip(model.steering, beta, strict=True)}
        m = np.array(model.matrix.xreplace(sub).evalf(), dtype=float).reshape(model.matrix.shape)
        idx = [robot.velocity_index(n) for n in assigned]
        q, res = solve_assigned(robot.constraint_matrix(beta), idx, q_a)
        solved = [robot.velocity_index(n) for n in model.solved]
        np.testing.assert_allclose(m @ q_a, q[solved], rtol=1e-8, atol=1e-8)
        if model.exact:  # an assignable set (4.10): no slip for any assigned values
            np.testing.assert_allclose(res, 0, atol=1e-9)
        residual = np.array(model.residual.xreplace(sub).evalf(), dtype=float).reshape(model.residual.shape)
        np.testing.assert_allclose(residual @ q_a, res, rtol=1e-8, atol=1e-8)


def test_mobility_and_rank_of_the_tricycle_479():
    model = tri(["w3.spin"])
    assert (model.rank, model.mobility, model.exact) == (5, 1, True)


def test_vx_cannot_be_assigned():
    with pytest.raises(SingularError, match=r"assigning \(vx\) does not determine \(vy, omega, w1\.spin, w2\.spin, "
                                            r"w3\.spin\)"):
        tri(["vx"])


def test_the_refusal_names_the_velocities_left_free_not_every_unknown():
    """The two spins of a differential drive fix its twist; an unsensed double wheel beside them can still turn on
    the spot (3.29). The message listed every unknown, (vx, vy, omega, unit.steer, ...), a false claim about the
    twist ('kinematics --symbolic' printed it as the direct model's 'not determined' line)."""
    robot = Robot.from_dict({"name": "dd-double", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, 0.2], "heading": 0, "r": 0.075},
        {"name": "right", "type": "fixed", "position": [0, -0.2], "heading": 0, "r": 0.075},
        {"name": "unit", "type": "double", "position": [0.5, 0], "heading": 0, "b": 0.05, "r": 0.05}]})
    with pytest.raises(SingularError, match=r"\(left\.spin, right\.spin\) does not determine \(unit\.steer, "
                                            r"unit\.spin1, unit\.spin2\): rank A_na = 5 < 6"):
        symbolic_model(robot, ["left.spin", "right.spin"])


# ---- the tricycle tables (4.80)/(4.81), digest C.5 (corrected) --------------------------------------------
C5 = {  # assigned velocity -> the other five, as multiples of it
    "w3.spin": {"vx": 0, "vy": -r * c, "omega": r * s / l3, "w1.spin": (l3 * c - l12 * s) / l3,
                "w2.spin": (l3 * c + l12 * s) / l3},
    "vy": {"vx": 0, "omega": -(s / c) / l3, "w1.spin": (-l3 + l12 * s / c) / (l3 * r),
           "w2.spin": (-l3 - l12 * s / c) / (l3 * r), "w3.spin": -1 / (c * r)},
    "omega": {"vx": 0, "vy": -l3 * c / s, "w1.spin": (-l12 + l3 * c / s) / r, "w2.spin": (l12 + l3 * c / s) / r,
              "w3.spin": l3 / (r * s)},
    "w1.spin": {"vx": 0, "vy": r * l3 * c / (-l3 * c + l12 * s), "omega": r * s / (l3 * c - l12 * s),
                "w2.spin": (l3 * c + l12 * s) / (l3 * c - l12 * s), "w3.spin": l3 / (l3 * c - l12 * s)},
    "w2.spin": {"vx": 0, "vy": -r * l3 * c / (l3 * c + l12 * s), "omega": r * s / (l3 * c + l12 * s),
                "w1.spin": (l3 * c - l12 * s) / (l3 * c + l12 * s), "w3.spin": l3 / (l3 * c + l12 * s)},
}


@pytest.mark.parametrize("assigned", list(C5))
def test_tricycle_480_481_corrected(assigned):
    q = sp.Symbol(assigned, real=True)
    model = tri([assigned])
    assert model.exact
    assert column(model, {k: v * q for k, v in C5[assigned].items()})


def test_tricycle_480_481_printed_garbles_differ():
    """001's (4.81) entries that the digest corrects are not the solution (errata)."""
    sol = {a: dict(zip(tri([a]).solved, tri([a]).matrix, strict=True)) for a in C5}
    assert not is_zero(sol["vy"]["omega"] - (-(s / c) / l3) / (l3 * r))  # printed (-tan(b3)/l3)/(l3 r)
    assert not is_zero(sol["omega"]["vy"] - (-l3 * c / s) / r)  # printed -l3 cot(b3) / r
    assert not is_zero(sol["w1.spin"]["w3.spin"] - (l3 * c + l12 * s) / (l3 * c - l12 * s))  # printed phi3
    assert not is_zero(sol["w2.spin"]["w3.spin"] - 1)  # printed (l3 c + l12 s)/(l3 c + l12 s)


def test_tricycle_numeric_oracle_c5():
    """r = 0.1, l12 = 0.5, l3 = 1.2, beta3 = 0.4: (vx, vy, omega, phi1, phi2, phi3) with the named velocity = 1."""
    oracle = {"w3.spin": (0, -0.092106, 0.032452, 0.758803, 1.083319, 1),
              "w1.spin": (0, -0.121383, 0.042767, 1, 1.427667, 1.317865),
              "w2.spin": (0, -0.085022, 0.029956, 0.700443, 1, 0.923089),
              "vy": (0, 1, -0.352328, -8.238362, -11.761638, -10.857044),
              "omega": (0, -2.838267, 1, 23.382669, 33.382669, 30.815189)}
    names = TRICYCLE.velocity_names
    for assigned, expected in oracle.items():
        model = symbolic_model(TRICYCLE, [assigned])  # numeric geometry, exact: 1/10, 1/2, 6/5
        values = dict(zip(model.solved, model.matrix.xreplace({model.steering[0]: sp.Float(0.4)}), strict=True))
        got = [1.0 if n == assigned else float(values[n]) for n in names]
        np.testing.assert_allclose(got, expected, atol=2e-6)


# ---- extended solutions (4.82), conditions (4.83), simplified forms (4.84) --------------------------------
D1 = 3 * l12**2 + 4 * l3**2
C6 = {  # digest C.6: assigned pair -> (solved names, matrix)
    ("w1.spin", "w3.spin"): (("vx", "vy", "omega", "w2.spin"), -r / D1 * sp.Matrix([
        [-l12 * l3, l12 * (l3 * c - l12 * s)],
        [2 * l3**2, (2 * l3**2 + 3 * l12**2) * c + 2 * l3 * l12 * s],
        [3 * l12, -3 * l12 * c - 4 * l3 * s],
        [(3 * l12**2 - 2 * l3**2) / r, -(2 * l3**2 + 6 * l12**2) * c / r - 6 * l3 * l12 * s / r]])),
    ("w2.spin", "w3.spin"): (("vx", "vy", "omega", "w1.spin"), -r / D1 * sp.Matrix([
        [l12 * l3, -l12 * (l3 * c + l12 * s)],
        [2 * l3**2, (2 * l3**2 + 3 * l12**2) * c - 2 * l3 * l12 * s],
        [-3 * l12, 3 * l12 * c - 4 * l3 * s],
        [(3 * l12**2 - 2 * l3**2) / r, -(2 * l3**2 + 6 * l12**2) * c / r + 6 * l3 * l12 * s / r]])),
    ("w1.spin", "w2.spin"): (("vx", "vy", "omega", "w3.spin"), -r / (6 * l12**2 + l3**2 * (1 + sp.cos(2 * b3)))
                             * sp.Matrix([  # the 8-entry column of 001 read as a 4 x 2 matrix
        [-l12 * c * (l3 * c + l12 * s), l12 * c * (l3 * c - l12 * s)],
        [(l3**2 + 3 * l12**2) * c**2 - l3 * l12 * c * s + 2 * l12**2 * s**2,
         (l3**2 + 3 * l12**2) * c**2 + l3 * l12 * c * s + 2 * l12**2 * s**2],
        [3 * l12 - l3 * sp.sin(2 * b3) / 2, -3 * l12 - l3 * sp.sin(2 * b3) / 2],
        [-(l3**2 + 3 * l12**2) * c / r + 3 * l3 * l12 * s / r, -(l3**2 + 3 * l12**2) * c / r - 3 * l3 * l12 * s / r]])),
    ("vy", "omega"): (("vx", "w1.spin", "w2.spin", "w3.spin"), -1 / ((5 + sp.cos(2 * b3)) * r) * sp.Matrix([
        [r * sp.sin(2 * b3), 2 * r * l3 * c**2],
        [5 + sp.cos(2 * b3), l12 * (5 + sp.cos(2 * b3))],
        [5 + sp.cos(2 * b3), -l12 * (5 + sp.cos(2 * b3))],
        [6 * c, -4 * l3 * s]])),
}


@pytest.mark.parametrize("assigned", list(C6), ids=str)
def test_extended_solutions_482(assigned):
    model = tri(assigned)
    solved, expected = C6[assigned]
    assert not model.exact and model.solved == solved
    assert all(is_zero(e) for e in model.matrix - expected)


def test_extended_numeric_oracle_c6():
    """Digest C.6 table: assigned values (1, 1) at beta3 = 0.4: the solution and the residual norm (slip)."""
    oracle = {("w1.spin", "w3.spin"): ((0.002223, -0.102777, 0.026894, 1.162236), 0.016043),
              ("w2.spin", "w3.spin"): ((0.000768, -0.08842, 0.030532, 0.731542), 0.005542),
              ("w1.spin", "w2.spin"): ((0.004548, -0.098077, 0.02183, 1.023075), 0.019611),
              ("vy", "omega"): ((-0.483333, -15.0, -5.0, -6.419776), 1.252477)}
    for assigned, (solution, slip) in oracle.items():
        model = tri(assigned)
        sub = {**NUMBERS, b3: 0.4}
        np.testing.assert_allclose(np.array(model.matrix.subs(sub) @ sp.Matrix([1, 1]), dtype=float).ravel(),
                                   solution, atol=2e-6)
        residual = np.array(model.residual.subs(sub) @ sp.Matrix([1, 1]), dtype=float)
        assert np.linalg.norm(residual) == pytest.approx(slip, abs=2e-6)


BETA_483 = {("w1.spin", "w2.spin"): sp.atan2(l3 * (p2 - p1), l12 * (p1 + p2)),  # corrected
            ("vy", "omega"): sp.atan2(-l3 * om, vy)}


@pytest.mark.parametrize("assigned", list(BETA_483), ids=str)
def test_conditions_483_zero_the_residual(assigned):
    """At the (corrected) steering angle of (4.83) the least-squares residual vanishes identically: no slip."""
    model = tri(assigned)
    q_a = sp.Matrix([sp.Symbol(n, real=True) for n in assigned])
    residual = (model.residual * q_a).xreplace({b3: BETA_483[assigned]})
    assert residual.applyfunc(sp.simplify) == sp.zeros(residual.rows, 1)


def test_condition_483_as_printed_leaves_slip():
    """001's (phi1, phi2) argument (l3 phi2 - phi1)/(l12 phi2 + phi1) is not a root (errata)."""
    model = tri(("w1.spin", "w2.spin"))
    printed = sp.atan((l3 * p2 - p1) / (l12 * p2 + p1))
    residual = (model.residual * sp.Matrix([p1, p2])).xreplace({b3: printed}).subs({**NUMBERS, p1: 2, p2: 3})
    assert np.linalg.norm(np.array(residual.evalf(), dtype=float)) > 1e-4


def test_acos_branches_483_are_roots_only_for_negative_phi3():
    """(phi1, phi3): the printed acos branches zero the residual for phi3 < 0 only; the general roots always."""
    model = tri(("w1.spin", "w3.spin"))

    def slip(beta, v1, v3):
        res = (model.residual * sp.Matrix([v1, v3])).subs({**NUMBERS, b3: beta})
        return float(sp.Matrix(res).norm().evalf())

    a, b = 1.2, 0.5
    for v1, v3 in ((0.7, -1.0), (0.7, 1.0)):
        s1 = math.sqrt((a**2 + b**2) * v3**2 - a**2 * v1**2)
        printed = (-math.acos((a**2 * v1 + b * s1) / ((a**2 + b**2) * v3)),
                   math.acos((a**2 * v1 - b * s1) / ((a**2 + b**2) * v3)))
        general = [-math.atan2(b, a) + k * math.acos(a * v1 / (math.hypot(a, b) * v3)) for k in (1, -1)]
        assert all(slip(g, v1, v3) < 1e-12 for g in general)
        assert all(slip(p, v1, v3) < 1e-12 for p in printed) == (v3 < 0)


def test_simplified_484():
    """(4.82) with beta3 of (4.83) substituted: the closed forms of (4.84), and the numbers of digest C.8."""
    direct = tri(("w1.spin", "w2.spin")).substitute({b3: BETA_483[("w1.spin", "w2.spin")]})
    root = sp.sqrt(l12**2 * (p1 + p2) ** 2 + l3**2 * (p1 - p2) ** 2)
    expected = sp.Matrix([0, -r * (p1 + p2) * l12, -r * (p1 - p2), root]) / (2 * l12)
    assert (direct - expected).applyfunc(sp.simplify) == sp.zeros(4, 1)
    inverse = tri(("vy", "omega")).substitute({b3: BETA_483[("vy", "omega")]})
    expected = -sp.Matrix([0, vy + l12 * om, vy - l12 * om, sp.sqrt(vy**2 + l3**2 * om**2)]) / r
    assert (inverse - expected).applyfunc(sp.simplify) == sp.zeros(4, 1)
    np.testing.assert_allclose(np.array(direct.subs({**NUMBERS, p1: 2, p2: 3}), dtype=float).ravel(),
                               (0, -0.25, 0.1, 2.773085), atol=2e-6)
    np.testing.assert_allclose(np.array(inverse.subs({**NUMBERS, vy: 0.3, om: 0.2}), dtype=float).ravel(),
                               (0, -4, -2, -3.841875), atol=2e-6)


# ---- printing and errors ---------------------------------------------------------------------------------
DIFF = Robot.from_dict({"name": "diff", "wheels": [
    {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
    {"name": "right", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
    {"name": "caster", "type": "castor", "position": [-0.3, 0], "d": 0.04, "r": 0.03}]})


def test_format_symbolic_differential_drive():
    """vx = r/2 (phi_l + phi_r), omega = r/(2 b) (phi_r - phi_l), phi = (vx -+ b omega)/r, with r = 1/20, b = 1/5."""
    text = format_symbolic(DIFF)
    assert "direct model (sensed), assigned: left.spin, right.spin" in text
    assert "vx = 1/40*left.spin + 1/40*right.spin" in text
    assert "omega = -1/8*left.spin + 1/8*right.spin" in text
    assert "inverse model, assigned: vx, omega" in text
    assert "left.spin = 20*vx - 4*omega" in text and "right.spin = 20*vx + 4*omega" in text
    latex = format_symbolic(DIFF, ["left.spin", "right.spin"], latex=True)
    assert r"\begin{aligned}" in latex
    assert r"v_x &= \frac{1}{40} \dot{\varphi}_{\mathrm{left}} + \frac{1}{40} \dot{\varphi}_{\mathrm{right}}" in latex
    assert r"\omega &=" in latex and r"\dot{\varphi}_{\mathrm{left}}" in latex


def test_format_symbolic_says_when_a_set_does_not_determine_the_rest():
    text = format_symbolic(TRICYCLE, ["vx"])
    assert "model, assigned: vx" in text and "not determined" in text and "rank A_na = 4 < 5" in text


def test_format_symbolic_says_how_beta_relates_to_the_heading():
    """The closed forms are in the thesis's beta, while every other line of the CLI speaks headings (a forklift going
    straight is heading 0, beta pi/2): the header printed 'steering [rad]: beta_steer' alone, so a user put the
    heading in. It now gives each wheel's beta = heading + pi/2 - delta, checked against Robot.beta_of_heading."""
    robot = Robot.from_dict({"name": "castor", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
        {"name": "right", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
        {"name": "c", "type": "castor", "position": [-0.3, 0], "d": 0.04, "delta": "10 deg", "r": 0.03},
        {"name": "s", "type": "steerable", "position": [0.3, 0], "r": 0.03}]})
    header = format_symbolic(robot).splitlines()[2]
    assert "beta_c = heading_c + 4*pi/9, beta_s = heading_s + pi/2" in header
    np.testing.assert_allclose(robot.beta_of_heading([0.0, 0.0]), [4 * math.pi / 9, math.pi / 2])
    assert "heading 0 = rolling straight ahead" in header
    assert "steering [rad]: none;" in format_symbolic(replace(robot, wheels=robot.wheels[:2]))


def test_default_assignments():
    assert sensed_rates(DIFF) == ("left.spin", "right.spin")
    assert twist_assignment(DIFF) == ("vx", "omega")
    assert twist_assignment(TRICYCLE) == ("vy",)  # m = 1; vx is never assignable (C.4)


def test_errors_name_the_culprit():
    with pytest.raises(UnknownNameError, match="no velocity 'vz'"):
        tri(["vz"])
    with pytest.raises(AssignmentError, match="'vy' listed twice"):
        tri(["vy", "vy"])
    with pytest.raises(AssignmentError, match="expected a sequence of names, got the string 'vy'"):  # was 'v'
        tri("vy")
    with pytest.raises(UnknownNameError, match="wheel 'w1' \\(fixed\\) has no geometric field 'd'"):
        symbolic_model(TRICYCLE, ["vy"], geometry={"w1.d": l12})
    with pytest.raises(AssignmentError, match="strings are never parsed"):
        symbolic_model(TRICYCLE, ["vy"], geometry={"w1.l": "l12"})
    with pytest.raises(AssignmentError, match="beta: expected 1 steering angles"):
        symbolic_model(TRICYCLE, ["vy"], [0.1, 0.2])


@pytest.mark.parametrize("angle", [1e20, 1e300, -7e6, 10**400, math.nan, math.inf, sp.nan, sp.oo, sp.zoo,
                                   sp.Float(1e20)])
def test_steering_numbers_beyond_a_million_turns_or_not_finite_are_refused(angle):
    """beta = 1e20 or 1e300 (no angle: its sine is round-off) was made exact and gave SingularError 'assigning (vy)
    does not determine (...)', a false claim about the robot; sympy's nan and zoo raised numpy's 'SVD did not
    converge', oo a TypeError, 10**400 an OverflowError. Now the Python API's rule for angles (as_angles: finite, at
    most 1e6 turns), one AssignmentError naming beta and the wheel."""
    with pytest.raises(AssignmentError, match=r"beta\[0\] \(w3\): .*at most 1e\+06 turns"):
        symbolic_model(TRICYCLE, ["vy"], [angle])
    with pytest.raises(AssignmentError, match=r"beta\[0\] \(w3\)"):
        symbolic_constraint_matrix(TRICYCLE, [angle])
    m = symbolic_model(TRICYCLE, ["vy"], [sp.pi / 3 + 2 * sp.pi * 10**5])  # within: as sin(pi/3), cos(pi/3)
    assert m.matrix == symbolic_model(TRICYCLE, ["vy"], [sp.pi / 3]).matrix


def test_a_double_castor_is_exact_in_closed_form():
    """(3.31) with ``cos(skew) = d / arm``, ``sin(skew) = b / arm``: the entries are plain fractions of the
    description's numbers. Its hypot/atan2 were floats made exact, so `kinematics --symbolic` printed
    4472135954999579/8944271909999159 for 1/2 and 30-digit ratios for 1/3."""
    robot = Robot.from_dict({"name": "dc", "wheels": [
        {"name": "drive", "type": "double", "position": [0.3, 0], "b": 0.06, "r": 0.08},
        {"name": "trailer", "type": "double_castor", "position": [-0.3, 0], "beta": "90 deg", "d": 0.1, "b": 0.05,
         "r": 0.04}]})
    a = symbolic_constraint_matrix(robot)
    numbers = [q for q in a.atoms(sp.Rational)]
    assert max(max(abs(q.p), abs(q.q)) for q in numbers) < 1000, sorted(numbers, key=lambda q: -abs(q.q))[:3]
    for beta in np.random.default_rng(2).uniform(-math.pi, math.pi, (3, 2)):
        values = a.xreplace({sym: sp.Float(v) for sym, v in zip(steering_symbols(robot), beta, strict=True)})
        np.testing.assert_allclose(np.array(values.evalf(), dtype=float), robot.constraint_matrix(beta),
                                   rtol=0, atol=1e-12)
    model = symbolic_model(robot, ("drive.steer", "drive.spin1", "drive.spin2"))
    assert model.exact and "0000000" not in str(model.matrix)


def test_steering_given_as_headings_as_every_function_takes_it():
    """symbolic_constraint_matrix and symbolic_model took the thesis's beta only, while every other function taking a
    steering configuration takes ``heading=`` too (docs/conventions.md): a user's heading 0 (the forklift driving
    straight) went in as beta = 0, where the forklift's inverse model for vx raises SingularError. ``heading=``
    now gives ``beta = heading + pi/2 - delta`` exactly, checked against Robot.constraint_matrix(heading=) for a
    castor with delta = 10 deg, with the robot's numbers and with its delta as a symbol."""
    robot = Robot.from_dict({"name": "castor", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
        {"name": "right", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.05, "sensed": ["spin"]},
        {"name": "c", "type": "castor", "position": [-0.3, 0], "d": 0.04, "delta": "10 deg", "r": 0.03},
        {"name": "s", "type": "steerable", "position": [0.3, 0], "r": 0.03}]})
    heading = np.array([0.7, -2.9])
    expected = robot.constraint_matrix(heading=heading)
    numeric_geometry = symbolic_constraint_matrix(robot, heading=heading)  # a numpy array, as numeric code gives
    np.testing.assert_allclose(np.array(numeric_geometry.evalf(), dtype=float), expected, rtol=0, atol=1e-12)
    symbols = geometry_symbols(robot)
    values = {symbols[k]: getattr(robot.wheel(k.split(".")[0]), k.split(".")[1]) for k in symbols}
    general = symbolic_constraint_matrix(robot, heading=list(heading), geometry="symbolic")
    assert symbols["c.delta"] in general.free_symbols
    np.testing.assert_allclose(np.array(general.xreplace(values).evalf(), dtype=float), expected, rtol=0, atol=1e-12)
    h = sp.Symbol("h", real=True)
    fork = Robot.from_dict({"name": "rear steer", "wheels": [
        {"name": "right", "type": "fixed", "position": [0, -0.45], "beta": "90 deg", "r": 0.2},
        {"name": "left", "type": "fixed", "position": [0, 0.45], "beta": "90 deg", "r": 0.2},
        {"name": "steer", "type": "steerable", "position": [-1.5, 0], "r": 0.1}]})
    with pytest.raises(SingularError):
        symbolic_model(fork, ["vx"], [0.0])  # beta = 0: the steered axle along x, no forward motion
    straight = symbolic_model(fork, ["vx"], heading=[0.0])
    assert straight.exact and list(straight.matrix) == [0, 0, 5, 5, 10]  # vy, omega, then the spins vx / r
    turning = symbolic_model(fork, ["vx"], heading=[h])  # rear steering left turns the robot right: -tan(h) / 1.5
    assert sp.simplify(turning.matrix[1] + sp.tan(h) / sp.Rational(3, 2)) == 0
    numpy_int = symbolic_model(fork, ["vx"], heading=[np.int64(1)])  # refused as 'int64' before
    assert numpy_int.matrix == symbolic_model(fork, ["vx"], heading=[1.0]).matrix
    with pytest.raises(AssignmentError, match=r"as beta .* or heading .*, not both"):
        symbolic_model(fork, ["vx"], [1.0], heading=[0.0])
    with pytest.raises(AssignmentError, match=r"heading: expected 1 steering angles .*got float 0\.0"):
        symbolic_model(fork, ["vx"], heading=0.0)
    with pytest.raises(AssignmentError, match="beta: expected sympy expressions or numbers, got bool"):
        symbolic_model(fork, ["vx"], [True])
    with pytest.raises(AssignmentError, match=r"heading\[0\] \(steer\): .*at most 1e\+06 turns"):
        symbolic_constraint_matrix(fork, heading=[math.nan])


def test_latex_escapes_names_that_latex_would_read_as_markup():
    """A wheel built in Python may have any name (descriptions allow identifiers only). In the LaTeX block 'l%'
    commented out the rest of its row (terms dropped without a word), 'r&#' added an alignment column and a '#'
    LaTeX refuses, and a name with a line break ended its '%' comment line. Now every special character is
    escaped: each row has exactly its one alignment '&', no bare '%', balanced braces, and only comments,
    'aligned' and rows as lines."""
    robot = Robot("a\nb", (Wheel("l%", "fixed", 0.2, math.pi / 2, 0.0, 0.05, sensed=("spin",)),
                           Wheel("r&#", "fixed", 0.2, -math.pi / 2, 0.0, 0.05, sensed=("spin",)),
                           Wheel("c~^{x}\\$_\n", "castor", 0.3, math.pi, 0.0, 0.03, d=0.04)))
    text = format_symbolic(robot, latex=True)
    bare = re.compile(r"(?<!\\)[%&#$^~]")  # a special character without its backslash (\hat{}, \sim{} are escapes)
    rows = [line for line in text.splitlines() if line.startswith("  ")]
    assert len(rows) == 5 + 6, text  # direct (two spins sensed): 5 solved; inverse (vy assigned): 6
    for row in rows:
        left, _, right = row.partition(" &= ")
        assert not bare.search(left + right), row
        depth = 0
        for ch in re.sub(r"\\[{}]", "", row):
            depth += {"{": 1, "}": -1}.get(ch, 0)
            assert depth >= 0, row
        assert depth == 0, row
    assert r"\dot{\varphi}_{\mathrm{l\%}}" in text and r"\dot{\varphi}_{\mathrm{r\&\#}}" in text
    assert r"\dot{\beta}_{\mathrm{c\sim{}\hat{}\{x\}\backslash{}\$\_\backslash{}n}}" in text
    for line in text.splitlines():
        assert line.startswith(("% ", "  ", r"\begin{aligned}", r"\end{aligned}")) or not line, line


@pytest.mark.parametrize(("field", "value", "message"), [
    ("f1.l", math.nan, "expected a finite number"), ("f1.r", sp.nan, "expected a finite number"),
    ("f1.r", sp.zoo, "expected a finite number"), ("o3.r", math.inf, "expected a finite number"),
    ("f1.r", 0.0, "r: must be > 0"), ("f1.r", -0.1, "r: must be > 0"), ("f1.l", -0.5, "l: must be >= 0"),
    ("f1.alpha", 1e300, "at most 1e\\+06 turns"), ("f1.r", True, "got bool"),
])
def test_geometry_numbers_follow_the_wheels_rules(field, value, message):
    """Numbers given for geometric fields were taken as they came: NaN raised 'cannot make nan exact' (no field
    named), sympy's nan numpy's LinAlgError 'SVD did not converge', r = 0 or l = 1e300 a SingularError, a false claim
    about the robot, alpha = 1e300 (no angle) was accepted. Now the rules of Wheel, naming the entry."""
    with pytest.raises(AssignmentError, match=rf"geometry\['{field}'\]: .*{message}"):
        symbolic_model(TRICYCLE_CATALOG, ["vy"], geometry={field: value})


def test_geometry_numbers_that_pass_keep_their_exact_value():
    """Checked numbers stay as given: a sympy surd is not replaced by its float (numpy floats are made exact)."""
    root = symbolic_constraint_matrix(TRICYCLE_CATALOG, geometry={"f1.r": sp.sqrt(2) / 20, "f2.r": np.float64(0.2)})
    assert any(entry.has(sp.sqrt(2)) for entry in root)
    assert sp.Rational(1, 5) in root.atoms(sp.Rational)


def test_format_symbolic_refuses_a_lone_string_as_symbolic_model_does():
    """format_symbolic(robot, "vx") read the string letter by letter: "no velocity 'v'"; a number raised TypeError."""
    with pytest.raises(AssignmentError, match=r"expected a sequence of .*names, got the string 'vy'"):
        format_symbolic(TRICYCLE, "vy")
    with pytest.raises(AssignmentError, match="assigned"):
        format_symbolic(TRICYCLE, 5)
    assert "model, assigned: vy" in format_symbolic(TRICYCLE, ("vy",))


MICRO = Robot.from_dict({"name": "micro", "wheels": [  # 1 um across, a castor of 1 nm: within docs/limits.md
    {"name": "left", "type": "fixed", "position": [0, 0.4e-6], "heading": 0, "r": 1e-7, "sensed": ["spin"]},
    {"name": "right", "type": "fixed", "position": [0, -0.4e-6], "heading": 0, "r": 1e-7, "sensed": ["spin"]},
    {"name": "caster", "type": "castor", "position": [-1e-6, 0], "d": 1e-7, "r": 1e-9}]})


@pytest.mark.parametrize("assigned", [("left.spin", "right.spin"), ("vx", "omega"), ("vx", "vy", "omega")])
def test_a_micro_robot_has_its_closed_forms(assigned):
    """Ranks were taken on the raw matrix, whose castor-spin column (r = 1 nm) fell below the rank tolerance: every
    model of this 1 um robot raised SingularError 'rank A_na = 4 < 5' (its mobility is 2, as the numeric models
    say), and write_code refused it. Columns are now equilibrated for the rank decisions; the closed form equals
    numeric least squares (4.11)."""
    model = symbolic_model(MICRO, assigned)
    assert model.mobility == 2 and model.exact == (len(assigned) == 2)
    a_idx = [MICRO.velocity_index(n) for n in assigned]
    scale = velocity_scale(MICRO)  # compared as nondimensional velocities (vx / L, rad/s), of order 1
    for beta in np.random.default_rng(3).uniform(-math.pi, math.pi, (3, 1)):
        q_a = np.random.default_rng(4).normal(size=len(assigned)) / scale[a_idx]
        expected = np.delete(solve_assigned(MICRO.constraint_matrix(beta), a_idx, q_a)[0] * scale, a_idx)
        m = np.array(model.matrix.xreplace({model.steering[0]: sp.Float(beta[0])}).evalf(), dtype=float)
        got = (m @ q_a) * np.delete(scale, a_idx)
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
