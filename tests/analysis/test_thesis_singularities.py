"""The singular configurations of Figs. 6.4-6.10 (digest §7): exact singular sets == roots of the closed forms.

Each closed form is the digest's condition written out here from the thesis's parameters; `singular_set` finds
the singular angles from the constraint lines (6.17) by polynomial roots, so the two are independent.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq
from thesis_vehicles import DEG, bicycle, differential, tricycle, type3, type5

from circle import same_angles as _same_angles
from wmrkit.analysis.icr import icr
from wmrkit.analysis.singularity import is_singular, is_singular_rank, singular_set

s, c = np.sin, np.cos
SEEDS = [0, 1, 2]


def _roots(f, n: int = 2880) -> np.ndarray:
    grid = np.linspace(-np.pi, np.pi, n + 1)
    v = np.array([f(x) for x in grid])
    out = list(grid[:-1][np.abs(v[:-1]) < 1e-13])
    for i in np.flatnonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0):
        out.append(brentq(f, grid[i], grid[i + 1], xtol=1e-15))
    x = np.sort(np.mod(np.array(out) + np.pi, 2 * np.pi) - np.pi)
    if len(x) > 1:  # a root on a grid point is found twice; -pi and pi are the same angle
        x = x[np.diff(np.concatenate([x, x[:1] + 2 * np.pi])) > 1e-9]
    return x


def test_same_angles_is_a_comparison_on_the_circle():
    assert _same_angles([0.0, np.pi], [-np.pi, 0.0])  # the fresh-clone failure of issue 8
    assert _same_angles([3.0, -1.0], [-1.0, 3.0 - 2 * np.pi])
    assert not _same_angles([0.0, np.pi], [0.0, 0.5])
    assert not _same_angles([0.0, 0.0], [0.0, 1.0])


def check(robot, assigned, var, f):
    """The exact singular set over steering angle `var` equals the roots of f(beta dict)."""
    names = robot.steer_names
    j = names.index(var)

    def g(x):
        b = dict(zip(names, robot.beta, strict=True))
        b[var] = x
        return f(b)

    got = singular_set(robot, assigned, variables=(var,))
    assert not got.always, (assigned, got.reasons)
    roots = _roots(g)
    assert _same_angles(got.configurations[:, 0], roots), (assigned, got.configurations[:, 0], roots)
    for x in roots:  # and the rank test agrees at each root and away from it
        beta = robot.beta.copy()
        beta[j] = x
        assert is_singular_rank(robot, beta, assigned)
        beta[j] = x + 0.1
        assert is_singular_rank(robot, beta, assigned) == (abs(g(x + 0.1)) < 1e-12)


def always(robot, assigned):
    assert singular_set(robot, assigned).always, assigned


def never(robot, assigned):
    got = singular_set(robot, assigned)
    assert got.never and got.exact, (assigned, got.configurations)


def _rng(seed):
    return np.random.default_rng(seed)


# ---- Type 2, Fig. 6.4 -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", SEEDS)
def test_fig_6_4_differential_with_castor(seed):
    g = _rng(seed)
    l12, l3, a3, d = g.uniform(0.3, 0.6), g.uniform(0.4, 1.0), g.uniform(-np.pi, np.pi), g.uniform(0.03, 0.2)
    r = differential(l12=l12, third="castor", l3=l3, alpha3=a3, d=d)
    check(r, ("c3.spin", "vy"), "c3", lambda b: l3 * c(b["c3"] - a3))  # (c)
    check(r, ("c3.steer", "vy"), "c3", lambda b: l3 * s(b["c3"] - a3) - d)  # (d)
    check(r, ("f1.spin", "c3.spin"), "c3", lambda b: l12 * c(b["c3"]) - l3 * c(b["c3"] - a3))  # (e)
    check(r, ("f2.spin", "c3.spin"), "c3", lambda b: -l12 * c(b["c3"]) - l3 * c(b["c3"] - a3))  # (e), wheel 2
    check(r, ("f1.spin", "c3.steer"), "c3", lambda b: l12 * s(b["c3"]) - l3 * s(b["c3"] - a3) + d)  # (f)
    check(r, ("c3.spin", "c3.steer"), "c3", lambda b: l3 * s(a3) + d * c(b["c3"]))  # (g) = a5 / (2 l12)
    check(r, ("c3.spin", "omega"), "c3", lambda b: c(b["c3"]))  # not drawn (digest §7.2, erratum 15)
    check(r, ("c3.steer", "omega"), "c3", lambda b: s(b["c3"]))
    for q_a in [("vx", "vy"), ("vx", "omega"), ("vx", "f1.spin"), ("vx", "c3.spin"), ("vx", "c3.steer")]:
        always(r, q_a)
    for q_a in [("f1.spin", "f2.spin"), ("vy", "omega"), ("f1.spin", "vy"), ("f1.spin", "omega")]:
        never(r, q_a)


@pytest.mark.parametrize("seed", SEEDS)
def test_fig_6_4_differential_with_swedish_design_conditions(seed):
    g = _rng(seed)
    l12, l3, a3 = g.uniform(0.3, 0.6), g.uniform(0.4, 1.0), g.uniform(-np.pi, np.pi)
    # (a) (phi_s3, v_y): roller line 3 through O_R  <=>  l3 cos(beta3 - alpha3) = 0
    assert is_singular(differential(l12=l12, l3=l3, alpha3=a3, beta3=a3 + np.pi / 2), None, ("s3.spin", "vy"))
    assert not is_singular(differential(l12=l12, l3=l3, alpha3=a3, beta3=a3 + 0.4), None, ("s3.spin", "vy"))
    # (b) (phi_f1, phi_s3): a2 = l12 cos(beta3) - l3 cos(beta3 - alpha3) = 0
    b3 = brentq(lambda b: l12 * c(b) - l3 * c(b - a3), *_bracket(lambda b: l12 * c(b) - l3 * c(b - a3)))
    assert is_singular(differential(l12=l12, l3=l3, alpha3=a3, beta3=b3), None, ("f1.spin", "s3.spin"))
    assert not is_singular(differential(l12=l12, l3=l3, alpha3=a3, beta3=b3 + 0.3), None, ("f1.spin", "s3.spin"))
    # (phi_s3, omega), not drawn (errata "Fig. 6.4 omits the omega-assigned sets"): singular iff cos(beta3) = 0
    for b3 in (np.pi / 2, -np.pi / 2):
        assert is_singular(differential(l12=l12, l3=l3, alpha3=a3, beta3=b3), None, ("s3.spin", "omega"))
    assert not is_singular(differential(l12=l12, l3=l3, alpha3=a3, beta3=np.pi / 2 + 0.3), None, ("s3.spin", "omega"))


def _bracket(f):
    grid = np.linspace(-np.pi, np.pi, 721)
    v = np.array([f(x) for x in grid])
    i = int(np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))[0])
    return grid[i], grid[i + 1]


# ---- Type 3, Figs. 6.5-6.7 ------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", SEEDS)
def test_fig_6_5_to_6_7_one_orientable_wheel_and_castors(seed):
    g = _rng(seed)
    l2, l3, d = g.uniform(0.5, 1.2), g.uniform(0.5, 1.2), g.uniform(0.03, 0.2)
    a2, a3 = g.uniform(-np.pi, 0), g.uniform(0, np.pi)
    r = type3(l2=l2, a2=a2, l3=l3, a3=a3, omni="castor", beta1=g.uniform(-3, 3), beta2=g.uniform(-3, 3),
              beta3=g.uniform(-3, 3), d=d)
    check(r, ("vx", "omega"), "o1", lambda b: s(b["o1"]))  # Fig. 6.5 (a)
    check(r, ("vy", "omega"), "o1", lambda b: c(b["o1"]))  # Fig. 6.5 (b)
    for q_a in [("vx", "vy"), ("vx", "o1.spin"), ("vy", "o1.spin")]:  # erratum 8: the last two too
        always(r, q_a)
    never(r, ("o1.spin", "omega"))
    check(r, ("o1.spin", "c2.spin"), "c2", lambda b: l2 * c(b["c2"] - a2))  # 6.7 (a)
    check(r, ("o1.spin", "c2.steer"), "c2", lambda b: l2 * s(b["c2"] - a2) - d)  # 6.7 (b)

    def fc(b):  # 6.7 (c)
        return l2 * c(b["c2"] - a2) * c(b["o1"] - b["c3"]) - l3 * c(b["c3"] - a3) * c(b["o1"] - b["c2"])

    def fd(b):  # 6.7 (d)
        return (s(b["o1"] - b["c2"]) * (l3 * s(b["c3"] - a3) - d)
                - s(b["o1"] - b["c3"]) * (l2 * s(b["c2"] - a2) - d))

    def fe(b):  # 6.7 (e)
        return l2 * s(b["o1"] - a2) - d * c(b["o1"] - b["c2"])

    def ff(b):  # 6.7 (f)
        return c(b["o1"] - b["c2"]) * (l3 * s(b["c3"] - a3) - d) + s(b["o1"] - b["c3"]) * l2 * c(b["c2"] - a2)

    for var in ("o1", "c2", "c3"):
        check(r, ("c2.spin", "c3.spin"), var, fc)
        check(r, ("c2.steer", "c3.steer"), var, fd)
        check(r, ("c2.spin", "c3.steer"), var, ff)
    for var in ("o1", "c2"):
        check(r, ("c2.spin", "c2.steer"), var, fe)
        check(r, ("c2.spin", "omega"), var, lambda b: c(b["o1"] - b["c2"]))  # (e')
        check(r, ("c2.steer", "omega"), var, lambda b: s(b["o1"] - b["c2"]))  # (f')
    # 6.7 (a) with v_x instead of phi_o1: also singular when E1 is the X axis (sin beta1 = 0)
    check(r, ("vx", "c2.spin"), "o1", lambda b: s(b["o1"]) * l2 * c(b["c2"] - a2))


@pytest.mark.parametrize("seed", SEEDS)
def test_fig_6_6_one_orientable_wheel_and_swedish_wheels(seed):
    g = _rng(seed)
    l2, l3, a2, a3 = g.uniform(0.5, 1.2), g.uniform(0.5, 1.2), g.uniform(-np.pi, 0), g.uniform(0, np.pi)
    b2, b3 = g.uniform(-3, 3), g.uniform(-3, 3)
    r = type3(l2=l2, a2=a2, l3=l3, a3=a3, omni="swedish", beta2=b2, beta3=b3)
    check(r, ("s2.spin", "s3.spin"), "o1",  # (b)
          lambda b: l2 * c(b2 - a2) * c(b["o1"] - b3) - l3 * c(b3 - a3) * c(b["o1"] - b2))
    check(r, ("s2.spin", "omega"), "o1", lambda b: c(b["o1"] - b2))  # (c)
    never(r, ("o1.spin", "s2.spin"))  # (a) is a design condition: roller line 2 through O_R
    radial = type3(l2=l2, a2=a2, l3=l3, a3=a3, omni="swedish", beta2=a2 + np.pi / 2, beta3=b3)
    always(radial, ("o1.spin", "s2.spin"))


# ---- Type 4, Figs. 6.8-6.9 ------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", SEEDS)
def test_fig_6_8_tricycle(seed):
    g = _rng(seed)
    l12, l3 = g.uniform(0.3, 0.8), g.uniform(0.5, 1.5)
    r = tricycle(l12=l12, l3=l3)
    always(r, ("vx",))
    check(r, ("vy",), "o3", lambda b: c(b["o3"]))  # (a)
    check(r, ("omega",), "o3", lambda b: s(b["o3"]))  # (b)
    check(r, ("f1.spin",), "o3", lambda b: l12 * s(b["o3"]) + l3 * c(b["o3"]))  # (c)
    check(r, ("f2.spin",), "o3", lambda b: l12 * s(b["o3"]) - l3 * c(b["o3"]))
    never(r, ("o3.spin",))


def test_fig_6_8_tricycle_example_angles():
    r = tricycle(l12=0.5, l3=1.0)
    got = np.degrees(singular_set(r, ("f1.spin",)).configurations[:, 0])
    np.testing.assert_allclose(np.sort(got), [-63.43494882, 116.56505118], atol=1e-7)
    got = np.degrees(singular_set(r, ("f2.spin",)).configurations[:, 0])
    np.testing.assert_allclose(np.sort(got), [-116.56505118, 63.43494882], atol=1e-7)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("third", ["swedish", "castor"])
def test_fig_6_9_bicycle(seed, third):
    g = _rng(seed)
    l2, l3, a3, d = g.uniform(0.5, 1.5), g.uniform(0.3, 1.0), g.uniform(-np.pi, np.pi), g.uniform(0.03, 0.2)
    b3 = g.uniform(-3, 3)
    r = bicycle(l2=l2, third=third, l3=l3, a3=a3, beta3=b3, d=d)
    k = "s3" if third == "swedish" else "c3"
    beta3 = (lambda b: b3) if third == "swedish" else (lambda b: b["c3"])
    always(r, ("vx",))
    check(r, ("vy",), "o2", lambda b: c(b["o2"]))  # (a)
    check(r, ("f1.spin",), "o2", lambda b: c(b["o2"]))
    check(r, ("omega",), "o2", lambda b: s(b["o2"]))  # (b)
    roller = lambda b: l3 * c(beta3(b) - a3) * s(b["o2"]) + l2 * c(b["o2"]) * c(beta3(b))  # noqa: E731
    check(r, (f"{k}.spin",), "o2", roller)  # (c), (d)
    never(r, ("o2.spin",))
    if third == "castor":
        check(r, ("c3.spin",), "c3", roller)
        axis = lambda b: (l3 * s(b["c3"] - a3) - d) * s(b["o2"]) + l2 * c(b["o2"]) * s(b["c3"])  # noqa: E731
        check(r, ("c3.steer",), "o2", axis)  # (e)
        check(r, ("c3.steer",), "c3", axis)


# ---- Type 5, Fig. 6.10 ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("third", ["swedish", "castor"])
def test_fig_6_10_two_orientable_wheels(seed, third):
    g = _rng(seed)
    l12, l3, a3, d = g.uniform(0.3, 0.8), g.uniform(0.5, 1.5), g.uniform(-np.pi, np.pi), g.uniform(0.03, 0.2)
    b3 = g.uniform(-3, 3)
    r = type5(l12=l12, third=third, l3=l3, a3=a3, beta1=g.uniform(-3, 3), beta2=g.uniform(-3, 3), beta3=b3, d=d)
    k = "s3" if third == "swedish" else "c3"
    beta3 = (lambda b: b3) if third == "swedish" else (lambda b: b["c3"])
    for var in ("o1", "o2"):
        check(r, ("vx",), var, lambda b: s(b["o1"]) * s(b["o2"]))  # (a): not everywhere (erratum 13)
        check(r, ("vy",), var, lambda b: s(b["o1"] + b["o2"]))  # (b)
        check(r, ("omega",), var, lambda b: s(b["o2"] - b["o1"]))  # (c)
        check(r, ("o1.spin",), var, lambda b: s(b["o2"]))  # (d)
        check(r, ("o2.spin",), var, lambda b: s(b["o1"]))  # (e)

        def roller(b):  # (f), (g)
            b1, b2, bb3 = b["o1"], b["o2"], beta3(b)
            return (s(b2 - b1) * l3 * c(bb3 - a3) + 2 * l12 * s(b1) * s(b2) * s(bb3) + l12 * s(b1 + b2) * c(bb3))

        check(r, (f"{k}.spin",), var, roller)
        if third == "castor":
            def axis(b):  # (h)
                b1, b2, bb3 = b["o1"], b["o2"], b["c3"]
                return (-2 * l12 * s(b1) * s(b2) * c(bb3) + l12 * s(b1 + b2) * s(bb3)
                        + s(b2 - b1) * (l3 * s(bb3 - a3) - d))

            check(r, ("c3.steer",), var, axis)
            check(r, ("c3.steer",), "c3", axis)


def test_type5_vx_is_not_singular_everywhere():
    """Erratum 13 (§6.5.5 says v_x is singular in the whole configuration space)."""
    r = type5(beta1=0.4, beta2=1.1)
    assert not is_singular(r, None, ("vx",)) and not is_singular_rank(r, None, ("vx",))
    assert is_singular(r, np.array([0.0, 1.1]), ("vx",))


# ---- ICR oracles (§2.2, §7.4) ---------------------------------------------------------------------------------
def test_icr_of_tricycle_and_bicycle():
    for b3 in (0.3, -1.2, 2.0):
        got = icr(tricycle(l12=0.5, l3=1.3, beta3=b3))
        assert got.kind == "point"
        np.testing.assert_allclose(got.point, [-1.3 / np.tan(b3), 0.0], atol=1e-12)
    got = icr(bicycle(l2=1.0, beta2=30 * DEG))
    np.testing.assert_allclose(got.point, [-1.7320508, 0.0], atol=1e-7)
    assert icr(tricycle(beta3=0.0)).kind == "infinity"


def test_tricycle_null_vector_5_72():
    """(5.72) with L read as l12 (erratum 10): the null vector of the tricycle's slip matrix."""
    l12, l3, r, b3 = 0.5, 1.2, 0.1, 0.4
    t = tricycle(l12=l12, l3=l3, r=r, beta3=b3)
    thesis = np.array([0.0, l3 * c(b3), s(b3), -(l12 * s(b3) + l3 * c(b3)) / r, (l12 * s(b3) - l3 * c(b3)) / r,
                       -l3 / r])
    a = t.constraint_matrix()
    assert np.allclose(a @ thesis, 0.0, atol=1e-12)
    assert np.linalg.matrix_rank(a) == a.shape[1] - 1


def test_type3_simultaneous_isotropy_claim_erratum_7():
    """§5.5.3.A: beta1 = beta2 = beta3 does not satisfy (5.65a); cos(b1 - b2) = cos(b1 - b3) = 0 does, and is
    singular for (phi_2, phi_3)."""
    from wmrkit.analysis.isotropy import natural_length

    equal = type3(beta1=0.7, beta2=0.7, beta3=0.7)
    assert natural_length(equal, joints=("o1.spin", "s2.spin"))[1] > 1.01  # (5.65a) fails
    perp = type3(beta1=0.7 + np.pi / 2, beta2=0.7, beta3=0.7)
    assert natural_length(perp, joints=("o1.spin", "s2.spin"))[1] == pytest.approx(1.0, abs=1e-9)
    assert is_singular(perp, None, ("s2.spin", "s3.spin")) and is_singular_rank(perp, None, ("s2.spin", "s3.spin"))
