"""The envelope's edges computed from typed numbers (docs/limits.md): a radius exactly 1e-4 of the reach, or ratios
exactly 1e4 apart, as typed in decimal, are accepted whatever the rounding of the product; just beyond is refused.
And a refused value is printed with the digits that show it is beyond its edge."""

from __future__ import annotations

import random
from decimal import Decimal

import pytest

from wmrkit import Robot, Wheel, catalog
from wmrkit.couplings import Coupling, CouplingError
from wmrkit.description import MAX_SIZE, MIN_RATIO, robot_from_dict, robot_to_dict
from wmrkit.errors import DescriptionError


def _decimals(count: int, seed: int, top: int) -> list[Decimal]:
    """`count` decimals of up to 3 significant digits from 1e-5 to 999e`top` (exact: an independent source)."""
    rng = random.Random(seed)
    return [Decimal(rng.randint(1, 999)).scaleb(rng.randint(-5, top)) for _ in range(count)]


def _diff_drive(reach: str, radius: str) -> dict:
    """Wheels at +-reach on y, the left one of `radius` (the typed numbers: strings read as YAML would read them)."""
    return {"name": "dd", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, float(reach)], "beta": 0, "r": float(radius)},
        {"name": "right", "type": "fixed", "position": [0, -float(reach)], "beta": 3.141592653589793,
         "r": float(reach) / 10}]}


def test_a_radius_exactly_the_smallest_fraction_of_the_reach_is_accepted_and_just_below_refused():
    """Before: r = 9.79e-05 m at a reach of 0.979 m was refused as "9.79e-05 m is less than 0.0001 of the robot's
    size (0.979 m ...)": 1e-4 * 0.979 rounds above the float 9.79e-05 (a third of 3000 such decimal pairs)."""
    robot_from_dict(_diff_drive("0.979", "9.79e-05"))
    for reach in _decimals(300, seed=1, top=0):
        edge = reach * Decimal(str(MIN_RATIO))
        robot_from_dict(_diff_drive(str(reach), str(edge)))
        with pytest.raises(DescriptionError, match=r"wheels\[0\]\.r: .* is less than 0\.0001 of the robot's size"):
            robot_from_dict(_diff_drive(str(reach), str(edge * Decimal("0.999999999"))))


def _forklift(ratios: list[float]) -> dict:
    data = catalog.load("forklift").to_dict()
    data["couplings"] = [{"kind": "gear", "joints": ["right_drive.spin", "left_drive.spin"], "ratios": ratios}]
    return data


def test_ratios_exactly_the_largest_spread_apart_are_accepted_and_just_beyond_refused():
    """Before: ratios [37.9, 379000] were refused as "the largest ratio is more than 10000 times the smallest":
    37.9 / 1e-4 rounds below the float 379000.0 (5512 of 20000 decimal pairs)."""
    spread = Decimal(1) / Decimal(str(MIN_RATIO))
    for small in [Decimal("37.9"), *_decimals(300, seed=2, top=-2)]:
        edge, beyond = [float(small)], [float(small)]
        edge.append(float(small * spread))
        beyond.append(float(small * spread * Decimal("1.000000001")))
        Robot.from_dict(_forklift(edge))
        Coupling("gear", ("a.spin", "b.spin"), tuple(edge))
        with pytest.raises(DescriptionError, match=r"couplings\[0\]\.ratios: the largest ratio is more than 10000"):
            Robot.from_dict(_forklift(beyond))
        with pytest.raises(CouplingError, match="more than 10000 times the smallest"):
            Coupling("gear", ("a.spin", "b.spin"), tuple(beyond))


def test_a_length_one_ulp_past_1_km_is_refused_printing_the_ulp():
    """Before: "wheels[0].r: 1000 m: longer than 1000 m" for r = 1000.0000000000001 (1e3 / 0.46875 * 0.46875)."""
    r = 0.46875 * (MAX_SIZE / 0.46875)
    assert r > MAX_SIZE
    data = robot_to_dict(Robot(name="r", wheels=(Wheel(name="w0", type="fixed", l=0.0, alpha=0.0, beta=0.0, r=r),)))
    with pytest.raises(DescriptionError, match=r"wheels\[0\]\.r: 1000\.0000000000001 m: longer than 1000 m"):
        robot_from_dict(data)
