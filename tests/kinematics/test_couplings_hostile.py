"""Hostile couplings (``couplings:``, ``wmrkit.couplings``): refused in one located line, or analysed right."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from wmrkit import Robot, UnknownNameError, catalog
from wmrkit.couplings import Coupling, CouplingError
from wmrkit.errors import DescriptionError
from wmrkit.kinematics.actuation import actuation_analysis


def forklift_with(ratios: list[float], kind: str = "differential") -> dict:
    data = catalog.load("forklift").to_dict()
    data["couplings"] = [{"kind": kind, "joints": ["right_drive.spin", "left_drive.spin"], "ratios": ratios}]
    return data


@pytest.mark.parametrize("ratios", [[1e-300, 1e-300], [1e300, 1e300], [1e-7, 1e-7], [1e4, 1e-4]], ids=str)
@pytest.mark.parametrize("kind", ["differential", "gear"])
def test_ratios_outside_the_handled_range_are_refused_at_the_field(kind, ratios):
    """Before: ratios 1e-300 divided 0 by 0 in the actuation analysis (a traceback under `wmrkit kinematics`),
    1e300 gave an actuated inverse of zeros, and a spread of 1e6 between two ratios turned a verdict."""
    with pytest.raises(DescriptionError, match=r"couplings\[0\]\.ratios"):
        Robot.from_dict(forklift_with(ratios, kind))
    with pytest.raises(CouplingError, match=r"docs/limits\.md"):
        Coupling(kind, ("a.spin", "b.spin"), tuple(ratios))


@pytest.mark.parametrize("scale", [2e-6, 1.0, 2e6])
def test_the_differential_inverse_is_the_weighted_sum_at_any_handled_scale(scale):
    """The actuated inverse of the forklift's differential is ``sum(k_j q_j)`` with ``q_j = v / r`` driving
    straight: ``2 k v / r`` for ratios ``k``, from 1e-6 to 1e6."""
    robot = Robot.from_dict(forklift_with([0.5 * scale, 0.5 * scale]))
    rate = actuation_analysis(robot).inverse([1.0, 0.0, 0.0])
    np.testing.assert_allclose(rate, [scale / 0.23], rtol=1e-9)


def test_a_python_coupling_is_checked_like_a_described_one():
    with pytest.raises(CouplingError, match="two or more distinct joints"):
        Coupling("gear", ("a.spin", "a.spin"), (1.0, 1.0))
    with pytest.raises(CouplingError, match="unknown kind"):
        Coupling("chain", ("a.spin", "b.spin"), (1.0, 1.0))
    with pytest.raises(CouplingError, match="magnitude"):
        Coupling("gear", ("a.spin", "b.spin"), (float("nan"), 1.0))
    robot = dataclasses.replace(catalog.load("forklift"),
                                couplings=(Coupling("gear", ("right_drive.spin", "rear.spin"), (1.0, 1.0)),))
    with pytest.raises(UnknownNameError, match=r"no joint rate rear\.spin"):
        actuation_analysis(robot)


def car_with(couplings: list[dict]) -> Robot:
    return Robot.from_dict({"name": "car", "wheels": [
        {"name": "a", "type": "fixed", "position": [0, 0.3], "heading": 0, "r": 0.1, "actuated": ["spin"]},
        {"name": "b", "type": "fixed", "position": [0, -0.3], "heading": 0, "r": 0.1, "actuated": ["spin"]},
        {"name": "c", "type": "castor", "position": [-0.5, 0], "beta": "90 deg", "d": 0.05, "r": 0.05},
        {"name": "s", "type": "steerable", "position": [0.5, 0], "heading": 0, "r": 0.05, "actuated": ["steer"]}],
        "couplings": couplings})


@pytest.mark.parametrize(("coupling", "m"), [
    ({"kind": "gear", "joints": ["a.spin", "b.spin"], "ratios": [1, 1]}, 1),  # a chain along one side: rolls
    ({"kind": "gear", "joints": ["a.spin", "b.spin"], "ratios": [1, -1]}, 0),  # wheels of one axle counter-rotate
    ({"kind": "gear", "joints": ["c.steer", "c.spin"]}, 0),  # rolling straight, the castor does not swivel
    ({"kind": "differential", "joints": ["a.spin", "b.spin"]}, 1),
], ids=["chain", "locked-axle", "locked-castor", "differential"])
def test_the_actuation_mobility_is_that_of_the_coupled_mechanism(coupling, m):
    """The car rolls straight only (m = 1); a gear that forbids that locks it. Before, the verdict said
    "over-actuated: more actuated rates than degrees of freedom (1 actuated rate, m = 1)" of a locked car."""
    analysis = actuation_analysis(car_with([coupling]))
    assert int(analysis.mobility) == m and f"m = {m})" in str(analysis.verdict)
    assert str(analysis.leaf) == ("determined" if m else "overdetermined")
