"""The chapter-3 wheel model against an independent 3-D oracle, the thesis's closed forms and its special wheels.

The oracle (:func:`contact_slips`) builds every contact point from the wheel's geometry and evaluates the slip
velocity (3.4) with numpy cross products: it shares no code with ``wmrkit.wheels`` (digest PART D, oracles 1-4).
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy import cos, sin
from scipy.linalg import null_space

from strategies import wheels
from wmrkit import KINDS, Robot, ShapeError, Wheel, generic_slip_rows, wheel_jacobian, wheel_slip_rows
from wmrkit.errors import UnknownNameError
from wmrkit.wheels import wrap_angle

Z = np.array([0.0, 0.0, 1.0])


def _u(angle: float) -> np.ndarray:
    return np.array([cos(angle), sin(angle), 0.0])


def contacts(w: Wheel, beta: float) -> list[dict]:
    """The contact points of `w` at steering angle `beta`, from its geometry alone (figs. 3.4, 3.5).

    Each: steering joint ``S``, offset ``S -> E``, axle angle, roller angle (None without rollers), radii, and the
    names of the joints giving ``(beta_dot, phi_dot, phi_dot_r)`` (None: that rate is absent or zero).
    """
    S = np.array([w.l * cos(w.alpha), w.l * sin(w.alpha), 0.0])
    sx, sy = _u(beta), _u(beta + math.pi / 2)  # steering frame axes S_x, S_y in the robot frame
    zero = np.zeros(3)
    one = {"S": S, "r": w.r, "rr": 0.0, "roller": None, "axle": beta, "steer": None, "spin": "spin", "rate_r": None}
    if w.type in ("fixed", "steerable"):
        return [{**one, "off": zero}]
    if w.type == "castor":  # contact at d along S_y, axle at beta + delta (3.8)
        return [{**one, "off": w.d * sy, "axle": beta + w.delta, "steer": "steer"}]
    if w.type in ("swedish", "ball", "orthogonal"):  # ball, orthogonal: rollers across the axle, radius r
        gamma, rr = (w.gamma, w.r_r) if w.type == "swedish" else (math.pi / 2, w.r)
        return [{**one, "off": zero, "roller": beta + gamma, "rr": rr, "rate_r": "roller"}]
    if w.type == "double":  # two coaxial wheels at +-b along the axle (cos beta, sin beta); spin1 at +b
        return [{**one, "off": s * w.b * sx, "steer": "steer", "spin": k} for s, k in ((1, "spin1"), (-1, "spin2"))]
    if w.type == "double_castor":  # contacts at (+-b, d) in the steering frame, axle along S_x; spin1 at +b
        return [{**one, "off": s * w.b * sx + w.d * sy, "steer": "steer", "spin": k}
                for s, k in ((1, "spin1"), (-1, "spin2"))]
    raise AssertionError(w.type)


def contact_slips(w: Wheel, beta: float, twist: np.ndarray, rates: dict[str, float]) -> list[tuple[np.ndarray, float]]:
    """Slip velocity ``(vx, vy)`` of every contact of `w` in the robot frame, eq. (3.4), and its roller angle."""
    v, omega = np.array([twist[0], twist[1], 0.0]), twist[2]
    out = []
    for c in contacts(w, beta):
        rate = {k: (rates[c[k]] if c[k] else 0.0) for k in ("steer", "spin", "rate_r")}
        vE = (v + np.cross(omega * Z, c["S"] + c["off"]) + np.cross(rate["steer"] * Z, c["off"])
              + np.cross(rate["spin"] * _u(c["axle"]), [0, 0, -c["r"]]))
        if c["roller"] is not None:
            vE = vE + np.cross(rate["rate_r"] * _u(c["roller"]), [0, 0, -c["rr"]])
        assert vE[2] == 0
        out.append((vE[:2], c["axle"] if c["roller"] is None else c["roller"]))
    return out


def _rot(x: float) -> np.ndarray:
    return np.array([[cos(x), -sin(x)], [sin(x), cos(x)]])  # (3.7)


def _oracle(robot: Robot, beta: np.ndarray, q_dot: np.ndarray, frame: str) -> np.ndarray:
    rates = dict(zip(robot.velocity_names, q_dot, strict=True))
    steer = dict(zip(robot.steer_names, beta, strict=True))
    rows = []
    for w in robot.wheels:
        own = {name.split(".", 1)[1]: value for name, value in rates.items() if name.startswith(w.name + ".")}
        for v_robot, theta in contact_slips(w, steer.get(w.name, w.beta), q_dot[:3], own):
            rows.append(v_robot if frame == "robot" else _rot(-theta) @ v_robot)  # (3.6): Rot(-theta_E)
    return np.concatenate(rows)


# ---- oracle 1: the generic slip rows are the 3-D slip velocity ---------------------------------------------------
@pytest.mark.parametrize("type_name", list(KINDS))
@settings(max_examples=250)
@given(data=st.data())
def test_constraint_matrix_is_the_3d_slip_velocity(type_name, data):
    w = data.draw(wheels(type_name, name="u"))
    other = data.draw(wheels(name="v"))
    robot = Robot("oracle", (w, other))
    beta = np.array(data.draw(st.lists(st.floats(-4, 4), min_size=len(robot.steer_names),
                                       max_size=len(robot.steer_names))))
    q_dot = np.array(data.draw(st.lists(st.floats(-3, 3), min_size=len(robot.velocity_names),
                                        max_size=len(robot.velocity_names))))
    for frame in ("robot", "roller"):
        expected = _oracle(robot, beta, q_dot, frame)
        np.testing.assert_allclose(robot.constraint_matrix(beta, frame=frame) @ q_dot, expected, atol=1e-12)
    # the described configuration is the default, and slip_velocity is the roller-frame product
    np.testing.assert_allclose(robot.slip_velocity(q_dot), _oracle(robot, robot.beta, q_dot, "roller"), atol=1e-12)
    own = q_dot[[0, 1, 2, *range(3, 3 + len(w.kind.rates))]]
    np.testing.assert_allclose(wheel_slip_rows(w) @ own, _oracle(Robot("one", (w,)), np.array([w.beta] * w.kind.steers),
                                                                 own, "roller"), atol=1e-12)


@settings(max_examples=400)
@given(data=st.data())
def test_generic_rows_match_3d_oracle_with_all_parameters(data):
    """The fully general wheel (3.6)/(3.10): d, delta, gamma and r_r all non-zero at once (castor with rollers)."""
    l, alpha, beta, delta, gamma = (data.draw(st.floats(-3, 3)) for _ in range(5))
    d, r, r_r = (data.draw(st.floats(0.01, 1)) for _ in range(3))
    p, q = np.array(data.draw(st.lists(st.floats(-2, 2), min_size=6, max_size=6))).reshape(2, 3)
    S = np.array([l * cos(alpha), l * sin(alpha), 0])
    off = d * _u(beta + math.pi / 2)
    vE = (np.array([p[0], p[1], 0]) + np.cross(p[2] * Z, S + off) + np.cross(q[0] * Z, off)
          + np.cross(q[1] * _u(beta + delta), [0, 0, -r]) + np.cross(q[2] * _u(beta + delta + gamma), [0, 0, -r_r]))
    rows = generic_slip_rows(beta, l, alpha, d, delta, gamma, r, r_r)
    np.testing.assert_allclose(rows @ np.r_[p, q], _rot(-(beta + delta + gamma)) @ vE[:2], atol=1e-12)


# ---- oracle 2: particularisations (3.11)-(3.13), written out from the digest ---------------------------------------
@settings(max_examples=400)
@given(l=st.floats(0, 2), alpha=st.floats(-4, 4), beta=st.floats(-4, 4), d=st.floats(-1, 1), delta=st.floats(-4, 4),
       gamma=st.floats(-4, 4), r=st.floats(0.01, 1), rim=st.floats(0.01, 1))
def test_particularisations(l, alpha, beta, d, delta, gamma, r, rim):
    r_r = rim * r  # the rollers sit on the rim: r_r <= r (Wheel refuses more)
    a = beta - alpha
    eq_3_11 = [[cos(beta), sin(beta), l * sin(a), 0], [-sin(beta), cos(beta), l * cos(a), r]]
    bd = beta + delta
    eq_3_12 = [[cos(bd), sin(bd), l * sin(bd - alpha) - d * cos(delta), -d * cos(delta), 0],
               [-sin(bd), cos(bd), l * cos(bd - alpha) + d * sin(delta), d * sin(delta), r]]
    bg = beta + gamma
    eq_3_13 = [[cos(bg), sin(bg), l * sin(bg - alpha), r * sin(gamma), 0],
               [-sin(bg), cos(bg), l * cos(bg - alpha), r * cos(gamma), r_r]]
    g = generic_slip_rows  # columns (vx, vy, omega, beta_dot, phi_dot, phi_dot_r)
    np.testing.assert_allclose(g(beta, l, alpha, 0, 0, 0, r, 0)[:, [0, 1, 2, 4]], eq_3_11, atol=1e-12)
    np.testing.assert_allclose(g(beta, l, alpha, d, delta, 0, r, 0)[:, [0, 1, 2, 3, 4]], eq_3_12, atol=1e-12)
    np.testing.assert_allclose(g(beta, l, alpha, 0, 0, gamma, r, r_r)[:, [0, 1, 2, 4, 5]], eq_3_13, atol=1e-12)
    # the dropped columns are zero: a steerable wheel's beta_dot (3.11), the castor's roller (3.12)
    assert np.all(g(beta, l, alpha, 0, 0, 0, r, 0)[:, [3, 5]] == 0)
    # and the wheel types give exactly these rows over their own rates
    kw = {"name": "w", "l": l, "alpha": alpha, "beta": beta, "r": r}
    np.testing.assert_allclose(wheel_slip_rows(Wheel(type="fixed", **kw)), eq_3_11, atol=1e-12)
    np.testing.assert_allclose(wheel_slip_rows(Wheel(type="steerable", **kw)), eq_3_11, atol=1e-12)
    np.testing.assert_allclose(wheel_slip_rows(Wheel(type="castor", d=d, delta=delta, **kw)), eq_3_12, atol=1e-12)
    np.testing.assert_allclose(wheel_slip_rows(Wheel(type="swedish", gamma=gamma, r_r=r_r, **kw)), eq_3_13,
                               atol=1e-12)


# ---- oracle 3: Jacobians (3.19), determinants, no-slip pairs ------------------------------------------------------
def _jacobians_3_19(l, alpha, beta, d, delta, gamma, r, r_r):
    sa, ca, sb, cb = sin(alpha), cos(alpha), sin(beta), cos(beta)
    j_fo = [[r * sb, l * sa], [-r * cb, -l * ca], [0, 1]]
    j_s = [[r * sb, r_r * sin(beta + gamma), l * sa], [-r * cb, -r_r * cos(beta + gamma), -l * ca], [0, 0, 1]]
    j_c = [[d * cb, r * sin(beta + delta), l * sa + d * cb], [d * sb, -r * cos(beta + delta), -l * ca + d * sb],
           [0, 0, 1]]
    return np.array(j_fo), np.array(j_s), np.array(j_c)


@settings(max_examples=400)
@given(l=st.floats(0, 2), alpha=st.floats(-4, 4), beta=st.floats(-4, 4), d=st.floats(-1, 1), delta=st.floats(-4, 4),
       gamma=st.floats(-4, 4), r=st.floats(0.01, 1), rim=st.floats(0.01, 1))
def test_jacobians_3_19_and_determinants(l, alpha, beta, d, delta, gamma, r, rim):
    r_r = rim * r  # the rollers sit on the rim: r_r <= r (Wheel refuses more)
    j_fo, j_s, j_c = _jacobians_3_19(l, alpha, beta, d, delta, gamma, r, r_r)
    kw = {"name": "w", "l": l, "alpha": alpha, "beta": beta, "r": r}
    np.testing.assert_allclose(wheel_jacobian(Wheel(type="fixed", **kw)), j_fo, atol=1e-12)
    np.testing.assert_allclose(wheel_jacobian(Wheel(type="steerable", **kw)), j_fo, atol=1e-12)
    np.testing.assert_allclose(wheel_jacobian(Wheel(type="swedish", gamma=gamma, r_r=r_r, **kw)), j_s, atol=1e-12)
    np.testing.assert_allclose(wheel_jacobian(Wheel(type="castor", d=d, delta=delta, **kw)), j_c, atol=1e-12)
    assert np.linalg.det(j_c) == pytest.approx(-r * d * cos(delta), abs=1e-12)
    assert np.linalg.det(j_s) == pytest.approx(r * r_r * sin(gamma), abs=1e-12)


def test_determinant_oracles():
    """Digest PART D oracle 3: numeric determinants."""
    kw = {"name": "w", "l": 0.3, "alpha": 0.5, "beta": 0.2, "r": 0.08}
    assert np.linalg.det(wheel_jacobian(Wheel(type="castor", d=0.05, delta=0.1, **kw))) == pytest.approx(
        -0.003980017, abs=5e-10)
    assert np.linalg.det(wheel_jacobian(Wheel(type="swedish", gamma=math.pi / 4, r_r=0.02, **kw))) == pytest.approx(
        0.001131371, abs=5e-10)


@pytest.mark.parametrize("type_name", ["fixed", "steerable", "castor", "swedish", "ball", "orthogonal"])
@settings(max_examples=300)
@given(data=st.data())
def test_jacobian_pairs_do_not_slip(type_name, data):
    """Every (twist, wheel rates) with twist = J q_w (3.18) makes both slip rows (3.6) zero."""
    w = data.draw(wheels(type_name))
    q_w = np.array(data.draw(st.lists(st.floats(-3, 3), min_size=len(w.kind.rates) + 1,
                                      max_size=len(w.kind.rates) + 1)))
    twist = wheel_jacobian(w) @ q_w
    assert twist[2] == pytest.approx(q_w[-1], abs=1e-15)  # the third row of (3.17) copies omega
    np.testing.assert_allclose(wheel_slip_rows(w) @ np.r_[twist, q_w[:-1]], 0, atol=1e-12)


def test_double_wheels_have_no_single_jacobian():
    w = Wheel("dw", "double", l=0.1, alpha=0, beta=0, r=0.1, b=0.05)
    with pytest.raises(UnknownNameError, match=r"wheel 'dw' \(double\) has 2 contact points"):
        wheel_jacobian(w)


def test_sign_convention():
    """A positive spin (right-hand rule about the axle) with beta = 90 deg drives the robot towards +x."""
    w = Wheel("w", "fixed", l=0.0, alpha=0.0, beta=math.pi / 2, r=0.2)
    np.testing.assert_allclose(wheel_jacobian(w) @ [1.0, 0.0], [0.2, 0, 0], atol=1e-15)
    np.testing.assert_allclose(wheel_slip_rows(w) @ [0.2, 0, 0, 1.0], 0, atol=1e-15)
    assert np.abs(wheel_slip_rows(w) @ [-0.2, 0, 0, 1.0]).max() > 0.3  # the opposite sign slips
    # beta = 0 at the origin: vy = -r phi_dot (digest A.6)
    w0 = Wheel("w", "fixed", l=0.0, alpha=0.0, beta=0.0, r=0.2)
    np.testing.assert_allclose(wheel_jacobian(w0) @ [1.0, 0.0], [0, -0.2, 0], atol=1e-15)


# ---- oracle 4: special wheels (3.28)-(3.29), (3.35)-(3.36) --------------------------------------------------------
def _no_slip_motions(robot: Robot, rng: np.random.Generator, n: int = 8) -> np.ndarray:
    basis = null_space(robot.constraint_matrix())
    assert basis.shape[1] >= 2  # a single unit always leaves the robot some motion
    return (basis @ rng.normal(size=(basis.shape[1], n))).T  # (n, k)


@pytest.mark.parametrize("unit", ["double", "double_castor"])
@settings(max_examples=300)
@given(data=st.data())
def test_double_units_equal_their_single_wheel(unit, data):
    """Semisum (3.28)/(3.35) and semidifference (3.29)/(3.36) from random no-slip motions of the unit."""
    w = data.draw(wheels(unit, name="u"))
    single = (Wheel("s", "steerable", l=w.l, alpha=w.alpha, beta=w.beta, r=w.r) if unit == "double"
              else Wheel("s", "castor", l=w.l, alpha=w.alpha, beta=w.beta, r=w.r, d=w.d, delta=0.0))
    robot = Robot("unit", (w,))
    for q in _no_slip_motions(robot, np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))):
        (vx, vy, omega, steer, spin1, spin2) = q
        phi = (spin1 * w.r + spin2 * w.r) / 2 / w.r  # (3.28)/(3.35)
        assert steer == pytest.approx((spin2 * w.r - spin1 * w.r) / (2 * w.b) - omega, abs=1e-9)  # (3.29)/(3.36)
        own = [vx, vy, omega, phi] if unit == "double" else [vx, vy, omega, steer, phi]
        np.testing.assert_allclose(wheel_slip_rows(single) @ own, 0, atol=1e-9)


@pytest.mark.parametrize("unit", ["double", "double_castor"])
def test_spin1_is_the_sub_wheel_at_plus_b_along_the_axle(unit):
    """Our naming: spin1 rolls the sub-wheel at +b along the axle (cos beta, sin beta), as the thesis's wheel 1."""
    w = Wheel("u", unit, l=0.0, alpha=0.0, beta=0.0, r=0.1, b=0.3, d=0.2 if unit == "double_castor" else 0.0)
    # the robot turns about the steering axis with the unit held (steer rate 0): the +b contact moves along +y
    # at b * omega, so its wheel must spin at -b omega / r, the other at +b omega / r (A.6 sign convention).
    twist = [0.2 * 1.0 if unit == "double_castor" else 0.0, 0.0, 1.0]  # castor arm: the axle centre at (0, d)
    q = np.r_[twist, 0.0, -0.3 / 0.1, 0.3 / 0.1]
    np.testing.assert_allclose(Robot("u", (w,)).constraint_matrix() @ q, 0, atol=1e-12)


# ---- STYLE rule 11: every wheel type x batch shape ---------------------------------------------------------------
BATCHES = [(), (1,), (5,), (2, 3)]
_EXAMPLES = {
    "fixed": {}, "steerable": {}, "castor": {"d": -0.04, "delta": 0.2}, "swedish": {"gamma": 0.7, "r_r": 0.01},
    "double": {"b": 0.1}, "double_castor": {"d": 0.05, "b": 0.1}, "ball": {}, "orthogonal": {},
}
assert set(_EXAMPLES) == set(KINDS)


def _example(type_name: str) -> Wheel:
    return Wheel("w", type_name, l=0.25, alpha=0.3, beta=0.4, r=0.05, **_EXAMPLES[type_name])


@pytest.mark.parametrize("type_name", list(KINDS))
@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_batch_equals_loop(type_name, batch):
    w = _example(type_name)
    helper = Wheel("h", "steerable", l=0.4, alpha=-2.0, beta=0.0, r=0.1)
    robot = Robot("b", (w, helper))
    rng = np.random.default_rng(0)
    beta_w = rng.uniform(-np.pi, np.pi, size=batch)
    beta = rng.uniform(-np.pi, np.pi, size=(*batch, len(robot.steer_names)))
    rows = wheel_slip_rows(w, beta_w)
    for frame in ("roller", "robot"):
        a = robot.constraint_matrix(beta, frame=frame)
        assert a.shape == (*batch, 2 * (len(w.elements()) + 1), len(robot.velocity_names))
        for idx in np.ndindex(*batch):
            np.testing.assert_allclose(a[idx], robot.constraint_matrix(beta[idx], frame=frame), rtol=0, atol=1e-15)
    assert rows.shape == (*batch, 2 * len(w.elements()), 3 + len(w.kind.rates))
    for idx in np.ndindex(*batch):
        np.testing.assert_allclose(rows[idx], wheel_slip_rows(w, beta_w[idx]), rtol=0, atol=1e-15)
        np.testing.assert_allclose(rows[idx], wheel_slip_rows(w.with_beta(beta_w[idx])), rtol=0, atol=1e-15)
    if len(w.elements()) == 1:
        jac = wheel_jacobian(w, beta_w)
        for idx in np.ndindex(*batch):
            np.testing.assert_allclose(jac[idx], wheel_jacobian(w.with_beta(beta_w[idx])), rtol=0, atol=1e-15)


@pytest.mark.parametrize("type_name", list(KINDS))
def test_wrong_shape_names_the_argument(type_name):
    robot = Robot("b", (_example(type_name), Wheel("h", "steerable", l=0.4, alpha=-2.0, beta=0.0, r=0.1)))
    n = len(robot.steer_names)
    with pytest.raises(ShapeError, match=rf"^beta: expected shape \(\.\.\., {n}\), got \(4, {n + 1}\)$"):
        robot.constraint_matrix(np.zeros((4, n + 1)))
    with pytest.raises(ShapeError, match=rf"^q_dot: expected shape \(\.\.\., {len(robot.velocity_names)}\)"):
        robot.slip_velocity(np.zeros(2))


# ---- errata of chapter 3 (docs/errata.md, digest PART E 1-10) -----------------------------------------------------
def test_errata_3_1_body_rate_in_the_recursion_is_absolute():
    """(3.1) uses omega_{i-1} (absolute), not omega*_{i-1}: a turning body with the castor locked moves the
    contact by omega x (the whole vector R -> E), arm included."""
    l, alpha, beta, d, delta, r = 0.4, 0.9, -0.5, 0.07, 0.3, 0.05
    w = Wheel("c", "castor", l=l, alpha=alpha, beta=beta, r=r, d=d, delta=delta)
    S = np.array([l * cos(alpha), l * sin(alpha), 0.0])
    E = S + d * _u(beta + math.pi / 2)
    column = Robot("c", (w,)).constraint_matrix(frame="robot") @ [0, 0, 1.0, 0, 0]  # omega = 1, joints locked
    np.testing.assert_allclose(column, np.cross(Z, E)[:2], atol=1e-15)
    assert np.abs(column - np.cross(Z, S)[:2]).max() > 0.05  # the misprint's omega*_{i-1} = 0 would miss the arm


@pytest.mark.parametrize("type_name", list(KINDS))
def test_errata_3_4_body_velocity_is_planar(type_name):
    """(3.4): the body's linear velocity is (v_x, v_y, 0), not (v_x, v_y, omega): in the robot frame every contact's
    rows take (v_x, v_y) as the identity and omega only through omega x d_E."""
    w = _example(type_name)
    a = Robot("p", (w,)).constraint_matrix(frame="robot")
    for k in range(a.shape[0] // 2):
        np.testing.assert_allclose(a[2 * k:2 * k + 2, :2], np.eye(2), atol=1e-15)
    expected = [np.cross(Z, c["S"] + c["off"])[:2] for c in contacts(w, w.beta)]
    np.testing.assert_allclose(a[:, 2], np.concatenate(expected), atol=1e-15)


@settings(max_examples=300)
@given(l=st.floats(0, 2), alpha=st.floats(-4, 4), beta=st.floats(-4, 4), d=st.floats(-1, 1), delta=st.floats(-4, 4),
       gamma=st.floats(-4, 4), r=st.floats(0.01, 1), r_r=st.floats(0.01, 1))
def test_errata_3_6_3_10_layout_and_distance_components(l, alpha, beta, d, delta, gamma, r, r_r):
    """(3.6): Rot(-theta_E) is the (v_x, v_y) block only; the other entries are the distances (3.10) in E
    coordinates, whose d_Sx/d_Six and d_Sy/d_Siy (printed both ways) are one quantity each."""
    theta = beta + delta + gamma
    S = np.array([l * cos(alpha), l * sin(alpha)])
    E = S + d * np.array([-sin(beta), cos(beta)])
    d_R = _rot(-theta) @ (0 - E)  # ^{E}d_R: from E to the robot origin, in E coordinates
    d_S = _rot(-theta) @ (S - E)  # ^{E}d_S
    # (3.10) as printed
    np.testing.assert_allclose(d_R, [-l * cos(theta - alpha) - d * sin(delta + gamma),
                                     l * sin(theta - alpha) - d * cos(delta + gamma)], atol=1e-12)
    np.testing.assert_allclose(d_S, [-d * sin(delta + gamma), -d * cos(delta + gamma)], atol=1e-12)
    rows = generic_slip_rows(beta, l, alpha, d, delta, gamma, r, r_r)
    np.testing.assert_allclose(rows[:, :2], _rot(-theta), atol=1e-15)
    expected = [[d_R[1], d_S[1], r * sin(gamma), 0], [-d_R[0], -d_S[0], r * cos(gamma), r_r]]
    np.testing.assert_allclose(rows[:, 2:], expected, atol=1e-12)


@pytest.mark.parametrize(("type_name", "singular"), [
    ("castor", {"delta": math.pi / 2}), ("castor", {"delta": -math.pi / 2}), ("castor", {"d": 0.0}),
    ("swedish", {"gamma": 0.0}), ("swedish", {"gamma": math.pi}),
])
def test_errata_3_19_omnidirectional_wheels_can_be_singular(type_name, singular):
    """(3.19) says the wheel Jacobians are always (pseudo-)invertible: not for d = 0, delta = +-90 deg, gamma = 0."""
    regular = _example(type_name)
    assert np.linalg.matrix_rank(wheel_jacobian(regular)) == 3
    j = wheel_jacobian(dataclasses.replace(regular, **singular))
    assert np.linalg.matrix_rank(j) == 2
    assert abs(np.linalg.det(j)) < 1e-15


def test_errata_3_24_double_wheel_sub_wheels_at_minus_d_and_plus_d():
    """(3.24) corrected: d_i1 = -d, d_i2 = +d (delta = -90 deg). The thesis's (3.26)/(3.27), written with its
    steering angle beta_th = beta + 90 deg (axle at beta_th - 90 deg), are our spin1/spin2 rows."""
    l, alpha, beta, b, r = 0.35, 2.0, 0.4, 0.06, 0.09
    w = Wheel("u", "double", l=l, alpha=alpha, beta=beta, r=r, b=b)
    bt = beta + math.pi / 2
    sb, cb, s, c = sin(bt), cos(bt), sin(bt - alpha), cos(bt - alpha)
    eq_3_26 = [[sb, -cb, -l * c, 0, 0], [cb, sb, l * s + b, b, r]]  # (v, omega, beta_dot, phi_1)
    eq_3_27 = [[sb, -cb, -l * c, 0, 0], [cb, sb, l * s - b, -b, r]]  # (v, omega, beta_dot, phi_2)
    rows = wheel_slip_rows(w)  # columns vx, vy, omega, steer, spin1, spin2
    np.testing.assert_allclose(rows[:2][:, [0, 1, 2, 3, 4]], eq_3_26, atol=1e-15)
    np.testing.assert_allclose(rows[2:][:, [0, 1, 2, 3, 5]], eq_3_27, atol=1e-15)
    assert np.all(rows[:2, 5] == 0) and np.all(rows[2:, 4] == 0)


def test_double_castor_rows_3_33_3_34():
    """(3.31)-(3.34): the double castor's sub-wheels at (+-b, a) in the steering frame (a = d), written out."""
    l, alpha, beta, a, b, r = 0.35, 2.0, 0.4, 0.1, 0.06, 0.09
    w = Wheel("u", "double_castor", l=l, alpha=alpha, beta=beta, r=r, b=b, d=a)
    sb, cb, s, c = sin(beta), cos(beta), sin(beta - alpha), cos(beta - alpha)
    eq_3_33 = [[cb, sb, l * s - a, -a, 0], [-sb, cb, l * c + b, b, r]]
    eq_3_34 = [[cb, sb, l * s - a, -a, 0], [-sb, cb, l * c - b, -b, r]]
    rows = wheel_slip_rows(w)
    np.testing.assert_allclose(rows[:2][:, [0, 1, 2, 3, 4]], eq_3_33, atol=1e-15)
    np.testing.assert_allclose(rows[2:][:, [0, 1, 2, 3, 5]], eq_3_34, atol=1e-15)


@pytest.mark.parametrize("unit", ["double", "double_castor"])
def test_errata_3_30_steering_angle_follows_the_heading(unit):
    """(3.30)/(3.37): beta = r (phi_2 - phi_1) / (2 b) - theta_R + const, with the heading theta_R itself (001 prints
    its integral). Integrates a smooth no-slip motion of the unit, re-solving the constraints at every step."""
    w = Wheel("u", unit, l=0.3, alpha=0.7, beta=0.2, r=0.08, b=0.05, d=0.1 if unit == "double_castor" else 0.0)
    robot = Robot("u", (w,))
    wanted = np.array([0.3, 0.1, 0.5, 0.4, 1.0, -2.0])  # projected on the no-slip motions: smooth in beta
    dt, beta, theta, phi1, phi2, theta_integral = 0.01, w.beta, 0.0, 0.0, 0.0, 0.0
    for _ in range(400):
        a = robot.constraint_matrix([beta])
        q = wanted - np.linalg.pinv(a) @ (a @ wanted)
        np.testing.assert_allclose(a @ q, 0, atol=1e-12)
        _, _, omega, steer, spin1, spin2 = q
        beta, theta, phi1, phi2 = beta + steer * dt, theta + omega * dt, phi1 + spin1 * dt, phi2 + spin2 * dt
        theta_integral += theta * dt
    assert abs(theta) > 0.1 and abs(beta - w.beta) > 0.1  # the motion turned the robot and the unit
    assert beta - w.beta == pytest.approx(w.r * (phi2 - phi1) / (2 * w.b) - theta, abs=1e-9)
    assert abs(beta - w.beta - (w.r * (phi2 - phi1) / (2 * w.b) - theta_integral)) > 0.05


def test_errata_chapter_3_cites_existing_tests():
    """Every test that docs/errata.md's chapter-3 section cites exists."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "errata.md").read_text()
    section = text[text.index("## Chapter 3"):]
    section = section[: section.find("\n## ", 1) if "\n## " in section[1:] else None]
    cited = re.findall(r"`tests/([\w/]+\.py)::(\w+)`", section)
    assert len(cited) >= 9
    for path, name in cited:
        source = (Path(__file__).resolve().parent / path).read_text()
        assert re.search(rf"^def {name}\(", source, flags=re.M), (path, name)


@pytest.mark.parametrize(("joints", "message"), [
    ("spin", r"expected a tuple of joint names \(spin\), got 'spin'"),  # Robot.actuated read 'left.s', 'left.p', ...
    (("steer",), r"no joint 'steer' on a fixed wheel \(joints: spin\)"),  # a fixed wheel 'actuated' in steering
    (("spin", "spin"), r"joint 'spin' listed twice"),
])
@pytest.mark.parametrize("field", ["actuated", "sensed"])
def test_a_wheel_built_in_python_names_joints_of_its_type(field, joints, message):
    from wmrkit.wheels import WheelError

    with pytest.raises(WheelError, match=rf"^wheel 'left': {field}: {message}$"):
        Wheel("left", "fixed", l=0.2, alpha=math.pi / 2, beta=math.pi / 2, r=0.1, **{field: joints})


def test_wrap_angle_is_the_round_formula_bit_for_bit():
    # np.rint (the loop's hot path) in place of np.round must change no bit: halves, turns, huge and tiny angles
    rng = np.random.default_rng(5)
    a = np.concatenate([rng.uniform(-20, 20, 10_000), rng.normal(0, 1e6, 1000), 10.0 ** rng.uniform(-300, 300, 1000),
                        np.arange(-41, 42) * math.pi, np.arange(-41, 42) * 2 * math.pi, [0.0, -0.0, 5e-324, 1e308]])
    a = np.concatenate([a, -a, np.nextafter(a, np.inf), np.nextafter(a, -np.inf)])
    y = a - 2 * math.pi * np.round(a / (2 * math.pi))
    expected = np.where(y <= -math.pi, y + 2 * math.pi, np.where(y > math.pi, y - 2 * math.pi, y))
    got = wrap_angle(a)
    assert np.array_equal(got.view(np.int64), expected.view(np.int64))
    assert wrap_angle(3 * math.pi).shape == () and float(wrap_angle(3 * math.pi)) == math.pi
