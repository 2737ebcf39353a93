"""Optimisers (§5.4 criteria): isotropic designs and configurations are recovered from a poor start."""

from __future__ import annotations

import math

import numpy as np
import pytest
from thesis_vehicles import DEG, differential, robot

from wmrkit import UnknownNameError, catalog
from wmrkit.analysis.optimize import best_configurations, optimize_geometry


def _omni(x):
    a = [0.0, 120 * DEG, float(x[0])]
    return robot("omni", *({"name": f"s{i + 1}", "type": "swedish", "l": 0.7, "alpha": ai, "beta": ai,
                            "gamma": math.pi / 2, "r": 0.1, "r_r": 0.02} for i, ai in enumerate(a)))


def test_equilateral_omni_design_is_recovered():
    """Saha et al. 95 (§5.5.1.A): wheels at 120 deg, planes perpendicular to the radius; D = sqrt(2) L."""
    res = optimize_geometry(_omni, [3.5], bounds=[(2.5, 5.5)], starts=1)
    assert math.degrees(res.x[0]) == pytest.approx(240.0, abs=1e-5)
    assert res.condition_number == pytest.approx(1.0, abs=1e-9)
    assert res.length == pytest.approx(math.sqrt(2) * 0.7, rel=1e-6)


def test_global_objective_without_steering_is_the_described_one():
    res = optimize_geometry(_omni, [3.5], bounds=[(2.5, 5.5)], objective="global", samples=8, starts=1)
    assert math.degrees(res.x[0]) == pytest.approx(240.0, abs=1e-2)
    assert res.condition_number == pytest.approx(1.0, abs=1e-6)


def test_equal_radii_differential_5_51():
    res = optimize_geometry(lambda x: differential(l12=0.5, r1=float(x[0]), r2=0.15), [0.3], bounds=[(0.05, 0.5)],
                            joints=("f1.spin", "f2.spin"), starts=2)
    assert res.x[0] == pytest.approx(0.15, rel=1e-6) and res.length == pytest.approx(0.5, rel=1e-6)


def test_swedish_wheel_design_5_52():
    def family(x):
        return differential(l12=0.5, r1=0.15, r2=0.15, third="swedish", l3=0.6, alpha3=-90 * DEG,
                            beta3=float(x[0]), r3=0.1)

    res = optimize_geometry(family, [0.5], bounds=[(-math.pi, math.pi)], joints=("f1.spin", "s3.spin"), starts=1)
    b = res.x[0]
    assert res.condition_number == pytest.approx(1.0, abs=1e-9)
    assert math.cos(b) * 0.6 * math.cos(b + 90 * DEG) == pytest.approx(-0.5 * (0.1 / 0.15) ** 2, abs=1e-8)


def test_invalid_parameters_are_skipped():
    def family(x):
        return differential(l12=0.5, r1=float(x[0]), r2=0.15)  # r1 <= 0 raises a DescriptionError

    res = optimize_geometry(family, [0.4], bounds=[(-0.2, 0.5)], joints=("f1.spin", "f2.spin"), starts=3)
    assert res.x[0] == pytest.approx(0.15, rel=1e-5)


def test_best_configurations_without_steering_and_bad_names():
    r = catalog.load("thesis-omni-swedish")
    (best,) = best_configurations(r)
    assert best.condition_number == pytest.approx(1.0, abs=1e-9) and best.beta == ()
    with pytest.raises(UnknownNameError, match="no steering wheel"):
        best_configurations(catalog.load("thesis-tricycle"), variables=("f1",))
    with pytest.raises(UnknownNameError, match="objective"):
        optimize_geometry(_omni, [4.0], objective="mean")


def test_best_configurations_of_a_type3_robot_are_local_minima():
    r = catalog.load("thesis-steer-castor")
    found = best_configurations(r, resolution=36, count=3)
    assert 1 <= len(found) <= 3
    ks = [c.condition_number for c in found]
    assert ks == sorted(ks)
    from wmrkit.analysis.isotropy import natural_length

    for c in found:
        beta = np.array(c.beta)
        k0 = natural_length(r, beta)[1]
        assert k0 == pytest.approx(c.condition_number, rel=1e-9)
        for j in range(3):  # no better neighbour along any steering angle
            for step in (-1e-3, 1e-3):
                b = beta.copy()
                b[j] += step
                assert natural_length(r, b)[1] >= k0 - 1e-9
