"""Parking with a robot description: only cars that drive along +x with the steering ahead, within their racks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from parking_cases import CAR_91, SLOT_91

from wmrkit import catalog
from wmrkit.errors import DescriptionError, WmrkitError
from wmrkit.parking.execute import execute_plan
from wmrkit.parking.planner import plan_parking
from wmrkit.parking.problem import car_axles, problem_from_text, steering_limit

SPACE = "space: {H: 7 m, J: 2.3 m, MS: 0.25 m, dx2: 1.4 m, final_gap: 0.1 m}\n"


def _car(robot: str, phi_max: str = "30 deg", a1: str = "3.6 m", b1: str = "1.0 m", c1: str = "1.8 m") -> str:
    return f"vehicle: {{robot: {robot}, a1: {a1}, b1: {b1}, c1: {c1}, phi_max: {phi_max}}}\n" + SPACE


@pytest.mark.parametrize(("robot", "message"), [
    # the thesis's frame (Y forward): driven along its x axis the car went sideways, 6 m off the plan, outside the slot
    ("thesis-tricycle", r"fixed wheel 'f1' rolls at heading -90 deg"),
    ("thesis-tricycle-ch4", r"fixed wheel '\w+' rolls at heading [-\d]+ deg"),
    # rear-steered: its steering wheel 1.35 m behind the axle stood outside a body ending b1 = 0.5 m behind it
    ("forklift", r"steerable wheels are 1\.35 m behind its fixed axle"),
])
def test_robots_that_are_not_front_steered_cars_along_x_are_refused(robot, message):
    with pytest.raises(DescriptionError, match=r"^car\.yaml:1: vehicle\.robot: .*" + message):
        problem_from_text(_car(robot, a1="1.6 m", b1="0.5 m", c1="1.4 m"), source="car.yaml")
    with pytest.raises(WmrkitError, match=message):
        car_axles(catalog.load(robot))
    with pytest.raises(WmrkitError, match=message):  # the Python door too
        execute_plan(plan_parking(CAR_91, SLOT_91), catalog.load(robot))


def test_the_inner_wheel_limits_the_equivalent_steering_angle():
    """The catalog car's rack is +-40 deg; the inner front wheel reaches it first (Ackermann), at an equivalent
    steering angle of atan(h1 kappa) with kappa = tan 40 / (h1 + track/2 tan 40)."""
    robot = catalog.load("ackermann")
    t = math.tan(math.radians(40))
    expected = math.atan(2.7 * t / (2.7 + 0.775 * t))
    assert steering_limit(robot) == pytest.approx(expected, abs=1e-9)
    assert math.degrees(expected) == pytest.approx(34.068, abs=0.001)
    assert steering_limit(catalog.load("bicycle")) == math.pi / 2  # no steer_range: no limit below 90 deg


def test_phi_max_beyond_the_robots_steering_range_is_refused():
    """phi_max 35 deg with the +-40 deg car turned the inner wheel to 41.2 deg, open loop, silently (45 deg: 54.5
    deg); closed loop the wheel stopped at 40 deg and the car hit the curb."""
    with pytest.raises(DescriptionError, match=r"^car\.yaml:1: vehicle\.phi_max: 35 deg turns the front wheels of "
                       r"robot 'ackermann' beyond their steer_range \(wheel 'front_\w+' to [-\d.]+ deg, range "
                       r"\[-40, 40\] deg\): at most 34\.06 deg with this robot$"):
        problem_from_text(_car("ackermann", "35 deg"), source="car.yaml")
    problem = problem_from_text(_car("ackermann", "34.06 deg"), source="car.yaml")
    plan = plan_parking(problem.vehicle, problem.space)
    assert plan.feasible
    run = execute_plan(plan, problem.robot)
    assert np.degrees(np.abs(run.wheel_headings).max()) <= 40.0


def test_execute_plan_refuses_a_robot_whose_wheels_cannot_steer_the_plan():
    plan = plan_parking(CAR_91, SLOT_91)  # 46 deg, the thesis's car
    assert max(abs(s.steering) for s in plan.segments) > steering_limit(catalog.load("ackermann"))
    with pytest.raises(WmrkitError, match=r"the plan steers to [\d.]+ deg; robot 'ackermann' steers at most "
                                          r"34\.06 deg"):
        execute_plan(plan, catalog.load("ackermann"))
