"""Table 8.1 (§8.5) for every vehicle of the catalog: the column, and which references each can follow."""

from __future__ import annotations

import numpy as np
import pytest
from continuity import feasibility  # Table 8.1's verdict: these shapes are tighter than the car's stops
from hypothesis import example, given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control.feasibility import COLUMNS, requirement, signals
from wmrkit.control.points import ControlError
from wmrkit.control.references import builtin_reference, load_reference, reference_from_samples
from wmrkit.control.track import track
from wmrkit.description import robot_from_dict

T1, T2_OFF, T2_ON = "type 1", "type 2, off axle", "type 2, on axle"
T4_OFF, T4_ON = "type 4, off axle", "type 4, on axle"
T35, T3_0 = "types 3 and 5, l_o != 0", "type 3, l_o = 0"
#: By hand from each file's geometry: where R (the origin) lies against the fixed axle / the steered wheels.
EXPECTED = {
    "ackermann": T4_ON, "agv-drive-unit": T4_ON, "bicycle": T4_ON, "diff-drive": T2_ON, "forklift": T4_OFF,
    "line-follower": T2_OFF, "mecanum-4": T1, "omni-3": T1, "omni-4": T1, "swerve-4": T35,
    "thesis-bicycle-castor": T4_ON, "thesis-bicycle-swedish": T4_ON, "thesis-diff-castor": T2_ON,
    "thesis-diff-swedish": T2_ON, "thesis-omni-castor": T1, "thesis-omni-swedish": T1, "thesis-steer-castor": T3_0,
    "thesis-steer-swedish": T3_0, "thesis-tricycle": T4_ON, "thesis-tricycle-ch4": T4_ON,
    "thesis-two-steer-castor": T35, "thesis-two-steer-swedish": T35, "skid-steer-4": T2_ON,
}
#: Table 8.1 read per column: feasible in the kinematic framework for (square with theta along the path, square
#: at a constant heading, arc-line, circle), and arc-line in the dynamic framework. square: tangent jumps, velocity
#: jumps (and theta with it, unless held constant); arc-line: curvature and turn rate jump, the tangent is continuous.
BEHAVIOUR = {
    T1: (False, True, True, True, False), T2_OFF: (True, True, True, True, True),
    T2_ON: (False, False, True, True, False), T4_OFF: (False, False, True, True, False),
    T4_ON: (False, False, False, True, False), T35: (False, False, False, True, False),
    T3_0: (False, False, True, True, False),
}
REFS = {name: builtin_reference(name) for name in ("square", "arc-line", "circle")}
REFS["square-fixed"] = reference_from_samples(
    "square at a constant heading", REFS["square"].t,
    np.column_stack([REFS["square"].pose[:, :2], 0 * REFS["square"].t]))


@pytest.mark.parametrize("name", catalog.names())
def test_table_8_1_for_every_catalog_vehicle(name):
    robot = catalog.load(name)
    assert name in EXPECTED, f"new catalog robot {name}: add its Table 8.1 column here"
    req = requirement(robot)
    assert req.column == EXPECTED[name]
    assert req.references == (2 if req.type in (2, 4) else 3)
    square, square_fixed, arc, circle, arc_dynamic = BEHAVIOUR[req.column]
    assert feasibility(robot, REFS["square"]).feasible == square
    assert feasibility(robot, REFS["square-fixed"]).feasible == square_fixed
    assert feasibility(robot, REFS["arc-line"]).feasible == arc
    assert feasibility(robot, REFS["circle"]).feasible == circle
    assert feasibility(robot, REFS["arc-line"], "dynamic").feasible == arc_dynamic
    assert feasibility(robot, REFS["circle"], "dynamic").feasible


def test_a_skid_steer_is_judged_as_the_differential_drive_it_drives_as():
    """skid-steer-4 (four fixed wheels on two parallel axles, degenerate: it turns only by slipping) was refused
    ('Table 8.1 does not apply'), while 'wmrkit track' drives it as a differential drive (the admissible twists of
    its wheels' linear rows). It is judged as one, saying so (``note``): the column and violations of diff-drive's
    for every reference and point; fixed wheels that fight otherwise (two axles crossing) are still refused."""
    skid, diff = catalog.load("skid-steer-4"), catalog.load("diff-drive")
    assert "skid steer" in requirement(skid).note and "type 2" in requirement(skid).note
    assert requirement(diff).note == ""
    for point in (None, (0.4, 0.0), (0.0, 0.2)):
        for framework in ("kinematic", "dynamic"):
            assert requirement(skid, framework, point=point).column == requirement(diff, framework, point=point).column
            for ref in REFS.values():
                got = feasibility(skid, ref, framework, point=point).violations
                assert got == feasibility(diff, ref, framework, point=point).violations
    crossed = robot_from_dict({"name": "crossed", "wheels": [
        {"name": "a", "type": "fixed", "position": [0.3, 0.0], "beta": 0.0, "r": 0.1},
        {"name": "b", "type": "fixed", "position": [-0.3, 0.0], "beta": 1.0, "r": 0.1},
        {"name": "c", "type": "fixed", "position": [0.0, 0.3], "beta": 0.5, "r": 0.1}]})
    with pytest.raises(ControlError, match=r"degenerate.*Table 8\.1 does not apply"):
        requirement(crossed)


def test_every_column_is_covered_by_the_catalog():
    assert set(EXPECTED.values()) == set(COLUMNS)


def test_violations_at_the_corners_with_their_remedies():
    square = REFS["square"]
    res = feasibility(catalog.load("forklift"), square)
    assert [v.t for v in res.violations] == pytest.approx(list(square.breaks), abs=0.011)
    assert all(v.signal == "chi" and "orientable wheel" in v.remedy for v in res.violations)
    assert all(v.size == pytest.approx(np.pi / 2, abs=1e-6) for v in res.violations)
    res = feasibility(catalog.load("diff-drive"), square)
    assert all("re-orient the vehicle" in v.remedy for v in res.violations)
    arc = feasibility(catalog.load("ackermann"), REFS["arc-line"])
    assert [v.signal for v in arc.violations] == ["kappa"]
    assert arc.violations[0].t == pytest.approx(REFS["arc-line"].breaks[0], abs=0.011)


def test_sampled_file_reference_gives_the_same_violations():
    """The square as samples (derivatives by finite differences): the same corners are found."""
    sq = REFS["square"]
    sampled = reference_from_samples("square.csv", sq.t, sq.pose)
    got = feasibility(catalog.load("forklift"), sampled)
    assert [round(v.t, 1) for v in got.violations] == [round(b, 1) for b in sq.breaks]
    # the central differences split each corner over two steps, each half of it: the jump is their sum (it was
    # reported as 0.785, half the corner)
    assert all(v.size == pytest.approx(np.pi / 2, abs=1e-6) for v in got.violations)
    assert feasibility(catalog.load("forklift"), reference_from_samples("c", REFS["circle"].t,
                                                                        REFS["circle"].pose)).feasible


def test_verdict_matches_the_closed_loop():
    """Independent check: in the ideal loop the forklift's wheel must jump exactly where Table 8.1 says."""
    robot, square = catalog.load("forklift"), REFS["square"]
    run = track(robot, square, duration=26.0, output_dt=0.02)
    dh = np.abs(np.angle(np.exp(1j * np.diff(run.heading[:, 0]))))
    jumps = run.t[1:][dh > 0.3]
    want = [v.t for v in feasibility(robot, square).violations if v.t < 26.0]
    assert jumps == pytest.approx(want, abs=0.02)
    smooth = track(robot, REFS["circle"], duration=10.0, output_dt=0.02)
    assert np.abs(np.angle(np.exp(1j * np.diff(smooth.heading[:, 0])))).max() < 0.05


def test_a_sampled_circle_has_no_jump_at_its_ends():
    """A reference from samples that starts and ends turning: first-order differences at the ends put the
    curvature at 1/6, 1/4, 1/3... and a false 'curvature jump' at the first and last samples (audit of ch. 8)."""
    t = np.arange(0.0, 37.7, 0.01)
    th = 0.5 / 3.0 * t
    ref = reference_from_samples("circle.csv", t, np.column_stack([3 * np.sin(th), 3 * (1 - np.cos(th)), th]))
    assert feasibility(catalog.load("ackermann"), ref).feasible
    assert feasibility(catalog.load("forklift"), ref, "dynamic").feasible
    assert np.nanmax(np.abs(signals(ref)["kappa"] - 1 / 3)) < 1e-6


def test_an_angular_acceleration_jump_breaks_the_dynamic_framework_of_steered_robots():
    """Types 3 and 5 with l_o != 0 need p_ref = (x, y, theta) in C2 in the dynamic framework (Table 8.1): a heading
    theta = 0.1 (t - 5)^2 from t = 5 s keeps theta and omega continuous but jumps theta'' from 0 to 0.2 rad/s^2,
    and the steering rates of a swerve drive jump there (the no-slip IK, below)."""
    from wmrkit.kinematics.wheel_ik import wheel_commands

    t = np.arange(0.0, 10.0, 0.01)
    theta = np.where(t > 5, 0.1 * (t - 5) ** 2, 0.0)
    ref = reference_from_samples("turn.csv", t, np.column_stack([0.5 * t, np.zeros_like(t), theta]))
    robot = catalog.load("swerve-4")
    got = feasibility(robot, ref, "dynamic")
    assert [v.signal for v in got.violations] == ["omega_rate"]
    assert got.violations[0].t == pytest.approx(5.0, abs=0.02)
    assert got.violations[0].size > 0.05  # a jump of 0.2 rad/s^2, spread over a few samples by the differences
    assert feasibility(robot, ref, "kinematic").feasible  # wheel rates may jump there
    # the independent check: module headings from the IK, their rate continuous, its derivative jumping at 5 s
    w = np.where(t > 5, 0.2 * (t - 5), 0.0)
    heading = wheel_commands(robot, np.column_stack([0.5 * np.cos(theta), -0.5 * np.sin(theta), w])).heading[:, 0]
    rate = np.diff(np.unwrap(heading)) / 0.01
    k = int(np.searchsorted(t, 5.0))
    assert np.abs(rate[k - 100:k - 1]).max() < 1e-9 and np.abs(rate[k + 1:k + 10]).min() > 0.05


def test_a_reference_mostly_at_rest_has_no_jump_where_it_moves_smoothly():
    """A smooth move of 1 m (speed 0 -> 1 -> 0 m/s over 2 s) in 22 s at rest: the median step of the whole reference
    was 0, so every moving step above the 1 mm floor was a 'position jump' (0.987 m, 'no vehicle can follow it').
    The typical step is now the median of the steps around each one; a real jump after a rest is still found."""
    t = np.arange(0.0, 22.0, 0.01)
    s = np.clip((t - 10) / 2, 0, 1)
    x = s - np.sin(2 * np.pi * s) / (2 * np.pi)
    smooth = reference_from_samples("move.csv", t, np.column_stack([x, 0 * t, 0 * t]))
    for name in ("omni-3", "diff-drive", "ackermann"):
        for framework in ("kinematic", "dynamic"):
            assert feasibility(catalog.load(name), smooth, framework).feasible, (name, framework)
    jump = reference_from_samples("jump.csv", t, np.column_stack([np.where(t >= 10, 1.0, 0.0), 0 * t, 0 * t]))
    got = feasibility(catalog.load("omni-3"), jump).violations
    assert [(v.signal, round(v.t, 2), round(v.size, 6)) for v in got] == [("position", 10.0, 1.0)]


def test_a_spike_is_reported_with_its_size():
    """A velocity spike, up and back down (one sample of 50 m/s given with a still pose): the whole change across it
    is 0, and the dynamic framework of a type 1 robot reported a 'velocity jump' of size 0.0. Its size is now the
    spike's."""
    from wmrkit.control.references import Reference

    t = np.arange(0.0, 20.0, 0.01)
    velocity = np.zeros((len(t), 3))
    velocity[1000, 0] = 50.0
    spike = Reference("spike", t, np.zeros((len(t), 3)), velocity, np.zeros((len(t), 3)))
    got = feasibility(catalog.load("omni-3"), spike, "dynamic").violations
    assert [v.signal for v in got] == ["velocity"] and got[0].size == pytest.approx(50.0)


@pytest.mark.parametrize(("name", "framework"), [("omni-3", "dynamic"), ("line-follower", "dynamic"),
                                                 ("swerve-4", "kinematic"), ("swerve-4", "dynamic"),
                                                 ("ackermann", "dynamic"), ("thesis-steer-castor", "dynamic")])
def test_a_sampled_step_is_one_violation(name, framework):
    """A file's step between two samples (a teleport of 1 m, a heading jump of 1 rad, a corner: a velocity step) is
    also a spike of its finite-difference derivative over the samples around it, starting one sample earlier: it was
    reported as a second violation ('velocity jump' at 9.99 s and 'position jump' at 10 s; 'heading-rate jump' and
    'heading jump'; 'acceleration jump' and 'velocity jump'). Each step is now reported once, as the step; a genuine
    step of the derivative elsewhere (the speed doubling at 15 s, the curvature of the arc-line stepping) still is."""
    t = np.arange(0.0, 20.0, 0.01)
    robot = catalog.load(name)
    # the speed doubles at 15 s (an independent velocity step, which the kinematic framework follows)
    x = np.where(t < 15, 0.5 * t, 7.5 + (t - 15))
    speed = [("velocity", 15.0)] if framework == "dynamic" else []
    teleport = np.where(t >= 10, 1.0, 0.0)
    for pose, first in [(np.column_stack([x + teleport, 0 * t, 0 * t]), ("position", 10.0)),
                        (np.column_stack([x, 0 * t, teleport]), ("theta", 10.0))]:
        if first[0] not in requirement(robot, framework).signals:
            continue  # a heading jump is nothing to types 2 and 4
        got = feasibility(robot, reference_from_samples("step.csv", t, pose), framework).violations
        assert [(v.signal, round(v.t, 2)) for v in got] == [first, *speed], got
    # a corner at constant heading at 10 s (a velocity step: its acceleration spikes from 9.99 s), for swerve-4
    corner = np.column_stack([np.minimum(0.5 * t, 5.0), np.clip(0.5 * t - 5.0, 0, None), 0 * t])
    got = feasibility(robot, reference_from_samples("corner.csv", t, corner), framework).violations
    assert len(got) == 1 and got[0].t == pytest.approx(10.0), got
    if name == "ackermann":  # the curvature step of the sampled arc-line and its curvature-rate spike: the step
        arc_line = reference_from_samples("arc-line.csv", REFS["arc-line"].t, REFS["arc-line"].pose)
        assert [v.signal for v in feasibility(robot, arc_line, framework).violations] == ["kappa"]


def _from_rest(t, ramp=4.0, v=1.0):
    """Arc length of a start from rest: speed v (1 - cos(pi t / ramp)) / 2 up to `ramp` [s], then v."""
    return np.where(t < ramp, 0.5 * v * (t - ramp / np.pi * np.sin(np.pi * t / ramp)), 0.5 * v * ramp + v * (t - ramp))


def _line_arc(s, line=5.0, radius=3.0):
    th = np.clip(s - line, 0, None) / radius
    return np.column_stack([np.where(s < line, s, line + radius * np.sin(th)),
                            np.where(s < line, 0, radius * (1 - np.cos(th))), th])


def test_a_sampled_circle_starting_from_rest_has_no_jump(tmp_path):
    """A 3 m circle whose speed ramps up smoothly from rest, as a CSV file: the finite-difference curvature near
    rest (0 to 1.6 1/m for 1/3) and the backward tangent of the first sample were reported as a curvature jump,
    a curvature-rate jump and a tangent-angle jump of pi (audit of ch. 8). Curvature is judged where it is defined."""
    t = np.arange(0.0, 20.0, 0.01)
    th = _from_rest(t) / 3.0
    path = tmp_path / "circle.csv"
    rows = "".join(f"{a:.6f},{x:.9f},{y:.9f},{c:.9f}\n" for a, x, y, c in
                   zip(t, 3 * np.sin(th), 3 * (1 - np.cos(th)), th, strict=True))
    path.write_text("t,x,y,theta\n" + rows)
    ref = load_reference(path)
    for name in ("ackermann", "forklift", "diff-drive"):
        for framework in ("kinematic", "dynamic"):
            assert feasibility(catalog.load(name), ref, framework).feasible, (name, framework)
    kappa = signals(ref)["kappa"]
    assert np.nanmax(np.abs(kappa - 1 / 3)) < 0.01 and np.isfinite(kappa[100:]).all()  # 1e-9 m file precision


def test_real_jumps_after_a_start_from_rest_are_found_where_they_are():
    """Starting from rest (as above), a line into an arc of 3 m (at s = 5 m, t = 7 s), a corner, a teleport: each
    is found at its time with its size, and nothing at the start."""
    t = np.arange(0.0, 15.0, 0.01)
    s = _from_rest(t)
    car, forklift = catalog.load("ackermann"), catalog.load("forklift")
    arc = reference_from_samples("line-arc.csv", t, _line_arc(s))
    got = [(v.signal, v.t, v.size) for v in feasibility(car, arc).violations]
    assert [g[0] for g in got] == ["kappa"] and got[0][1] == pytest.approx(7.0, abs=0.02)
    assert got[0][2] == pytest.approx(1 / 3, rel=0.02)
    got = feasibility(car, arc, "dynamic").violations  # the step, and not its curvature-rate spike too
    assert [v.signal for v in got] == ["kappa"] and all(abs(v.t - 7.0) < 0.03 for v in got)
    got = feasibility(forklift, arc, "dynamic").violations
    assert [v.signal for v in got] == ["chi_rate"] and got[0].size == pytest.approx(1 / 3, rel=0.02)
    corner = reference_from_samples("corner.csv", t, np.column_stack(
        [np.minimum(s, 5.0), np.clip(s - 5.0, 0, None), np.where(s < 5, 0, np.pi / 2)]))
    for robot in (car, forklift):
        got = feasibility(robot, corner).violations
        assert [(v.signal, round(v.t, 2), round(v.size, 6)) for v in got] == [("chi", 7.0, round(np.pi / 2, 6))]
    pose = _line_arc(s)
    pose[:, 0] += np.where(t >= 8, 0.5, 0.0)
    got = feasibility(car, reference_from_samples("teleport.csv", t, pose)).violations
    found = [(v.signal, round(v.t, 2)) for v in got]
    assert found[0] == ("kappa", 6.99) and ("position", 8.0) in found
    # and the tangent on either side of the jump (finite differences across it), as before
    assert all(s == "chi" and abs(t - 8.0) < 0.05 for s, t in found[1:] if s != "position")


def test_a_stop_and_turn_in_place_is_a_tangent_jump_for_a_car_only():
    """Along +x to rest at 6 s, a quarter turn in place, then along +y from 8 s. A car cannot turn at rest: its
    tangent jumps by pi/2 across the stop (it was not found: the tangent is undefined at rest). A vehicle that can
    re-orient at rest (Table 8.1's remedy: a diff drive, a forklift's steered wheel) follows it."""
    t = np.arange(0.0, 15.0, 0.01)

    def move(t0):  # from rest to rest over 6 s, 3 m
        u = np.clip((t - t0) / 6, 0, 1)
        return 3 * (u - np.sin(2 * np.pi * u) / (2 * np.pi))

    ref = reference_from_samples("stop-turn.csv", t, np.column_stack(
        [move(0), move(8), np.pi / 2 * np.clip((t - 6) / 2, 0, 1)]))
    for framework in ("kinematic", "dynamic"):
        got = feasibility(catalog.load("ackermann"), ref, framework).violations
        assert [v.signal for v in got] == ["chi"] and got[0].size == pytest.approx(np.pi / 2, abs=1e-6)
        assert 6.0 <= got[0].t <= 8.5  # reported when the tangent is defined again after the stop
        for name in ("diff-drive", "forklift"):
            assert feasibility(catalog.load(name), ref, framework).feasible
    straight = reference_from_samples("stop-go.csv", t, np.column_stack([move(0) + move(8), 0 * t, 0 * t]))
    assert feasibility(catalog.load("ackermann"), straight, "dynamic").feasible


@settings(max_examples=120)
@example(0.5, 1.0, 0.0, 0.25, 1.0)  # the ramp's end rang in the curvature rate, while it fell by 0.03 1/(m s) anyway
@given(st.floats(0.5, 8.0), st.floats(0.2, 2.0), st.floats(-0.5, 0.5), st.floats(-0.3, 0.3), st.floats(0.5, 4.0))
def test_smooth_paths_from_rest_have_no_jump(ramp, speed, amplitude, bend, period):
    """Random smooth paths y = amplitude sin(x / period) + bend x^2, driven along x from rest (speed ramping up as
    above, for `ramp` s, to `speed`), sampled at 100 Hz: a car follows them, in both frameworks."""
    _assert_a_car_follows(_smooth_path(0.01, ramp, speed, amplitude, bend, period))


def _smooth_path(dt, ramp, speed, amplitude, bend, period):
    """y = amplitude sin(x / period) + bend x^2 driven along x from rest, sampled every `dt` [s] for 12 s."""
    t = np.arange(0.0, 12.0, dt)
    x = _from_rest(t, ramp, speed)
    slope = amplitude / period * np.cos(x / period) + 2 * bend * x
    return reference_from_samples("smooth.csv", t, np.column_stack(
        [x, amplitude * np.sin(x / period) + bend * x**2, np.arctan(slope)]))


def _assert_a_car_follows(ref):
    for framework in ("kinematic", "dynamic"):
        got = feasibility(catalog.load("ackermann"), ref, framework).violations
        assert not got, [(v.signal, v.t, v.size) for v in got]


#: (ramp, speed, amplitude, bend, period) of smooth paths that reported a curvature jump when sampled at 10 Hz.
SPARSE = [(4.3457, 1.8724, -0.4339, 0.2048, 0.7334), (3.6309, 1.1745, -0.3874, -0.0558, 0.5011),
          (0.6342, 1.2439, -0.3089, 0.2853, 0.8762), (1.1099, 1.7754, 0.4417, -0.1429, 0.5424),
          (5.2134, 1.8118, -0.3300, -0.2101, 0.9267), (1.0733, 1.1616, -0.3343, 0.1843, 0.5791)]


@pytest.mark.parametrize("case", SPARSE)
def test_sparse_smooth_paths_from_rest_have_no_curvature_jump(case):
    """The paths of the property test above sampled at 10 Hz: where the speed changes by more than 5 % a sample
    (steep parts, not only the start) the curvature is not judged, and the change across those samples (0.09 1/m over
    6 samples, 1.2 over 3 on a tight wiggle) was compared with one typical step, and the median of the steps counted
    the held samples as steps of 0 (6 of 120 random paths were reported). It is compared with as many typical steps."""
    _assert_a_car_follows(_smooth_path(0.1, *case))


def test_sparse_real_curvature_jump_is_still_found():
    """At 10 Hz from rest, the line into a 3 m arc (above) is still a curvature jump of 1/3 at 7 s."""
    t = np.arange(0.0, 15.0, 0.1)
    got = feasibility(catalog.load("ackermann"), reference_from_samples("line-arc.csv", t, _line_arc(_from_rest(t)))
                      ).violations
    assert [v.signal for v in got] == ["kappa"] and got[0].t == pytest.approx(7.0, abs=0.15)
    assert got[0].size == pytest.approx(1 / 3, rel=0.05)


def test_a_densely_sampled_reference_is_judged_above_rounding():
    """A 3 m circle at 1 m/s sampled every 3 us (positions 3 um apart; a whole lap, 6.3 M samples, reported
    the same): the rounding of positions and times made curvature-rate 'jumps' of 3 1/(m s) near 0.016 s for a car
    in the dynamic framework. The curvature signals are judged every few samples, where rounding is small; a real
    curvature-rate step (a line into a clothoid, kappa = 20 u at u m into it) is found with its size."""
    from scipy.special import fresnel

    t = np.arange(0.0, 0.3, 3e-6)
    th = t / 3.0
    car = catalog.load("ackermann")
    circle = reference_from_samples("circle.csv", t, np.column_stack([3 * np.sin(th), 3 * (1 - np.cos(th)), th]))
    assert feasibility(car, circle, "dynamic").feasible
    u = np.clip(t - 0.15, 0, None)  # 1 m/s, the clothoid from 0.15 m: heading 10 u^2
    sin, cos = fresnel(u * np.sqrt(20 / np.pi))
    c = np.sqrt(np.pi / 20)
    clothoid = reference_from_samples("clothoid.csv", t, np.column_stack([np.minimum(t, 0.15) + c * cos, c * sin,
                                                                         10 * u**2]))
    assert feasibility(car, clothoid).feasible
    got = feasibility(car, clothoid, "dynamic").violations
    # (its end, inside the clothoid, is another matter: the one-sided curvature rate of the last samples, 20 -> 10)
    assert [(v.signal, round(v.t, 3)) for v in got if v.t < 0.29] == [("kappa_rate", 0.15)]
    assert got[0].size == pytest.approx(20.0, rel=0.02)


@pytest.mark.parametrize("name", ["diff-drive", "forklift", "ackermann", "line-follower", "thesis-steer-castor"])
def test_a_speed_step_breaks_the_dynamic_framework_of_every_vehicle(name):
    """Along +x at 0.5 m/s, then 1 m/s from t = 5 s: the tangent, its rate and the curvature stay continuous, but the
    drive wheels' spins jump with the speed (below, from the no-slip IK), which the dynamic framework forbids (wheel
    rates continuous, §8.5). A diff drive, forklift or car (types 2 on the axle and 4) was reported feasible:
    Table 8.1 states their condition on chi only, by (8.34) 'chi C1 => v_a C0', which a speed step on a line
    contradicts. The kinematic framework lets the rates jump: feasible there."""
    from wmrkit.kinematics.wheel_ik import wheel_commands

    t = np.arange(0.0, 10.0, 0.01)
    x = np.where(t < 5, 0.5 * t, 2.5 + (t - 5))
    ref = reference_from_samples("speed-step.csv", t, np.column_stack([x, 0 * t, 0 * t]))
    robot = catalog.load(name)
    spins = [np.asarray(wheel_commands(robot, [v, 0.0, 0.0]).spin) for v in (0.5, 1.0)]
    assert np.abs(spins[1] - spins[0]).max() > 1.0  # the wheels' rates jump (rad/s)
    assert feasibility(robot, ref, "kinematic").feasible
    got = feasibility(robot, ref, "dynamic").violations
    assert [v.signal for v in got] == ["velocity"]
    assert got[0].t == pytest.approx(5.0, abs=0.02) and got[0].size == pytest.approx(0.5, rel=1e-6)
    assert "re-orient" not in got[0].remedy  # nothing turns: the speed steps


def test_a_reversal_of_the_direction_of_travel_is_no_tangent_jump():
    """(8.29) defines the tangent as arctan(dy/dx): a cusp (the reference slows to a stop between two samples and
    comes back) leaves it continuous, and each vehicle follows one without a jump of its wheels: a diff drive or a
    car drives back (the car keeps its steering on a curve: (8.41) divides by the signed speed), a forklift's or a
    single steered wheel's 2-quadrant root keeps its angle and its spin changes sign. Every such reversal was a
    'tangent-angle jump' of pi (the car's on a curve also a curvature jump of twice the curvature)."""
    t = np.arange(0.0, 20.0, 0.01)
    s = np.sin(0.5 * t)  # back and forth, the speed through 0 between samples at 3.14, 9.42, 15.71 s
    line = reference_from_samples("back-forth.csv", t, np.column_stack([s, 0 * t, 0 * t]))
    curve = reference_from_samples("curve-back-forth.csv", t, np.column_stack([s, s * s / 4, 0 * t]))
    for name in ("diff-drive", "forklift", "ackermann", "thesis-steer-castor"):
        for ref in (line, curve):
            for framework in ("kinematic", "dynamic"):
                got = feasibility(catalog.load(name), ref, framework).violations
                assert not got, (name, ref.name, framework, [(v.signal, v.t, v.size) for v in got])
    # the signed curvature of the parabola y = x^2 / 4 against the vehicle: 1/2 at its vertex, each way through
    kappa = signals(curve)["kappa"]
    vertex = np.flatnonzero(np.abs(s) < 0.005)
    assert np.allclose(kappa[vertex], 0.5, atol=1e-3)
    # an instant reversal on a line is followed in the kinematic framework (the wheels' rates jump); the dynamic
    # one needs the speed continuous: a velocity jump of 1 m/s, not a tangent jump
    x = np.where(t < 10, 0.5 * t, 10 - 0.5 * t)
    instant = reference_from_samples("instant.csv", t, np.column_stack([x, 0 * t, 0 * t]))
    robot = catalog.load("diff-drive")
    assert feasibility(robot, instant).feasible
    got = feasibility(robot, instant, "dynamic").violations
    assert [v.signal for v in got] == ["velocity"] and got[0].size == pytest.approx(1.0, rel=0.01)


def test_a_gap_in_the_samples_is_no_jump():
    """A 3 m circle at 0.5 m/s logged at 100 Hz with 0.5 s of samples missing (a dropped stretch of a log): each
    step is compared with the typical step over as long a time, and the gap is no jump (it was a 'position jump' of
    0.26 m, which no vehicle can follow, for every robot; in the dynamic framework a velocity jump of 0.042)."""
    t = np.arange(0.0, 20.0, 0.01)
    t = t[(t < 8.0) | (t >= 8.5)]
    th = t / 6
    gap = reference_from_samples("gap.csv", t, np.column_stack([3 * np.sin(th), 3 * (1 - np.cos(th)), th]))
    for name in ("mecanum-4", "line-follower", "diff-drive", "forklift", "ackermann", "swerve-4"):
        for framework in ("kinematic", "dynamic"):
            got = feasibility(catalog.load(name), gap, framework).violations
            assert not got, (name, framework, [(v.signal, v.t, v.size) for v in got])
    # a teleport inside the gap is still found, with its size, when the gap cannot explain it: more than jump_factor
    # (20) times the 0.25 m the reference moves in 0.5 s (a 2 m one is 4 m/s of motion the file did not sample)
    pose = np.column_stack([3 * np.sin(th), 3 * (1 - np.cos(th)), th])
    pose[t >= 8.5, 1] += 10.0
    got = feasibility(catalog.load("mecanum-4"), reference_from_samples("gap-jump.csv", t, pose)).violations
    assert [(v.signal, v.t) for v in got][:1] == [("position", 8.5)] and got[0].size > 10.0


def test_a_sampled_reference_coming_to_rest_on_a_curve_has_no_jump_at_its_end():
    """A file's velocity at its last sample is a one-sided finite difference: on a 2 m arc decelerating to rest at
    0.5 m/s^2 it was 1.2e-5 m/s across the path, square to the acceleration, so its tangent was defined there and a
    quarter turn off: a 'tangent-angle jump' at the end for the bicycle and the diff drive (R on the axle), and for
    every parking plan (each ends so). The same motion from exact derivatives has none; the sampled one must agree."""
    from wmrkit.control.references import Reference

    t = np.arange(0, 4.0001, 0.05)
    s = np.where(t < 3, 0.5 * t, 1.5 + 0.5 * (t - 3) - 0.25 * (t - 3) ** 2)
    ds, dds = np.where(t < 3, 0.5, 0.5 - 0.5 * (t - 3)), np.where(t < 3, 0.0, -0.5)
    radius = 2.0
    phi = s / radius
    pose = np.column_stack([radius * np.sin(phi), radius * (1 - np.cos(phi)), phi])
    velocity = np.column_stack([ds * np.cos(phi), ds * np.sin(phi), ds / radius])
    acceleration = np.column_stack([dds * np.cos(phi) - ds**2 / radius * np.sin(phi),
                                    dds * np.sin(phi) + ds**2 / radius * np.cos(phi), dds / radius])
    exact = Reference("arc", t, pose, velocity, acceleration)
    sampled = reference_from_samples("arc.csv", t, pose)
    for name in ("bicycle", "diff-drive", "swerve-4", "forklift"):
        robot = catalog.load(name)
        assert feasibility(robot, exact).feasible
        assert feasibility(robot, sampled).violations == ()


@pytest.mark.parametrize("name", ["mecanum-4", "line-follower"])
def test_each_framework_gives_its_own_reason_for_a_jump_of_type_1_and_type_2_off_axle(name):
    """Type 1 and type 2 off the axle: the dynamic framework forbids a velocity (and type 1 a heading-rate) step
    because the wheels' rates would jump, not because of the kinematics (which lets them jump: the kinematic
    framework follows the same steps). The remedy said '(kinematics allows no jump here)' in both frameworks."""
    t = np.arange(0.0, 10.0, 0.01)
    x = np.where(t < 5, 0.5 * t, 2.5 + (t - 5))
    theta = np.where(t < 5, 0.0, 0.2 * (t - 5))  # the heading rate steps from 0 to 0.2 rad/s
    robot = catalog.load(name)
    ref = reference_from_samples("steps.csv", t, np.column_stack([x, 0 * t, theta]))
    assert feasibility(robot, ref, "kinematic").feasible
    got = feasibility(robot, ref, "dynamic").violations
    assert {v.signal for v in got} == ({"velocity", "omega"} if name == "mecanum-4" else {"velocity"})
    for v in got:
        assert "kinematics" not in v.remedy and "dynamic framework" in v.remedy and "rates would jump" in v.remedy
        assert v.remedy.endswith("an error appears that the position loop then removes")
    # a heading jump of type 1 in the kinematic framework: the pose is the twist's integral, it cannot jump
    jump = reference_from_samples("turn.csv", t, np.column_stack([0.5 * t, 0 * t, np.where(t < 5, 0.0, 1.0)]))
    if name == "mecanum-4":
        (v,) = feasibility(robot, jump, "kinematic").violations
        assert v.signal == "theta" and "kinematics allows no jump" in v.remedy


def _twist_steps():
    """References whose twist steps at t = 5 s, exact derivatives: (name, reference, robot-frame twist of the tracked
    point just before and just after the step)."""
    from wmrkit.control.references import Reference

    t = np.arange(0.0, 10.0, 0.01)
    after = t >= 5
    s, ds = np.where(after, 2.5 + (t - 5), 0.5 * t), np.where(after, 1.0, 0.5)
    zero = 0 * t
    line = Reference("speed step on a line", t, np.column_stack([s, zero, zero]), np.column_stack([ds, zero, zero]),
                     np.zeros((len(t), 3)))
    ph = s / 3  # a 3 m circle, the heading along it: v and omega double together (the same ICR)
    circle = Reference("speed step on a circle", t, np.column_stack([3 * np.sin(ph), 3 * (1 - np.cos(ph)), ph]),
                       np.column_stack([ds * np.cos(ph), ds * np.sin(ph), ds / 3]),
                       np.column_stack([-ds**2 / 3 * np.sin(ph), ds**2 / 3 * np.cos(ph), zero]))
    th = np.where(after, 0.2 * (t - 5), 0.0)  # the heading rate steps from 0 to 0.2 rad/s: the ICR moves
    turn = Reference("heading-rate step", t, np.column_stack([0.5 * t, zero, th]),
                     np.column_stack([0.5 + zero, zero, np.where(after, 0.2, 0.0)]), np.zeros((len(t), 3)))
    # robot-frame velocity of the point (0.5, 0.1) m/s and omega 0.2 rad/s from t = 5 s (before: (0.5, 0), 0)
    tau = np.where(after, t - 5, 0.0)
    c, sn = np.cos(0.2 * tau), np.sin(0.2 * tau)
    vx, vy = np.where(after, 0.5 * c - 0.1 * sn, 0.5), np.where(after, 0.5 * sn + 0.1 * c, 0.0)
    px = np.where(after, 2.5 + (0.5 * sn + 0.1 * (c - 1)) / 0.2, 0.5 * t)
    py = np.where(after, (0.5 * (1 - c) + 0.1 * sn) / 0.2, 0.0)
    bend = Reference("twist step keeping one wheel's heading", t, np.column_stack([px, py, 0.2 * tau]),
                     np.column_stack([vx, vy, np.where(after, 0.2, 0.0)]),
                     np.column_stack([-0.2 * vy * after, 0.2 * vx * after, zero]))
    return {"line": (line, (0.5, 0, 0), (1, 0, 0)), "circle": (circle, (0.5, 0, 1 / 6), (1, 0, 1 / 3)),
            "turn": (turn, (0.5, 0, 0), (0.5, 0, 0.2)), "bend": (bend, (0.5, 0, 0), (0.5, 0.1, 0.2))}


@pytest.mark.parametrize(("name", "point", "case"), [
    ("swerve-4", None, "line"), ("swerve-4", None, "circle"), ("swerve-4", None, "turn"),
    ("thesis-two-steer-castor", None, "line"), ("thesis-two-steer-castor", None, "circle"),
    ("thesis-two-steer-castor", None, "turn"), ("thesis-steer-castor", (0.5, 0.0), "bend"),
    ("thesis-steer-castor", (0.5, 0.0), "turn")])
def test_types_3_and_5_off_the_wheels_break_the_kinematic_framework_only_where_a_steered_wheel_turns(name, point,
                                                                                                     case):
    """Types 3 and 5 with some l_o != 0 (Table 8.1: p_ref C1, kinematic framework): the steering angles are states,
    the spin rates may jump. A speed step along a line or a circle (the twist scaled: the same ICR) leaves every
    steered wheel's heading where it was, and so does, for one steered wheel off the tracked point, a twist step that
    keeps that wheel's velocity direction; a heading-rate step moves the ICR and turns the wheels. Each was a
    'velocity jump' ('stop and re-orient the orientable wheels') before. The independent verdict: the no-slip IK's
    headings just before and after the step (modulo half a turn, a 2-quadrant root), at R."""
    from wmrkit.kinematics.wheel_ik import wheel_commands

    reference, before, after = _twist_steps()[case]
    robot = catalog.load(name)
    px, py = (0.0, 0.0) if point is None else point
    steered = [i for i, w in enumerate(robot.wheels) if w.type == "steerable"]
    headings = [np.asarray(wheel_commands(robot, [vx + w * py, vy - w * px, w]).heading)[steered]
                for vx, vy, w in (before, after)]
    turn = np.abs(np.angle(np.exp(2j * (headings[1] - headings[0])))) / 2
    turns = bool(turn.max() > 0.05)
    assert turns == (case == "turn")
    assert feasibility(robot, reference, point=point).requirement.column == "types 3 and 5, l_o != 0"
    sampled = reference_from_samples(reference.name, reference.t, reference.pose)
    for ref in (reference, sampled):
        got = feasibility(robot, ref, point=point).violations
        assert bool(got) == turns, (ref.name, [(v.signal, v.t, v.size) for v in got])
        assert all(v.t == pytest.approx(5.0, abs=0.02) and "re-orient the orientable wheels" in v.remedy for v in got)
        # the dynamic framework forbids every such step (the spin rates jump); a wheel is re-oriented only where
        # one turns (a sampled step also spikes the acceleration: reported where it changes a steering rate)
        got = feasibility(robot, ref, "dynamic", point=point).violations
        assert {v.signal for v in got} & {"velocity", "omega"}, [(v.signal, v.t, v.size) for v in got]
        assert all(("re-orient" in v.remedy) == turns for v in got if v.signal in ("velocity", "omega")), got


@pytest.mark.parametrize("name", ["swerve-4", "thesis-two-steer-castor"])
def test_types_3_and_5_follow_an_acceleration_step_that_keeps_the_icr_in_the_dynamic_framework(name):
    """A trapezoidal speed profile on a line and on a circle with the heading along it: the acceleration steps
    (Table 8.1's 'p_ref C2' is broken), but the twist keeps its direction, so every steered wheel holds its heading
    (steering rate 0 on both sides, from the IK below) and the spin rates, proportional to the speed, stay continuous:
    only the spin accelerations jump, which the dynamic framework allows. It was an 'acceleration jump (p_ref not
    C2)': 'stop and re-orient the orientable wheels'."""
    from wmrkit.control.references import Reference
    from wmrkit.kinematics.wheel_ik import wheel_commands

    robot = catalog.load(name)
    t = np.arange(0.0, 10.0, 0.01)
    s = np.where(t < 2, 0.25 * t**2, 1 + (t - 2))  # 0.5 m/s^2 up to 1 m/s at t = 2 s, then steady
    ds, dds = np.where(t < 2, 0.5 * t, 1.0), np.where(t < 2, 0.5, 0.0)
    ph = s / 3
    zero = 0 * t
    refs = [Reference("ramp on a line", t, np.column_stack([s, zero, zero]), np.column_stack([ds, zero, zero]),
                      np.column_stack([dds, zero, zero])),
            Reference("ramp on a circle", t, np.column_stack([3 * np.sin(ph), 3 * (1 - np.cos(ph)), ph]),
                      np.column_stack([ds * np.cos(ph), ds * np.sin(ph), ds / 3]),
                      np.column_stack([dds * np.cos(ph) - ds**2 / 3 * np.sin(ph),
                                       dds * np.sin(ph) + ds**2 / 3 * np.cos(ph), dds / 3]))]
    for curvature, ref in zip((0.0, 1 / 3), refs, strict=True):
        # the IK at R around the step: headings constant (steering rate 0), spins continuous through it
        ik = [wheel_commands(robot, [v, 0.0, v * curvature]) for v in (1 - 1e-6, 1.0)]
        steered = [i for i, w in enumerate(robot.wheels) if w.type == "steerable"]
        assert np.allclose(ik[0].heading[steered], ik[1].heading[steered], atol=1e-12)
        assert np.abs(np.asarray(ik[1].spin) - np.asarray(ik[0].spin))[steered].max() < 1e-4
        assert not feasibility(robot, ref, "dynamic").violations, ref.name
        assert not feasibility(robot, reference_from_samples(ref.name, t, ref.pose), "dynamic").violations


def test_a_remedy_re_orients_only_what_would_jump():
    """Table 8.1's remedies (stop and re-orient the vehicle or a wheel) answer a jump of an angle the vehicle holds.
    Where only a rate steps, the angles stay continuous: at the arc-line's junction the forklift's steered wheel and
    the diff drive's heading (R on its axle) keep their angles (the ideal loop's wheel, below), and a heading-rate
    step leaves a single steered wheel at R where it was; the dynamic framework's verdict said 'stop and re-orient
    the orientable wheel' / 'the vehicle' there. A jump of the reference's heading is a jump of the pose, which no
    re-orientation of a wheel follows; it said 'stop and re-orient the orientable wheel(s)'."""
    from wmrkit.kinematics.wheel_ik import wheel_commands

    arc_line = REFS["arc-line"]
    # the ideal loop's forklift wheel through the junction (9.43 s): its angle does not jump (it did at the square's
    # corners, test_verdict_matches_the_closed_loop), only its rate changes
    run = track(catalog.load("forklift"), arc_line, duration=11.0, output_dt=0.01)
    steps = np.abs(np.angle(np.exp(1j * np.diff(run.heading[:, 0]))))
    assert steps[run.t[1:] > 8.0].max() < 0.01
    for name in ("forklift", "diff-drive"):  # the diff drive's heading is chi (R on its axle), continuous here
        (v,) = feasibility(catalog.load(name), arc_line, "dynamic").violations
        assert v.signal == "chi_rate" and "re-orient" not in v.remedy and "slow to rest there" in v.remedy
    (v,) = feasibility(catalog.load("ackermann"), arc_line, "dynamic").violations  # its wheel's angle jumps
    assert v.signal == "kappa" and "re-orient the orientable wheel" in v.remedy
    t = np.arange(0.0, 10.0, 0.01)
    step = reference_from_samples("omega-step.csv", t, np.column_stack([0.5 * t, 0 * t, np.where(t < 5, 0.0,
                                                                                               0.2 * (t - 5))]))
    robot = catalog.load("thesis-steer-castor")
    heading = [wheel_commands(robot, tw).heading[0] for tw in ([0.5, 0, 0], [0.5, 0, 0.2])]
    assert heading[0] == heading[1]  # the wheel at R rolls along R's velocity
    (v,) = feasibility(robot, step, "dynamic").violations
    assert v.signal == "omega" and "re-orient" not in v.remedy
    jump = reference_from_samples("turn.csv", t, np.column_stack([0.5 * t, 0 * t, np.where(t < 5, 0.0, 1.0)]))
    for name, framework in [("swerve-4", "kinematic"), ("swerve-4", "dynamic"), ("thesis-steer-castor", "kinematic"),
                            ("thesis-steer-castor", "dynamic"), ("mecanum-4", "kinematic"), ("mecanum-4", "dynamic")]:
        got = [v for v in feasibility(catalog.load(name), jump, framework).violations if v.signal == "theta"]
        assert got and all("re-orient" not in v.remedy and "no jump" in v.remedy for v in got), (name, framework)


def test_the_dynamic_framework_needs_the_pose_continuous_too():
    """C1 is C0 too: a reference whose pose jumps at t = 5 s (1 m along x, 1 rad of heading) while the derivatives it
    gives stay smooth (a Reference built in Python) was 'feasible: yes' in the dynamic framework of type 1 and type 2
    off the axle, whose lists held the velocity (and heading rate) only; the kinematic framework found the jump."""
    from wmrkit.control.references import Reference

    t = np.arange(0.0, 10.0, 0.01)
    z = 0 * t
    jump = np.where(t < 5, 0.0, 1.0)
    ref = Reference("teleport", t, np.column_stack([0.5 * t + jump, z, jump]), np.column_stack([0.5 + z, z, z]),
                    np.zeros((len(t), 3)))
    for name in ("mecanum-4", "line-follower", "diff-drive", "forklift", "swerve-4", "thesis-steer-castor"):
        for framework in ("kinematic", "dynamic"):
            got = feasibility(catalog.load(name), ref, framework).violations
            assert [(v.signal, v.t) for v in got] == [("position", 5.0)], (name, framework)
    turn = Reference("turn", t, np.column_stack([0.5 * t, z, jump]), ref.velocity, ref.acceleration)
    got = feasibility(catalog.load("mecanum-4"), turn, "dynamic").violations  # the heading alone jumps
    assert [(v.signal, v.t) for v in got] == [("theta", 5.0)]


def _s_curve(speed, radius=3.0, duration=40.0):
    """A 3 m arc to the left then one to the right, at `speed` with the heading along the path (exact derivatives):
    the heading rate steps from speed / radius to -speed / radius at half time."""
    from wmrkit.control.references import Reference

    t = np.arange(0.0, duration, 0.01)
    s, a = speed * t, speed * duration / (2 * radius)
    left = s < speed * duration / 2
    th = np.where(left, s / radius, 2 * a - s / radius)
    cx, cy = radius * np.sin(a) + radius * np.sin(a), radius * (1 - np.cos(a)) - radius * np.cos(a)
    x = np.where(left, radius * np.sin(th), cx - radius * np.sin(th))
    y = np.where(left, radius * (1 - np.cos(th)), cy + radius * np.cos(th))
    w = np.where(left, 1.0, -1.0) * speed / radius
    velocity = np.column_stack([speed * np.cos(th), speed * np.sin(th), w])
    acceleration = np.column_stack([-speed * w * np.sin(th), speed * w * np.cos(th), 0 * t])
    return Reference("s-curve", t, np.column_stack([x, y, th]), velocity, acceleration)


@pytest.mark.parametrize("name", ["swerve-4", "thesis-two-steer-castor"])
def test_a_steering_jump_at_a_low_speed_is_found(name):
    """Types 3 and 5 off the wheels: a steering angle is a state at any speed, but a twist step under the floor of
    its signal (0.02 m/s, 0.02 rad/s) went unreported: the S-curve reversing its curvature at 0.01 m/s (heading rate
    +-0.0033 rad/s) and a corner at 0.01 m/s (a velocity step of 0.014 m/s) were 'feasible: yes' although the
    wheels' headings jump (the no-slip IK just before and after, below). A step from rest turns no wheel that
    moves (its heading is undefined at rest): still feasible."""
    from wmrkit.kinematics.wheel_ik import wheel_commands

    robot = catalog.load(name)
    steered = [i for i, w in enumerate(robot.wheels) if w.type == "steerable"]

    def turn(before, after):  # the largest heading change of a steered wheel, modulo half a turn
        h = [np.asarray(wheel_commands(robot, list(tw)).heading)[steered] for tw in (before, after)]
        return float(np.max(np.abs(np.angle(np.exp(2j * (h[1] - h[0])))) / 2))

    exact = _s_curve(0.01)
    assert turn((0.01, 0, 0.01 / 3), (0.01, 0, -0.01 / 3)) > 0.1  # robot-frame twists either side
    corner_t = np.arange(0.0, 20.0, 0.01)
    corner = reference_from_samples("corner.csv", corner_t, np.column_stack(
        [np.minimum(0.01 * corner_t, 0.1), np.clip(0.01 * corner_t - 0.1, 0, None), 0 * corner_t]))
    assert turn((0.01, 0, 0), (0, 0.01, 0)) == pytest.approx(np.pi / 2)
    cases = [(exact, "omega", 20.0), (reference_from_samples("s.csv", exact.t, exact.pose), "omega", 20.0),
             (corner, "velocity", 10.0)]
    for ref, signal, t in cases:
        for framework in ("kinematic", "dynamic"):
            got = feasibility(robot, ref, framework).violations
            assert [(v.signal, round(v.t, 2)) for v in got] == [(signal, t)], (ref.name, framework, got)
            assert "re-orient the orientable wheels" in got[0].remedy
    start = reference_from_samples("start.csv", corner_t, np.column_stack(
        [0 * corner_t, 0.01 * np.clip(corner_t - 5, 0, None), 0 * corner_t]))
    assert feasibility(robot, start).feasible


def _speed_step(v0=0.5, v1=0.53, at=10.0, duration=20.0):
    """Along the x axis at `v0`, then at `v1` from `at` [s] (exact derivatives): a velocity step of v1 - v0."""
    from wmrkit.control.references import Reference

    t = np.arange(0.0, duration, 0.01)
    z = 0 * t
    v, x = np.where(t < at, v0, v1), np.where(t < at, v0 * t, v0 * at + v1 * (t - at))
    return Reference("speed step", t, np.column_stack([x, z, z]), np.column_stack([v, z, z]), np.column_stack([z] * 3))


def _step_from_positions(ref, signal, at, width=3.0):
    """The step of `signal` at `at` [s], fitted on the positions alone over `width` seconds on each side (clear of
    the step): the speed (velocity), the turn rate of the direction of travel (chi_rate, and omega with the heading
    along the path), or that over the speed (kappa)."""
    out = []
    for lo, hi in ((at - 1 - width, at - 1), (at + 1, at + 1 + width)):
        k = (ref.t > lo) & (ref.t < hi)
        t, (x, y) = ref.t[k], ref.pose[k, :2].T
        chi = np.unwrap(np.arctan2(np.diff(y), np.diff(x)))
        speed = np.polyfit(t[1:], np.cumsum(np.hypot(np.diff(x), np.diff(y))), 1)[0]
        rate = np.polyfit(t[1:], chi, 1)[0]
        out.append({"velocity": speed, "chi_rate": rate, "omega": rate, "kappa": rate / speed}[signal])
    return abs(out[1] - out[0])


#: One signal per column whose step is between 1x and 2x its floor: (robot, framework, reference, signal, at [s]).
_WHOLE_STEPS = [("mecanum-4", "dynamic", lambda: _s_curve(0.05), "omega", 20.0),
                ("line-follower", "dynamic", _speed_step, "velocity", 10.0),
                ("diff-drive", "dynamic", lambda: _s_curve(0.05), "chi_rate", 20.0),
                ("forklift", "dynamic", lambda: _s_curve(0.05), "chi_rate", 20.0),
                ("bicycle", "kinematic", lambda: _s_curve(0.5, radius=60.0, duration=80.0), "kappa", 40.0),
                ("swerve-4", "kinematic", lambda: _s_curve(0.05), "omega", 20.0),
                ("thesis-steer-castor", "dynamic", _speed_step, "velocity", 10.0)]


@pytest.mark.parametrize(("name", "framework", "make", "signal", "at"), _WHOLE_STEPS)
def test_a_sampled_step_between_one_and_two_floors_is_found_as_with_exact_derivatives(name, framework, make, signal,
                                                                                        at):
    """Finite differences split a step landing between samples into consecutive changes of one sign, each compared
    with the signal's floor on its own: the forklift's turn-rate step of 0.033 rad/s on an S-curve at 0.05 m/s
    (3 m arcs) was found with exact derivatives and missed read from a file (two halves of 0.017 under the 0.02
    floor); so for a signal of each column. The floor is compared with the whole step; its size is the one fitted
    on the positions on each side."""
    from wmrkit.control.feasibility import _FLOOR

    robot, exact = catalog.load(name), make()
    sampled = reference_from_samples("sampled.csv", exact.t, exact.pose)
    step = _step_from_positions(sampled, signal, at)
    assert _FLOOR[signal] < step < 2 * _FLOOR[signal]
    assert requirement(robot, framework).column == EXPECTED[name]
    for ref in (exact, sampled):
        got = [v for v in feasibility(robot, ref, framework).violations if v.signal == signal]
        assert [round(v.t, 1) for v in got] == [at], (ref.name, got)
        assert got[0].size == pytest.approx(step, rel=0.02), ref.name
