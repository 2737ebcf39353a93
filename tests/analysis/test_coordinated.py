"""Robots whose steering must be coordinated (Ackermann, swerve): singular sets over the admissible steering."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.analysis import _fast, coordinated
from wmrkit.analysis.coordinated import coordinated_singular_set
from wmrkit.analysis.icr import icr, steer_to_icr
from wmrkit.analysis.singularity import is_singular_rank

icr_module = importlib.import_module("wmrkit.analysis.icr")  # the package exports the function icr too


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


def _steered_circle(n):
    """n independently steered wheels on a 0.5 m circle (a swerve robot with many modules)."""
    wheels = [{"name": f"w{i}", "type": "steerable", "r": 0.05, "actuated": ["spin", "steer"],
               "sensed": ["spin", "steer"],
               "position": [0.5 * np.cos(2 * np.pi * i / n), 0.5 * np.sin(2 * np.pi * i / n)]} for i in range(n)]
    return Robot.from_dict({"name": f"steered{n}", "wheels": wheels})


def test_steer_to_icr_builds_the_wheel_rows_once(monkeypatch):
    """steer_to_icr evaluated every wheel's element rows once per wheel and call (64 x 64 rows for one ICR of a
    64-wheel robot; the report's searches call it thousands of times): now once per robot, every wheel at once."""
    r = _steered_circle(64)
    calls = []
    real = icr_module.element_rows
    monkeypatch.setattr(icr_module, "element_rows", lambda *a, **k: calls.append(1) or real(*a, **k))
    h = np.array([0.2, -0.1, 1.0])
    beta = steer_to_icr(r, h)
    for _ in range(3):
        np.testing.assert_array_equal(steer_to_icr(r, h), beta)
    assert len(calls) <= 1
    np.testing.assert_allclose(icr(r, beta).point, h[:2], atol=1e-12)  # every axle through the ICR


def test_search_is_chunked_and_its_fallback_budgeted(monkeypatch):
    """A robot of many steered wheels: the ICR grid went to steer_to_icr and the line SVDs whole ((resolution/4 + 1)
    x resolution ICRs times the wheels: 6.7 GB at resolution 1440 for 64 wheels), and when no grid row met the
    singular ICR (at the wheel whose spin is assigned) six 2-D searches ran to the end, ~200 evaluations each,
    though all found the same point (727 s for the report of 64 wheels). Now CHUNK ICRs at once, and the searches
    share MAX_EVALUATIONS."""
    r = _steered_circle(8)
    largest, searches = [0], []
    real_steer, real_minimize = coordinated.steer_to_icr, coordinated.minimize
    monkeypatch.setattr(coordinated, "steer_to_icr",
                        lambda robot, h: largest.__setitem__(0, max(largest[0], np.size(h) // 3))
                        or real_steer(robot, h))
    monkeypatch.setattr(coordinated, "minimize",
                        lambda *a, **k: searches.append(real_minimize(*a, **k)) or searches[-1])
    for resolution in (360, 22):  # the report's grid (a quarter of the default), where no row meets the wheel
        searches.clear()
        s = coordinated_singular_set(r, ("w0.spin",), resolution=resolution)
        (point,) = _icr_points(r, s)
        np.testing.assert_allclose(point, r.wheel("w0").position, atol=1e-9)  # turning about the wheel
    assert 0 < largest[0] <= _fast.CHUNK < 91 * 360
    assert 0 < len(searches) <= 6 and sum(res.nfev for res in searches) <= coordinated.MAX_EVALUATIONS
