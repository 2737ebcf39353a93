"""Exact geometry (shapely) on the planner's motion: the thesis's examples and random cars and slots."""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from parking_cases import CAR_91, CAR_92, SLOT_91, SLOT_92

from wmrkit.parking import blackburn_min_length, plan_parking, shortest_slot
from wmrkit.parking.geometry import Space, Vehicle
from wmrkit.parking.path import Segment

pytest.importorskip("shapely")
from wmrkit.parking.verify import check_plan, check_poses


@pytest.mark.parametrize(("car", "slot"), [(CAR_91, SLOT_91), (CAR_92, SLOT_92)], ids=["9.1", "9.2"])
def test_thesis_plans_are_collision_free_and_end_in_the_slot(car, slot):
    plan = plan_parking(car, slot)
    report = check_plan(car, slot, plan.segments)
    assert report.collision_free, report.what
    assert report.inside
    assert len(report.poses) > 1000


def test_the_check_sees_a_collision():
    """Independence: the same path moved 30 cm forward hits the front car; a pose over the curb hits the curb."""
    plan = plan_parking(CAR_91, SLOT_91)
    shifted = [Segment(s.phase, s.maneuver, s.direction, s.curvature, s.length, s.steering,
                       (s.start[0] + 0.3, *s.start[1:]), (s.end[0] + 0.3, *s.end[1:])) for s in plan.segments]
    report = check_plan(CAR_91, SLOT_91, shifted)
    assert not report.collision_free and report.what == "front"
    report = check_poses(CAR_91, SLOT_91, np.array([[-2.0, -1.0, 0.0], [-2.0, -1.4, 0.0]]))
    assert report.colliding.tolist() == [False, True] and report.what == "curb"


def test_a_check_in_chunks_sees_what_one_pass_sees(monkeypatch):
    """The check tests its poses CHUNK at a time (memory bounded): a shifted path that hits the front car (the
    hits in the middle of the path) gives the same per-pose answers, obstacle and clearance in chunks of 7 as in
    one; the rear car is hit by a path shifted back."""
    from wmrkit.parking import verify

    plan = plan_parking(CAR_91, SLOT_91)
    for dx, first in ((0.3, "front"), (-1.0, "rear")):
        shifted = [Segment(s.phase, s.maneuver, s.direction, s.curvature, s.length, s.steering,
                           (s.start[0] + dx, *s.start[1:]), (s.end[0] + dx, *s.end[1:])) for s in plan.segments]
        whole = check_plan(CAR_91, SLOT_91, shifted)
        monkeypatch.setattr(verify, "CHUNK", 7)
        chunked = check_plan(CAR_91, SLOT_91, shifted)
        monkeypatch.undo()
        assert whole.what == chunked.what == first and 0 < chunked.n_collisions < len(chunked.poses)
        assert np.array_equal(whole.colliding, chunked.colliding)
        assert (whole.min_clearance, whole.inside) == (chunked.min_clearance, chunked.inside)


def test_too_many_poses_are_refused_before_they_are_made():
    """At most MAX_CHECK_POSES poses: eleven 100 m stretches sampled every 0.1 mm of corner motion would be 1.1e7
    (the count said 2.2e6 while sample_poses capped a segment at 200,000 poses: the check was coarser)."""
    from wmrkit.errors import WmrkitError
    from wmrkit.parking.verify import MAX_CHECK_POSES, densify

    segs = [Segment(1, 0, 1, 0.0, 100.0, 0.0, (100.0 * k, 5.0, 0.0), (100.0 * (k + 1), 5.0, 0.0)) for k in range(11)]
    with pytest.raises(WmrkitError, match=f"would test 1.1e\\+07 poses .*at most {MAX_CHECK_POSES}"):
        check_plan(CAR_91, SLOT_91, segs, corner_step=1e-4)
    with pytest.raises(WmrkitError, match=f"at most {MAX_CHECK_POSES}"):
        check_poses(CAR_91, SLOT_91, np.zeros((MAX_CHECK_POSES + 1, 3)))
    with pytest.raises(WmrkitError, match=f"at most {MAX_CHECK_POSES}"):
        densify(CAR_91, np.array([[-1000.0, 5.0, 0.0], [0.0, 5.0, 0.0]]), corner_step=1e-4)


def test_touching_is_not_a_collision():
    """Example 1 drives with the car's side on the obstacles' line (dx2 = c1/2): clearance 0, no overlap."""
    report = check_plan(CAR_91, SLOT_91, plan_parking(CAR_91, SLOT_91).segments)
    assert report.min_clearance == pytest.approx(0.0, abs=1e-9) and report.collision_free


@st.composite
def problems(draw):
    a1 = draw(st.floats(0.4, 4.0))
    b1 = draw(st.floats(0.0, 1.5))
    c1 = draw(st.floats(0.5, 3.5))
    h1 = draw(st.floats(0.3, min(a1, 3.0)))  # the front axle within the body
    phi = draw(st.floats(math.radians(15), math.radians(60)))
    ms = draw(st.floats(0.0, 0.3))
    length = a1 + b1
    H = draw(st.floats(length + 2 * ms - 0.3, 2.5 * length + 2 * ms + 1.0))
    J = draw(st.floats(c1 - 0.2, c1 + 1.5))
    dx2 = draw(st.floats(c1 / 2 - 0.3, c1 / 2 + 1.5))
    gap = draw(st.floats(0.02, min(0.3, 0.9 * J)))  # a gap less than the width (Space refuses one wider)
    return Vehicle(a1, b1, c1, h1, 0.5, phi), Space(max(H, 0.1), max(J, 0.1), ms, max(dx2, 0.0), gap)


@settings(max_examples=240)
@given(problems())
def test_planner_never_loops_and_feasible_plans_are_exactly_collision_free(problem):
    vehicle, space = problem
    t0 = time.perf_counter()
    plan = plan_parking(vehicle, space, max_maneuvers=40)
    assert time.perf_counter() - t0 < 10.0  # bounded: no hang on any input (a plan takes about 1 ms; no timing)
    if not plan.feasible:
        assert plan.reason and plan.maneuvers == 0
        return
    report = check_plan(vehicle, space, plan.segments, corner_step=0.005)
    assert report.collision_free, (plan.reason, report.what)
    assert report.inside
    assert plan.final_gap < space.final_gap + 1e-9 and abs(plan.final_pose[2]) < 1e-9
    assert 1 <= plan.maneuvers <= 40


@pytest.mark.parametrize("car", [CAR_91, CAR_92, Vehicle(3.6, 1.0, 1.8, 2.7, 1.55, math.radians(35))],
                         ids=["9.1", "9.2", "car"])
def test_one_manoeuvre_slots_are_not_shorter_than_blackburns_bound(car):
    """The shortest slot the planner enters in one manoeuvre (no margin) is at least the closed-form bound."""
    slot = Space(H=10.0, J=car.c1 + 2.0, MS=0.0, dx2=car.c1 / 2 + 0.5, final_gap=2.1)  # any gap in the slot is < 2
    h = shortest_slot(car, slot, step=0.02, span=8.0, max_maneuvers=1)
    assert h is not None
    bound = blackburn_min_length(car)
    assert h >= bound - 1e-9
    if car.c1 < car.length:  # ordinary cars: close to it (the 3.5 m wide example 2 must first shift by its width)
        assert h < 1.6 * bound
    assert check_plan(car, replace(slot, H=h), plan_parking(car, replace(slot, H=h)).segments).collision_free


@pytest.mark.parametrize(("car", "slot"), [(CAR_91, SLOT_91), (CAR_92, SLOT_92)], ids=["9.1", "9.2"])
def test_errata_algorithm_5_travel_is_the_free_length(car, slot):
    """Algorithm 5 step 3 prints Y = H - 2 MS = H': a forward manoeuvre that long drives the front into the front
    car; Y = H' - (a1 + b1) (the free length for P_f) stays clear, and reproduces the counts 2 and 4."""
    from wmrkit.parking.planner import _symmetric_arcs, maneuver_arcs

    plan = plan_parking(car, slot)
    first = [s for s in plan.segments if s.phase == 3 and s.maneuver == 1]
    end = (first[-1].end[0], first[-1].end[1], 0.0)
    room = end[1] + slot.J
    for travel, clear in ((slot.effective_length, False), (slot.effective_length - car.length, True)):
        arcs = maneuver_arcs(car, travel, room, 1)
        assert arcs is not None
        segs = _symmetric_arcs(car, 3, 2, end, 1, -1, *arcs)
        report = check_plan(car, slot, segs)
        assert report.collision_free == clear
        if not clear:
            assert report.what == "front"


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 10**6), step=st.floats(0.001, 0.01))
def test_densified_poses_move_no_corner_more_than_the_step(seed, step):
    """Between neighbours of :func:`densify` no corner of the car moves more than `step` (corners placed by
    rotation, independent of the bound it uses), and every given pose is kept, in order."""
    from wmrkit.parking.geometry import footprint
    from wmrkit.parking.verify import densify

    rng = np.random.default_rng(seed)
    poses = np.cumsum(rng.normal(0.0, [0.03, 0.03, 0.05], size=(20, 3)), axis=0)
    dense = densify(CAR_91, poses, step)
    corners = np.array(footprint(CAR_91))
    c, s = np.cos(dense[:, 2]), np.sin(dense[:, 2])
    x = dense[:, None, 0] + c[:, None] * corners[:, 0] - s[:, None] * corners[:, 1]
    y = dense[:, None, 1] + s[:, None] * corners[:, 0] + c[:, None] * corners[:, 1]
    assert np.hypot(np.diff(x, axis=0), np.diff(y, axis=0)).max() <= step * (1 + 1e-9)
    kept = [int(np.flatnonzero(np.all(np.isclose(dense, p, rtol=0, atol=1e-12), axis=1))[0]) for p in poses]
    assert kept == sorted(kept) and kept[0] == 0 and kept[-1] == len(dense) - 1


@pytest.mark.parametrize("poses", [np.zeros((6, 2)), np.zeros((3, 4)), np.zeros((2, 2, 3)),
                                   [[-1.7, -1.245, math.nan]], [[0.0, 0.0, "30 deg"]]])
def test_pose_arrays_other_than_n_by_3_finite_are_refused(poses):
    """(6, 2) positions were reshaped into four poses mixing x, y and theta (a wrong answer), NaN raised a GEOS
    traceback, (3, 4) numpy's reshape error."""
    from wmrkit.errors import ShapeError
    from wmrkit.parking.verify import densify

    with pytest.raises(ShapeError, match="poses"):
        check_poses(CAR_91, SLOT_91, poses)
    with pytest.raises(ShapeError, match="poses"):
        densify(CAR_91, poses)


def test_one_pose_is_one_row():
    final = plan_parking(CAR_91, SLOT_91).final_pose
    report = check_poses(CAR_91, SLOT_91, np.array(final))
    assert report.poses.shape == (1, 3) and report.collision_free and report.inside
