"""Issue 9: the combinatorial searches of chapter 4 are bounded, pruned without losing sets, and say when they stop."""

from __future__ import annotations

import itertools
import math

import numpy as np

from wmrkit.description import robot_from_dict
from wmrkit.kinematics import assignable_sets, is_assignable, minimal_actuator_sets
from wmrkit.kinematics.search import MAX_MINIMAL_SETS, WALK_WORK, search_sets


def _brute(n: int, size: int, good) -> list[tuple[int, ...]]:
    return [s for s in itertools.combinations(range(n), size) if good(s)]


def test_a_search_finds_what_brute_force_finds_in_order_with_or_without_a_prefilter():
    good = lambda s: sum(s) % 3 == 0  # noqa: E731
    exact = lambda sets: np.array([good(tuple(s)) for s in sets], dtype=bool)  # noqa: E731
    prefilter = lambda sets: sets.sum(axis=1) % 3 != 1  # noqa: E731  (necessary: keeps every good set)
    expected = _brute(30, 3, good)  # C(30, 3) = 4060 candidates: pruned
    for pre in (None, prefilter):
        found, complete, note = search_sets(range(30), 3, exact, prefilter=pre, limit=10_000)
        assert found == expected and complete and note == ""


def test_a_search_stops_at_its_limit_and_says_so():
    found, complete, note = search_sets(range(20), 2, lambda s: np.ones(len(s), bool), limit=50)
    assert found == list(itertools.combinations(range(20), 2))[:50]
    assert not complete and note == "more than 50 sets (the first 50 listed)"


def test_a_search_stops_when_its_exact_budget_is_spent():
    calls = []

    def exact(sets):
        calls.append(len(sets))
        return np.zeros(len(sets), bool)

    found, complete, note = search_sets(range(40), 3, exact, max_exact=100)
    assert found == [] and not complete and sum(calls) == 100 and "after 100 exact tests" in note


def _castors(n: int):
    wheels = [{"name": f"c{i}", "type": "castor", "l": 0.3, "alpha": 2 * math.pi * i / n, "d": 0.05, "r": 0.05,
               "actuated": ["spin"], "sensed": ["spin"]} for i in range(n)]
    return robot_from_dict({"name": "castors", "wheels": wheels})


def test_large_robots_get_a_bounded_list_of_true_sets():
    robot = _castors(12)  # k = 27 velocities, m = 3: 2,925 candidate sets
    sets = assignable_sets(robot)
    assert len(sets) == 1000 and not sets.complete and "more than 1000" in sets.note
    names = np.array(sets)
    assert all(is_assignable(robot, list(s), method="nullspace") for s in names[::37])  # another method agrees
    minimal = minimal_actuator_sets(robot)
    assert len(minimal) == MAX_MINIMAL_SETS and not minimal.complete
    assert all(is_assignable(robot, [n for n in s if n.endswith(".spin") or n.endswith(".steer")],
                             method="rref") for s in minimal[:5])


def test_small_robots_are_searched_completely():
    sets = assignable_sets(_castors(3))  # C(9, 3) = 84 candidates: no pruning, no bound reached
    assert sets.complete and sets.note == "" and len(sets) == len(set(sets))


def test_the_prefilter_walk_stops_when_its_work_is_spent_and_says_so():
    """Each candidate costs the prefilter an m x m SVD per configuration: 8 double wheels (m = 9, self-motions)
    walked a million candidates per search and `wmrkit kinematics` took 83 s (16 wheels: over 5 min)."""
    walked = []

    def prefilter(sets):
        walked.append(len(sets))
        return np.zeros(len(sets), bool)

    found, complete, note = search_sets(range(60), 10, lambda s: np.ones(len(s), bool), prefilter=prefilter,
                                        walk_cost=WALK_WORK / 1000)
    assert found == [] and not complete and sum(walked) == 1000
    assert note == f"search stopped after 1000 of {math.comb(60, 10)} candidate sets (docs/limits.md)"


def test_a_robot_of_double_wheels_is_searched_within_the_walk_budget(monkeypatch):
    from wmrkit.kinematics import models, search
    from wmrkit.kinematics.models import generically_assignable_sets

    wheels = [{"name": f"d{i}", "type": "double", "l": 0.5, "alpha": 2 * math.pi * i / 8, "b": 0.02, "r": 0.05,
               "heading": 0} for i in range(8)]
    robot = robot_from_dict({"name": "doubles", "wheels": wheels})  # k = 27, generic m = 8: 2,220,075 sets
    walked = []

    def counting(a, m, offset=0, every=True):  # the depth-first walk's work: its rank tests (PrunedCombinations)
        test = search.null_space_prefilter(a, m, offset, every)
        rows, cost = test.rows, search.null_space_cost(a.shape, m)

        def count(cols):
            walked.append(cost)
            assert sum(walked) <= WALK_WORK + cost, "walk not bounded"
            return rows(cols)
        test.rows = count
        return test

    monkeypatch.setattr(models, "null_space_prefilter", counting)
    sets = generically_assignable_sets(robot)
    assert walked and not sets.complete and "search stopped after" in sets.note


def test_a_search_stopped_before_a_set_is_found_does_not_claim_there_is_none(monkeypatch):
    """With the walk's budget spent before any set was found, the default direct model of 8 double wheels said
    'no set of 9 wheel rates can be assigned', a false claim (the search had seen 73,728 of 1.3 million sets)."""
    import pytest

    from wmrkit.errors import SingularError
    from wmrkit.kinematics import direct_model, inverse_model, search

    robot = _castors(4)  # assignable sets exist
    assert direct_model(robot).assigned and inverse_model(robot).assigned
    monkeypatch.setattr(search, "PRUNE_FROM", 0)
    monkeypatch.setattr(search, "MAX_CANDIDATES", 1)  # the walk stops after one candidate, which the prefilter drops
    monkeypatch.setattr(search, "BATCH", 1)

    def nothing(a, m, offset=0):
        return lambda sets: np.zeros(len(sets), bool)

    from wmrkit.kinematics import models
    monkeypatch.setattr(models, "null_space_prefilter", nothing)
    with pytest.raises(SingularError, match=r"no set of \d+ wheel rates was found assignable at .* before the search "
                                            r"stopped after 1 of \d+ candidate sets \(docs/limits\.md\); name the"):
        direct_model(robot)
