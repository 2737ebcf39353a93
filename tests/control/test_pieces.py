"""The loop's pieces: actuator-loop models (settling time, overshoot, coupling), admissible twists, castor feedback."""

from __future__ import annotations

import math
from contextlib import nullcontext

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control.actuators import ActuatorLoop, LowLevelLoops
from wmrkit.control.points import ControlError, control_point, point_pose, twist_for_velocity
from wmrkit.control.references import builtin_reference
from wmrkit.control.track import track
from wmrkit.control.trackers import ArrivalWarning
from wmrkit.kinematics.wheel_ik import wheel_commands


def _step(loops: LowLevelLoops, command, duration=12.0, h=1e-3):
    x = np.zeros(loops.size)
    out = []
    for _ in range(int(duration / h)):  # RK4 on the held command
        k1 = loops.derivative(x, command)
        k2 = loops.derivative(x + h / 2 * k1, command)
        k3 = loops.derivative(x + h / 2 * k2, command)
        k4 = loops.derivative(x + h * k3, command)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(x[: len(command)].copy())
    return np.arange(1, len(out) + 1) * h, np.array(out)


def test_first_order_loop_settles_to_2_percent_at_the_settling_time():
    t, y = _step(LowLevelLoops(("a.spin",), (ActuatorLoop(1.5),)), np.array([1.0]))
    assert y[np.searchsorted(t, 1.5), 0] == pytest.approx(0.98, abs=1e-3)
    np.testing.assert_allclose(y[:, 0], 1 - np.exp(-t * math.log(50) / 1.5), atol=1e-9)


@pytest.mark.parametrize("overshoot", [0.05, 0.15, 0.3])
def test_second_order_loop_has_the_given_overshoot(overshoot):
    """Peak 1 + OS (closed form of an underdamped second-order step); within 2 % from about t_s on."""
    t, y = _step(LowLevelLoops(("a.spin",), (ActuatorLoop(3.5, overshoot),)), np.array([1.0]))
    assert y[:, 0].max() == pytest.approx(1 + overshoot, abs=1e-6)
    assert np.all(np.abs(y[t >= 3.5 * 1.15, 0] - 1) < 0.02)


def test_coupled_loops_disturb_each_other_and_uncoupled_do_not():
    loops = (ActuatorLoop(1.0), ActuatorLoop(1.0))
    alone = _step(LowLevelLoops(("a.spin", "b.spin"), loops), np.array([1.0, 0.0]), 3.0)[1]
    coupled = _step(LowLevelLoops(("a.spin", "b.spin"), loops, ((0, 0.5), (0.5, 0))), np.array([1.0, 0.0]), 3.0)[1]
    assert np.all(alone[:, 1] == 0) and np.abs(coupled[:, 1]).max() > 0.05
    with pytest.raises(ControlError, match="zero diagonal"):
        LowLevelLoops(("a.spin", "b.spin"), loops, ((1, 0), (0, 0)))


REDUCED = [n for n in catalog.names() if control_point(catalog.load(n)).reduced]


@settings(max_examples=100, deadline=None)
@given(name=st.sampled_from(REDUCED), vx=st.floats(-2, 2), vy=st.floats(-2, 2), th=st.floats(-math.pi, math.pi))
def test_point_twist_gives_the_point_its_velocity_and_no_slip(name, vx, vy, th):
    """The admissible twist (null space of (8.14)) moves P at the wanted world velocity and the fixed wheels do not
    slip sideways (skid steering excepted: it must slip to turn)."""
    robot = catalog.load(name)
    cp = control_point(robot)
    pose = np.array([0.3, -0.2, th])
    twist = twist_for_velocity(cp, pose, [vx, vy])
    h = 1e-6  # a central difference: a forward one is off by h |d2p/dt2| (1.3e-5 at 2.8 m/s for diff-drive)
    rate = np.array([math.cos(th) * twist[0] - math.sin(th) * twist[1],
                     math.sin(th) * twist[0] + math.cos(th) * twist[1], twist[2]])
    vel = (point_pose(cp, pose + h * rate) - point_pose(cp, pose - h * rate))[:2] / (2 * h)
    np.testing.assert_allclose(vel, [vx, vy], atol=1e-5)
    assert np.all(np.abs(wheel_commands(robot, twist).slip) <= 1e-9) or cp.skid  # (the steering may be beyond
    # its range: the car's +-40 deg rack cannot strafe its point, which is what the twist asks; not this test's)


def test_castor_angle_is_fed_back_and_trails():
    """diff-drive: the castor starts across the motion and ends trailing it (heading 0) after a straight run."""
    robot = catalog.load("diff-drive").with_steering({"caster": math.pi / 2})
    run = track(robot, builtin_reference("line"), duration=8.0)
    assert abs(run.heading[0, 0] - math.pi / 2) < 1e-9
    assert abs(run.heading[-1, 0]) < 1e-3
    assert run.error.max() < 1e-9


def test_closed_loop_through_the_dynamics():
    """The forklift with Pacejka tyres and servos (ch. 7) under the thesis's law: the fork tips converge to within a
    few millimetres (tyre slip), close to the ideal kinematic loop's exponential early on."""
    ref = builtin_reference("circle")
    start = np.array([0.0, 0.3, 0.0])
    fork = catalog.load("forklift")
    dyn = track(fork, ref, initial_pose=start, duration=12.0, dynamics=True, period=0.02)
    kin = track(fork, ref, initial_pose=start, duration=12.0, period=0.02)
    assert dyn.error[0] == pytest.approx(0.3) and dyn.error[-1] < 5e-3
    assert np.abs(dyn.error - kin.error).max() < 0.05
    with pytest.raises(ControlError, match="low-level loops"):
        track(fork, ref, dynamics=True, loops=LowLevelLoops(("steer.steer",), (ActuatorLoop(1.0),)))


@pytest.mark.parametrize("name", ["forklift", "diff-drive", "swerve-4", "mecanum-4", "ackermann"])
def test_single_call_tick_equals_the_batched_path(name):
    """control_tick (scalar law + compiled IK) gives the twist of law_controller and the rates of wheel_commands."""
    from wmrkit.control.laws import PositionLaw
    from wmrkit.control.loop import law_controller
    from wmrkit.control.tick import control_tick

    robot = catalog.load(name)
    ref = builtin_reference("figure-eight")
    law = PositionLaw.uniform("p", 0.7, gate=0.4)
    tick = control_tick(robot, law)
    ctrl = law_controller(control_point(robot), law, ref)
    twist_out, rates = np.zeros(3), np.zeros(len(robot.rate_names))
    heading = np.array(robot.heading, dtype=float)
    new = np.zeros_like(heading)
    rng = np.random.default_rng(1)
    for k in rng.integers(0, len(ref.t), 20):
        pose = ref.pose[k] + rng.normal(0, 0.3, 3)
        p, v = ref.at(float(ref.t[k]))
        tick.tick(*pose, *p, *v, heading, twist_out, rates, new)
        want, _ = ctrl(float(ref.t[k]), pose, np.zeros(3))
        np.testing.assert_allclose(twist_out, want, atol=1e-12)
        batched = wheel_commands(robot, want, robot.beta_of_heading(heading))
        np.testing.assert_allclose(rates, batched.rates, atol=1e-9)


def test_odometry_feedback_through_the_dynamics():
    """Closed on the odometer (sensed drive spins and steering, one exact step per period): the *estimate* follows
    the reference, so the true error is the odometry's drift caused by the tyre slip."""
    from wmrkit.control.points import point_pose as pp

    fork = catalog.load("forklift")
    ref = builtin_reference("circle")
    run = track(fork, ref, initial_pose=[0.0, 0.3, 0.0], duration=12.0, dynamics=True, feedback="odometry")
    cp = control_point(fork)
    est_error = np.hypot(*(pp(cp, run.estimate)[:, :2] - run.reference[:, :2]).T)
    drift = np.hypot(*(pp(cp, run.estimate)[:, :2] - pp(cp, run.pose)[:, :2]).T)
    assert est_error[-1] < 5e-3 and 1e-3 < drift[-1] < 0.3
    assert abs(run.error[-1] - drift[-1]) < est_error[-1] + 1e-9
    with pytest.raises(ControlError, match="dynamic plant"):
        track(fork, ref, feedback="odometry")


@pytest.mark.parametrize("size", [3.0, 8.0])
def test_stanley_s_projection_past_a_corner_takes_the_leg_ahead(size):
    """A point past a corner on the first leg's extension is as far from both legs (the corner): the tie went to the
    leg behind, so Stanley saw no heading or cross-track error and drove straight on for its 5 s search window
    whenever roundoff put its front axle a hair left of that line ('wmrkit track ackermann --reference corner
    --controller stanley --size 8': at the stops from t = 21 s, not 16, max error 4.09 m, not 1.36; the bicycle's
    3.5 m, not 0.66). Now the leg ahead, as for a point a hair to the right of the line."""
    from wmrkit.control.trackers import PathIndex

    path = PathIndex(builtin_reference("corner", size=size))
    corner = 2 * size  # [s]: the corner (0, -size), at arc length `size`, is reached at 0.5 m/s
    for x in (0.0, -1e-15, 1e-15):
        s, chi, e = path.project(np.array([x, -size - 0.3]), corner + 0.6)
        assert (s, chi) == (pytest.approx(size), pytest.approx(0.0, abs=1e-12)), (x, s, chi)
        assert e == pytest.approx(-0.3)  # right of the second leg, along +x
    for robot in ("ackermann", "bicycle"):
        # the car's front point turns on 4.82 m at best (below): from the 3 m corner it is at the second leg's end's
        # abscissa 4.46 m past the leg's line (sqrt(4.82**2 - 1.82**2)), and passes that end beside it
        beside = robot == "ackermann" and size == 3.0
        with pytest.warns(ArrivalWarning, match="passed the path's end beside it") if beside else nullcontext():
            run = track(catalog.load(robot), builtin_reference("corner", size=size), controller="stanley")
        k0, k1 = np.searchsorted(run.t, [corner, corner + 3.0])
        turned = run.pose[k1, 2] - run.pose[0, 2]
        arc = np.hypot(*np.diff(run.tracked[k0:k1 + 1, :2], axis=0).T).sum()  # driven by the front point
        # it turns left (to +x) within 3 s of the corner: the car at its tightest (its front point drives its arc on
        # the radius hypot(3.993, 2.7) m about the turning centre, the rear axle on its 3.99 m turning radius: 1.5 m
        # at the path's 0.5 m/s, 0.3111 rad, less where it slows to stop at the 3 m corner's end; it turned 0.5 rad
        # while its wheels were asked beyond their stops, and scrubbed)
        assert turned > (0.99 * arc / math.hypot(3.993, 2.7) if robot == "ackermann" else 0.5), (robot, turned)


@settings(max_examples=200)
@given(st.floats(-math.pi, math.pi), st.lists(st.tuples(st.floats(1.0, 3.0), st.floats(-1.5, 1.5)), min_size=1,
                                              max_size=4),
       st.floats(0.05, 0.5), st.data())
def test_the_projection_is_the_nearest_point_of_the_polyline(heading, legs, spacing, data):
    """Random polylines (legs of 1-3 m turning up to 1.5 rad at each corner, sampled every `spacing` m at 0.5 m/s,
    the corners among the samples) and random points near them: PathIndex.project's arc length is that of the
    nearest point of every segment, found here by brute force (ties: any of the nearest), and its cross-track error
    the signed distance from the leg it lies on."""
    from wmrkit.control.references import reference_from_samples
    from wmrkit.control.trackers import PathIndex

    pts, chi = [np.zeros(2)], heading
    for length, turn in legs:
        n = max(1, math.ceil(length / spacing))
        step = length / n * np.array([math.cos(chi), math.sin(chi)])
        pts += [pts[-1] + k * step for k in range(1, n + 1)]
        chi += turn
    xy = np.array(pts)
    seg = np.hypot(*np.diff(xy, axis=0).T)
    s_knots = np.concatenate([[0.0], np.cumsum(seg)])
    t = s_knots / 0.5
    path = PathIndex(reference_from_samples("polyline.csv", t, np.column_stack([xy, np.zeros(len(t))])))
    j = data.draw(st.integers(0, len(xy) - 2))
    u, offset = data.draw(st.floats(0, 1)), data.draw(st.floats(-0.3, 0.3)) * spacing
    d = xy[j + 1] - xy[j]
    point = xy[j] + u * d + offset * np.array([-d[1], d[0]]) / seg[j]
    s, chi_, e = path.project(point, data.draw(st.floats(t[j] - 1.0, t[j + 1] + 1.0)))
    # brute force: the nearest point of each segment
    a, b = xy[:-1], xy[1:]
    w = np.clip(np.sum((point - a) * (b - a), axis=1) / seg**2, 0, 1)
    foot = a + w[:, None] * (b - a)
    dist = np.hypot(*(point - foot).T)
    nearest = dist <= dist.min() + 1e-12
    assert np.min(np.abs(s_knots[:-1][nearest] + w[nearest] * seg[nearest] - s)) < 1e-9, (s, dist.min())
    q = path.point_at(s)
    assert np.hypot(*(point - q)) == pytest.approx(dist.min(), abs=1e-12)
    assert e == pytest.approx((point - q) @ np.array([-math.sin(chi_), math.cos(chi_)]), abs=1e-12)
    assert abs(e) <= dist.min() + 1e-12
