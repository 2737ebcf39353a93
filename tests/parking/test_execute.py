"""Execution: the timed reference, open loop through the robot's kinematics, closed loop through wmrkit.control."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest
from parking_cases import CAR_91, CAR_92, SLOT_91, SLOT_92, scaled

from wmrkit import Robot
from wmrkit.errors import WmrkitError
from wmrkit.parking import plan_parking
from wmrkit.parking.execute import execute_plan, timed_reference, trapezoid, trapezoid_duration, vehicle_robot
from wmrkit.parking.problem import problem_from_text


@pytest.mark.parametrize(("length", "v", "a"), [(2.0, 0.5, 0.5), (0.1, 0.5, 0.5), (1e-4, 1.0, 2.0)])
def test_trapezoid_reaches_the_length_with_bounded_speed(length, v, a):
    t = np.linspace(0, trapezoid_duration(length, v, a), 2001)
    s = trapezoid(length, v, a, t)
    assert s[0] == 0 and s[-1] == pytest.approx(length, rel=1e-12)
    speed = np.diff(s) / np.diff(t)
    assert speed.max() <= v * (1 + 1e-9) and (speed >= -1e-12).all()
    assert np.abs(np.diff(speed) / np.diff(t)[1:]).max() <= a * (1 + 1e-6) + 1e-9


def test_reference_stops_between_segments_and_waits_for_the_steering():
    plan = plan_parking(CAR_92, SLOT_92)
    t, pose, dist, seg = timed_reference(plan.segments, v_max=0.5, a_max=0.5, steer_rate=0.5, dt=0.02)
    assert (np.diff(t) > 0).all()
    for k, s in enumerate(plan.segments):
        rows = np.flatnonzero(seg == k)
        np.testing.assert_allclose(pose[rows[-1]], s.end, atol=1e-9)  # each segment ends where planned
        assert (dist[rows] >= 0).all() and (dist[rows] <= s.length).all()
    # between the two arcs of a manoeuvre the steering reverses: the car waits |2 phi| / rate at rest
    k = 4
    assert plan.segments[k].maneuver == plan.segments[k - 1].maneuver
    rows = np.flatnonzero(seg == k)
    wait = abs(plan.segments[k].steering - plan.segments[k - 1].steering) / 0.5
    at_rest = t[rows][dist[rows] == 0.0]
    assert at_rest[-1] - t[rows[0] - 1] == pytest.approx(wait, abs=0.02)


@pytest.mark.parametrize(("car", "slot"), [(CAR_91, SLOT_91), (CAR_92, SLOT_92)], ids=["9.1", "9.2"])
def test_open_loop_execution_follows_the_plan_exactly(car, slot):
    plan = plan_parking(car, slot)
    run = execute_plan(plan)
    assert run.mode == "open-loop"
    assert run.deviation.max() < 1e-9
    np.testing.assert_allclose(run.pose[-1], plan.final_pose, atol=1e-9)
    # the robot's own IK steers the equivalent front wheel to atan(h1 kappa) (9.27): the planner's heading
    np.testing.assert_allclose(run.wheel_headings[:, 0], run.steering, atol=1e-9)
    assert np.abs(run.steering).max() <= car.phi_max + 1e-12


def test_ackermann_wheels_steer_to_their_own_angles_and_any_origin_works():
    """A catalog car (two front wheels): each front wheel's heading is atan(h1 / (rho -+ track/2)) (Ackermann),
    and moving the robot's origin off the rear axle changes nothing for P_f."""
    text = ("vehicle: {robot: ackermann, a1: 3.6 m, b1: 1.0 m, c1: 1.8 m, phi_max: 34 deg}\n"
            "space: {H: 7 m, J: 2.3 m, MS: 0.25 m, dx2: 1.4 m, final_gap: 0.1 m}\n")
    problem = problem_from_text(text, source="car.yaml")
    plan = plan_parking(problem.vehicle, problem.space)
    assert plan.feasible
    run = execute_plan(plan, problem.robot)
    assert run.deviation.max() < 1e-9
    kappa = np.array([s.curvature for s in plan.segments])[run.segment]
    turning = np.abs(kappa) > 1e-9
    h1, half = 2.70, 1.55 / 2
    left = np.arctan(h1 * kappa[turning] / (1 - half * kappa[turning]))
    right = np.arctan(h1 * kappa[turning] / (1 + half * kappa[turning]))
    names = problem.robot.steer_names
    np.testing.assert_allclose(run.wheel_headings[turning, names.index("front_left")], left, atol=1e-9)
    np.testing.assert_allclose(run.wheel_headings[turning, names.index("front_right")], right, atol=1e-9)
    data = problem.robot.to_dict()
    for w in data["wheels"]:  # origin 1 m ahead of the rear axle
        w["position"][0] -= 1.0
    moved = execute_plan(plan, Robot.from_dict(data))
    np.testing.assert_allclose(moved.pose, run.pose, atol=1e-9)


def test_closed_loop_with_the_thesis_law_tracks_within_centimetres():
    """wmrkit.control's P law (8.2) on the steering axle's midpoint, reversing included."""
    plan = plan_parking(CAR_91, SLOT_91)
    run = execute_plan(plan, controller="p", gain=2.0, dt=0.1)
    assert run.mode == "p"
    assert run.deviation.max() < 0.02
    assert np.hypot(*(run.pose[-1, :2] - np.array(plan.final_pose[:2]))) < 0.01


def test_execution_refuses_bad_requests():
    with pytest.raises(WmrkitError, match="not feasible"):
        execute_plan(plan_parking(CAR_91, replace(SLOT_91, H=2.0)))
    with pytest.raises(WmrkitError, match="reverses"):
        execute_plan(plan_parking(CAR_91, SLOT_91), controller="pure-pursuit")
    with pytest.raises(WmrkitError, match="not car-like"):
        execute_plan(plan_parking(CAR_91, SLOT_91), Robot.from_dict({"name": "d", "wheels": [
            {"name": "l", "type": "fixed", "position": [0, 0.2], "beta": "90 deg", "r": 0.1},
            {"name": "r", "type": "fixed", "position": [0, -0.2], "beta": "90 deg", "r": 0.1}]}))


def test_vehicle_robot_is_the_thesis_car():
    robot = vehicle_robot(CAR_91)
    assert robot.steer_names == ("steer",)
    assert {w.name for w in robot.wheels if w.type == "fixed"} == {"rear_left", "rear_right"}


def test_open_loop_execution_passes_the_exact_check():
    shapely = pytest.importorskip("shapely")
    assert shapely
    from wmrkit.parking.verify import check_poses

    for car, slot in ((CAR_91, SLOT_91), (CAR_92, SLOT_92)):
        run = execute_plan(plan_parking(car, slot), dt=0.02)
        report = check_poses(car, slot, run.pose)
        assert report.collision_free and report.inside


def test_a_long_open_loop_execution_is_driven_in_bounded_memory():
    """The open loop's batched inverse and forward kinematics took about 2 KB a sample at once (a 9.8 km plan,
    394,511 samples: 870 MB); solved in chunks, the run keeps well under 1 KB a sample and drives the same path."""
    import tracemalloc

    plan = plan_parking(CAR_91, SLOT_91)
    tracemalloc.start()
    try:
        run = execute_plan(plan, dt=0.0004)  # 73,371 samples
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(run.t) > 70_000 and peak < 1000 * len(run.t)
    assert run.deviation.max() < 1e-9
    np.testing.assert_allclose(run.pose[-1], plan.final_pose, atol=1e-9)
    np.testing.assert_allclose(run.wheel_headings[:, 0], run.steering, atol=1e-9)


def test_an_execution_of_too_many_samples_is_refused_before_it_is_sampled():
    """A 57 km plan (91 manoeuvres of a 500 m car) was sampled into 2.3e6 poses and its execution took over 3.2 GB
    (a MemoryError traceback under a 4 GB limit, from 'park --animate'); refused, naming the drive's duration."""
    from wmrkit.parking.execute import MAX_SAMPLES

    plan = plan_parking(CAR_91, SLOT_91)  # 29.35 s of driving
    dt = 29.0 / MAX_SAMPLES  # 506,000 samples
    message = f"the plan takes 29.35 s to drive: executing it samples at most {MAX_SAMPLES}"
    with pytest.raises(WmrkitError, match=message):
        timed_reference(plan.segments, dt=dt)
    with pytest.raises(WmrkitError, match="at most 500000 poses"):
        execute_plan(plan, dt=dt)
    assert len(timed_reference(plan.segments, dt=29.4 / MAX_SAMPLES)[0]) == 499_106  # within the bound


def test_a_gif_renders_each_frame_once_and_draws_a_bounded_trail(tmp_path, monkeypatch):
    """animate_plan rendered every frame twice (FuncAnimation.save's draw_idle, then the writer's savefig) and kept
    it as RGBA until the end; its trail drew every sample up to the frame (800 frames of a 9.8 km plan, 394,511
    samples: over 6 min and 1.2 GB). Now the figure is rendered once, each frame draws only what moves over it (blit),
    and the trail draws at most MAX_TRAIL dots."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.lines import Line2D
    from PIL import Image

    from wmrkit.parking.plot import MAX_TRAIL, animate_plan

    plan = plan_parking(CAR_91, SLOT_91)
    run = execute_plan(plan, dt=0.001)  # 29,349 samples
    renders, drawn = [], []
    draw, set_data = FigureCanvasAgg.draw, Line2D.set_data
    monkeypatch.setattr(FigureCanvasAgg, "draw", lambda self, *a, **k: renders.append(1) or draw(self, *a, **k))
    monkeypatch.setattr(Line2D, "set_data", lambda self, *a: drawn.append(len(a[0])) or set_data(self, *a))
    assert animate_plan(plan, tmp_path / "a.gif", run, max_frames=5) == 5
    assert len(renders) == 1  # the background; the frames are the moving artists drawn over it
    assert max(drawn) <= MAX_TRAIL < len(run.t) and sum(drawn[-2:]) == MAX_TRAIL  # the last frame: the whole trail
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 5 and gif.size == (640, 368)


@pytest.mark.parametrize("dt", [0.05, 0.3])
def test_open_loop_keeps_the_distance_driven_at_a_segments_first_sample(dt):
    """Where the steering wait between two segments is shorter than dt (none at all when the steering does not
    change: the reverse S into the first manoeuvre of a car passing beyond its approach point), the first sample
    of the new segment is already under way; the open loop dropped that distance (0.6 mm per stop at dt = 0.05 s,
    1 cm at 0.3 s) and ended off the plan."""
    text = ("vehicle: {robot: ackermann, a1: 3.6 m, b1: 1.0 m, c1: 1.8 m, phi_max: 30 deg}\n"
            "space: {H: 6 m, J: 2.2 m, MS: 0.2 m, dx2: 1.2 m, final_gap: 10 cm}\n")
    problem = problem_from_text(text, source="car.yaml")
    plan = plan_parking(problem.vehicle, problem.space)
    assert any(a.steering == b.steering for a, b in itertools.pairwise(plan.segments))  # the case at stake
    for robot in (None, problem.robot):
        run = execute_plan(plan, robot, dt=dt)
        assert run.deviation.max() < 1e-9
        np.testing.assert_allclose(run.pose[-1], plan.final_pose, atol=1e-9)


@pytest.mark.parametrize(("option", "value"), [("a_max", np.inf), ("dt", np.inf), ("v_max", np.nan),
                                               ("steer_rate", 0.0), ("v_max", True), ("dt", "0.05")])
def test_execution_options_are_finite_positive_numbers_named(option, value):
    """a_max = inf raised 'dt: expected finite numbers, got nan' (another option's name) after RuntimeWarnings;
    dt = inf drove one sample a segment; v_max = True was read as 1 m/s."""
    plan = plan_parking(CAR_91, SLOT_91)
    with pytest.raises(WmrkitError, match=rf"^{option}: must be a finite number > 0"):
        execute_plan(plan, **{option: value})


@pytest.mark.parametrize(("option", "value"), [("max_frames", 10**9), ("max_frames", 1), ("max_frames", 2.5),
                                               ("fps", 0), ("fps", True)])
def test_animation_options_are_bounded_integers_refused_before_the_work(tmp_path, option, value):
    """animate_plan(max_frames=10**9) drew every executed sample (up to 500,000 frames: hours; the CLI's --frames
    stops at 800), 2.5 raised a TypeError, fps=0 a ZeroDivisionError once every frame was rendered."""
    from wmrkit.parking.plot import animate_plan

    plan = plan_parking(CAR_91, SLOT_91)
    with pytest.raises(WmrkitError, match=rf"^{option}: expected an integer from"):
        animate_plan(plan, tmp_path / "a.gif", **{option: value})
    assert not (tmp_path / "a.gif").exists()


def test_a_scaled_car_is_driven_to_the_same_answers_scaled():
    """Example 1 scaled by 1e-3, 1 and 1e2 (at 1e3 its wheelbase is past wmrkit's 1 km robots): the same Table
    8.1 verdict, the same collisions of the closed-loop run, and its deviations from the plan scaled (kinematics
    has no unit of length once the speeds are in car lengths per second). Before, at 0.5 m/s the 2 mm car drove
    its 9 mm path in 7 samples: Table 8.1 'NO' and 1001 poses into the front car."""
    from wmrkit.parking.execute import plan_feasibility
    from wmrkit.parking.verify import check_poses, densify

    pytest.importorskip("shapely")
    answers = []
    for scale in (1e-3, 1.0, 1e2):
        car, slot = scaled(CAR_91, SLOT_91, scale)
        plan = plan_parking(car, slot)
        run = execute_plan(plan, controller="p")
        report = check_poses(car, slot, densify(car, run.pose))
        answers.append((plan_feasibility(plan).feasible, report.n_collisions, report.what, report.inside,
                        len(run.t), run.deviation / scale))
    for verdict, hits, what, inside, n, deviation in answers:
        assert (verdict, hits, what, inside, n) == answers[1][:5]
        # control.track integrates with an absolute tolerance of 1e-10 m (5e-8 of the 2 mm car): its largest and
        # final deviations (car-scaled) differ by 0.7 % (1.045 against 1.038 mm), the 200 m car's by 0.03 %
        np.testing.assert_allclose([deviation.max(), deviation[-1]], [answers[1][5].max(), answers[1][5][-1]],
                                   rtol=0.01)
    assert answers[1][0]  # the thesis's plan is feasible (Table 8.1)
