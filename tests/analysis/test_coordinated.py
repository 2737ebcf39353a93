"""Robots whose steering must be coordinated (Ackermann, swerve): singular sets over the admissible steering."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.analysis.coordinated import coordinated_singular_set
from wmrkit.analysis.icr import icr
from wmrkit.analysis.singularity import is_singular_rank


def _icr_points(robot, s):
    out = []
    for b in s.configurations:
        assert is_singular_rank(robot, b, s.assigned)  # the rank test (6.12) agrees at every reported point
        got = icr(robot, b)
        out.append(got.point if got.kind == "point" else ("inf", *np.round(np.abs(got.direction), 9)))
    return out


def test_ackermann():
    car = catalog.load("ackermann")  # origin at the rear-axle midpoint, x forward
    assert singular_set_icrs(car, ("vx",)) == [(0.0, 0.0)]  # turning about the origin: vx = 0
    assert coordinated_singular_set(car, ("vy",)).always  # vy = 0 for every car motion
    assert singular_set_icrs(car, ("omega",)) == [("inf", 1.0, 0.0)]  # driving straight
    for name in ("rear_left", "rear_right"):
        (point,) = singular_set_icrs(car, (f"{name}.spin",))
        np.testing.assert_allclose(point, car.wheel(name).position, atol=1e-9)  # ICR at that wheel
    for name in ("front_left", "front_right"):  # the ICR is on the rear axle, never at a front wheel
        assert coordinated_singular_set(car, (f"{name}.spin",)).never


def singular_set_icrs(robot, assigned):
    pts = _icr_points(robot, coordinated_singular_set(robot, assigned, resolution=60))
    return [tuple(float(np.round(v, 9)) if not isinstance(v, str) else v for v in p) for p in pts]


def test_swerve_spin_singular_when_turning_about_the_wheel():
    r = catalog.load("swerve-4")
    s = coordinated_singular_set(r, ("front_left.spin",), resolution=48)
    assert len(s.configurations) == 1 and s.coordinated
    np.testing.assert_allclose(icr(r, s.configurations[0]).point, r.wheel("front_left").position, atol=1e-6)
    vx = coordinated_singular_set(r, ("vx",), resolution=48)
    assert len(vx.configurations) > 5
    for b in vx.configurations:  # vx = omega y_c = 0: the ICR on the X axis, or a translation along y
        got = icr(r, b)
        if got.kind == "point":
            assert got.point[1] == pytest.approx(0.0, abs=1e-7)
        else:
            assert got.kind == "infinity" and got.direction[0] == pytest.approx(0.0, abs=1e-7)
    assert coordinated_singular_set(r, tuple(r.rate_names), resolution=24).never  # all four spins: never
