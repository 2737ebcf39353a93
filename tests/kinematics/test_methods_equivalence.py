"""The three methods of chapter 4 agree on random robots of every wheel type (digest PART D, oracles 5-9, 12).

Random robots come from ``conftest.robots`` (regular wheels of all types). Rank decisions near a singular
configuration depend on tolerances, so examples whose singular values come close to the rank threshold are
skipped with ``assume``: the properties are about generic configurations.
"""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from strategies import robots, wheels
from wmrkit import Robot
from wmrkit.kinematics.actuation import actuated_inverse_matrix, actuation_equation, actuation_tree
from wmrkit.kinematics.linalg import delta_projector, matrix_rank
from wmrkit.kinematics.models import assignable_sets, kinematic_model, mobility
from wmrkit.kinematics.nullspace import null_space_basis, null_space_solution, rref_solution
from wmrkit.kinematics.ranks import ranks_solution
from wmrkit.kinematics.sensing import sensed_direct_matrix, sensed_full_matrix, sensing_tree
from wmrkit.kinematics.trees import (
    contact_blocks,
    independent_wheel_rates,
    jacobian_names,
    vehicle_dof,
    wheel_jacobians,
)

EXAMPLES = settings(max_examples=200)


def clear_ranks(*matrices: np.ndarray) -> bool:
    """No singular value between 1e-13 and 1e-4 (times the scale): ranks are decided with a wide margin."""
    for m in matrices:
        if m.size == 0:
            continue
        s = np.linalg.svd(m, compute_uv=False)
        scale = max(float(s.max(initial=0.0)), 1.0)
        if np.any((s > 1e-13 * scale) & (s < 1e-4 * scale)):
            return False
    return True


ONE_CONTACT = ["fixed", "steerable", "castor", "swedish", "ball", "orthogonal"]


@st.composite
def one_contact_robots(draw, max_wheels: int = 4) -> Robot:
    """Random robots whose wheels touch the ground at one point each (J block diagonal, 4.20)."""
    n = draw(st.integers(1, max_wheels))
    return Robot("r", tuple(draw(wheels(draw(st.sampled_from(ONE_CONTACT)), name=f"w{i}")) for i in range(n)))


@EXAMPLES
@given(robots())
def test_h_equals_g_equals_m(robot):
    """(4.75): H (4.19) = G (4.22) = m (4.3), and the rank identities (4.69), (4.73).

    A double wheel (two singular castors sharing the steering, §3.5.1) breaks (4.69): its steering turns by
    differential spin without moving the robot (3.29), a self-motion that m counts and G (a count of twist
    DOF) does not; then G = m - (dim q_w - rank J).
    """
    a = robot.constraint_matrix()
    i_bar, j = robot.jacobian_form()
    assume(clear_ranks(a, j, np.concatenate([i_bar, j], -1)))
    m = int(mobility(robot))
    assert int(independent_wheel_rates(robot)) == m
    self_motions = j.shape[-1] - int(matrix_rank(j))
    assert int(vehicle_dof(robot)) == m - self_motions
    has_double = any(w.type == "double" for w in robot.wheels)
    assert self_motions == 0 or has_double  # (4.69) for every other wheel type
    contacts = len(contact_blocks(robot))
    assert matrix_rank(np.concatenate([i_bar, j], -1)) == matrix_rank(a) + contacts  # (4.73)


@EXAMPLES
@given(robots())
def test_three_methods_agree_on_every_set(robot):
    """Ranks (4.10)/(4.11), null space (4.5) and RREF (4.6) give the same sets and the same models."""
    a = robot.constraint_matrix()
    k, m = a.shape[-1], int(mobility(robot))
    assume(clear_ranks(a))
    sets = set()
    for subset in itertools.combinations(range(k), m):
        rest = [c for c in range(k) if c not in subset]
        if not clear_ranks(a[:, rest], null_space_basis(a, m)[list(subset)]):
            continue
        by_ranks = bool(matrix_rank(a[:, rest]) == matrix_rank(a))
        matrix_ns, ok_ns = null_space_solution(a, subset)
        matrix_rref, ok_rref = rref_solution(a, subset)
        assert bool(ok_ns) == by_ranks and bool(ok_rref) == by_ranks, subset
        if by_ranks:
            sets.add(tuple(robot.velocity_names[c] for c in subset))
            matrix = ranks_solution(a, subset)
            np.testing.assert_allclose(matrix_ns, matrix, rtol=1e-7, atol=1e-7)
            np.testing.assert_allclose(matrix_rref, matrix, rtol=1e-7, atol=1e-7)
    found = set(assignable_sets(robot))
    assert sets <= found


@EXAMPLES
@given(robots(), st.data())
def test_models_have_zero_slip(robot, data):
    """Every model's velocities satisfy A q_dot = 0 (4.1) to round-off, for a batch of assigned values."""
    sets = assignable_sets(robot)
    a = robot.constraint_matrix()
    assume(sets and clear_ranks(a))
    assigned = data.draw(st.sampled_from(sets))
    model = kinematic_model(robot, assigned)
    q_dot = model.velocities(np.random.default_rng(0).normal(size=(4, len(assigned))))
    scale = np.abs(a).max() * np.abs(q_dot).max(axis=-1, keepdims=True)
    assert np.all(np.abs(robot.slip_velocity(q_dot)) <= 1e-10 * scale)


@EXAMPLES
@given(one_contact_robots())
def test_delta_of_the_composite_jacobian_is_the_stack_of_the_wheels(robot):
    """(4.20): Delta(J) I_bar = [Delta(J_1); ...; Delta(J_N)] when every wheel has one contact."""
    i_bar, j = robot.jacobian_form()
    stacked = np.concatenate([delta_projector(ji) for ji in wheel_jacobians(robot)], axis=0)
    np.testing.assert_allclose(delta_projector(j) @ i_bar, stacked, atol=1e-9)


def test_delta_properties_417_and_466():
    assert np.array_equal(delta_projector(np.zeros((3, 0))), -np.eye(3))  # empty: -I
    np.testing.assert_allclose(delta_projector(np.zeros((3, 2))), -np.eye(3))  # zero matrix: -I (4.17)
    square = np.random.default_rng(1).normal(size=(3, 3))
    np.testing.assert_allclose(delta_projector(square), 0, atol=1e-12)
    for n in (1, 2, 4):  # (4.66): Delta(I_bar) = ones-blocks / N - I, since I_bar^T I_bar = N I
        i_bar = np.tile(np.eye(3), (n, 1))
        np.testing.assert_allclose(delta_projector(i_bar), np.kron(np.ones((n, n)), np.eye(3)) / n - np.eye(3 * n),
                                   atol=1e-12)


@EXAMPLES
@given(robots(), st.data())
def test_actuation_tree_agrees_with_the_ranks_method(robot, data):
    """B.3.8: Fig. 4.4 gives 'determined' with rank I_u = 3 iff |u| = m and rank A_na = rank A (4.10).

    For robots without the self-motion of a double wheel (rank J = dim q_w, 4.69).
    """
    a = robot.constraint_matrix()
    _, j = robot.jacobian_form()
    assume(matrix_rank(j) == j.shape[-1])
    usable = [n for n in robot.rate_names if not n.endswith(".roller")]
    chosen = data.draw(st.lists(st.sampled_from(usable), unique=True, max_size=4)) if usable else []
    i_u, j_u = actuation_equation(robot, chosen)
    cols = [robot.velocity_index(n) for n in chosen]
    rest = [c for c in range(a.shape[-1]) if c not in cols]
    assume(clear_ranks(a, a[:, rest], i_u, np.concatenate([i_u, j_u], -1)))
    tree = actuation_tree(robot, chosen)
    by_tree = tree.leaf == "determined" and tree.rank_a == 3
    by_ranks = len(chosen) == int(mobility(robot)) and matrix_rank(a[:, rest]) == matrix_rank(a)
    assert by_tree == by_ranks
    sensed = sensing_tree(robot, chosen)  # the same matrices, another meaning (§4.4.7)
    assert sensed.leaf == tree.leaf


@EXAMPLES
@given(one_contact_robots(), st.data())
def test_actuated_inverse_426_is_least_squares_425_per_wheel(robot, data):
    """(4.26) per wheel (thesis form) = the global least squares (4.25), for any twist."""
    usable = [n for n in robot.rate_names if not n.endswith(".roller")]
    chosen = data.draw(st.lists(st.sampled_from(usable), unique=True)) if usable else []
    twist = np.array([0.3, -0.2, 0.5])
    names = jacobian_names(robot)
    cols = sorted(names.index(n) for n in chosen)
    i_bar, j = robot.jacobian_form()
    j_p = np.concatenate([j[:, cols], j[:, [c for c in range(j.shape[1]) if c not in cols]]], axis=1)
    least_squares = np.linalg.lstsq(j_p, i_bar @ twist, rcond=None)[0][: len(cols)]
    per_wheel = np.zeros(len(cols))
    for ji, (_, block_cols) in zip(wheel_jacobians(robot), contact_blocks(robot), strict=True):
        u = [p for p, c in enumerate(block_cols) if c in cols]
        nu = [p for p, c in enumerate(block_cols) if c not in cols]
        if not u:
            continue
        weight = ji[:, u].T @ delta_projector(ji[:, nu])
        per_wheel[[cols.index(block_cols[p]) for p in u]] = np.linalg.solve(weight @ ji[:, u], weight @ twist)
    np.testing.assert_allclose(actuated_inverse_matrix(robot, chosen) @ twist, least_squares, atol=1e-8)
    np.testing.assert_allclose(per_wheel, least_squares, atol=1e-8)


@EXAMPLES
@given(one_contact_robots(), st.data())
def test_reduced_sensed_direct_432_is_the_twist_of_431(robot, data):
    """(4.32) in the thesis's per-wheel form = the first three rows of (4.31), with sufficient sensors."""
    usable = [n for n in robot.rate_names if not n.endswith(".roller")]
    chosen = data.draw(st.lists(st.sampled_from(usable), unique=True, min_size=len(usable) // 2))
    names = jacobian_names(robot)
    cols = sorted(names.index(n) for n in chosen)
    tree = sensing_tree(robot, chosen)
    assume(tree.rank_a == 3)
    total, blocks = np.zeros((3, 3)), []
    for ji, (_, block_cols) in zip(wheel_jacobians(robot), contact_blocks(robot), strict=True):
        s = [p for p, c in enumerate(block_cols) if c in cols]
        d = delta_projector(ji[:, [p for p, c in enumerate(block_cols) if c not in cols]])
        total += d
        blocks.append(d @ ji[:, s])
    i_bar, j = robot.jacobian_form()
    i_ns = np.concatenate([i_bar, -j[:, [c for c in range(j.shape[1]) if c not in cols]]], axis=1)
    assume(clear_ranks(total, i_ns))
    thesis = np.linalg.solve(total, np.concatenate(blocks, axis=1))
    np.testing.assert_allclose(sensed_direct_matrix(robot, chosen), thesis, atol=1e-8)
    np.testing.assert_allclose(sensed_full_matrix(robot, chosen)[:3], thesis, atol=1e-8)
