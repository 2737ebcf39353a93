"""Geometry of §9.3.2.B: (9.27)-(9.31), the segments' poses, Blackburn's closed-form bound."""

from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from parking_cases import CAR_91, CAR_92, SLOT_91, arc_poses, corners_world

from wmrkit.errors import WmrkitError
from wmrkit.parking.geometry import (
    Space,
    Vehicle,
    arcs_displacement,
    arcs_through,
    blackburn_min_length,
    corner_angle,
    corner_distance,
    length_ratio,
    turning_radius,
    xi_from_lateral,
    xi_from_longitudinal,
)
from wmrkit.parking.path import arc_end, sample_poses
from wmrkit.parking.planner import _symmetric_arcs

rho_st = st.floats(0.2, 20.0)
xi_st = st.floats(0.01, math.pi / 2)


@settings(max_examples=300)
@given(rho_st, xi_st, st.sampled_from([-1, 1]), st.sampled_from([-1, 1]))
def test_symmetric_arcs_displacement_9_31(rho, xi, direction, side):
    """Two arcs of opposite curvature end parallel, displaced by (Y, X) of (9.31); the second ICR is at (Y, Z)."""
    segs = _symmetric_arcs(CAR_91, 3, 1, (0.0, 0.0, 0.0), direction, side, rho, xi)
    X, Y, Z = arcs_displacement(rho, xi)
    poses = np.vstack([arc_poses(s.start, s.direction, s.curvature, s.length) for s in segs])
    end = poses[-1]
    np.testing.assert_allclose(end, [direction * Y, side * X, 0.0], atol=1e-9 * max(1, rho))
    mid = segs[1].start  # the second arc's ICR, from the junction pose and its curvature
    icr = np.array(mid[:2]) + np.array([-math.sin(mid[2]), math.cos(mid[2])]) / segs[1].curvature
    np.testing.assert_allclose(icr, [direction * Y, side * Z], atol=1e-9 * max(1, rho))


@settings(max_examples=300)
@given(rho_st, xi_st)
def test_inverse_solutions_of_9_31(rho, xi):
    X, Y, _ = arcs_displacement(rho, xi)
    assert xi_from_longitudinal(Y, rho) == pytest.approx(xi if xi <= math.pi / 2 else math.pi - xi, rel=1e-6)
    assert xi_from_lateral(X, rho) == pytest.approx(xi, rel=1e-6, abs=1e-9)
    rho2, xi2 = arcs_through(X, Y)
    assert (rho2, xi2) == pytest.approx((rho, xi), rel=1e-6)
    assert xi_from_longitudinal(2.01 * rho, rho) is None


def test_turning_radius_9_27_and_ratio_9_37():
    # the digest's computed values: rho_min 101.40 and 57.94 cm, ratios 32.2 % and 70.6 %
    assert turning_radius(1.05, math.radians(46)) == pytest.approx(1.0140, abs=5e-5)
    assert CAR_92.rho_min == pytest.approx(0.5794, abs=5e-5)
    assert length_ratio(CAR_91, Space(3.35, 2.0, 0.2, 0.7, 0.07)) == pytest.approx(0.322, abs=5e-4)
    assert length_ratio(CAR_92, Space(3.30, 3.6, 0.12, 0.17, 0.17)) == pytest.approx(0.706, abs=5e-4)


@settings(max_examples=300)
@given(st.floats(0.05, 5.0), st.floats(0.0, math.pi / 2))
def test_corner_polar_coordinates_9_28_to_9_30(rho, theta):
    """(9.29): at angle theta of the last arc each corner sits at d_i (9.28) from the ICR, at theta -+ delta_i."""
    v = CAR_91
    # the car at angle theta before the end of a left-curving arc ending at P_f = (0, 0, 0): ICR at (0, rho)
    pose = np.array([[rho * math.sin(-theta), rho - rho * math.cos(theta), -theta]])
    x, y = corners_world(v, pose)
    for k, corner in ((0, 1), (1, 2), (2, 4), (3, 3)):  # right = outer (away from the ICR), left = inner
        dx, dy = x[0, k], y[0, k] - rho
        assert math.hypot(dx, dy) == pytest.approx(corner_distance(v, rho, corner), rel=1e-12)
        along = 1 if corner in (2, 4) else -1  # front corners lead by +delta in the ICR frame
        angle = math.atan2(dx, -dy)  # from the ICR's radius to P_f's end position
        expected = -theta + along * corner_angle(v, rho, corner)
        assert math.remainder(angle - expected, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_corner_angle_uses_atan2_for_icr_inside_the_width():
    """(9.30) with rho < c1/2: the inner corners' angle lies in (pi/2, pi], as (9.34) requires."""
    rho = 0.3
    assert math.pi / 2 < corner_angle(CAR_91, rho, 3) <= math.pi
    assert math.pi / 2 < corner_angle(CAR_91, rho, 4) <= math.pi


@settings(max_examples=300)
@given(st.floats(0.05, 3.0), st.one_of(st.just(0.0), st.floats(0.01, 1.0), st.floats(-1.0, -0.01)),
       st.sampled_from([-1, 1]))
def test_arc_end_and_sampled_poses_agree_with_the_exact_integrator(length, curvature, direction):
    """The planner's closed-form arc end equals wmrkit.odometry's exact SE(2) step (sample_poses)."""
    start = (0.3, -0.2, 0.4)
    end = arc_end(start, direction, curvature, length)
    from wmrkit.parking.path import Segment

    seg = Segment(3, 1, direction, curvature, length, 0.0, start, end)
    poses = sample_poses([seg], 0.01)
    np.testing.assert_allclose(poses[-1], end, atol=1e-12)
    np.testing.assert_allclose(poses, arc_poses(start, direction, curvature, length, len(poses) - 1), atol=1e-10)


@pytest.mark.parametrize("vehicle", [CAR_91, CAR_92, Vehicle(3.6, 1.0, 1.8, 2.7, 1.55, math.radians(35))],
                         ids=["9.1", "9.2", "car"])
def test_blackburn_bound_against_a_numeric_sweep(vehicle):
    """Blackburn's closed form equals the smallest gap found by sweeping the car about the last ICR numerically.

    The car ends at P_f = (0, 0) heading +x, ICR at (0, rho) on the road side; the obstacle is the quadrant
    x >= D, y <= c1/2 (the parked car ahead, its side level with the car's road side). Rotating the car back
    from its final pose about the ICR, its front-right corner must stay out of the quadrant.
    """
    rho = max(vehicle.rho_min, vehicle.c1 / 2)
    theta = np.linspace(0.0, math.pi / 2, 200001)
    poses = np.column_stack([rho * np.sin(theta), rho - rho * np.cos(theta), theta])  # earlier on the last arc
    x, y = corners_world(vehicle, poses)
    hits = y[:, 1] <= vehicle.c1 / 2 + 1e-12  # the front-right corner below the road-side line
    gap = np.max(np.where(hits, x[:, 1], -np.inf))  # its farthest reach ahead: the obstacle must start beyond
    resolution = 2 * math.hypot(vehicle.a1, rho + vehicle.c1) * (theta[1] - theta[0])  # corner travel per sample
    assert vehicle.b1 + gap == pytest.approx(blackburn_min_length(vehicle), abs=resolution)
    assert vehicle.b1 + gap <= blackburn_min_length(vehicle) + 1e-12  # samples can only miss the extreme


def test_space_refuses_a_negative_dx2_as_a_problem_file_does():
    """Space(dx2=-1) was planned (a pass at c1/2 + MS, with a warning) where a problem file refuses it."""
    with pytest.raises(WmrkitError, match=r"space\.dx2: must be >= 0, got -1\.0 m"):
        Space(**{**asdict(SLOT_91), "dx2": -1.0})


def test_space_refuses_a_gap_to_the_curb_of_the_slots_width_as_a_problem_file_does():
    """Space(final_gap=7) (7 m, meant 7 cm) was planned: the planner stopped after its first manoeuvre, whatever gap
    it left (7.6 cm for example 1), where a problem file refuses it."""
    with pytest.raises(WmrkitError, match=r"space\.final_gap: the gap to the curb \(7 m\) must be less than the "
                                          r"slot's width J = 2 m"):
        Space(**{**asdict(SLOT_91), "final_gap": 7.0})
    with pytest.raises(WmrkitError, match=r"space\.final_gap: .* J = 2 m"):
        Space(**{**asdict(SLOT_91), "final_gap": 2.0})
    assert Space(**{**asdict(SLOT_91), "final_gap": 1.99}).final_gap == 1.99
