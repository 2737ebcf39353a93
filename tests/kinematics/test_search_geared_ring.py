"""A ring of 16 double wheels whose neighbours' spins and steering turn on gears (m = 8 with them): its assignable
sets are the 6**8 picks of one rate per geared pair, none of them with a twist component (the body cannot move).

Before: the lexicographic walk spent its budget (98,304 of C(51, 8) candidates) on sets holding two rates of the
first pair, so `kinematics` listed "assignable sets (0)", no direct model and no minimal actuator or sensor set.
The brute force here is the null space of the slip matrix with each gear's rows (tests/geared.py).
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
from scipy.linalg import null_space

from wmrkit.cli.main import main
from wmrkit.description import robot_from_dict
from wmrkit.errors import SingularError
from wmrkit.kinematics import (
    assignable_sets,
    direct_model,
    generically_assignable_sets,
    inverse_model,
    minimal_actuator_sets,
)
from wmrkit.kinematics.models import generic_configurations

from ..geared import held_constraints


def _ring(n: int = 16, own: bool = False):
    return robot_from_dict(_ring_dict(n, own))


def _ring_dict(n: int, own: bool) -> dict:
    """Neighbours' spins and steering on gears; `own`: each wheel's spins at 1:k (k = 1, 2, 3) and the pairs'
    steering, which lock it (m = 0; /tmp/s30h17_work/r16own.yaml)."""
    wheels = [{"name": f"w{i}", "type": "double", "position": [0.5 * math.cos(a), 0.5 * math.sin(a)], "heading": a,
               "b": 0.05, "r": 0.05, "actuated": ["spin1"], "sensed": ["spin1", "steer"]}
              for i, a in enumerate(2 * math.pi * np.arange(n) / n)]
    gears = [{"kind": "gear", "joints": [f"w{i}.{j}", f"w{i + 1}.{j}"]} for i in range(0, n, 2)
             for j in (("steer",) if own else ("spin1", "spin2", "steer"))]
    if own:
        gears += [{"kind": "gear", "joints": [f"w{i}.spin1", f"w{i}.spin2"], "ratios": [1, i % 3 + 1]}
                  for i in range(n)]
    return {"name": "ring", "wheels": wheels, "couplings": gears}


def _brute(robot):
    basis = null_space(held_constraints(robot))
    full = lambda s: np.linalg.matrix_rank(basis[list(s)], tol=1e-9) == basis.shape[1]  # noqa: E731
    first, rank = [], 0  # the lexicographically first basis of the row matroid is the greedy one
    for i in range(basis.shape[0]):
        if np.linalg.matrix_rank(basis[[*first, i]], tol=1e-9) > rank:
            first, rank = [*first, i], rank + 1
    return basis, full, tuple(first)


def test_the_geared_ring_has_assignable_sets_and_a_direct_model_as_the_brute_force_says():
    robot = _ring()
    basis, full, first = _brute(robot)
    assert basis.shape[1] == 8 and np.abs(basis[:3]).max() < 1e-12  # m = 8, the body at rest
    names = robot.velocity_names
    sets = assignable_sets(robot)
    assert len(sets) > 0
    assert sets[0] == tuple(names[i] for i in first)
    assert all(full([names.index(v) for v in s]) for s in sets)
    model = direct_model(robot)
    assert model.assigned == tuple(names[i] for i in first)
    q = np.random.default_rng(1).normal(size=8)
    expected = basis @ np.linalg.solve(basis[list(first)], q)  # the null-space motion with those rates
    assert np.allclose(model.velocities(q), expected, atol=1e-9)
    assert len(minimal_actuator_sets(robot)) > 0


def test_the_generically_assignable_sets_of_the_geared_ring_walk_the_pruned_tree():
    """Before: the lexicographic walk spent its budget on sets holding two rates of the first pair and listed none
    ("search stopped after 32768 of 636763050 candidate generically assignable sets"). Brute force at the generic
    samples: a set is generically assignable when its null-space rows have full rank at one of them at least, and
    the first such set is the smallest of the samples' greedy first bases."""
    robot = _ring()
    names, sets = robot.velocity_names, generically_assignable_sets(robot)
    samples = [null_space(held_constraints(robot, beta)) for beta in generic_configurations(robot)]
    firsts = []
    for basis in samples:
        first, rank = [], 0
        for i in range(basis.shape[0]):
            if np.linalg.matrix_rank(basis[[*first, i]], tol=1e-9) > rank:
                first, rank = [*first, i], rank + 1
        firsts.append(tuple(first))
    assert len(sets) > 0 and "exact tests" in sets.note  # the walk reached candidates; the exact budget ended it
    assert sets[0] == tuple(names[i] for i in min(firsts))
    assert list(sets) == sorted(set(sets), key=lambda s: [names.index(v) for v in s])
    assert all(any(np.linalg.matrix_rank(b[[names.index(v) for v in s]], tol=1e-9) == 8 for b in samples)
               for s in sets)


def test_the_inverse_model_of_the_geared_ring_says_why_no_twist_can_be_assigned():
    with pytest.raises(SingularError, match=r"no set of \(vx, vy, omega\) with w0\.steer, .* the body cannot move "
                                            r"\(its 8 degrees of freedom move the joints with the body at rest"):
        inverse_model(_ring())


def test_the_inverse_model_of_a_locked_ring_says_the_robot_cannot_move_as_the_direct_model(tmp_path, capsys):
    """Before: the inverse model said "no set of (vx, vy, omega) with w0.steer, w2.steer, ..., w14.steer can be
    assigned", naming steering rates the gears lock, while the direct model said the robot cannot move."""
    robot = _ring(own=True)
    assert null_space(held_constraints(robot)).shape[1] == 0  # the brute force: nothing moves
    model = inverse_model(robot)
    assert model.assigned == () and np.array_equal(model.velocities(np.zeros(0)), np.zeros(len(robot.velocity_names)))
    assert model.kind == direct_model(robot).kind == "none"  # nothing assigned: was "inverse" (all([]) is True)
    path = tmp_path / "locked.yaml"
    path.write_text(json.dumps(_ring_dict(16, own=True)))
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    stuck = "    the robot cannot move (m = 0): every velocity is zero\n"
    assert f"  direct model:\n{stuck}  inverse model:\n{stuck}" in out and "no set of" not in out
    assert main(["kinematics", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["coupled_mobility"] == 0 and data["inverse_model"]["assigned"] == data["direct_model"]["assigned"] == []
    assert data["inverse_model"]["kind"] == data["direct_model"]["kind"] == "none"


@pytest.mark.parametrize("seed", range(6))
def test_the_pruned_walk_yields_exactly_the_sets_of_independent_rows_in_order(seed):
    """Against itertools over every candidate: random rows with repeated, parallel and zero rows, 1 or 2
    configurations (a set must be independent at each, or with ``every=False`` at one at least: the generic sets)."""
    from wmrkit.kinematics.search import PrunedCombinations

    rng = np.random.default_rng(seed)
    k, m = 11, 4
    rows = rng.normal(size=(2, k, m))
    rows[:, 3] = 2 * rows[:, 1]
    rows[:, 5] = 0
    rows[1, 7] = rows[1, 0] - rows[1, 2]
    basis = rows / np.linalg.norm(rows, axis=(-2, -1), keepdims=True)  # singular values <= 1, as an orthonormal basis's
    for b, every in itertools.product((basis[:1], basis), (True, False)):  # not every: at one configuration at least
        good = [s for s in itertools.combinations(range(k), m)
                if (all if every else any)(np.linalg.svd(x[list(s)], compute_uv=False)[-1] > 1e-9 * m for x in b)]
        walk = PrunedCombinations(range(k), m, lambda cols, b=b: b[:, list(cols)], budget=10**9, every=every)
        assert list(walk) == good and walk.covered == math.comb(k, m)


def _held_spins(n: int, held: list[int], ratio: float = 2.0, steer_gear: bool = False):
    """A ring of `n` double wheels, the spins of the wheels `held` geared at 1:ratio (a wheel turns on the spot only
    with ratio -1), and with `steer_gear` the steering of w0 and w1 on a gear."""
    wheels = [{"name": f"w{i}", "type": "double", "position": [0.5 * math.cos(a), 0.5 * math.sin(a)], "heading": a,
               "b": 0.05, "r": 0.05} for i, a in enumerate(2 * math.pi * np.arange(n) / n)]
    gears = [{"kind": "gear", "joints": [f"w{i}.spin1", f"w{i}.spin2"], "ratios": [1, ratio]} for i in held]
    gears += [{"kind": "gear", "joints": ["w0.steer", "w1.steer"]}] if steer_gear else []
    return robot_from_dict({"name": "held", "wheels": wheels, "couplings": gears})


@pytest.mark.parametrize("args", [(2, [0, 1]), (2, [0]), (3, [0]), (4, [0, 1]), (4, [1, 2], 2.0, True),
                                  (4, [0, 1, 2, 3], -1.0)], ids=str)
def test_the_inverse_model_assigns_only_the_steering_rates_the_gears_leave_free(args):
    """A double wheel whose spins a gear holds at 1:2 cannot turn on the spot: its steering rate turns with the
    twist. Before: the inverse model of two such wheels (m = 1, the body rolls) said "no set of (vx, vy, omega)
    with w0.steer, w1.steer can be assigned"; with the body at rest it named steering rates the gears lock.
    Brute force (tests/geared.py): N, the null space with the gears' rows; the twist's rows have rank g."""
    robot = _held_spins(*args)
    basis = null_space(held_constraints(robot))
    g, names = np.linalg.matrix_rank(basis[:3], tol=1e-9), robot.velocity_names
    moving = [n for n in robot.free_steering if np.abs(basis[names.index(n)]).max() > 1e-9]
    if g == 0:  # the body cannot move: the message names the steering rates that do
        with pytest.raises(SingularError, match=r"the body cannot move") as err:
            inverse_model(robot)
        named = str(err.value).split(" with ")[1].split(" can be assigned")[0].split(", ")
        assert named == moving
        return
    model = inverse_model(robot)
    twist = [n for n in model.assigned if n in ("vx", "vy", "omega")]
    assert len(twist) == g and len(model.assigned) == basis.shape[1]
    assert np.linalg.matrix_rank(basis[[names.index(n) for n in model.assigned]], tol=1e-9) == basis.shape[1]
    q = model.velocities(np.random.default_rng(2).normal(size=len(model.assigned)))
    assert np.abs(held_constraints(robot) @ q).max() < 1e-9 * np.abs(q).max()
