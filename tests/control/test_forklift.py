"""The forklift of §8.6: IK (8.46)-(8.51) against the wheel equations (3.11), the two simulation examples, theta's
zero dynamics, and the real truck's behaviour in kind with its low-level loops (§8.6.3)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control.forklift import forklift_ik, forklift_real_loops, from_thesis_pose
from wmrkit.control.references import builtin_reference
from wmrkit.control.track import track
from wmrkit.kinematics.wheel_ik import wheel_commands
from wmrkit.wheels import generic_slip_rows

L12, L3, E, R = 0.45, 2.35, 1.0, 0.23
FORKLIFT = catalog.load("forklift")


def _thesis_rows(beta3):
    """(3.11) rows of the three wheels with the parameters (8.46), thesis frame (Y forward, X right)."""
    l1 = math.hypot(E, L12)
    a1, a2 = -math.atan(E / L12), math.pi + math.atan(E / L12)
    return [generic_slip_rows(0.0, l1, a1, 0, 0, 0, R, 0), generic_slip_rows(0.0, l1, a2, 0, 0, 0, R, 0),
            generic_slip_rows(beta3, L3, -math.pi / 2, 0, 0, 0, R, 0)]


@settings(max_examples=200, deadline=None)
@given(vx=st.floats(-2, 2), vy=st.floats(-2, 2), theta=st.floats(-math.pi, math.pi), quadrants=st.sampled_from([2, 4]))
@example(vx=1.0, vy=0.0, theta=0.0, quadrants=2)  # R v_y = 0: sign(R v_y) of (8.51) undefined (docs/errata.md)
@example(vx=-1.0, vy=0.0, theta=0.0, quadrants=2)
def test_ik_zeroes_the_wheel_equations(vx, vy, theta, quadrants):
    """Both rows of (3.11) vanish for every wheel at the IK's omega, spins and beta3 (4- and 2-quadrant)."""
    c, s = math.cos(theta), math.sin(theta)
    rvx, rvy = c * vx + s * vy, -s * vx + c * vy
    if math.hypot(rvx, rvy) < 1e-6:
        return
    ik = forklift_ik([vx, vy], theta, quadrants=quadrants)
    twist = np.array([rvx, rvy, float(ik.omega)])
    for rows, phi in zip(_thesis_rows(float(ik.beta3)), (ik.phi1, ik.phi2, ik.phi3), strict=True):
        q = np.concatenate([twist, [0.0, float(phi), 0.0]])
        np.testing.assert_allclose(rows @ q, 0.0, atol=1e-12)
    if quadrants == 4:
        assert ik.phi3 <= 0
    else:
        assert -math.pi / 2 < ik.beta3 <= math.pi / 2 + 1e-12


def test_ik_digest_oracles():
    """Digest §1.5.3 values (computed there from (8.47)-(8.51))."""
    ik = forklift_ik([0.5, 1.0], 0.0)
    assert (float(ik.omega), float(ik.phi1), float(ik.phi2), float(ik.phi3)) == pytest.approx(
        (-0.5, -3.3696, -5.3261, -5.2456), abs=1e-4)
    assert math.degrees(ik.beta3) == pytest.approx(34.0193, abs=1e-4)
    four, two = forklift_ik([0.3, -0.4], math.radians(30)), forklift_ik([0.3, -0.4], math.radians(30), quadrants=2)
    assert math.degrees(four.beta3) == pytest.approx(170.76, abs=0.01)
    assert float(four.phi3) == pytest.approx(-2.1867, abs=1e-4)
    assert math.degrees(two.beta3) == pytest.approx(-9.24, abs=0.01)
    assert float(two.phi3) == pytest.approx(2.1867, abs=1e-4)
    assert (float(four.phi1), float(four.phi2)) == pytest.approx((2.2753, 2.0413), abs=1e-4)


def test_ik_of_large_velocities_does_not_overflow(recwarn):
    """|phi3| was sqrt((k R v_x)^2 + R v_y^2) / r: squares of 1e200 overflowed to inf (a RuntimeWarning, seen in
    the README's pytest) where the magnitude is finite."""
    ik = forklift_ik([3e200, 4e200], 0.0)
    k = (2.35 - 1.0) / 1.0
    assert float(ik.phi3) == pytest.approx(-math.hypot(k * 3e200, 4e200) / 0.23, rel=1e-15)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]
    # 2-quadrant beta3 = arctan(k R v_x / R v_y) (8.51): a tiny R v_y overflowed the quotient with a RuntimeWarning
    # (a random draw of test_ik_zeroes_the_wheel_equations in the README's pytest); arctan(inf) is the right 90 deg
    ik = forklift_ik([1.0, 1e-310], 0.0, quadrants=2)
    assert float(ik.beta3) == math.pi / 2
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@settings(max_examples=150, deadline=None)
@given(vx=st.floats(-2, 2), vy=st.floats(-2, 2), theta=st.floats(-math.pi, math.pi))
def test_ik_equals_the_generic_per_wheel_ik_on_the_catalog_truck(vx, vy, theta):
    """The catalog forklift (REP-103: x = thesis Y, y = -thesis X) through wheel_commands: thesis spins negated,
    heading = thesis beta3 (4-quadrant: the root with a forward roll)."""
    ik = forklift_ik([vx, vy], theta)
    c, s = math.cos(theta), math.sin(theta)
    rvx, rvy = c * vx + s * vy, -s * vx + c * vy
    if math.hypot(rvx, rvy) < 1e-6:
        return
    cmd = wheel_commands(FORKLIFT, [rvy, -rvx, float(ik.omega)])
    np.testing.assert_allclose(cmd.spin[:2], [-ik.phi1, -ik.phi2], atol=1e-9)
    heading = FORKLIFT.heading_of_beta(cmd.beta)[0]
    spin3 = cmd.spin[2]
    if spin3 < 0:  # the other root: turn half round, roll forward
        heading, spin3 = heading + math.pi, -spin3
    assert abs(np.angle(np.exp(1j * (heading - ik.beta3)))) < 1e-9
    assert spin3 == pytest.approx(-float(ik.phi3), abs=1e-9)
    assert bool(cmd.feasible)


def _jumps(run, tol=0.3):
    dh = np.angle(np.exp(1j * np.diff(run.heading[:, 0])))
    k = np.flatnonzero(np.abs(dh) > tol)
    return run.t[k], dh[k]


def test_example_1_arc_then_line():
    """p(0) = (0, 4 m, 180 deg): the error decays as exp(-2 t), beta3 is continuous, its rate jumps at the
    arc-to-line curvature discontinuity (t = pi R / v = 9.42 s)."""
    ref = builtin_reference("arc-line")
    run = track(FORKLIFT, ref, gain=2.0, initial_pose=from_thesis_pose([0, 4, math.pi]), output_dt=0.01)
    np.testing.assert_allclose(run.error, run.error[0] * np.exp(-2.0 * run.t), atol=1e-6)
    assert _jumps(run, 0.05)[0].size == 0
    rate = np.diff(run.heading[:, 0]) / np.diff(run.t)
    t_disc = ref.breaks[0]
    before = rate[(run.t[:-1] > t_disc - 0.3) & (run.t[:-1] < t_disc - 0.05)]
    after = rate[(run.t[:-1] > t_disc + 0.05) & (run.t[:-1] < t_disc + 0.3)]
    assert t_disc == pytest.approx(9.42, abs=0.01)
    assert np.ptp(before) < 0.01 and np.ptp(after) < 0.05 and abs(after.mean() - before.mean()) > 0.25


def test_example_2_tangent_discontinuity_gives_the_pi_and_half_pi_jumps():
    """p(0) = 0 with a corner: 2-quadrant steering jumps by pi (the wheel passes +-90 deg) and by pi/2 at the
    corner; 4-quadrant keeps only the pi/2 jump (unrealisable: stop and re-orient)."""
    ref = builtin_reference("corner")
    t_corner = ref.breaks[0]
    two = track(FORKLIFT, ref, gain=2.0, initial_pose=from_thesis_pose([0, 0, 0]), policy="2-quadrant",
                output_dt=0.01)
    four = track(FORKLIFT, ref, gain=2.0, initial_pose=from_thesis_pose([0, 0, 0]), policy="4-quadrant",
                 output_dt=0.01)
    t2, d2 = _jumps(two)
    t4, d4 = _jumps(four)
    assert sorted(np.round(np.abs(d2) / (math.pi / 2)).tolist()) == [1.0, 2.0]
    assert np.all(np.abs(t2 - t_corner) < 0.05)
    assert np.round(np.abs(d4) / (math.pi / 2)).tolist() == [1.0] and abs(t4[0] - t_corner) < 0.05
    assert np.all(two.error < 1e-6)  # the fork tips stay on the reference: the jumps are the wheel's alone


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_theta_zero_dynamics_stable_forwards_unstable_backwards(direction):
    """Exact tracking of a straight line leaves theta' = -(v/e) sin(theta): tan(theta/2) = tan(theta0/2) exp(-v t/e)."""
    theta0, v = 0.3, 0.5 * direction
    ref = builtin_reference("line", speed=0.5, duration=12.0)
    if direction < 0:
        from wmrkit.control.references import reference_from_samples

        ref = reference_from_samples("back", ref.t, np.column_stack([-ref.pose[:, 0], ref.pose[:, 1:]]))
    run = track(FORKLIFT, ref, gain=1.0, initial_pose=[0.0, 0.0, theta0], duration=8.0)
    want = 2 * np.arctan(math.tan(theta0 / 2) * np.exp(-v * run.t / E))
    np.testing.assert_allclose(run.pose[:, 2], want, atol=2e-4)


def _real(a):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = track(FORKLIFT, builtin_reference("line", duration=40), gain=a, initial_pose=[0, 0.5, 0],
                    loops=forklift_real_loops(), gate=1.5, period=0.1, delay=1, duration=20, policy="2-quadrant")
    return run.tracked[:, 1]


def test_real_forklift_behaviour_in_kind():
    """§8.6.3 with steering 1.5 s / traction 3.5 s + 15 % loops, a 0.1 s PLC period and one sample of delay:
    a = 0.5 converges without overshoot, a = 1 with a slight oscillation, a = 2 diverges."""
    slow, mid, fast = _real(0.5), _real(1.0), _real(2.0)
    assert np.all(slow > 0) and abs(slow[-1]) < 0.01
    assert mid.min() < 0 and abs(mid.min()) < 0.3 * 0.5 and abs(mid[-1]) < 0.01
    assert np.abs(fast[-20:]).max() > 1.0
