"""The extended solutions judge a gear's assigned rates with ik's floor, row by row, as ``fk`` judges its rates.

Before: ``extended_solution(CART, ['left.spin', 'right.spin'], [[1e-320, 0.0]]).in_gear`` was ``[[False]]`` with a
GearWarning "100% apart" (CART: two fixed wheels on one axle, spins geared 1:1, and a castor): the assigned rows were
judged relatively only (``GEAR_EXACT_RTOL``). Checked against the cart's closed form: spins ``a`` and ``-a`` on a 1:1
gear have the least-squares turn 0, so each contact departs from the gear by ``a r``; at robot scales 1e-3, 1 and
1e3, departures of 0.5 and 0.9 ``SLIP_TOL`` hold and 1.1 and 2 ``SLIP_TOL`` break the gear, each row on its own.
"""

from __future__ import annotations

import warnings

import pytest
import yaml
from test_fk_gear_floor import FLOORS
from test_gear_check_doors import SCALES, cart, scaled

from geared import STEERED, R, cart_yaml
from wmrkit import Robot
from wmrkit.couplings import GearWarning
from wmrkit.errors import SingularError
from wmrkit.kinematics.extended import extended_solution, solve_steering
from wmrkit.kinematics.wheel_ik import SLIP_TOL

SPINS = ["left.spin", "right.spin"]


def judged(robot, names, q) -> tuple[list, int]:
    """``(in_gear as a list, number of GearWarnings)`` of extended_solution on `q`."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = extended_solution(robot, names, q)
    return sol.in_gear.tolist(), sum(issubclass(w.category, GearWarning) for w in caught)


@pytest.mark.parametrize("right", [0.0, -1e-320, 1e-320, 2e-320])
def test_tiny_assigned_rates_are_in_the_gear(right):
    assert judged(cart(1.0), SPINS, [[1e-320, right]]) == ([[True]], 0)


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize(("f", "holds"), FLOORS)
def test_extended_gear_floor_is_the_contact_speed(s, f, holds):
    a = f * SLIP_TOL / (R * s)  # each contact a r s off the gear's turn 0
    assert judged(scaled(cart(1.0), s), SPINS, [[a, -a]]) == ([[holds]], 0 if holds else 1)


@pytest.mark.parametrize("s", SCALES)
def test_each_row_is_judged_on_its_own(s):
    """A row within the floor holds beside rows that break the gear (1 rad/s apart, 2 SLIP_TOL at the contacts),
    whichever row is the largest: one warning for the gear."""
    a = SLIP_TOL / (R * s)
    q = [[1e-320, 0.0], [0.9 * a, -0.9 * a], [1.0, 0.0], [2 * a, -2 * a], [3.0, 3.0]]
    assert judged(scaled(cart(1.0), s), SPINS, q) == ([[True], [True], [False], [False], [True]], 1)


def test_a_real_departure_is_caught_with_other_assigned_rates():
    """5 % out of a 1:2 gear with the castor's spin also assigned: breaks the gear at 1e-6..10 m/s."""
    robot = cart(2.0)
    for v in (1e-6, 1.0, 10.0):
        u = v / R
        rows, said = judged(robot, [*SPINS, "caster.spin"], [[u, 2 * u * 1.05, 0.0]])
        assert (rows, said) == ([[False]], 1)


def test_solve_steering_judges_its_rates_by_the_same_rule():
    """solve_steering warns as extended_solution does: not on 1e-320 and 0 (a root), on 1 and 0 (no root here)."""
    robot = Robot.from_dict(yaml.safe_load(cart_yaml(1.0, STEERED)))
    names = [*SPINS, "front.spin"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        solve_steering(robot, names, [1e-320, 0.0, 0.0])
    assert not [w for w in caught if issubclass(w.category, GearWarning)]
    with pytest.warns(GearWarning, match="100% apart"), pytest.raises(SingularError):
        solve_steering(robot, names, [1.0, 0.0, 0.0])
