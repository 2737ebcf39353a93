"""The tricycle of thesis §4.6 (digest ch3-4 PART C), numerically: (4.77)-(4.84) against their closed forms.

The robot is built here from the table C.1 (not from the catalog); the oracles are the digest's closed forms and
numbers, re-derived from the thesis and independent of wmrkit's code.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from wmrkit import Robot, Wheel, catalog
from wmrkit.kinematics.actuation import actuated_inverse_matrix, actuation_analysis, actuation_tree
from wmrkit.kinematics.extended import extended_solution, no_slip_extended_solution, solve_steering
from wmrkit.kinematics.linalg import matrix_rank
from wmrkit.kinematics.models import assignable_sets, is_assignable, kinematic_model, mobility
from wmrkit.kinematics.nullspace import enumerate_subsets, rref_free_columns
from wmrkit.kinematics.sensing import sensed_direct_matrix, sensed_full_matrix, sensing_analysis, sensing_tree
from wmrkit.kinematics.trees import (
    independent_wheel_rates,
    inverse_tree,
    motion_constraints,
    vehicle_dof,
    wheel_jacobians,
)

R, L12, L3 = 0.1, 0.5, 1.2
B3 = 0.4
GENERIC = np.array([0.4, -1.1, 2.3, 0.07, -2.9])  # steering angles away from the singular list of C.4


def tricycle(r: float = R, l12: float = L12, l3: float = L3, beta3: float = B3) -> Robot:
    """Table C.1: fixed wheels at (+-l12, 0) with beta 0, a steerable wheel at (0, -l3)."""
    return Robot("tricycle", (
        Wheel("w1", "fixed", l12, 0.0, 0.0, r, sensed=("spin",)),
        Wheel("w2", "fixed", l12, math.pi, 0.0, r, sensed=("spin",)),
        Wheel("w3", "steerable", l3, -math.pi / 2, beta3, r, actuated=("spin", "steer"), sensed=("steer",)),
    ))


TRI = tricycle()
COLS = ("vx", "vy", "omega", "w1.spin", "w2.spin", "w3.spin")


def a_478(b, r=R, l12=L12, l3=L3):
    """(4.78), R-bar form (3.5), one matrix per angle."""
    b = np.asarray(b, dtype=float)
    z, o = np.zeros_like(b), np.ones_like(b)
    rows = [
        [o, z, z, z, z, z],
        [z, o, l12 * o, r * o, z, z],
        [o, z, z, z, z, z],
        [z, o, -l12 * o, z, r * o, z],
        [o, z, l3 * o, z, z, -r * np.sin(b)],
        [z, o, z, z, z, r * np.cos(b)],
    ]
    return np.moveaxis(np.array(rows), (0, 1), (-2, -1))


def null_vectors_c5(name, b, r=R, l12=L12, l3=L3):
    """The corrected null vectors of C.5 (v_x, v_y, omega, phi1, phi2, phi3) with `name` = 1."""
    c, s, t = np.cos(b), np.sin(b), np.tan(b)
    d1, d2 = l3 * c - l12 * s, l3 * c + l12 * s
    return {
        "w3.spin": [0, -r * c, r * s / l3, d1 / l3, d2 / l3, 1],
        "vy": [0, 1, -t / l3, (-l3 + l12 * t) / (l3 * r), (-l3 - l12 * t) / (l3 * r), -1 / (c * r)],
        "omega": [0, -l3 / t, 1, (-l12 + l3 / t) / r, (l12 + l3 / t) / r, l3 / (r * s)],
        "w1.spin": [0, r * l3 * c / (-d1), r * s / d1, 1, d2 / d1, l3 / d1],
        "w2.spin": [0, -r * l3 * c / d2, r * s / d2, d1 / d2, 1, l3 / d2],
    }[name]


def test_catalog_robot_matches_table_c1():
    if "thesis-tricycle-ch4" not in catalog.names():
        pytest.skip("catalog robot thesis-tricycle-ch4 not added yet")
    robot = catalog.load("thesis-tricycle-ch4")
    np.testing.assert_allclose(robot.constraint_matrix([[b] for b in GENERIC]),
                               TRI.constraint_matrix([[b] for b in GENERIC]), atol=1e-12)


def test_a_is_478_and_its_rank_is_5():
    beta = GENERIC[:, None]
    np.testing.assert_allclose(TRI.constraint_matrix(beta, frame="robot"), a_478(GENERIC), atol=1e-15)
    assert (matrix_rank(TRI.constraint_matrix(beta)) == 5).all()
    assert (mobility(TRI, beta) == 1).all()  # (4.79)


def test_jacobian_method_gives_h_g_1_and_rank_8():
    beta = GENERIC[:, None]
    assert (independent_wheel_rates(TRI, beta) == 1).all() and (vehicle_dof(TRI, beta) == 1).all()
    i_bar, j = TRI.jacobian_form(beta)
    stacked = np.concatenate([np.broadcast_to(i_bar, (len(GENERIC), 9, 3)), j], axis=-1)
    assert (matrix_rank(stacked) == 8).all()  # (4.73): rank A + N = 5 + 3
    feasible = np.array(null_vectors_c5("w3.spin", B3), dtype=float)[:3]
    assert inverse_tree(TRI, None, feasible).leaf == "consistent"  # Fig. 4.3
    assert inverse_tree(TRI, None, feasible + np.array([0.01, 0, 0])).leaf == "inconsistent"  # v_x = 0 violated


def test_wheel_jacobians_are_477():
    j1, j2, j3 = wheel_jacobians(TRI)
    np.testing.assert_allclose(j1, [[0, 0], [-R, -L12], [0, 1]], atol=1e-15)
    np.testing.assert_allclose(j2, [[0, 0], [-R, L12], [0, 1]], atol=1e-15)
    np.testing.assert_allclose(j3, [[R * math.sin(B3), -L3], [-R * math.cos(B3), 0], [0, 1]], atol=1e-15)


def test_only_vx_is_not_assignable_at_generic_angles():
    assert len(enumerate_subsets(6, 1)) == 6  # (4.8): C(6, 1) null-space computations
    expected = tuple((n,) for n in COLS[1:])
    for method in ("ranks", "nullspace", "rref"):
        assert assignable_sets(TRI, GENERIC[:, None], method=method) == expected


@pytest.mark.parametrize(("beta3", "lost"), [
    (0.0, "omega"), (math.pi / 2, "vy"), (-math.pi / 2, "vy"),
    (math.atan(L3 / L12), "w1.spin"), (math.atan(-L3 / L12), "w2.spin"),
])
def test_singular_steering_angles_of_c4(beta3, lost):
    for method in ("ranks", "nullspace", "rref"):
        sets = assignable_sets(TRI, [beta3], method=method)
        assert sets == tuple((n,) for n in COLS[1:] if n != lost), method
        assert is_assignable(TRI, [lost], [[B3], [beta3]], method=method).tolist() == [True, False]


@pytest.mark.parametrize("name", ["w3.spin", "vy", "omega", "w1.spin", "w2.spin"])
@pytest.mark.parametrize("method", ["ranks", "nullspace", "rref"])
def test_null_vectors_of_c5(name, method):
    model = kinematic_model(TRI, [name], GENERIC[:, None], method=method)
    expected = np.stack([np.broadcast_to(x, GENERIC.shape) for x in null_vectors_c5(name, GENERIC)], -1)
    np.testing.assert_allclose(model.velocities(np.ones((len(GENERIC), 1))), expected, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize(("name", "oracle"), [
    ("w3.spin", (0, -0.092106, 0.032452, 0.758803, 1.083319, 1)),
    ("w1.spin", (0, -0.121383, 0.042767, 1, 1.427667, 1.317865)),
    ("w2.spin", (0, -0.085022, 0.029956, 0.700443, 1, 0.923089)),
    ("vy", (0, 1, -0.352328, -8.238362, -11.761638, -10.857044)),
    ("omega", (0, -2.838267, 1, 23.382669, 33.382669, 30.815189)),
])
def test_numeric_oracle_of_c5(name, oracle):
    np.testing.assert_allclose(kinematic_model(TRI, [name]).velocities([1.0]), oracle, atol=5e-7)


def test_rref_with_vx_last_frees_phi3():
    a = TRI.constraint_matrix()
    free = rref_free_columns(a, [1, 2, 3, 4, 5, 0])  # v_x placed last (C.5 first row)
    assert [COLS[i] for i in np.flatnonzero(free)] == ["w3.spin"]


def test_motion_constraints_of_c5():
    deltas = motion_constraints(TRI, GENERIC[:, None])
    np.testing.assert_allclose(deltas[:, 0], np.broadcast_to(np.diag([-1.0, 0, 0]), (5, 3, 3)), atol=1e-12)
    np.testing.assert_allclose(deltas[:, 1], deltas[:, 0], atol=1e-12)
    n = np.stack([np.cos(GENERIC), np.sin(GENERIC), L3 * np.cos(GENERIC)], -1)
    expected = -n[:, :, None] * n[:, None, :] / np.sum(n**2, -1)[:, None, None]
    np.testing.assert_allclose(deltas[:, 2], expected, atol=1e-12)


def test_actuated_inverse_and_sensed_direct_numbers_of_c5():
    exact = np.array(null_vectors_c5("w3.spin", B3), dtype=float)  # the feasible motion with phi3 = 1
    twist = exact[:3]
    np.testing.assert_allclose(twist, [0, -0.092106, 0.032452], atol=5e-7)
    for wheel, rate in (("w1", 0.758803), ("w2", 1.083319), ("w3", 1.0)):
        m = actuated_inverse_matrix(TRI, [f"{wheel}.spin"])  # (4.26), one wheel actuated
        np.testing.assert_allclose(m @ twist, [rate], atol=5e-7)
    sensed = ["w1.spin", "w2.spin"]
    q_s = exact[3:5]
    np.testing.assert_allclose(sensed_direct_matrix(TRI, sensed) @ q_s, twist, atol=1e-12)  # (4.32)
    full = sensed_full_matrix(TRI, sensed) @ q_s  # (4.31): twist, then (phi3, omega1, omega2, omega3)
    np.testing.assert_allclose(full, [*twist, 1.0, *[0.032452] * 3], atol=5e-7)


def test_actuation_tree_verdicts_of_c4():
    spins = ["w1.spin", "w2.spin", "w3.spin"]
    for size in range(4):
        for subset in itertools.combinations(spins, size):
            tree = actuation_tree(TRI, list(subset), GENERIC[:, None])
            expected = {0: "indeterminate", 1: "determined"}.get(size, "overdetermined")
            assert (tree.leaf == expected).all(), subset
            assert (tree.rank_a == (2 if size == 0 else 3)).all()
    analysis = actuation_analysis(TRI)
    assert analysis.actuated == ("w3.spin",) and analysis.steering == ("w3",)
    assert bool(analysis.consistent) and bool(analysis.sufficient)


def test_sensing_tree_verdicts_of_c4():
    spins = ["w1.spin", "w2.spin", "w3.spin"]
    for size in range(1, 4):
        for subset in itertools.combinations(spins, size):
            tree = sensing_tree(TRI, list(subset), GENERIC[:, None])
            assert (tree.leaf == ("determined" if size == 1 else "overdetermined")).all(), subset
    analysis = sensing_analysis(TRI)
    assert bool(analysis.sufficient) and bool(analysis.slip_detectable)


# ---- extended solutions (4.82)-(4.84) -------------------------------------------------------------------


def extended_c6(assigned, b, r=R, l12=L12, l3=L3):
    """The matrices (4.82) of C.6, rows (solved velocities in robot order), columns (assigned)."""
    c, s = np.cos(b), np.sin(b)
    if assigned == ("w1.spin", "w3.spin"):  # -> vx, vy, omega, phi2
        k = -r / (3 * l12**2 + 4 * l3**2)
        m = [[-l12 * l3, l12 * (l3 * c - l12 * s)],
             [2 * l3**2, (2 * l3**2 + 3 * l12**2) * c + 2 * l3 * l12 * s],
             [3 * l12, -3 * l12 * c - 4 * l3 * s],
             [(3 * l12**2 - 2 * l3**2) / r, -(2 * l3**2 + 6 * l12**2) * c / r - 6 * l3 * l12 * s / r]]
    elif assigned == ("w2.spin", "w3.spin"):  # -> vx, vy, omega, phi1
        k = -r / (3 * l12**2 + 4 * l3**2)
        m = [[l12 * l3, -l12 * (l3 * c + l12 * s)],
             [2 * l3**2, (2 * l3**2 + 3 * l12**2) * c - 2 * l3 * l12 * s],
             [-3 * l12, 3 * l12 * c - 4 * l3 * s],
             [(3 * l12**2 - 2 * l3**2) / r, -(2 * l3**2 + 6 * l12**2) * c / r + 6 * l3 * l12 * s / r]]
    elif assigned == ("w1.spin", "w2.spin"):  # -> vx, vy, omega, phi3
        k = -r / (6 * l12**2 + l3**2 * (1 + np.cos(2 * b)))
        m = [[-l12 * c * (l3 * c + l12 * s), l12 * c * (l3 * c - l12 * s)],
             [(l3**2 + 3 * l12**2) * c**2 - l3 * l12 * c * s + 2 * l12**2 * s**2,
              (l3**2 + 3 * l12**2) * c**2 + l3 * l12 * c * s + 2 * l12**2 * s**2],
             [3 * l12 - l3 * np.sin(2 * b) / 2, -3 * l12 - l3 * np.sin(2 * b) / 2],
             [-(l3**2 + 3 * l12**2) * c / r + 3 * l3 * l12 * s / r,
              -(l3**2 + 3 * l12**2) * c / r - 3 * l3 * l12 * s / r]]
    else:  # ("vy", "omega") -> vx, phi1, phi2, phi3
        q = 5 + np.cos(2 * b)
        k = -1 / (q * r)
        m = [[r * np.sin(2 * b), 2 * r * l3 * c**2], [q, l12 * q], [q, -l12 * q], [6 * c, -4 * l3 * s]]
    return k * np.array(m, dtype=float)


EXTENDED_SETS = [("w1.spin", "w3.spin"), ("w2.spin", "w3.spin"), ("w1.spin", "w2.spin"), ("vy", "omega")]


@pytest.mark.parametrize("assigned", EXTENDED_SETS, ids=str)
def test_extended_matrices_482(assigned):
    for b in GENERIC:
        matrix = extended_c6(assigned, b)
        for q in ([1.0, 0.0], [0.0, 1.0], [0.3, -2.0]):
            sol = extended_solution(TRI, assigned, q, [b])
            np.testing.assert_allclose(sol.values(sol.solved), matrix @ q, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize(("assigned", "result", "slip"), [
    (("w1.spin", "w3.spin"), (0.002223, -0.102777, 0.026894, 1.162236), 0.016043),
    (("w2.spin", "w3.spin"), (0.000768, -0.08842, 0.030532, 0.731542), 0.005542),
    (("w1.spin", "w2.spin"), (0.004548, -0.098077, 0.02183, 1.023075), 0.019611),
    (("vy", "omega"), (-0.483333, -15.0, -5.0, -6.419776), 1.252477),
], ids=str)
def test_extended_numbers_of_c6(assigned, result, slip):
    sol = extended_solution(TRI, assigned, [1.0, 1.0])
    np.testing.assert_allclose(sol.values(sol.solved), result, atol=5e-7)
    assert sol.slip == pytest.approx(slip, abs=5e-7)


def test_steering_conditions_483_phi1_phi2_corrected():
    rng = np.random.default_rng(3)
    q = rng.uniform(-3, 3, size=(20, 2))
    expected = np.arctan2(L3 * (q[:, 1] - q[:, 0]), L12 * (q[:, 0] + q[:, 1]))  # C.7, phi3 >= 0
    beta = solve_steering(TRI, ("w1.spin", "w2.spin"), q, expected[:, None] + 0.2)
    np.testing.assert_allclose(beta[:, 0], expected, atol=1e-7)
    sol = extended_solution(TRI, ("w1.spin", "w2.spin"), q, beta)
    assert (sol.values(["w3.spin"]) >= 0).all() and (sol.slip < 1e-9).all()


def test_steering_conditions_483_vy_omega():
    rng = np.random.default_rng(4)
    q = rng.uniform(-1, 1, size=(20, 2))
    expected = np.arctan2(-L3 * q[:, 1], q[:, 0])  # C.7, phi3 <= 0
    beta = solve_steering(TRI, ("vy", "omega"), q, expected[:, None] - 0.2)
    np.testing.assert_allclose(beta[:, 0], expected, atol=1e-7)
    assert (extended_solution(TRI, ("vy", "omega"), q, beta).values(["w3.spin"]) <= 0).all()


@pytest.mark.parametrize(("wheel", "sign"), [("w1.spin", -1), ("w2.spin", 1)])
def test_steering_conditions_483_with_phi3(wheel, sign):
    """C.7 general roots: beta3 = sign * atan2(l12, l3) +- acos(l3 phi_i / (sqrt(l3^2 + l12^2) phi3))."""
    rng = np.random.default_rng(5)
    phi3 = rng.uniform(0.5, 2, 10) * rng.choice([-1, 1], 10)
    phi_i = phi3 * rng.uniform(-0.9, 0.9, 10) * math.hypot(L3, L12) / L3
    arc = np.arccos(L3 * phi_i / (math.hypot(L3, L12) * phi3))
    roots = np.stack([sign * math.atan2(L12, L3) + arc, sign * math.atan2(L12, L3) - arc], -1)
    q = np.stack([phi_i, phi3], -1)
    for k in range(2):
        beta = solve_steering(TRI, (wheel, "w3.spin"), q, roots[:, k:k + 1] + 0.05)
        np.testing.assert_allclose(np.cos(beta[:, 0] - roots[:, k]), 1.0, atol=1e-12)
        assert (extended_solution(TRI, (wheel, "w3.spin"), q, beta).slip < 1e-9).all()


def test_simplified_extended_solutions_484():
    q = np.array([[2.0, 3.0], [-1.0, 0.5], [0.7, 0.2]])
    sol = no_slip_extended_solution(TRI, ("w1.spin", "w2.spin"), q)
    p1, p2 = q[:, 0], q[:, 1]
    expected = np.stack([0 * p1, -R * (p1 + p2) * L12, -R * (p1 - p2),
                         np.sqrt(L12**2 * (p1 + p2) ** 2 + L3**2 * (p1 - p2) ** 2)], -1) / (2 * L12)
    got = sol.values(sol.solved)
    np.testing.assert_allclose(got[:, :3], expected[:, :3], atol=1e-10)
    np.testing.assert_allclose(np.abs(got[:, 3]), expected[:, 3], atol=1e-10)  # the sign follows the beta branch
    np.testing.assert_allclose(sol.beta[0], [0.447520], atol=5e-7)
    np.testing.assert_allclose(got[0], (0, -0.25, 0.1, 2.773085), atol=5e-7)

    v = np.array([[0.3, 0.2], [-0.5, 0.1], [0.2, -0.4]])
    sol = no_slip_extended_solution(TRI, ("vy", "omega"), v, np.full((3, 1), -0.5))
    vy, om = v[:, 0], v[:, 1]
    expected = -np.stack([0 * vy, vy + L12 * om, vy - L12 * om, np.hypot(vy, L3 * om)], -1) / R
    got = sol.values(sol.solved)
    np.testing.assert_allclose(got[:, :3], expected[:, :3], atol=1e-10)
    np.testing.assert_allclose(np.abs(got[:, 3]), np.abs(expected[:, 3]), atol=1e-10)
    np.testing.assert_allclose(sol.beta[0], [-0.674741], atol=5e-7)
    np.testing.assert_allclose(got[0], (0, -4, -2, -3.841875), atol=5e-7)
    assert extended_solution(TRI, ("vy", "omega"), [0.3, 0.2], [0.1]).slip == pytest.approx(0.219800, abs=5e-7)


# ---- where the thesis text is wrong (docs/errata.md, chapter 4) -------------------------------------------


def test_483_printed_phi1_phi2_condition_is_not_a_root():
    """001 prints beta3 = atan((l3 phi2 - phi1) / (l12 phi2 + phi1)); the root is atan2(l3 (phi2 - phi1), ...)."""
    for p1, p2 in [(2.0, 3.0), (1.0, -0.5), (0.3, 0.9)]:
        printed = math.atan((L3 * p2 - p1) / (L12 * p2 + p1))
        corrected = math.atan2(L3 * (p2 - p1), L12 * (p1 + p2))
        assert extended_solution(TRI, ("w1.spin", "w2.spin"), [p1, p2], [printed]).slip > 1e-3
        assert extended_solution(TRI, ("w1.spin", "w2.spin"), [p1, p2], [corrected]).slip < 1e-12


@pytest.mark.parametrize(("phi_i", "phi3"), [(0.5, 1.0), (-0.7, 1.5), (1.0, 1.2), (0.5, -1.0), (-0.7, -1.5)])
def test_483_printed_acos_branches_are_roots_only_for_negative_phi3(phi_i, phi3):
    big = L3**2 + L12**2
    s = math.sqrt(big * phi3**2 - L3**2 * phi_i**2)
    printed = {
        ("w1.spin", "w3.spin"): [-math.acos((L3**2 * phi_i + L12 * s) / (big * phi3)),
                                 math.acos((L3**2 * phi_i - L12 * s) / (big * phi3))],
        ("w2.spin", "w3.spin"): [-math.acos((L3**2 * phi_i - L12 * s) / (big * phi3)),
                                 math.acos((L3**2 * phi_i + L12 * s) / (big * phi3))],
    }
    for assigned, branches in printed.items():
        slips = [float(extended_solution(TRI, assigned, [phi_i, phi3], [b]).slip) for b in branches]
        if phi3 < 0:
            assert max(slips) < 1e-12
        else:
            assert min(slips) > 1e-3


def test_431_needs_the_transposed_product_and_sufficient_sensors():
    """(4.31) prints (I_ns I_ns^T)^-1: I_ns is tall (9 x 7 here) so that product is singular; with no sensor
    at all I_ns is 9 x 9 of rank 8 and not invertible either ("always pseudo-invertible" is false)."""
    i_bar, j = TRI.jacobian_form()
    i_ns = np.concatenate([i_bar, -j[:, [2, 3, 4, 5]]], axis=1)  # sensors phi1, phi2
    assert i_ns.shape == (9, 7) and matrix_rank(i_ns @ i_ns.T) == 7 < 9
    assert matrix_rank(i_ns.T @ i_ns) == 7
    # wmrkit's (4.31) is the least-squares solution with (I_ns^T I_ns)^-1 (the printed order cannot be inverted)
    expected = np.linalg.solve(i_ns.T @ i_ns, i_ns.T @ j[:, [0, 1]])
    np.testing.assert_allclose(sensed_full_matrix(TRI, ["w1.spin", "w2.spin"]), expected, atol=1e-12)
    none_sensed = np.concatenate([i_bar, -j], axis=1)
    assert none_sensed.shape == (9, 9) and matrix_rank(none_sensed) == 8
    assert not bool(sensing_analysis(TRI, sensed=[]).sufficient)
