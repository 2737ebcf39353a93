"""Isotropy (§5.4-5.5): condition numbers, natural lengths and the isotropy conditions (5.37)-(5.70)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.optimize import brentq
from thesis_vehicles import DEG, differential, omni_castor, omni_swedish, type3

from circle import assert_same_angles
from wmrkit import Robot, UnknownNameError, Wheel, catalog, wheel_commands
from wmrkit.analysis.isotropy import (
    condition_map,
    condition_number,
    default_joints,
    isotropy_length,
    isotropy_matrix,
    natural_length,
    twist_condition_number,
    twist_model,
)
from wmrkit.analysis.optimize import best_configurations, isotropic_configurations
from wmrkit.analysis.singularity import robot_size
from wmrkit.errors import ShapeError, WmrkitError


def _roots(f, lo=-np.pi, hi=np.pi, n=2880):
    grid = np.linspace(lo, hi, n + 1)
    v = np.array([f(x) for x in grid])
    return np.array([brentq(f, grid[i], grid[i + 1], xtol=1e-15)
                     for i in np.flatnonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)])


def test_condition_number_matches_numpy():
    rng = np.random.default_rng(0)
    for shape in [(3, 3), (5, 2), (4, 3), (2, 2)]:
        h = rng.normal(size=(6, *shape))
        np.testing.assert_allclose(condition_number(h), np.linalg.cond(h), rtol=1e-12)
    assert condition_number(np.array([[1.0, 2.0], [2.0, 4.0]])) == np.inf


# ---- the models themselves (5.37), (5.45)-(5.46) -------------------------------------------------------------
def test_omni_swedish_model_5_37():
    L, r = 0.7, 0.1
    got = twist_model(omni_swedish(L=L, r=r)).rates()
    thesis = (1 / r) * np.array([[0, -1, -L], [math.sqrt(3) / 2, 0.5, -L], [-math.sqrt(3) / 2, 0.5, -L]])
    np.testing.assert_allclose(got, thesis, atol=1e-12)
    forward = (r / 3) * np.array([[0, math.sqrt(3), -math.sqrt(3)], [-2, 1, 1], [-1 / L, -1 / L, -1 / L]])
    np.testing.assert_allclose(np.linalg.inv(got), forward, atol=1e-12)


def test_differential_models_5_45_5_46():
    l12, r1, r2 = 0.5, 0.15, 0.2
    got = twist_model(differential(l12=l12, r1=r1, r2=r2), ("f1.spin", "f2.spin")).rates()
    np.testing.assert_allclose(got, [[0, -1 / r1, -l12 / r1], [0, -1 / r2, l12 / r2]], atol=1e-12)  # (5.46)
    forward = np.array([[-r1 / 2, -r2 / 2], [-r1 / (2 * l12), r2 / (2 * l12)]])  # (5.45), rows v_y, omega
    np.testing.assert_allclose(np.linalg.inv(got[:, 1:]), forward, atol=1e-12)


# ---- type 1 ---------------------------------------------------------------------------------------------------
def test_omni_swedish_isotropy():
    r = omni_swedish(L=0.7)
    assert twist_condition_number(r, length=1.0) == pytest.approx(1.0101525445522, rel=1e-9)
    assert twist_condition_number(r, length=0.7) == pytest.approx(math.sqrt(2), rel=1e-12)
    assert twist_condition_number(r, length=math.sqrt(2) * 0.7) == pytest.approx(1.0, abs=1e-12)
    d, k = natural_length(r)
    assert d == pytest.approx(math.sqrt(2) * 0.7, rel=1e-9) and k == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("gamma_deg", [45, 30, 60])
def test_omni_swedish_general_gamma(gamma_deg):
    g = gamma_deg * DEG
    r = omni_swedish(L=0.7, gamma=g)
    assert twist_condition_number(r, length=math.sqrt(2) * 0.7 * math.sin(g)) == pytest.approx(1.0, abs=1e-12)
    assert natural_length(r)[0] == pytest.approx(math.sqrt(2) * 0.7 * math.sin(g), rel=1e-9)


def test_omni_castor_six_rate_model():
    """Digest §4.1.B: r = d, beta spaced 120 deg -> kappa = 1 at D^2 = mean(L^2 + d^2 - 2 L d sin(beta - alpha))."""
    L, d = 1.0, 0.2
    a = np.array([0, 120, 240]) * DEG
    b = 0.3 + a
    r = omni_castor(L=L, d=d, r=d, betas=tuple(b))
    joints = r.rate_names
    expected = math.sqrt(np.mean(L**2 + d**2 - 2 * L * d * np.sin(b - a)))
    assert twist_condition_number(r, joints=joints, length=expected) == pytest.approx(1.0, abs=1e-12)
    assert natural_length(r, joints=joints)[0] == pytest.approx(expected, rel=1e-9)
    r2 = omni_castor(L=L, d=d, r=d, betas=(0.3, 1.0, 2.0))
    assert natural_length(r2, joints=joints)[1] == pytest.approx(1.1504, abs=1e-4)
    # with the spins only, H = -A_p2 / r does not depend on d (digest §4.1.B)
    spins = ("c1.spin", "c2.spin", "c3.spin")
    k = [twist_condition_number(omni_castor(L=L, d=dd, r=0.2, betas=(0.3, 1.0, 2.0)), joints=spins, length=0.8)
         for dd in (0.05, 0.2, 0.4)]
    np.testing.assert_allclose(k, k[0], rtol=1e-12)


# ---- type 2 ---------------------------------------------------------------------------------------------------
def test_differential_5_51():
    r = differential(l12=0.5, r1=0.15, r2=0.15)
    assert natural_length(r, joints=("f1.spin", "f2.spin")) == pytest.approx((0.5, 1.0), abs=1e-12)
    r = differential(l12=0.5, r1=0.15, r2=0.2)
    d, k = natural_length(r, joints=("f1.spin", "f2.spin"))
    assert d == pytest.approx(0.5, rel=1e-12) and k == pytest.approx(0.2 / 0.15, rel=1e-12)
    # the thesis's printed (5.49) lacks 1/D1 off the diagonal; the correct H^T H (digest §4.2) at D1 = 0.3:
    h = isotropy_matrix(r, None, ("f1.spin", "f2.spin"), ("vy", "omega"), length=0.3)
    hth = h.T @ h
    s, t = 1 / 0.15**2 + 1 / 0.2**2, 1 / 0.15**2 - 1 / 0.2**2
    np.testing.assert_allclose(hth, [[s, 0.5 / 0.3 * t], [0.5 / 0.3 * t, (0.5 / 0.3) ** 2 * s]], rtol=1e-12)


def test_differential_swedish_5_52():
    l12, r1, r3, l3, a3 = 0.5, 0.15, 0.1, 0.6, -90 * DEG
    c1 = l12 * (r3 / r1) ** 2
    assert c1 == pytest.approx(0.2222, abs=1e-4)
    cond = lambda b: math.cos(b) * l3 * math.cos(b - a3) + c1  # noqa: E731
    roots = np.sort(_roots(cond))
    np.testing.assert_allclose(np.degrees(roots), [-156.1027, -113.8973, 23.8973, 66.1027], atol=1e-4)
    for b3, d2 in zip(roots, [0.3646, 0.8228, 0.3646, 0.8228], strict=True):
        r = differential(l12=l12, r1=r1, r2=r1, third="swedish", l3=l3, alpha3=a3, beta3=b3, r3=r3)
        d, k = natural_length(r, joints=("f1.spin", "s3.spin"))
        assert k == pytest.approx(1.0, abs=1e-9) and d == pytest.approx(d2, abs=1e-4)
    r = differential(l12=l12, r1=r1, r2=r1, third="swedish", l3=l3, alpha3=a3, beta3=0.2, r3=r3)
    assert natural_length(r, joints=("f1.spin", "s3.spin"))[1] > 1.01


def _castor_diff(r1, d, l3=0.6, a3=-90 * DEG, r3=0.1):
    return differential(l12=0.5, r1=r1, r2=r1, third="castor", l3=l3, alpha3=a3, beta3=0.0, r3=r3, d=d)


def test_differential_castor_5_58():
    l12, r1, d, l3, a3 = 0.5, 0.3, 0.1, 0.6, -90 * DEG
    c2 = (d / r1) ** 2 * l12
    assert c2 == pytest.approx(0.05556, abs=1e-5)
    roots = np.sort(_roots(lambda b: math.sin(b) * (l3 * math.sin(b - a3) - d) + c2))
    np.testing.assert_allclose(np.degrees(roots), [-74.774, -6.428, 85.767, 175.435], atol=1e-3)
    got = isotropic_configurations(_castor_diff(r1, d), joints=("f1.spin", "c3.steer"))
    assert_same_angles([c.beta[0] for c in got], roots, tol=1e-8)
    lengths = {round(math.degrees(c.beta[0]), 3): c.length for c in got}
    for b, d4 in zip(np.degrees(roots), [0.1727, 1.4887, 0.1671, 2.0943], strict=True):
        assert lengths[round(b, 3)] == pytest.approx(d4, abs=1e-4)
        sb, q = math.sin(math.radians(b)), l3 * math.sin(math.radians(b) - a3) - d  # D4 of digest §4.2
        assert lengths[round(b, 3)] == pytest.approx(math.sqrt((l12**2 / r1**2 + q**2 / d**2)
                                                               / (1 / r1**2 + sb**2 / d**2)), rel=1e-7)


def test_differential_castor_5_58_infeasible():
    """r1 = 0.15, d = 0.3: C2 = 2.0 > l3 + d = 0.9, no isotropic configuration (thesis's existence remark)."""
    r = _castor_diff(0.15, 0.3)
    assert isotropic_configurations(r, joints=("f1.spin", "c3.steer")) == ()
    assert best_configurations(r, joints=("f1.spin", "c3.steer"))[0].condition_number > 1.5


def test_differential_castor_5_59():
    r3, d, l3, a3 = 0.1, 0.3, 0.6, -90 * DEG
    cond = lambda b: (d / r3) ** 2 * math.cos(b) * l3 * math.cos(b - a3) + math.sin(b) * (l3 * math.sin(b - a3) - d)  # noqa: E731
    got = isotropic_configurations(_castor_diff(0.15, d, r3=r3), joints=("c3.spin", "c3.steer"))
    betas = np.array([c.beta[0] for c in got])
    assert all(abs(cond(b)) < 1e-9 for b in betas)
    # the digest lists -93.583, 0 and 93.583 deg (D5 = 1.8, 0.1, 1.8); beta3 = 180 deg (D5 = 0.3) solves (5.59) too
    expected = {-93.583: 1.8, 0.0: 0.1, 93.583: 1.8, -180.0: 0.3}
    got_map = {round(math.degrees(c.beta[0]), 3): c.length for c in got}
    assert set(got_map) == set(expected)
    for b, d5 in expected.items():
        assert got_map[b] == pytest.approx(d5, abs=1e-9)


def test_differential_castor_5_61_wheel_against_wheel():
    for b3, a3 in [(152.745, -106.255), (75.583, -38.217), (104.417, 38.217), (-27.255, 73.745)]:
        r = differential(l12=0.5, r1=0.15, r2=0.15, third="castor", l3=0.6, alpha3=a3 * DEG, beta3=b3 * DEG,
                         r3=0.15, d=0.3)
        h = isotropy_matrix(r, None, ("c3.spin", "c3.steer"), ("f1.spin", "f2.spin"))
        assert condition_number(h) == pytest.approx(1.0, abs=1e-4)  # the angles are given to 1e-3 deg
        assert math.isnan(isotropy_length(r, None, ("c3.spin", "c3.steer"), ("f1.spin", "f2.spin"))[0])  # no omega


def test_5_57c_a5_erratum():
    """(5.57)c: a5 = 2 l12 (l3 sin(alpha3) + d cos(beta3)), not (l3 sin(beta3) + d cos(beta3))."""
    l12, r1, r2, r3, d, l3, a3, b3 = 0.5, 0.15, 0.2, 0.12, 0.3, 0.6, -70 * DEG, 0.4
    r = differential(l12=l12, r1=r1, r2=r2, third="castor", l3=l3, alpha3=a3, beta3=b3, r3=r3, d=d)
    h = isotropy_matrix(r, None, ("f1.spin", "f2.spin"), ("c3.spin", "c3.steer"))
    a1, a2 = l12 * math.cos(b3) + l3 * math.cos(b3 - a3), l12 * math.cos(b3) - l3 * math.cos(b3 - a3)
    a3_, a4 = l12 * math.sin(b3) + l3 * math.sin(b3 - a3), l12 * math.sin(b3) - l3 * math.sin(b3 - a3)

    def matrix(a5):
        return np.array([[2 * l12 * r3 * (a4 + d) / (r1 * a5), 2 * l12 * d * a2 / (r1 * a5)],
                         [2 * l12 * r3 * (d - a3_) / (r2 * a5), -2 * l12 * d * a1 / (r2 * a5)]])

    np.testing.assert_allclose(h, matrix(2 * l12 * (l3 * math.sin(a3) + d * math.cos(b3))), rtol=1e-10)
    assert not np.allclose(h, matrix(2 * l12 * (l3 * math.sin(b3) + d * math.cos(b3))), rtol=1e-3)


def test_5_60_erratum_unequal_radii():
    """(5.60) second equation: r3^2((d+a4)^2 r2^2 + (d-a3)^2 r1^2) = d^2 (a2^2 r2^2 + a1^2 r1^2) at isotropy."""
    l12, r1, r2, r3, d, l3 = 0.5, 0.15, 0.25, 0.12, 0.3, 0.6
    def hh(x):
        rr = differential(l12=l12, r1=r1, r2=r2, third="castor", l3=l3, alpha3=x[1], beta3=x[0], r3=r3, d=d)
        h = isotropy_matrix(rr, None, ("f1.spin", "f2.spin"), ("c3.spin", "c3.steer"))
        return h.T @ h

    from scipy.optimize import least_squares

    sol = least_squares(lambda x: [hh(x)[0, 1], hh(x)[0, 0] - hh(x)[1, 1]], [0.5, -1.0], xtol=1e-15, ftol=1e-15)
    b3, a3 = sol.x
    assert condition_number(isotropy_matrix(
        differential(l12=l12, r1=r1, r2=r2, third="castor", l3=l3, alpha3=a3, beta3=b3, r3=r3, d=d),
        None, ("f1.spin", "f2.spin"), ("c3.spin", "c3.steer"))) == pytest.approx(1.0, abs=1e-8)
    a1, a2 = l12 * math.cos(b3) + l3 * math.cos(b3 - a3), l12 * math.cos(b3) - l3 * math.cos(b3 - a3)
    a3_, a4 = l12 * math.sin(b3) + l3 * math.sin(b3 - a3), l12 * math.sin(b3) - l3 * math.sin(b3 - a3)
    lhs = r3**2 * ((d + a4) ** 2 * r2**2 + (d - a3_) ** 2 * r1**2)
    assert lhs == pytest.approx(d**2 * (a2**2 * r2**2 + a1**2 * r1**2), rel=1e-6)
    assert lhs != pytest.approx(d**2 * (a1**2 * r2**2 + a2**2 * r1**2), rel=1e-3)  # as printed


# ---- type 3 ---------------------------------------------------------------------------------------------------
def test_type3_swedish_5_65b():
    base = dict(r2=0.1, r3=0.15, l2=1.2, a2=-120 * DEG, l3=1.0, a3=-50 * DEG, beta2=0.4, beta3=1.3)
    cond = lambda b1: (math.cos(b1 - 1.3) * 1.0 * math.cos(1.3 + 50 * DEG)  # noqa: E731
                       + (0.15**2 / 0.1**2) * math.cos(b1 - 0.4) * 1.2 * math.cos(0.4 + 120 * DEG))
    roots = np.sort(_roots(cond))
    np.testing.assert_allclose(np.degrees(roots), [-57.0453, 122.9547], atol=1e-4)
    for b1 in roots:
        r = type3(beta1=b1, **base)
        q_a = ("s2.spin", "s3.spin")
        assert isotropy_length(r, None, q_a, ("vy", "omega")) == pytest.approx((1.1782, 1.0), abs=1e-4)
        assert isotropy_length(r, None, q_a, ("vx", "omega")) == pytest.approx((1.8174, 1.0), abs=1e-4)
        assert natural_length(r, joints=q_a)[1] == pytest.approx(1.0, abs=1e-9)  # same condition, another D
    got = isotropic_configurations(type3(beta1=0.0, **base), joints=("s2.spin", "s3.spin"))
    assert_same_angles([c.beta[0] for c in got], roots, tol=1e-9)


def test_type3_swedish_5_65a():
    """q_a = (phi_1, phi_2): the orientable wheel perpendicular to Swedish wheel 2, beta1 = beta2 +- 90 deg."""
    r = type3(beta1=0.0, beta2=0.4)
    got = [c.beta[0] for c in isotropic_configurations(r, joints=("o1.spin", "s2.spin"))]
    assert_same_angles(got, 0.4 + np.array([-1, 1]) * np.pi / 2, tol=1e-9)


@pytest.mark.parametrize("q_a", ["a1", "a2", "a3", "a4", "a5", "a6"])
def test_type3_castor_5_70(q_a):
    """The six wheel-pair vs vehicle-pair isotropy conditions (5.70): their roots in beta1 give kappa = 1."""
    l2, a2, l3, a3, d, rr = 1.2, -120 * DEG, 1.0, -50 * DEG, 0.3, 0.2
    b2, b3 = 0.4, 1.3
    c, s = math.cos, math.sin
    b22, b33 = b2 - a2, b3 - a3
    joints, cond = {
        "a1": (("o1.spin", "c2.spin"), lambda b1: c(b1 - b2) * c(b22)),
        "a2": (("o1.spin", "c2.steer"), lambda b1: s(b1 - b2) * (d - l2 * s(b22))),
        "a3": (("c2.spin", "c3.spin"), lambda b1: l2 * c(b22) * c(b1 - b2) + l3 * c(b33) * c(b1 - b3)),
        "a4": (("c2.steer", "c3.steer"),
               lambda b1: s(b1 - b2) * (d - l2 * s(b22)) + s(b1 - b3) * (d - l3 * s(b33))),
        "a5": (("c2.spin", "c2.steer"),
               lambda b1: l2 * c(b22) * c(b1 - b2) + (rr / d) ** 2 * s(b1 - b2) * (d - l2 * s(b22))),
        "a6": (("c2.spin", "c3.steer"),
               lambda b1: l2 * c(b22) * c(b1 - b2) + (rr / d) ** 2 * s(b1 - b3) * (d - l3 * s(b33))),
    }[q_a]
    roots = _roots(cond)
    assert len(roots) == 2
    for b1 in roots:
        r = type3(omni="castor", l2=l2, a2=a2, l3=l3, a3=a3, beta1=b1, beta2=b2, beta3=b3, r=rr, d=d)
        assert natural_length(r, joints=joints)[1] == pytest.approx(1.0, abs=1e-9)
    r = type3(omni="castor", l2=l2, a2=a2, l3=l3, a3=a3, beta1=roots[0] + 0.3, beta2=b2, beta3=b3, r=rr, d=d)
    assert natural_length(r, joints=joints)[1] > 1.001


# ---- batching, maps, defaults ---------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["thesis-steer-castor", "thesis-omni-castor", "thesis-diff-castor", "forklift"])
@pytest.mark.parametrize("batch", [(), (1,), (5,), (2, 3)], ids=str)
def test_condition_batches_like_a_loop(name, batch):
    r = catalog.load(name)
    beta = np.random.default_rng(3).uniform(-np.pi, np.pi, (*batch, len(r.steer_names)))
    out = twist_condition_number(r, beta, length=0.4)
    assert out.shape == batch
    for idx in np.ndindex(*batch):
        np.testing.assert_allclose(out[idx], twist_condition_number(r, beta[idx], length=0.4), rtol=1e-12)


@pytest.mark.parametrize("name", ["thesis-steer-castor", "thesis-omni-castor", "thesis-steer-swedish", "diff-drive"])
def test_condition_map_matches_an_independent_null_space_computation(name):
    """Closed-form map kernel == per-configuration SVD of the slip matrix (null space B of 6.7).

    m = 2: twists are measured at the foot P of the perpendicular from the origin on the line of ICRs, here found
    from two admissible twists' ICRs; the joint rates per unit scaled twist at P are ``B_u S^+ Q``.
    """
    r = catalog.load(name)
    beta = np.random.default_rng(4).uniform(-np.pi, np.pi, (3000, max(len(r.steer_names), 1)))[:, :len(r.steer_names)]
    length = 0.3
    fast = condition_map(r, beta, length=length)
    joints = [r.velocity_index(n) for n in default_joints(r)]
    m = 3 if name == "thesis-omni-castor" else 2
    for i in range(0, 3000, 150):
        b = np.linalg.svd(r.constraint_matrix(beta[i]))[2][-m:].T  # null-space basis (6.7), (k, m)
        twists = b[:3]
        if m == 2:
            t1, t2 = twists.T + 0.5 * twists[:, ::-1].T
            icr1, icr2 = (np.array([-t[1] / t[2], t[0] / t[2]]) for t in (t1, t2))
            u = (icr2 - icr1) / np.linalg.norm(icr2 - icr1)
            p = icr1 - (icr1 @ u) * u  # foot of the perpendicular from the origin
            to_p = np.array([[1.0, 0.0, -p[1]], [0.0, 1.0, p[0]], [0.0, 0.0, 1.0]])
        else:
            to_p = np.eye(3)
        s_mat = np.diag([1.0, 1.0, length]) @ to_p @ twists
        q, _ = np.linalg.qr(s_mat)
        kappa_ref = condition_number(b[joints] @ np.linalg.pinv(s_mat) @ q)
        assert fast[i] == pytest.approx(kappa_ref, rel=1e-6)


def test_type3_condition_uses_the_wheel_frame():
    """m = 2 with the axle through the origin: the basis is (speed along the wheel, omega) = eta of (5.64)."""
    r = catalog.load("thesis-steer-swedish")
    b1 = r.beta[0]
    rates = twist_model(r).rates()
    along, spin = np.array([math.sin(b1), -math.cos(b1), 0.0]), np.array([0.0, 0.0, 1.0])
    for length in (0.1, 0.3, 1.0):
        h = np.stack([rates @ along, rates @ spin / length], axis=1)
        assert twist_condition_number(r, length=length) == pytest.approx(condition_number(h), rel=1e-12)


def test_offset_origin_differential_is_measured_at_the_axle():
    """The line follower's origin is 0.39 m ahead of its axle; kappa is that of (v, D omega) at the axle midpoint."""
    r = catalog.load("line-follower")
    assert natural_length(r) == pytest.approx((0.17, 1.0), abs=1e-12)


def test_m1_robots_and_uncoordinated_steering():
    r = catalog.load("forklift")
    assert twist_condition_number(r) == 1.0
    car = catalog.load("ackermann")
    assert np.isnan(twist_condition_number(car, np.array([1.2, 1.6]), length=1.0))  # axles do not meet: no motion


def test_unknown_joint_names_raise():
    with pytest.raises(UnknownNameError, match=r"no joint rate 'f9\.spin'"):
        twist_condition_number(catalog.load("thesis-tricycle"), joints=("f9.spin",))
    with pytest.raises(UnknownNameError, match="as many selected as assigned"):
        isotropy_matrix(catalog.load("thesis-tricycle"), None, ("vy",), ("vy",))


@pytest.mark.parametrize(("length", "kappa"), [(1e-4, 1e7), (1e-6, 1e9), (1e3, 1.0)])
def test_a_large_condition_number_is_a_number_not_infinite(length, kappa):
    """A differential drive of half track b = 1 km: its two wheel-rate columns per (v, D omega) are orthogonal, of
    norms sqrt(2)/r and sqrt(2) b/(r D), so kappa = b / D for D < b. The Gram eigenvalues bottom out at sqrt(eps),
    so 'analyze --length 1e-4' printed 'condition number infinite (these joints do not determine the twist)' for
    this robot, whose joints do; the SVD (few configurations) resolves it to eps."""
    from wmrkit import Robot

    huge = Robot.from_dict({"name": "huge", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, 1000], "heading": 0, "r": 0.1, "sensed": ["spin"]},
        {"name": "right", "type": "fixed", "position": [0, -1000], "heading": 0, "r": 0.1, "sensed": ["spin"]},
        {"name": "caster", "type": "castor", "position": [-1000, 0], "heading": 0, "d": 0.1, "r": 0.1}]})
    joints = ("left.spin", "right.spin")
    assert float(twist_condition_number(huge, joints=joints, length=length)) == pytest.approx(kappa, rel=1e-9)
    omni = catalog.load("omni-3")  # m = 3 against the reference SVD of the isotropy matrix (5.30)
    reference = condition_number(isotropy_matrix(omni, None, default_joints(omni), ("vx", "vy", "omega"),
                                                 length=length))
    assert float(twist_condition_number(omni, length=length)) == pytest.approx(float(reference), rel=1e-9)


@pytest.mark.parametrize(("name", "joints"), [("mecanum-4", ("front_left.spin",)),
                                              ("mecanum-4", ("front_left.spin", "front_right.spin")),
                                              ("diff-drive", ("left.spin",))])
def test_fewer_joints_than_the_mobility_cannot_tell_the_motions_apart(name, joints):
    """Two Mecanum spins for three degrees of freedom gave kappa = 1 ("isotropic") at D = 372 m: the SVD of a 2 x 3
    map has two singular values, and they were equal. The Gram route of large batches said inf already."""
    robot = catalog.load(name)
    assert np.isinf(twist_condition_number(robot, joints=joints)).all()
    many = np.tile(robot.beta, (5000, 1))  # beyond the SVD route's batch size
    assert np.isinf(twist_condition_number(robot, many, joints=joints)).all()
    assert np.isinf(condition_number(np.ones((4, 2, 3)))).all() and condition_number(np.eye(3)[:, :2]) == 1


@pytest.mark.parametrize("k", [1.0, 0.01, 3.0])
def test_joints_blind_to_rotation_have_no_natural_length(k):
    """A type-2 robot whose spins do not see omega: a fixed wheel and a double castor, both mounted at the origin (the
    castor's steering takes the rotation). kappa is infinite at every length, but the m = 2 closed form D = |h_omega|
    / |h_v| took |h_omega|'s round-off: 'condition number 1.084 at the natural length D = 1.613e-18 m' (wmrkit
    analyze), 1.213 at D = 2.2e-20 m for the same robot at a hundredth of its size."""
    robot = Robot(name="blind", wheels=(
        Wheel(name="c", type="double_castor", l=0.0, alpha=0.0, beta=0.0, r=0.01 * k, d=-0.47 * k, b=0.01 * k),
        Wheel(name="f", type="fixed", l=0.0, alpha=0.0, beta=0.0, r=0.01 * k)))
    joints = default_joints(robot)
    assert joints == ("c.spin1", "c.spin2", "f.spin")
    spins = wheel_commands(robot, [0.0, 0.0, 1.0]).velocity([0.0, 0.0, 1.0])  # turning on the spot moves no spin
    np.testing.assert_allclose([spins[robot.velocity_index(j)] for j in joints], 0.0, atol=1e-12)
    length, kappa = natural_length(robot)
    assert np.isinf(kappa) and length == robot_size(robot)
    assert np.isinf(twist_condition_number(robot, length=length))


@pytest.mark.parametrize("k", [1.0, 4.0, 8.0, 100.0])
def test_the_natural_length_of_a_robot_mounted_at_its_origin_scales_with_it(k):
    """A double castor mounted at the origin (0.5 m offset, half-separation and radius) is sized 1 mm
    (robot_size's floor: no mount point away from the origin) at any scale, and the natural length was searched up
    to 1 m only: scaled by 4 its D was that bound, 1 m, with kappa 1.966 instead of the minimum 1.932 at 0.289 * 4 m
    (hypothesis found it). The search now reaches 1000 times the robot's largest length. Independent: kappa scanned
    on a fine grid of lengths."""
    wheel = Wheel("w0", "double_castor", l=0.0, alpha=0.0, beta=0.0, r=0.5 * k, d=-0.5 * k, b=0.5 * k,
                  actuated=("steer", "spin1", "spin2"))
    robot = Robot("r", (wheel,))
    joints = default_joints(robot)
    d, kappa = natural_length(robot, joints=joints)
    scan = np.array([twist_condition_number(robot, joints=joints, length=x) for x in np.geomspace(0.01, 100, 4001) * k])
    assert scan.min() * (1 - 1e-3) <= kappa <= scan.min()  # at the minimum, between the scan's lengths
    assert math.isclose(d / k, 0.5 / math.sqrt(3), rel_tol=1e-6)  # where the scan's minimum lies, below
    assert math.isclose(np.geomspace(0.01, 100, 4001)[scan.argmin()], 0.5 / math.sqrt(3), rel_tol=5e-3)


@pytest.mark.parametrize(("tol", "error", "message"), [
    ("1", ShapeError, "tol: got the text '1', but the Python API reads no units"),
    (math.nan, WmrkitError, "tol: expected a tolerance >= 0 on the condition number, got nan"),
    (-1e-3, WmrkitError, "tol: expected a tolerance >= 0 on the condition number, got -0.001"),
])
def test_isotropic_configurations_refuses_a_tolerance_that_is_not_one(tol, error, message):
    """Text raised a bare TypeError ('int' + 'str'); NaN kept no configuration, read as 'not isotropic'."""
    with pytest.raises(error, match=f"^{re.escape(message)}"):
        isotropic_configurations(catalog.load("thesis-omni-swedish"), tol=tol)
