"""The planner (§9.3.2-9.3.3): Tables 9.1 and 9.2, Fig. 9.30's trend, bounded loops, infeasible answers."""

from __future__ import annotations

import math
import time
from dataclasses import replace

import pytest
from parking_cases import CAR_91, CAR_92, SLOT_91, SLOT_92

from wmrkit.errors import WmrkitError
from wmrkit.parking import Space, Vehicle, length_ratio, plan_parking, shortest_slot
from wmrkit.parking.collisions import lateral_reach
from wmrkit.parking.geometry import arcs_through, corner_distance
from wmrkit.parking.planner import approach_point, first_reach, pass_end, plan_thesis, roomy_length
from wmrkit.parking.problem import load_problem

#: Seconds past which a plan is taken to hang (the printed loops never end); a plan takes about 1 ms, which
#: benchmarks/bench_parking.py measures: no test is timed against a target.
HANG = 10.0


def test_table_9_1_gives_two_manoeuvres():
    plan = plan_parking(CAR_91, SLOT_91)
    assert plan.feasible and plan.maneuvers == 2
    first = plan.arcs[0]  # digest §3.6: phi reduced to 37 deg, rho 139.3 cm, xi 71.97 deg, X 192.4, gap 7.6
    assert first.rho == pytest.approx(1.05 / math.tan(math.radians(37)), rel=1e-12)
    assert math.degrees(first.xi) == pytest.approx(71.97, abs=0.005)
    assert first.X == pytest.approx(1.924, abs=5e-4)
    assert first.gap_after == pytest.approx(0.076, abs=5e-4)
    assert plan.dx1 == pytest.approx(0.70) and plan.dy3 == 0.0
    assert plan.final_gap < SLOT_91.final_gap <= first.gap_after


def test_table_9_2_gives_four_manoeuvres():
    plan = plan_parking(CAR_92, SLOT_92)
    assert plan.feasible and plan.maneuvers == 4
    # digest §3.6 (cm): rho 175 / 175 / 175 / 270.0; xi 59.96 / 38.11 / 38.11 / 23.58 deg; gaps 200.6 / 126.0 /
    # 51.4 / 6.3; dx1 = 190.4
    assert [a.rho for a in plan.arcs[:3]] == pytest.approx([1.75] * 3)
    assert plan.arcs[3].rho == pytest.approx(2.700, abs=5e-4)
    assert [math.degrees(a.xi) for a in plan.arcs] == pytest.approx([59.96, 38.11, 38.11, 23.58], abs=0.005)
    assert [a.gap_after for a in plan.arcs] == pytest.approx([2.006, 1.260, 0.514, 0.063], abs=5e-4)
    assert [a.direction for a in plan.arcs] == [-1, 1, -1, 1]
    assert plan.dx1 == pytest.approx(1.904, abs=5e-4)


def test_shipped_problem_files_are_the_tables():
    for name, car, slot, count in (("thesis-9.1", CAR_91, SLOT_91, 2), ("thesis-9.2", CAR_92, SLOT_92, 4)):
        problem = load_problem(name)
        assert _close(problem.vehicle, car)
        assert _close(problem.space, slot)
        assert plan_parking(problem.vehicle, problem.space).maneuvers == count


def _close(a, b) -> bool:
    return all(math.isclose(getattr(a, f), getattr(b, f), rel_tol=1e-12) for f in a.__slots__)


@pytest.mark.parametrize("step_deg", [0.1, 0.25, 0.5, 1.0])
def test_counts_hold_for_steering_decrements_from_0_1_to_1_deg(step_deg):
    """Digest §3.6 (a): the counts are sensitive to Algorithm 3's unspecified decrement; 0.1-1 deg give 2 and 4."""
    step = math.radians(step_deg)
    assert plan_parking(CAR_91, SLOT_91, phi_step=step).maneuvers == 2
    assert plan_parking(CAR_92, SLOT_92, phi_step=step).maneuvers == 4


def test_errata_algorithm_3_decreases_phi_while_2_rho_is_shorter_than_the_travel():
    """Example 1: D_y = 265 cm > 2 rho_min = 202.8 cm, (9.31)b has no xi; phi drops to 38 deg, then to 37 (step 7)."""
    d_y = SLOT_91.H - SLOT_91.MS - CAR_91.b1
    assert d_y > 2 * CAR_91.rho_min
    rho, _, dx1 = approach_point(CAR_91, SLOT_91, SLOT_91.dx2)
    assert dx1 == pytest.approx(CAR_91.c1 / 2)  # the sweep allows 68.3 cm, clamped to c1/2 (step 8)
    assert rho == pytest.approx(1.05 / math.tan(math.radians(37)))
    rho38 = 1.05 / math.tan(math.radians(38))
    xi38 = math.asin(d_y / (2 * rho38))
    assert lateral_reach(CAR_91, rho38, xi38, 1) - SLOT_91.J > SLOT_91.dx2  # why 38 deg is refused


def test_figure_9_30_manoeuvres_grow_quickly_below_30_percent():
    """Fig. 9.30 (example 1, H varied): few manoeuvres above a 30 % length ratio, many below (pass at c1/2 + MS)."""
    slot = replace(SLOT_91, dx2=0.9)
    counts = {}
    for h in (2.9, 3.0, 3.1, 3.3, 3.5, 3.7, 3.9, 4.1):
        s = replace(slot, H=h)
        counts[round(100 * length_ratio(CAR_91, s))] = plan_parking(CAR_91, s).maneuvers
    low = [n for r, n in counts.items() if r < 27]
    high = [n for r, n in counts.items() if r > 30]
    assert min(low) > 2 * max(high)
    assert counts[20] > counts[23] > counts[26] > max(high)
    assert max(high) <= 3


def test_too_short_slot_is_infeasible_with_the_reason_and_the_shortest_slot():
    short = replace(SLOT_91, H=2.3)
    plan = plan_parking(CAR_91, short)
    assert not plan.feasible and "too short" in plan.reason
    h = shortest_slot(CAR_91, replace(SLOT_91, H=2.3, dx2=0.9))
    assert h is not None
    assert plan_parking(CAR_91, replace(SLOT_91, H=h, dx2=0.9)).feasible
    assert not plan_parking(CAR_91, replace(SLOT_91, H=h - 0.002, dx2=0.9)).feasible


def test_narrow_slot_is_infeasible_and_no_length_helps():
    narrow = replace(SLOT_91, J=1.3)
    plan = plan_parking(CAR_91, narrow)
    assert not plan.feasible and "narrower" in plan.reason
    assert shortest_slot(CAR_91, narrow, span=2.0, step=0.05) is None


def test_errata_algorithm_4_literal_loop_never_ends_and_is_bounded_here():
    """Moving toward the obstacles onto an approach point at c1/2, the leading rear corner's reach (9.33) exceeds
    the pass's offset for every dy3: the printed "dy3 += Delta" loop never exits. wmrkit's search is bounded, and
    the plan moves the approach point out by the remaining overshoot instead."""
    v, dx1, offset = CAR_91, CAR_91.c1 / 2, CAR_91.c1 / 2 + 0.2
    for dy3 in (1.0, 3.0, 10.0, 30.0, 100.0):
        rho, xi = arcs_through(offset - dx1, dy3)
        assert lateral_reach(v, rho, xi, 1) > offset  # still colliding: the loop would go on
    t0 = time.perf_counter()
    assert pass_end(v, dx1, offset) is None
    plan = plan_parking(v, replace(SLOT_91, dx2=offset))
    assert time.perf_counter() - t0 < HANG  # the printed loop never ends
    assert plan.feasible and plan.maneuvers == 2 and c1_half_clear(plan)


def c1_half_clear(plan) -> bool:
    return CAR_91.c1 / 2 < plan.dx1 < CAR_91.c1 / 2 + 0.01


def test_errata_algorithm_4_printed_branches_are_swapped():
    """"max(dx1, dx2) >= (9.33) -> no collision; else EXIT" exits exactly when there is a collision."""
    v, dx1, offset = CAR_91, 1.2, 1.5  # toward the obstacles by 30 cm
    dy3, rho, xi = pass_end(v, dx1, offset)
    assert lateral_reach(v, rho, xi, 1) <= max(dx1, offset)  # the S found is collision-free by (9.33)
    rho0, xi0 = arcs_through(offset - dx1, 2 * v.rho_min * math.sin(math.acos(1 - 0.3 / (2 * v.rho_min))))
    assert lateral_reach(v, rho0, xi0, 1) <= max(dx1, offset)  # the shortest S is already clear: printed
    # branch "no collision -> continue" would lengthen it forever; wmrkit keeps it
    assert dy3 == pytest.approx(2 * rho0 * math.sin(xi0))


def test_pass_touching_the_obstacles_cannot_back_away_from_them():
    """From a pass at c1/2 (touching the parked cars), any reverse S away from them swings the front corner in."""
    v = CAR_91
    assert pass_end(v, v.c1 / 2 + 0.2, v.c1 / 2) is None
    plan = plan_thesis(v, replace(SLOT_91, H=3.0))  # example 1's pass, a shorter slot needs dx1 > dx2
    assert not plan.feasible and "Algorithm 4" in plan.reason
    # plan_parking steers the first manoeuvre less (13 deg, not Algorithm 3's): an approach point on the pass
    gentler = plan_parking(v, replace(SLOT_91, H=3.0))
    assert gentler.feasible and gentler.dx1 == v.c1 / 2 and gentler.maneuvers == 21


def test_algorithm_5_root_touches_the_curb_exactly():
    """Example 1's second manoeuvre: the reach of P2 equals the room W_max (the root of Algorithm 5 step 4)."""
    plan = plan_parking(CAR_91, SLOT_91)
    second = plan.arcs[1]
    room = plan.arcs[0].gap_after + CAR_91.c1 / 2
    assert lateral_reach(CAR_91, second.rho, second.xi, 2) == pytest.approx(room, abs=1e-9)
    assert second.rho > corner_distance(CAR_91, 0.0, 2)  # far larger than the minimum radius


def test_units_rounding_does_not_change_the_plan():
    """"70 cm" and "140 cm" / 2 differ in floating point (0.7 vs 0.7000000000000001): same plan, no warning."""
    wide = replace(CAR_91, c1=1.4000000000000001)
    for dx2 in (0.7, 0.7000000000000001, 0.7000000000000002):
        plan = plan_parking(wide, replace(SLOT_91, dx2=dx2))
        assert plan.feasible and plan.maneuvers == 2 and not plan.warnings
        assert plan.dx1 == plan.pass_offset == dx2


def test_huge_but_finite_inputs_return_quickly():
    """Python callers are not limited to 1 km: every loop and search stays bounded. (A 1e9 m slot parks in its
    front part: a longer slot is never harder, tests/parking/test_long_slots.py.)"""
    t0 = time.perf_counter()
    space = replace(SLOT_91, H=1e9, dx2=1e6)
    plan = plan_parking(CAR_91, space)
    assert time.perf_counter() - t0 < HANG and plan.used_H <= roomy_length(CAR_91, space)
    assert not plan_thesis(CAR_91, space).feasible  # Algorithm 3 alone reverses along the whole slot
    assert shortest_slot(replace(CAR_91, a1=1e4), replace(SLOT_91, J=1.3)) is None
    assert time.perf_counter() - t0 < 2 * HANG


@pytest.mark.parametrize(("search", "options", "message"), [
    (plan_parking, {"phi_step": 0.0}, "phi_step: must be a finite angle >= phi_max / 100000"),  # ZeroDivisionError
    (plan_parking, {"phi_step": float("nan")}, "phi_step: must be a finite angle"),  # ValueError: NaN to integer
    (plan_parking, {"phi_step": -0.01}, "phi_step: must be a finite angle"),  # 'no steering angle...': wrong reason
    (plan_parking, {"phi_step": 1e-12}, "phi_step: must be a finite angle"),  # 6e11 steering angles: days of looping
    (plan_parking, {"max_maneuvers": 0}, "max_maneuvers: must be an integer >= 1, got 0"),  # 1 manoeuvre anyway
    (plan_parking, {"max_maneuvers": 2.5}, "max_maneuvers: must be an integer >= 1, got 2.5"),
    (shortest_slot, {"step": float("nan")}, "step: must be a finite length > 0 m, got nan"),  # NaN to integer
    (shortest_slot, {"span": float("nan")}, "span: must be a finite length > 0 m, got nan"),
    (shortest_slot, {"span": -1.0}, "span: must be a finite length > 0 m, got -1.0"),  # None: 'no length works'
    (shortest_slot, {"max_maneuvers": -1}, "max_maneuvers: must be an integer >= 1, got -1"),
])
def test_the_parking_searches_refuse_their_options_by_name(search, options, message):
    vehicle = Vehicle(a1=3.5, b1=0.9, c1=1.8, h1=2.6, track=1.5, phi_max=0.6)
    space = Space(H=7.0, J=2.5, MS=0.2, dx2=1.5, final_gap=0.1)
    with pytest.raises(WmrkitError) as err:
        search(vehicle, space, **options)
    assert str(err.value).startswith(message)


def test_shortest_slot_over_a_huge_span_still_finds_the_window():
    """Slots that work are not monotonic in H: past first_reach (2 rho at the smallest steering angle tried, 790 m
    here) Algorithm 3 cannot enter them. With span=1e9 the scan's step grew to 5e5 m, jumped over every slot that
    works, and answered None ('no length works'), though 5.32 m does; the scan now stops at that reach."""
    vehicle = Vehicle(a1=3.5, b1=0.9, c1=1.8, h1=2.6, track=1.5, phi_max=0.6)
    space = Space(H=7.0, J=2.5, MS=0.2, dx2=1.5, final_gap=0.1)
    found = shortest_slot(vehicle, space)
    assert found == pytest.approx(5.3246, abs=1e-3)
    assert shortest_slot(vehicle, space, span=1e9) == pytest.approx(found, abs=1e-3)
    reach = space.MS + vehicle.b1 + first_reach(vehicle)
    assert plan_thesis(vehicle, replace(space, H=reach - 1.0)).reason != plan_thesis(
        vehicle, replace(space, H=reach + 1.0)).reason  # the bound is where the thesis planner's reason changes
    assert plan_parking(vehicle, replace(space, H=reach + 1.0)).feasible  # in the slot's front part
