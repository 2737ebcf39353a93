"""``fk`` judges a gear's given rates with ik's floor.

Before: ``wmrkit fk CART --spin left=1e-320 --spin right=0`` (CART: two fixed wheels on one axle, spins geared 1:1,
and a castor) warned "100% apart" and printed "residual 0 m/s (INCONSISTENT)": fk judged a gear relatively only
(``GEAR_EXACT_RTOL``), while ik's ``gear_check`` holds a departure whose contact speed is within ``SLIP_TOL``. Checked
against the closed form of the cart: spins ``a`` and ``-a`` on a 1:1 gear have the least-squares turn 0, so each
contact departs from the gear by ``a r``; at robot scales 1e-3, 1 and 1e3, departures of 0.5 and 0.9 ``SLIP_TOL``
pass and 1.1 and 2 ``SLIP_TOL`` (and rates 5 % out of a 1:2 gear) warn.
On a gear with joints not given, the floor is judged over the given ones.
"""

from __future__ import annotations

import json
import warnings

import pytest
import yaml
from test_gear_check_doors import SCALES, cart, scaled

from geared import SYNCHRO, R, cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.couplings import GearWarning
from wmrkit.kinematics.wheel_ik import SLIP_TOL, forward_kinematics_check

GEAR = "gear(left.spin, right.spin)"
FLOORS = [(0.5, True), (0.9, True), (1.1, False), (2.0, False)]


def judged(robot, rates: dict) -> tuple[bool, tuple[str, ...], int]:
    """``(consistent, out_of_gear, number of GearWarnings)`` of fk on `rates`."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fk = forward_kinematics_check(robot, rates)
    return fk.consistent, fk.out_of_gear, sum(issubclass(w.category, GearWarning) for w in caught)


@pytest.mark.parametrize("right", ["0", "-1e-320", "1e-320", "2e-320"])
def test_cli_fk_tiny_rates_are_in_the_gear(tmp_path, capsys, right):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(1.0))
    assert main(["fk", str(path), "--spin", "left=1e-320", "--spin", f"right={right}", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["warnings"] == [] and out["consistent"] is True


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize(("f", "holds"), FLOORS)
def test_fk_gear_floor_is_the_contact_speed(s, f, holds):
    robot = scaled(cart(1.0), s)
    a = f * SLIP_TOL / (R * s)  # each contact a r s off the gear's turn 0
    consistent, out_of_gear, said = judged(robot, {"left.spin": a, "right.spin": -a})
    assert (consistent, out_of_gear, said) == ((True, (), 0) if holds else (False, (GEAR,), 1))


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("v", [1e-6, 1.0, 10.0])
def test_fk_real_departure_is_caught_at_every_scale(s, v):
    """Rates 5 % out of a 1:2 gear, the left contact at `v` [m/s]: the least-squares turn is 0.96 u, so the left
    contact departs by 0.04 v, at least 40 times the floor."""
    robot = scaled(cart(2.0), s)
    u = v / (R * s)
    assert judged(robot, {"left.spin": u, "right.spin": 1.9 * u}) == (False, (GEAR,), 1)
    assert judged(robot, {"left.spin": u, "right.spin": 2.0 * u}) == (True, (), 0)


@pytest.mark.parametrize(("f", "holds"), FLOORS)
def test_fk_gear_floor_over_the_given_joints_of_a_gear(f, holds):
    """A synchro drive's three spins on one gear, two given (``a`` and 0): their least-squares turn is ``a / 2``,
    each contact ``r a / 2`` off it; the third spin, not given, is not judged."""
    robot = Robot.from_dict(yaml.safe_load(SYNCHRO))
    a = 2 * f * SLIP_TOL / robot.wheel("a").r
    said = judged(robot, {"a.spin": a, "b.spin": 0.0})
    assert said[1:] == (((), 0) if holds else (("gear(a.spin, b.spin, c.spin)",), 1))
