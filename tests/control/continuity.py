"""Table 8.1's continuity verdict alone, for the tests of its jumps: :func:`feasibility` without the steering stops'
tight turns (``TightTurn``: tests/control/test_tight_turns.py). Those tests drive the catalog car on shapes tighter
than its stops allow (the 3 m circle, clothoids to 1 1/m) to judge their continuity."""

from __future__ import annotations

from wmrkit.control.feasibility import Feasibility, TightTurn
from wmrkit.control.feasibility import feasibility as judged


def feasibility(robot, reference, framework="kinematic", **options) -> Feasibility:
    """:func:`wmrkit.control.feasibility.feasibility` with its Table 8.1 violations only."""
    got = judged(robot, reference, framework, **options)
    return Feasibility(got.requirement, tuple(v for v in got.violations if not isinstance(v, TightTurn)))
