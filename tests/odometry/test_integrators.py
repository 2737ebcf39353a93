"""Integration schemes: the oracles of papers-odometry.md A.6, closed-form arcs, convergence orders, peers."""

from __future__ import annotations

import doctest
import math

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import ShapeError, WmrkitError
from wmrkit.odometry import integrators
from wmrkit.odometry.integrators import (
    METHODS,
    integrate_euler,
    integrate_exact,
    integrate_increments,
    integrate_paper002,
    integrate_rk2,
    sinc,
    sinc_derivative,
    step,
)

BATCHES = [(), (1,), (4,), (2, 3)]


def test_docstring_oracle():
    """STYLE rule 9: the docstring example is the A.6 oracle and must run."""
    assert doctest.testmod(integrators, raise_on_error=False).failed == 0


@pytest.mark.parametrize(("method", "expected"), [
    ("exact", (0.0999733355, 0.0019997333)),  # A.6: exact arc
    ("paper002", (0.0999200107, 0.0039989334)),  # A.6: 002 eq. (15), new heading
    ("euler", (0.1, 0.0)),  # A.6: forward Euler, old heading
    ("rk2", (0.0999800007, 0.0019998667)),  # A.6: midpoint
])
def test_single_step_oracles_of_a6(method, expected):
    # l = 0.25 m, dS_right = 0.11 m, dS_left = 0.09 m: dS = 0.1 m, theta = (0.11 - 0.09) / 0.5 = 0.04 rad (002 (1), (6))
    x, y, th = step([0.0, 0.0, 0.0], [0.1, 0.0, 0.04], method)
    assert (x, y) == pytest.approx(expected, abs=5e-11)
    assert th == pytest.approx(0.04, abs=1e-15)


def test_twist_helpers_are_the_steps():
    pose, twist, dt = [0.3, -0.2, 1.1], [0.5, 0.1, -0.7], 0.25
    for fn, method in ((integrate_exact, "exact"), (integrate_rk2, "rk2"), (integrate_euler, "euler"),
                       (integrate_paper002, "paper002")):
        np.testing.assert_allclose(fn(pose, twist, dt), step(pose, np.multiply(twist, dt), method), rtol=0, atol=1e-15)


def test_exact_step_equals_corrected_paper002_arc():
    """002 (11)-(12) corrected (A.3): x = x0 + R [sin phi - sin(phi - theta)],
    y = y0 + R [cos(phi - theta) - cos phi]."""
    phi0, ds, theta = 0.7, 0.3, 0.2
    r_centro, phi = ds / theta, phi0 + theta
    expected = [1.0 + r_centro * (math.sin(phi) - math.sin(phi - theta)),
                2.0 + r_centro * (math.cos(phi - theta) - math.cos(phi)), phi]
    np.testing.assert_allclose(step([1.0, 2.0, phi0], [ds, 0.0, theta]), expected, rtol=0, atol=1e-15)


def test_pure_rotation_keeps_the_position():
    for method in METHODS:  # A.6: dS_right = -dS_left = 0.1, l = 0.25 -> theta = 0.4, position unchanged
        np.testing.assert_allclose(step([1.0, -2.0, 0.3], [0.0, 0.0, 0.4], method), [1.0, -2.0, 0.7], atol=1e-15)


@pytest.mark.parametrize("dth", [0.0, 1e-300, 1e-12, 1e-8, 9.99e-5, 1e-4, 1.01e-4, 1e-3, 0.1, 1.0, 3.0])
def test_exact_step_keeps_full_precision_near_the_straight_line(dth):
    """Against the closed form in 50-digit arithmetic: no loss where 1 - cos would cancel."""
    mpmath.mp.dps = 50
    theta0, dx, dy = mpmath.mpf("0.3"), mpmath.mpf("1.7"), mpmath.mpf("-0.4")
    d = mpmath.mpf(dth)
    if d == 0:
        sx, cx = mpmath.mpf(1), mpmath.mpf(0)
    else:
        sx, cx = mpmath.sin(d) / d, (1 - mpmath.cos(d)) / d  # V(d) = [[sx, -cx], [cx, sx]]
    bx, by = sx * dx - cx * dy, cx * dx + sx * dy
    ex = mpmath.cos(theta0) * bx - mpmath.sin(theta0) * by
    ey = mpmath.sin(theta0) * bx + mpmath.cos(theta0) * by
    got = step([0.0, 0.0, 0.3], [1.7, -0.4, dth], "exact")
    # a few ulps of the inputs' scale (|dx| + |dy| ~ 2); a 1 - cos form would lose ~eps / dth here
    np.testing.assert_allclose(got[:2], [float(ex), float(ey)], rtol=0, atol=1e-15)


def test_sinc_and_its_derivative_against_mpmath():
    mpmath.mp.dps = 40
    for h in (0.0, 1e-9, 5e-5, 9.9e-4, 1.1e-3, 0.3, 0.999, 1.001, 2.0, -0.7, 6.0):
        m = mpmath.mpf(h)
        ref = 1 if h == 0 else mpmath.sin(m) / m
        dref = 0 if h == 0 else (m * mpmath.cos(m) - mpmath.sin(m)) / m**2
        assert float(sinc(h)) == pytest.approx(float(ref), rel=2e-16)
        assert float(sinc_derivative(h)) == pytest.approx(float(dref), rel=1e-14, abs=1e-300)


def _arc(pose0, twist, t):
    """Closed-form pose under a constant body twist: z = z0 + (vx + i vy) e^{i th0} (e^{i w t} - 1) / (i w),
    written (e^{ia} - 1) / (iw) = 2 sin(a/2) / w e^{ia/2} (a = w t) so that tiny w does not cancel."""
    x0, y0, th0 = pose0
    vx, vy, w = twist
    v = complex(vx, vy) * np.exp(1j * th0)
    z = v * t if w == 0 else v * 2 * np.sin(w * t / 2) / w * np.exp(0.5j * w * t)
    return np.column_stack([x0 + z.real, y0 + z.imag, th0 + w * t])


@pytest.mark.parametrize("twist", [(0.8, 0.0, 0.5), (0.3, -0.6, -1.3), (1.2, 0.0, 0.0), (0.0, 0.0, 2.0),
                                   (0.5, 0.2, 1e-9)])
def test_exact_integrator_reproduces_arcs_and_lines(twist):
    dt, n = 0.01, 2000
    pose0 = (0.5, -1.0, 0.4)
    poses = integrate_increments(pose0, np.tile(np.multiply(twist, dt), (n, 1)), "exact")
    expected = _arc(pose0, twist, dt * np.arange(1, n + 1))
    np.testing.assert_allclose(poses, expected, rtol=0, atol=2e-12)


@pytest.mark.parametrize(("n", "paper", "midpoint"), [(10, 6.67e-2, 8.7e-4), (100, 6.66e-3, 8.7e-6),
                                                      (1000, 6.66e-4, 8.7e-8)])
def test_quarter_circle_end_point_errors_of_a6(n, paper, midpoint):
    """A.6: quarter circle R = 0.6 m from (0, 0, 0) in N equal steps; exact end (0.6, 0.6, pi/2)."""
    inc = np.tile([0.6 * math.pi / 2 / n, 0.0, math.pi / 2 / n], (n, 1))
    end = np.array([0.6, 0.6])
    err = {m: np.hypot(*(integrate_increments([0, 0, 0], inc, m)[-1, :2] - end)) for m in METHODS}
    assert err["paper002"] == pytest.approx(paper, rel=5e-3)
    assert err["euler"] == pytest.approx(paper, rel=5e-3)  # same size as (15), mirrored
    assert err["rk2"] == pytest.approx(midpoint, rel=1e-2)
    assert err["exact"] < 1e-14


@pytest.mark.parametrize("n", [8, 100])
def test_whole_circles_of_equal_steps_close_with_every_scheme_on_a_wrong_circle(n):
    """A.6: equal steps at evenly spaced headings sum to zero, so every scheme returns to its start; only exact
    stays on the circle (R = 0.6 m: the half-way pose is (0, 1.2)), so loop closure is no accuracy test."""
    inc = np.tile([0.6 * 2 * math.pi / n, 0.0, 2 * math.pi / n], (n, 1))
    for method in METHODS:
        poses = integrate_increments([0, 0, 0], inc, method)
        np.testing.assert_allclose(poses[-1], [0.0, 0.0, 2 * math.pi], atol=1e-13)
        off = np.hypot(*(poses[n // 2 - 1, :2] - [0.0, 1.2]))
        assert off < 1e-13 if method == "exact" else off > {"rk2": 0.5 / n**2}.get(method, 0.5 / n)  # 2nd, 1st order


def test_measured_convergence_orders():
    """Time-varying twist; increments are the exact integrals of the twist over each step (what encoders
    measure); reference by an independent adaptive ODE solver. Orders: Euler and (15) first, RK2 and the
    exact (constant-twist) scheme second."""
    from scipy.integrate import solve_ivp

    def v(t):
        return 1.0 + 0.5 * np.sin(t)

    def w(t):
        return 0.8 * np.cos(0.7 * t)

    def iv(t):  # antiderivatives
        return t - 0.5 * np.cos(t)

    def iw(t):
        return 0.8 / 0.7 * np.sin(0.7 * t)

    T = 4.0
    ref = solve_ivp(lambda t, p: [v(t) * math.cos(p[2]), v(t) * math.sin(p[2]), w(t)], (0, T), [0, 0, 0],
                    rtol=1e-13, atol=1e-13).y[:, -1]
    orders = {}
    for method in METHODS:
        errs = []
        for n in (200, 400, 800):
            t = np.linspace(0, T, n + 1)
            inc = np.column_stack([np.diff(iv(t)), np.zeros(n), np.diff(iw(t))])
            errs.append(np.hypot(*(integrate_increments([0, 0, 0], inc, method)[-1, :2] - ref[:2])))
        orders[method] = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    for method, order in (("euler", 1), ("paper002", 1), ("rk2", 2), ("exact", 2)):
        np.testing.assert_allclose(orders[method], order, atol=0.05, err_msg=method)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_trajectory_equals_repeated_steps(method, batch):
    rng = np.random.default_rng(3)
    pose0 = rng.normal(size=(*batch, 3))
    inc = rng.normal(size=(*batch, 25, 3)) * [0.2, 0.1, 0.5]
    poses = integrate_increments(pose0, inc, method)
    assert poses.shape == (*batch, 25, 3)
    p = pose0
    for k in range(25):
        p = step(p, inc[..., k, :], method)
        np.testing.assert_allclose(poses[..., k, :], p, rtol=0, atol=1e-13)


@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_step_batches_equal_loops(batch):
    rng = np.random.default_rng(5)
    pose, inc = rng.normal(size=(*batch, 3)), rng.normal(size=(*batch, 3))
    out = step(pose, inc, "exact")
    assert out.shape == (*batch, 3)
    for idx in np.ndindex(*batch):
        np.testing.assert_allclose(out[idx], step(pose[idx], inc[idx], "exact"), rtol=0, atol=1e-15)


def test_external_heading_replaces_the_wheel_heading():
    rng = np.random.default_rng(1)
    inc = rng.normal(size=(30, 3)) * 0.1
    heading = np.cumsum(np.concatenate([[0.2], rng.normal(size=30) * 0.05]))
    for method in METHODS:
        poses = integrate_increments([1.0, 2.0, 99.0], inc, method, heading_world=heading)
        np.testing.assert_allclose(poses[:, 2], heading[1:], rtol=0, atol=0)
        swapped = inc.copy()
        swapped[:, 2] = np.diff(heading)
        np.testing.assert_allclose(poses, integrate_increments([1.0, 2.0, heading[0]], swapped, method), atol=1e-13)


@settings(max_examples=400)
@given(st.floats(-3, 3), st.floats(-1, 1), st.floats(-1, 1), st.floats(-6, 6))
def test_exact_steps_form_a_one_parameter_group(theta, dx, dy, dth):
    """exp(u/2) exp(u/2) = exp(u): two half steps of a constant twist are one step."""
    pose = [0.1, -0.2, theta]
    half = step(step(pose, [dx / 2, dy / 2, dth / 2]), [dx / 2, dy / 2, dth / 2])
    np.testing.assert_allclose(half, step(pose, [dx, dy, dth]), rtol=0, atol=1e-12)


def test_wrong_shapes_and_methods_are_named():
    with pytest.raises(ShapeError, match=r"increment_robot: expected shape \(\.\.\., 3\)"):
        step([0, 0, 0], [1.0, 2.0])
    with pytest.raises(ShapeError, match=r"pose_world_robot"):
        integrate_increments([0, 0], np.zeros((3, 3)))
    with pytest.raises(WmrkitError, match=r"increments_robot: expected shape \(\.\.\., N, 3\)"):
        integrate_increments([0, 0, 0], np.zeros(3))
    with pytest.raises(WmrkitError, match=r"heading_world: expected shape \(\.\.\., 4\)"):
        integrate_increments([0, 0, 0], np.zeros((3, 3)), heading_world=np.zeros(3))
    with pytest.raises(WmrkitError, match=r"unknown integration method 'rk4' \(methods: exact, rk2, euler, paper002\)"):
        step([0, 0, 0], [0, 0, 0], "rk4")


def test_exact_step_agrees_with_wpimath_pose_exponential():
    geometry = pytest.importorskip("wpimath.geometry")
    rng = np.random.default_rng(7)
    for _ in range(50):
        pose, inc = rng.normal(size=3), rng.normal(size=3) * [0.5, 0.5, 1.5]
        p = geometry.Pose2d(pose[0], pose[1], geometry.Rotation2d(pose[2])).exp(geometry.Twist2d(*inc))
        ours = step(pose, inc, "exact")
        np.testing.assert_allclose([p.X(), p.Y()], ours[:2], rtol=0, atol=1e-12)
        assert math.remainder(p.rotation().radians() - ours[2], 2 * math.pi) == pytest.approx(0, abs=1e-12)


def test_euler_agrees_with_roboticstoolbox_vehicle_update():
    mobile = pytest.importorskip("roboticstoolbox.mobile")
    veh = mobile.Bicycle()
    rng = np.random.default_rng(2)
    x = np.array([0.2, -0.3, 0.5])
    ours = x.copy()
    for _ in range(40):
        dd, dth = rng.normal() * 0.2, rng.normal() * 0.3
        x = veh.f(x, [dd, dth])
        ours = step(ours, [dd, 0.0, dth], "euler")
    np.testing.assert_allclose(ours, x, rtol=0, atol=1e-13)
