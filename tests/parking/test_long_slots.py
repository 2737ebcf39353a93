"""Long slots: a longer slot is never harder to park in. The car parks in the part of the slot behind the front
obstacle where the thesis's planner does best; Algorithm 3 alone reverses along the whole slot."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from parking_cases import CAR_91, CAR_92, SLOT_91, SLOT_92, scaled

from wmrkit.parking import Space, Vehicle, plan_parking
from wmrkit.parking.path import path_length
from wmrkit.parking.planner import plan_thesis, roomy_length
from wmrkit.parking.verify import check_plan

pytest.importorskip("shapely")


def _after_pass(plan) -> float:
    """P_f's path after the detection pass [m] (the pass runs along the whole slot, whatever the car does)."""
    return path_length([s for s in plan.segments if s.phase > 1])


@pytest.mark.parametrize(("car", "slot"), [(CAR_91, SLOT_91), (CAR_92, SLOT_92)])
def test_a_1_km_slot_parks_with_no_more_than_the_thesis_slot_needs(car, slot):
    """Before: 'the slot is longer than the first backward manoeuvre can span' (no plan) for example 1's car in a
    1 km slot: Algorithm 3 reverses along the whole slot. Now a plan, with no more manoeuvres and no longer a
    manoeuvre than the thesis's own slot needs, collision-free and inside the 1 km slot by the exact check."""
    comfortable = plan_parking(car, slot)
    space = replace(slot, H=1000.0)
    plan = plan_parking(car, space)
    assert plan.feasible, plan.reason
    assert plan.maneuvers <= comfortable.maneuvers
    assert _after_pass(plan) <= _after_pass(comfortable)
    assert plan.used_H <= roomy_length(car, space) and plan.space == space
    assert plan.final_gap < space.final_gap
    first = plan.segments[0]  # the detection pass starts at the 1 km slot's start
    assert first.phase == 1 and first.start[0] == pytest.approx(-space.H - car.a1)
    report = check_plan(car, space, [s for s in plan.segments if s.phase > 1])
    assert report.collision_free and report.inside


@pytest.mark.parametrize("H", [25.0, 60.0, 400.0])
def test_past_the_roomy_length_the_answer_no_longer_depends_on_the_length(H):
    """Before: example 1's car in a 25 m slot reversed along 24 m in a 45 m shallow S; from 23 m on, no plan."""
    plan = plan_parking(CAR_91, replace(SLOT_91, H=H))
    far = plan_parking(CAR_91, replace(SLOT_91, H=1000.0))
    assert plan.feasible and plan.arcs == far.arcs and plan.used_H == far.used_H
    assert _after_pass(plan) < 5.0


def test_slots_up_to_the_roomy_length_keep_the_thesis_plan():
    """The thesis's examples and every slot its planner handles up to the roomy length are unchanged."""
    for car, slot in ((CAR_91, SLOT_91), (CAR_92, SLOT_92), (CAR_91, replace(SLOT_91, H=5.5))):
        assert slot.H <= roomy_length(car, slot)
        plan = plan_parking(car, slot)
        assert plan == plan_thesis(car, slot) and plan.used_H is None


cars = st.builds(
    lambda c1, h1, front, b1, phi: Vehicle(a1=h1 + front, b1=b1, c1=c1, h1=h1, track=0.8 * c1,
                                           phi_max=math.radians(phi)),
    st.floats(1.0, 2.5), st.floats(1.5, 3.5), st.floats(0.3, 1.5), st.floats(0.2, 1.2), st.floats(25.0, 45.0))


@settings(max_examples=36)
@given(cars, st.floats(0.1, 1.0), st.floats(0.0, 0.3), st.floats(0.0, 1.0), st.floats(0.0, 1.0),
       st.floats(1.0, 100.0))
def test_a_longer_slot_never_turns_yes_into_no_nor_needs_more_manoeuvres(car, room, margin, offset, where, longer):
    """A slot of any length up to the roomy length against one past it (up to 100 times longer): a plan in the
    shorter one means a plan in the longer one, with no more manoeuvres. Before, slots longer than about eleven
    car lengths had no plan at all."""
    slot = Space(H=10.0, J=car.c1 + room, MS=margin, dx2=car.c1 / 2 + offset, final_gap=0.05)
    roomy = roomy_length(car, slot)
    lo = car.length + 2 * margin
    short = plan_parking(car, replace(slot, H=lo + where * (roomy - lo) + 1e-6))
    long = plan_parking(car, replace(slot, H=roomy * longer + 1e-6))
    if short.feasible:
        assert long.feasible, long.reason
        assert long.maneuvers <= short.maneuvers


@pytest.mark.parametrize("scale", [1e-3, 1e3])
@pytest.mark.parametrize(("car", "slot"), [
    (CAR_91, replace(SLOT_91, H=3.0)), (CAR_91, replace(SLOT_91, H=3.2, dx2=0.9)),
    (CAR_91, replace(SLOT_91, H=30.0, dx2=0.9)), (CAR_92, replace(SLOT_92, H=3.9)), (CAR_92, replace(SLOT_92, H=40.0))])
def test_a_mm_or_km_car_plans_the_same_manoeuvresscaled(car, slot, scale):
    """Geometry has no unit of length: the car and slot scaled by 1e-3 or 1e3 plan the same manoeuvres, scaled.
    Before, Algorithm 4's pass-end search had a 1 cm step and a 5 m range in metres: example 1 with H = 3 m had
    no plan, a 2 mm copy of it had one of 11 manoeuvres (its pass 1.8 km-equivalent past the front car), and a
    2 km car with H = 3.2 km, dx2 = 0.9 km got an approach point 7 cm-equivalent off (0.771 vs 0.703 m)."""
    plan = plan_parking(car, slot)
    small = plan_parking(*scaled(car, slot, scale))
    assert (small.feasible, small.maneuvers) == (plan.feasible, plan.maneuvers)
    if plan.feasible:
        for name in ("dx1", "dy3", "final_gap"):
            assert getattr(small, name) / scale == pytest.approx(getattr(plan, name), rel=1e-6, abs=1e-9), name
        assert [a.rho / scale for a in small.arcs] == pytest.approx([a.rho for a in plan.arcs], rel=1e-6)
        assert [a.xi for a in small.arcs] == pytest.approx([a.xi for a in plan.arcs], rel=1e-6)


@pytest.mark.parametrize(("scale", "H"), [(1.0, 1000.0), (1e-3, 3.35), (1e3, 3.35)])
def test_the_plan_figure_frames_the_manoeuvres_at_any_scale(scale, H):
    """The figure's frame is the slot (or the part parked in) and the path after the pass, padded in car sizes.
    Before: a 1 km slot's figure spanned 1 km, the manoeuvre a speck; a 2 mm car sat in a frame padded by metres
    (2.3 m wide for a 3.35 mm slot)."""
    from wmrkit.parking.plot import plot_plan

    car, slot = scaled(CAR_91, replace(SLOT_91, H=H), scale)
    plan = plan_parking(car, slot)
    ax = plot_plan(plan).axes[0]
    shown = plan.used_H if plan.used_H is not None else slot.H
    (left, right), (bottom, top) = ax.get_xlim(), ax.get_ylim()
    final = plan.final_pose
    assert left < final[0] - car.b1 and right > 0 and bottom < -slot.J and top > plan.pass_offset  # all in view
    assert right - left < shown + 3 * car.length and top - bottom < slot.J + plan.pass_offset + 2 * car.c1


@pytest.mark.parametrize("shift", [0.005, 0.05])
@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_the_exact_check_finds_the_same_collisions_at_any_scale(scale, shift):
    """Table 9.1's plan (after the pass) moved `shift` car-scaled metres toward the front car hits it, at any scale.
    Before, the check sampled every 2 mm of corner motion, in metres: the 2 mm copy was checked at 7 poses and
    called collision-free 50 um (5 cm scaled) into the front car; the 2 km copy was refused as too long."""
    car, slot = scaled(CAR_91, SLOT_91, scale)
    plan = plan_parking(car, slot)
    moved = [replace(s, start=(s.start[0] + shift * scale, *s.start[1:]), end=(s.end[0] + shift * scale, *s.end[1:]))
             for s in plan.segments if s.phase > 1]
    ref_car, ref_slot = scaled(CAR_91, SLOT_91, 1.0)
    reference = check_plan(ref_car, ref_slot, [replace(s, start=(s.start[0] + shift, *s.start[1:]),
                                                       end=(s.end[0] + shift, *s.end[1:]))
                                               for s in plan_parking(ref_car, ref_slot).segments if s.phase > 1])
    report = check_plan(car, slot, moved)
    assert not report.collision_free and report.what == "front"
    assert len(report.poses) == len(reference.poses)
    assert report.n_collisions == pytest.approx(reference.n_collisions, abs=2)


def test_the_exact_check_samples_a_kilometre_pass_as_densely_as_a_short_one():
    """sample_count capped a segment at 200,000 poses: the 1 km detection pass was checked every 5 mm, not every
    2 mm (1/1000 of the car's size) as documented. The corners' largest move between consecutive poses, from the
    body's corners placed at each pose, is within the documented step."""
    from wmrkit.parking.geometry import footprint
    from wmrkit.parking.verify import dense_poses

    plan = plan_parking(CAR_91, replace(SLOT_91, H=1000.0))
    poses = dense_poses(CAR_91, plan.segments)
    corners = np.array(footprint(CAR_91))
    c, s = np.cos(poses[:, 2:]), np.sin(poses[:, 2:])
    xy = np.stack([poses[:, :1] + c * corners[:, 0] - s * corners[:, 1],
                   poses[:, 1:2] + s * corners[:, 0] + c * corners[:, 1]], axis=-1)  # (N, 4, 2)
    moved = np.linalg.norm(np.diff(xy, axis=0), axis=-1).max()
    assert moved <= 1e-3 * max(CAR_91.length, CAR_91.c1) * (1 + 1e-9)
    assert len(poses) > 500_000  # the 1 km pass alone, every 2 mm


def test_the_animation_of_a_long_slot_shows_the_car_in_every_frame(tmp_path, monkeypatch):
    """Frames were spread over the whole drive: in a 1 km slot the 1 km detection pass took 2000 of the 2030 s,
    and 197 of 200 frames showed the car outside the frame (framed like the plot, on the manoeuvre). Each frame's
    car body (drawn, read back from its polygon) now overlaps the frame, and the last frame is the end."""
    from wmrkit.parking import plot

    drawn = []

    def fake_save(fig, update, frames, path, **_):
        ax = fig.axes[0]
        for k in frames:
            body = update(k)[0].get_xy()
            drawn.append((body[:, 0].max() >= ax.get_xlim()[0] and body[:, 0].min() <= ax.get_xlim()[1],
                          body[:4].mean(axis=0)))  # (closed: the first corner repeated)

    monkeypatch.setattr(plot, "save_gif", fake_save)
    plan = plan_parking(CAR_91, replace(SLOT_91, H=1000.0))
    assert plot.animate_plan(plan, tmp_path / "a.gif", max_frames=200) == len(drawn) == 200
    assert all(seen for seen, _ in drawn)
    end = np.array(plan.final_pose[:2])  # the body's centre at the end: P_f plus half (a1 - b1) ahead
    np.testing.assert_allclose(drawn[-1][1], end + np.array([(CAR_91.a1 - CAR_91.b1) / 2, 0.0]), atol=1e-6)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_the_plan_figure_draws_the_arcs_at_the_cars_scale(scale):
    """Each drawn arc's chords stay within 5e-5 car sizes of the circle (distance of each chord's midpoint to the
    arc's centre, placed from the segment's start pose by hand), and the path and rear axle are drawn with the same
    points at any scale. Before: samples every 2 cm, so a 2 mm car's 1.75 mm arcs were single chords (sagitta
    0.5 car sizes), and its rear axle a 5 cm bar."""
    from matplotlib.colors import to_hex

    from wmrkit.parking.plot import BACKWARD, FORWARD, plot_plan

    car, slot = scaled(CAR_91, SLOT_91, scale)
    plan = plan_parking(car, slot)
    ax = plot_plan(plan).axes[0]
    paths = [ln for ln in ax.lines if to_hex(ln.get_color()) in (FORWARD, BACKWARD) and ln.get_linewidth() == 1.4]
    assert len(paths) == len(plan.segments)
    unit = max(car.length, car.c1)
    counts = []
    for seg, line in zip(plan.segments, paths, strict=True):
        xy = np.asarray(line.get_xydata())
        counts.append(len(xy))
        assert np.allclose(xy[[0, -1]], [seg.start[:2], seg.end[:2]], atol=1e-9 * unit)
        if seg.curvature == 0:
            continue
        r = 1 / seg.curvature  # signed: the centre is on the left for r > 0
        x0, y0, th0 = seg.start
        centre = np.array([x0 - r * math.sin(th0), y0 + r * math.cos(th0)])
        mid = (xy[1:] + xy[:-1]) / 2
        sagitta = abs(r) - np.hypot(*(mid - centre).T)
        assert sagitta.max() < 5e-5 * unit
    assert counts == [len(ln.get_xydata()) for ln in _path_lines_at_scale_1()]
    axle = ax.lines[-1].get_xydata()  # the final car's rear axle is drawn last
    assert math.dist(*axle) == pytest.approx(car.track, rel=1e-9)


def _path_lines_at_scale_1():
    from matplotlib.colors import to_hex

    from wmrkit.parking.plot import BACKWARD, FORWARD, plot_plan

    ax = plot_plan(plan_parking(CAR_91, SLOT_91)).axes[0]
    return [ln for ln in ax.lines if to_hex(ln.get_color()) in (FORWARD, BACKWARD) and ln.get_linewidth() == 1.4]
