"""Collision characterisation (§9.3.2.C): (9.32)-(9.35), Algorithms 1 and 2, against sampled rigid-body motion."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from parking_cases import CAR_91, CAR_92, arc_poses, corners_world

from wmrkit.parking.collisions import (
    approach_offset_closed_form,
    approach_offset_sweep,
    front_rear_collision,
    front_rear_collision_printed,
    lateral_reach,
    trailing_dip,
)
from wmrkit.parking.geometry import Vehicle, corner_angle, corner_distance
from wmrkit.parking.planner import _symmetric_arcs

vehicles = st.builds(Vehicle, st.floats(0.3, 4.0), st.floats(0.0, 1.5), st.floats(0.3, 3.0), st.just(0.3),
                     st.just(0.3), st.just(0.7))  # h1 and the track within the smallest body (wheels inside it)


def manoeuvre(vehicle, rho, xi, direction, n=3000):
    """P_f's poses over the two arcs of a manoeuvre toward the right (the curb), from (0, 0, 0)."""
    segs = _symmetric_arcs(vehicle, 3, 1, (0.0, 0.0, 0.0), direction, -1, rho, xi)
    return [arc_poses(s.start, s.direction, s.curvature, s.length, n) for s in segs]


@settings(max_examples=200)
@given(vehicles, st.floats(0.1, 6.0), st.floats(0.01, math.pi / 2), st.sampled_from([-1, 1]))
def test_lateral_reach_9_33_is_the_sampled_maximum_of_the_second_arc(vehicle, rho, xi, direction):
    """(9.33) with the clamp theta = min(delta_i, xi): the leading outer corner's farthest lateral reach."""
    _, arc2 = manoeuvre(vehicle, rho, xi, direction)
    _, y = corners_world(vehicle, arc2)
    corner = 0 if direction < 0 else 1  # rear-right (P1) reversing, front-right (P2) forward
    reach = float(np.max(-y[:, corner]))
    step = corner_distance(vehicle, rho, 1 if direction < 0 else 2) * xi / 3000  # corner travel per sample
    assert lateral_reach(vehicle, rho, xi, 1 if direction < 0 else 2) == pytest.approx(reach, abs=step)


@settings(max_examples=150)
@given(vehicles, st.floats(0.05, 3.0), st.floats(0.01, math.pi / 2), st.sampled_from([-1, 1]))
def test_with_rho_at_least_half_the_width_the_second_arc_decides(vehicle, rho, xi, direction):
    """The thesis's "only the second arc matters": no part of the body reaches farther over the whole manoeuvre."""
    rho = max(rho, vehicle.c1 / 2)
    both = np.vstack(manoeuvre(vehicle, rho, xi, direction))
    _, y = corners_world(vehicle, both)
    step = corner_distance(vehicle, rho, 2) * xi / 3000
    assert float(np.max(-y)) <= lateral_reach(vehicle, rho, xi, 1 if direction < 0 else 2) + step


def test_errata_9_33_maximum_needs_the_clamp():
    """(9.33) as printed (d_i + Z, at theta = delta_i) overstates the reach when delta_i > xi: the arc ends first."""
    rho, xi = 10.0, math.radians(2.5)  # like example 1's second manoeuvre: delta_2 = 8 deg > xi
    assert corner_angle(CAR_91, rho, 2) > xi
    _, arc2 = manoeuvre(CAR_91, rho, xi, 1)
    _, y = corners_world(CAR_91, arc2)
    true_reach = float(np.max(-y[:, 1]))
    printed = corner_distance(CAR_91, rho, 2) + rho * (1 - 2 * math.cos(xi))
    assert printed - true_reach > 0.005  # millimetres matter: this is the curb clearance
    assert lateral_reach(CAR_91, rho, xi, 2) == pytest.approx(true_reach, abs=1e-5)


@settings(max_examples=200)
@given(vehicles, st.one_of(st.floats(0.05, 0.95), st.floats(1.05, 2.0)), st.floats(0.01, math.pi / 2),
       st.sampled_from([-1, 1]))
def test_algorithm_1_front_rear_overshoot(vehicle, scale, xi, direction):
    """The body overshoots its final longitudinal extent iff rho < c1/2 (sampled motion, both arcs)."""
    rho = scale * vehicle.c1 / 2
    both = np.vstack(manoeuvre(vehicle, rho, xi, direction))
    x, _ = corners_world(vehicle, both)
    overshoot = float(np.max(direction * x) - np.max(direction * x[-1]))
    assert (overshoot > 1e-6) == front_rear_collision(vehicle, rho, xi, 3 if direction < 0 else 4)


def test_errata_9_35_second_condition_does_not_prevent_the_overshoot():
    """(9.35) "rho <= c1/2 - b1 tan(xi)" -> no collision: the sampled motion overshoots by decimetres."""
    v = Vehicle(a1=1.0, b1=0.45, c1=2.5, h1=1.0, track=0.5, phi_max=0.7)
    rho, xi = 0.57, math.radians(54.2)
    assert rho <= v.c1 / 2 - v.b1 * math.tan(xi)
    assert not front_rear_collision_printed(v, rho, xi, 3)
    x, _ = corners_world(v, np.vstack(manoeuvre(v, rho, xi, -1)))
    assert float(np.max(-x) - np.max(-x[-1])) > 0.1
    assert front_rear_collision(v, rho, xi, 3)


@pytest.mark.parametrize(("vehicle", "rho", "xi"), [(CAR_92, 1.75, math.asin(3.03 / 3.5)),
                                                    (CAR_91, 1.2, 0.9), (CAR_91, 2.5, 0.5)])
def test_algorithm_2_closed_form_equals_the_printed_sweep(vehicle, rho, xi):
    closed = approach_offset_closed_form(vehicle, rho, xi)
    sweep = approach_offset_sweep(vehicle, rho, xi)
    if closed is None:
        assert sweep is None
    else:
        assert closed == pytest.approx(sweep, abs=1e-5)


def test_algorithm_2_example_2_and_the_grazing_corner():
    """Example 2: dx1 = 190.4 cm (digest §3.6); from that offset the front-right corner grazes the obstacle corner."""
    rho, xi = 1.75, math.asin(3.03 / 3.5)
    dx1 = approach_offset_closed_form(CAR_92, rho, xi)
    assert dx1 == pytest.approx(1.904, abs=5e-4)
    segs = _symmetric_arcs(CAR_92, 3, 1, (0.0, dx1, 0.0), -1, -1, rho, xi)
    poses = np.vstack([arc_poses(s.start, s.direction, s.curvature, s.length, 20000) for s in segs])
    x, y = corners_world(CAR_92, poses)
    inside = (x[:, 1] > 1e-9) & (y[:, 1] < -1e-9)  # the front-right corner inside the front obstacle
    assert not inside.any()
    assert float(np.min(np.hypot(x[:, 1], y[:, 1]))) < 1e-3  # and it passes through the obstacle's corner
    segs = _symmetric_arcs(CAR_92, 3, 1, (0.0, dx1 - 0.01, 0.0), -1, -1, rho, xi)
    poses = np.vstack([arc_poses(s.start, s.direction, s.curvature, s.length, 20000) for s in segs])
    x, y = corners_world(CAR_92, poses)
    assert ((x[:, 1] > 1e-6) & (y[:, 1] < -1e-6)).any()  # 1 cm closer: it cuts the obstacle


def test_algorithm_2_no_constraint_in_example_1():
    """Example 1 (rho = 139.3 cm, xi = 71.97 deg): P2 clears the face during the whole second arc (digest)."""
    assert approach_offset_closed_form(CAR_91, 1.05 / math.tan(math.radians(37)), math.radians(71.97)) is None


@settings(max_examples=150)
@given(vehicles, st.floats(0.1, 6.0), st.floats(0.01, math.pi / 2))
def test_trailing_dip_is_the_sampled_swing_of_the_first_arc(vehicle, rho, xi):
    """Reversing to the left (away from y < 0), the front-right corner swings right in the first arc."""
    segs = _symmetric_arcs(vehicle, 2, 0, (0.0, 0.0, 0.0), -1, 1, rho, xi)
    arc1 = arc_poses(segs[0].start, segs[0].direction, segs[0].curvature, segs[0].length, 3000)
    _, y = corners_world(vehicle, arc1)
    dip = float(np.max(-(y[:, 1] + vehicle.c1 / 2)))
    step = corner_distance(vehicle, rho, 2) * xi / 3000
    assert trailing_dip(vehicle, rho, xi, 2) == pytest.approx(dip, abs=step)
