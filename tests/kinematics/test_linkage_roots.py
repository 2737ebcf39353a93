"""``ik`` sets a linked wheel at the root of (8.9) its linkage sets, in every path (kinematics/linkage_check.py).

Before: each wheel kept the root closest to its current heading, so the catalog car without its +-40 deg racks at
``--twist 0.2 0 1`` printed front_left at -77.98 deg with spin -8.37 rad/s, where the linkage, from front_right at
70.14 deg, sets 102.02 deg and +8.37 rad/s (the same rolling), and ``fk`` given those headings said the linkage cannot
set them. The expectation is independent of the law's code: an Ackermann linkage (fronts off the fixed axle line)
turns continuously from its rest headings, at which both wheels roll along their axes' velocities ``u``, and ``u``
never vanishes on its way (the ICR stays on the axle line), so it sets both wheels along ``u`` or both against it.
The paths: ``wheel_commands`` (batched, and its compiled batch), the control loop's ``checked_steering_config``
(``_ik_fast.steering_one``), the compiled single-call ``realtime`` ik. The generated code takes headings as inputs
and chooses no root: at ik's headings its ``inverse`` gives ik's rates and its ``in_linkage`` holds.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import Robot, catalog
from wmrkit.kinematics.codegen import write_code
from wmrkit.kinematics.linkage_check import LinkageAngleWarning
from wmrkit.kinematics.loop_ik import checked_steering_config
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import forward_kinematics_check, wheel_commands

from .test_codegen import load_module
from .test_linkage_ik import ackermann_car, synchro

#: ``math.atan2`` (the plain-float and compiled paths) and ``np.arctan2`` (SIMD) may differ by an ulp of the angle,
#: which a wrap carries to an ulp of 2 pi (tests/control/test_loop_speed.py); a root is pi away.
ULPS = 2 * float(np.spacing(2 * np.pi))


def car_without_racks() -> Robot:
    data = catalog.load("ackermann").to_dict()
    for w in data["wheels"]:
        w.pop("steer_range", None)
    return Robot.from_dict({**data, "name": "car"})


def axis_directions(robot: Robot, twist) -> np.ndarray:
    """The headings [rad] of the steering axes' velocities ``u = v + omega x p`` ``(n_steer,)``."""
    vx, vy, w = twist
    xy = np.array([robot.wheel(n).position for n in robot.steer_names])
    return np.arctan2(vy + w * xy[:, 0], vx - w * xy[:, 1])


def along(robot: Robot, twist, heading) -> np.ndarray:
    """+1 where a wheel rolls along ``u`` at `heading`, -1 against it."""
    return np.sign(np.cos(np.asarray(heading) - axis_directions(robot, twist)))


def test_the_car_s_front_left_wheel_is_set_where_the_linkage_sets_it():
    robot = car_without_racks()
    c = wheel_commands(robot, [0.2, 0.0, 1.0])
    fl, fr = robot.wheel_names.index("front_left"), robot.wheel_names.index("front_right")
    assert math.degrees(c.heading[fl]) == pytest.approx(math.degrees(math.atan2(2.7, 0.2 - 0.775)), abs=1e-9)
    assert math.degrees(c.heading[fl]) == pytest.approx(102.02, abs=0.01)
    assert math.degrees(c.heading[fr]) == pytest.approx(70.14, abs=0.01)
    assert c.spin[fl] == pytest.approx(math.hypot(0.2 - 0.775, 2.7) / 0.33, rel=1e-12)  # +8.37 rad/s
    assert c.spin[fl] > 0 and c.spin[fr] > 0 and c.feasible


def test_fk_given_ik_s_headings_says_the_linkage_can_set_them():
    robot = car_without_racks()
    c = wheel_commands(robot, [0.2, 0.0, 1.0])
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    with warnings.catch_warnings():
        warnings.simplefilter("error", LinkageAngleWarning)
        fk = forward_kinematics_check(robot, dict(zip(robot.rate_names, c.rates.tolist(), strict=True)),
                                      heading=c.heading[steer])
    assert fk.consistent and fk.out_of_linkage == ()
    np.testing.assert_allclose(fk.twist, [0.2, 0.0, 1.0], atol=1e-12)


def car_twist(axle_heading: float, rear_x: float, speed: float, omega: float) -> list[float]:
    """A twist the car's fixed wheels roll with (the ICR on their axle line)."""
    c, s = math.cos(axle_heading), math.sin(axle_heading)
    return [speed * c + omega * rear_x * s, speed * s - omega * rear_x * c, omega]


@settings(max_examples=150, deadline=None)
@given(wheelbase=st.floats(0.3, 5), track=st.floats(0.2, 3), rear_x=st.floats(-2, 2),
       axle_heading=st.floats(-math.pi, math.pi), speed=st.floats(-3, 3), omega=st.floats(-3, 3),
       current=st.tuples(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi)))
def test_random_cars_get_the_roots_their_linkage_sets_and_fk_agrees(wheelbase, track, rear_x, axle_heading, speed,
                                                                     omega, current):
    robot = ackermann_car(wheelbase, track, rear_x, axle_heading)
    twist = car_twist(axle_heading, rear_x, speed, omega)
    c = wheel_commands(robot, twist, heading=current)
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    heading = c.heading[steer]
    if c.held[steer].any():
        return  # a wheel at rest keeps its heading: no root to choose
    sides = along(robot, twist, heading)
    assert sides[0] == sides[1], (heading, axis_directions(robot, twist))
    assert c.feasible
    config = checked_steering_config(robot, np.array(twist), robot.beta_of_heading(np.array(current)))
    np.testing.assert_allclose(config, c.beta, rtol=0, atol=ULPS)
    with warnings.catch_warnings():
        warnings.simplefilter("error", LinkageAngleWarning)
        fk = forward_kinematics_check(robot, dict(zip(robot.rate_names, c.rates.tolist(), strict=True)),
                                      heading=heading)
    assert fk.out_of_linkage == ()


def test_a_batch_judged_compiled_sets_the_same_roots():
    """128 twists (the compiled batch, linkage_check.COMPILED_BATCH) against the same twists one by one."""
    robot = car_without_racks()
    rng = np.random.default_rng(3)
    twist = np.c_[rng.uniform(-1, 1, (128, 1)), np.zeros((128, 1)), rng.uniform(-2, 2, (128, 1))]
    current = rng.uniform(-math.pi, math.pi, (128, 2))
    batch = wheel_commands(robot, twist, heading=current)
    for i in range(0, 128, 16):
        one = wheel_commands(robot, twist[i], heading=current[i])
        np.testing.assert_allclose(batch.heading[i], one.heading, rtol=0, atol=ULPS)
        np.testing.assert_allclose(batch.rates[i], one.rates, rtol=1e-14)  # BLAS blocks: the last bit may differ
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    sides = np.array([along(robot, t, h) for t, h in zip(twist, batch.heading[:, steer], strict=True)])
    assert (sides[:, 0] == sides[:, 1]).all() and batch.feasible.all()


def ranged_synchro() -> Robot:
    """A synchro drive whose first wheel steers within +-100 deg and second within [0, 180] deg."""
    data = synchro().to_dict()
    data["wheels"][0]["steer_range"] = ["-100 deg", "100 deg"]
    data["wheels"][1]["steer_range"] = ["0 deg", "180 deg"]
    return Robot.from_dict({**data, "name": "ranged-synchro"})


def test_a_linkage_whose_wheels_fit_their_ranges_only_turned_half_round_is_turned():
    """A translation at heading 95 deg from current headings -85 deg: w0 (the reference: all axes equally fast) may
    take -85 deg or 95 deg, both within +-100 deg, and keeps the closer, -85 deg; the linkage then sets w1 at -85 deg,
    outside [0, 180] deg. Turned half round together (w0 too), all three fit: feasible, every path."""
    robot = ranged_synchro()
    twist = [math.cos(math.radians(95)), math.sin(math.radians(95)), 0.0]
    current = np.radians([-85.0, -85.0, -85.0])
    c = wheel_commands(robot, twist, heading=current)
    np.testing.assert_allclose(np.degrees(c.heading), 95.0, atol=1e-9)
    assert c.feasible and (c.spin > 0).all()
    rates, out = np.empty(3), np.empty(3)
    assert realtime(robot).ik(*twist, current, rates, out)
    np.testing.assert_allclose(out, c.heading, atol=1e-12)
    np.testing.assert_allclose(rates, c.rates, atol=1e-12)
    config = checked_steering_config(robot, np.array(twist), robot.beta_of_heading(current))
    np.testing.assert_allclose(config, c.beta, rtol=0, atol=ULPS)
    batch = wheel_commands(robot, np.tile(twist, (70, 1)), heading=current)  # the compiled batch
    assert batch.feasible.all()
    np.testing.assert_allclose(batch.heading, np.tile(c.heading, (70, 1)), rtol=0, atol=ULPS)


def realtime_robots() -> list[Robot]:
    return [car_without_racks(), ackermann_car(1.7, 1.1, -0.4, 0.3), synchro()]


@pytest.mark.parametrize("index", range(3))
def test_the_realtime_ik_and_the_control_loop_s_steering_are_wheel_commands(index):
    robot = realtime_robots()[index]
    rt = realtime(robot)
    rng = np.random.default_rng(index)
    n = len(robot.steer_names)
    rates, out = np.empty(len(robot.rate_names)), np.empty(n)
    steer = [robot.wheel_names.index(k) for k in robot.steer_names]
    turned = 0
    for _ in range(60):
        twist = rng.uniform(-1, 1, 3)
        if robot.name != "synchro" and rng.uniform() < 0.7:  # mostly twists the fixed wheels roll with
            axle = 0.0 if robot.name == "car" else 0.3
            twist = np.array(car_twist(axle, 0.0 if robot.name == "car" else -0.4, *rng.uniform(-1, 1, 2)))
        heading = rng.uniform(-math.pi, math.pi, n)
        ref = wheel_commands(robot, twist, heading=heading)
        assert rt.ik(*map(float, twist), heading, rates, out) == bool(ref.feasible)
        np.testing.assert_allclose(out, ref.heading[steer], atol=1e-12)
        np.testing.assert_allclose(rates, ref.rates, atol=1e-12)
        config = checked_steering_config(robot, twist, robot.beta_of_heading(heading))
        np.testing.assert_allclose(config, ref.beta, rtol=0, atol=ULPS)
        closest = np.cos(ref.heading[steer] - heading) >= 0
        turned += int(not closest.all())
    assert turned  # some wheel was set more than 90 deg from its current heading: the linkage's root


def test_the_generated_code_at_ik_s_headings_gives_ik_s_rates_and_holds_the_linkage(tmp_path):
    robot = car_without_racks()
    mod = load_module(write_code(robot, "python", tmp_path)[0])
    twist = np.array([car_twist(0.0, 0.0, s, w) for s, w in [(0.2, 1.0), (-0.5, 0.3), (1.0, -2.0), (0.0, 1.0)]])
    c = wheel_commands(robot, twist, heading=[[0.0, 3.0], [0.0, -3.0], [2.0, -2.0], [1.0, -1.0]])
    steer = [robot.wheel_names.index(n) for n in robot.steer_names]
    cols = [robot.rate_names.index(n) for n in mod.RATE_NAMES]
    np.testing.assert_allclose(mod.inverse(twist, c.heading[:, steer]), c.rates[:, cols], atol=1e-12)
    assert mod.in_linkage(twist, c.heading[:, steer]).all()
