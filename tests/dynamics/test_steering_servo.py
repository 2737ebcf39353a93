"""Steering through the dynamics: servos sized on the inertia they move (checked against closed forms of a drive
unit's turn), and the roots of (8.9) the loops command."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from dynamics_robots import double_unit_robot, tricycle

from wmrkit import Robot, catalog
from wmrkit.control.dynamic_plant import simulate_dynamics
from wmrkit.control.points import ControlError
from wmrkit.control.references import builtin_reference
from wmrkit.control.slip_loop import simulate_slip_control
from wmrkit.control.track import track
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program
from wmrkit.dynamics.simulate import LiftOffError, simulate
from wmrkit.errors import ShapeError
from wmrkit.kinematics.wheel_ik import wheel_commands
from wmrkit.wheels import wrap_angle

STEERED = ("steer", "spin1", "spin2")


def _stiffer(robot: Robot, cs: float) -> Robot:
    data = robot.to_dict()
    for w in data["wheels"]:
        w["tyre"] = {**w["tyre"], "cs": cs}
    return Robot.from_dict(data)


def test_a_steerable_wheel_servo_moves_its_own_inertia():
    model = DynamicModel.of(tricycle())
    assert model.steering_inertia() == pytest.approx([0.8], rel=1e-12)
    assert model.steering_inertia(c for c in range(3, model.n) if model.is_actuated(c)) == pytest.approx([0.8])


def test_a_drive_unit_whose_spins_are_held_turns_the_body_about_its_pivot():
    """Held spins keep the unit still: a unit steering rate of 1 rad/s turns the body at -1 rad/s about the pivot
    (0.3, 0), so the body twist is (0, 0.3, -1), the castors follow it (their rates from the wheel IK: the motion is
    unique) and the inertia is that motion's 2 T (7.17)."""
    robot = double_unit_robot(actuated=STEERED)
    model = DynamicModel.of(robot)
    held = [c for c in range(3, model.n) if model.is_actuated(c)]
    twist = np.array([0.0, 0.3, -1.0])
    cmd = wheel_commands(robot, twist)
    nu = np.zeros(model.n)
    nu[:3] = twist
    for name in ("left.steer", "left.spin", "right.steer", "right.spin"):
        nu[model.names.index(name)] = cmd.rates[robot.rate_names.index(name)]
    nu[model.names.index("drive.steer")] = 1.0
    assert np.abs(model.slip_matrix() @ nu).max() < 1e-12  # it rolls
    expected = nu @ model.mass_matrix() @ nu
    assert expected > 100 * robot.wheel("drive").steer_inertia  # the body, not the unit
    assert model.steering_inertia(held)[0] == pytest.approx(expected, rel=1e-9)
    # with the spins free the unit turns under the body (its spins counter-rotate): little more than its own
    assert model.steering_inertia()[0] < 2 * robot.wheel("drive").steer_inertia


@pytest.mark.parametrize("cs", [2000.0, 20000.0])
def test_a_drive_unit_ahead_of_castors_turns_as_its_yaw_balance_says(cs):
    """In a steady turn the castors carry no force, so the unit's lateral force ``m v omega`` acts at the pivot
    ``x_p = 0.3 m`` ahead of the centre of mass; the yaw moment ``x_p m v omega`` must come from the unit's two
    traction forces ``b`` either side, by a yaw-rate error ``omega - omega_cmd`` through the tyres' longitudinal
    stiffness and the spin servos' gain in series: ``k = 2 b^2 / (v / cs + r^2 / g)``, so
    ``omega = omega_cmd k / (k - x_p m v)``. This holds only if the steering servo holds the unit's angle: with
    its gains from the unit's own inertia (0.05 kg m^2; it turns the body, 6.8 kg m^2) it sat 2.3 deg off at
    0.5 m/s and the robot turned 8 % off this balance, and above 0.3 m/s the loops of ``track --dynamics`` lifted
    the robot off its castors. (Slower, at 0.1 m/s on the stiffer tyres, the castors shimmy and carry force.)"""
    robot = _stiffer(double_unit_robot(actuated=STEERED), cs)
    model = DynamicModel.of(robot)
    x_p, m, b, r = 0.3, robot.body.mass, 0.06, 0.08
    for speed in (0.2, 0.3, 0.5):
        inputs, duration = path_program(model, "turn", speed=speed)
        sim = simulate(model, inputs, duration + 5.0, record_step=0.01)
        castors = [model.contacts.index(c) for c in ("left", "right")]
        assert np.abs(sim.forces[-1, castors]).max() < 1e-3 * np.abs(sim.forces[-1]).max()  # force-free castors
        g = inputs.rate_gain[model.names.index("drive.spin1")]
        v, omega = sim.twist[-1, 0], sim.twist[-1, 2]
        k = 2 * b * b / (v / cs + r * r / g)
        ratio = k / (k - x_p * m * v)
        assert omega / (speed / 3) - 1 == pytest.approx(ratio - 1, rel=0.02), (cs, speed)
        assert sim.heading[-1, 0] == pytest.approx(inputs.heading_reference[-1, 0], abs=math.radians(0.05))


def test_a_drive_unit_ahead_of_castors_spins_out_beyond_its_yaw_balance():
    """Where ``x_p m v`` exceeds ``k`` (soft tyres at 1 m/s) nothing restores the yaw rate: the robot spins out."""
    robot = double_unit_robot(actuated=STEERED)
    model = DynamicModel.of(robot)
    inputs, duration = path_program(model, "turn", speed=1.0)
    g = inputs.rate_gain[model.names.index("drive.spin1")]
    assert 2 * 0.06**2 / (1.0 / 2000 + 0.08**2 / g) < 0.3 * robot.body.mass * 1.0
    sim = simulate(model, inputs, duration, record_step=0.01)
    assert sim.twist[-1, 2] > 3 * (1.0 / 3)


def test_track_dynamics_of_a_drive_unit_with_a_steering_motor_follows_a_circle():
    """Before, the steering servo was 100 times too soft (damping ratio 0.09): 0.30 m RMS error on a 3 m circle
    at 0.5 m/s, and at 0.3 m/s the oscillation lifted a castor off the ground after 25 s."""
    robot = double_unit_robot(actuated=STEERED)
    for speed in (0.3, 0.5):
        run = track(robot, builtin_reference("circle", speed=speed), dynamics=True, duration=30)
        assert run.summary()["rms_error"] < 0.1, speed


def _sideways(period: float, stop: float = math.inf):
    """A controller asking for 0.1 m/s to the left with a forward component of +-1 mm/s alternating each period
    (a wheel heading straddles +90 deg), slowing to rest over the half second before `stop`."""
    def controller(t, pose, integral):
        scale = min(1.0, max(0.0, (stop - t) / 0.5))
        return scale * np.array([1e-3 * (-1) ** round(t / period), 0.1, 0.0]), np.zeros(3)
    return controller


def _backwards(t, pose, integral):
    return np.array([-0.1, 0.0, 0.0]), np.zeros(3)


def _swerve(com_height: float = 0.05) -> Robot:
    """The catalog's swerve drive with mass properties (its modules are steerable: each servo turns its wheel)."""
    data = catalog.load("swerve-4").to_dict()
    data["body"] = {"mass": 40.0, "inertia": 2.0, "com": [0.0, 0.0], "com_height": com_height}
    for w in data["wheels"]:
        w.update(inertia={"spin": 0.001, "steer": 0.005}, tyre={"model": "dugoff"})
    return Robot.from_dict(data)


def _loops(robot, controller, duration, policy):
    """The two loops through the dynamics: plain servos, and the slip-model loop (here without a slip model)."""
    return [simulate_dynamics(robot, controller, np.zeros(3), duration, period=0.02, policy=policy),
            simulate_slip_control(robot, controller, np.zeros(3), duration, period=0.02, slip_model="none",
                                  policy=policy)]


def test_the_dynamic_loop_steers_to_the_root_closest_to_the_current_heading():
    """Each period's IK took the root closest to the *described* heading (0), not the current one: a heading
    straddling +90 deg was commanded +89.4 deg and -89.4 deg (the other root, spins reversed) in turns, a half turn
    of the steering every period; the kinematic loop (and the slip-model loop) always took the current heading. A
    double wheel asked to steer 90 deg from rest also needs its servo's limit (the grip): 9600 N m lifted it."""
    for robot in (double_unit_robot(actuated=STEERED), _swerve()):
        out = simulate_dynamics(robot, _sideways(0.02), np.zeros(3), 2.0, period=0.02)
        heading = robot.heading_of_beta(out["target"])[5:, 0]
        assert np.abs(np.diff(heading)).max() < math.radians(2), robot.name
        assert np.abs(heading - math.pi / 2).max() < math.radians(2), robot.name
        assert out["pose"][-1, 1] > 0.15, robot.name  # it went left


def test_the_dynamic_loop_holds_the_steering_when_the_robot_stops():
    """At rest the IK keeps the current heading; it used to command the described one, so the wheels turned back
    to straight ahead as soon as the robot stopped."""
    robot = _swerve()
    out = simulate_dynamics(robot, _sideways(0.02, stop=1.0), np.zeros(3), 2.0, period=0.02)
    heading = robot.heading_of_beta(out["beta"])
    assert np.abs(out["twist"][-20:]).max() == 0.0
    assert np.abs(heading[-10:] - math.pi / 2).max() < math.radians(2)


def test_the_dynamic_loops_follow_the_steering_policy():
    """`policy` (`track --steering`) was ignored with `--dynamics`: both loops through the dynamics now pick the
    root it asks for, as the kinematic loop does. Sideways with a heading straddling 90 deg, "2-quadrant" keeps
    the headings within +-90 deg (flipping), "closest" and "4-quadrant" do not flip; backwards, "closest" keeps
    the wheels straight and reverses them, "4-quadrant" turns them round to roll forwards."""
    robot = _swerve()
    for policy, flips in (("closest", False), ("2-quadrant", True), ("4-quadrant", False)):
        for out in _loops(robot, _sideways(0.02), 1.0, policy):
            heading = robot.heading_of_beta(out["target"])[5:]
            assert (np.abs(np.diff(heading, axis=0)).max() > math.radians(170)) == flips, policy
            if policy == "2-quadrant":
                assert np.all(np.abs(wrap_angle(heading)) <= math.pi / 2 + 1e-9)
    for policy, expected in (("closest", 0.0), ("4-quadrant", math.pi)):
        for out in _loops(robot, _backwards, 1.0, policy):
            heading = robot.heading_of_beta(out["beta"])[-1]
            assert np.abs(wrap_angle(heading - expected)).max() < math.radians(2), policy
            assert out["pose"][-1, 0] < -0.05, policy
    with pytest.raises(ControlError, match="unknown steering policy"):
        simulate_dynamics(robot, _sideways(0.02), np.zeros(3), 1.0, period=0.02, policy="nearest")


def test_the_loops_through_the_dynamics_start_rolling_at_the_first_command():
    """They started at rest, so the first period was a step from 0 to the reference speed that the servos took at
    the grip (1 g): a swerve robot 0.56 m square with its centre of mass 0.3 m high (an FRC robot's) tipped over
    at t = 1 ms on a straight line at 0.5 m/s, in every loop through the dynamics. Now it starts rolling at the
    law's first command, as the kinematic loop moves at once, and follows the line."""
    robot = _swerve(com_height=0.3)
    line = builtin_reference("line", speed=0.5)
    for kwargs in ({}, {"ramp": True}):
        run = track(robot, line, dynamics=True, duration=4, **kwargs)
        assert run.summary()["max_error"] < 1e-6, kwargs


def test_a_loop_through_the_dynamics_that_tips_the_robot_says_why_and_what_to_change():
    """`track --dynamics` told a user whose robot tipped at a corner to 'use smaller torques or speeds' (the advice
    of `simulate`, whose torques are the user's); now it names the cause in the loop, a step in the command."""
    robot = double_unit_robot(actuated=STEERED)
    for kwargs in ({}, {"ramp": True}):  # (at 0.5 m/s the unit now takes the corner rolling forward, untipped)
        with pytest.raises(ControlError, match=r"contact '\w+' lifts off the ground at t = 3\.\d+ s .* a step in the "
                                               r"command \(a corner of the reference"):
            track(robot, builtin_reference("corner", speed=0.8), dynamics=True, duration=8, **kwargs)
    # The swerve robot's 8 m/s turn tips it with its centre of mass 0.8 m high: at t = 0.002 s at 1 ms, 0.00075 s at
    # 62.5 us (December 2026). 0.5 m high it tipped at 1 ms only by the step (the explicit load transfer): with the
    # step's own loads it goes on, 1.9 N left on the front wheels, and 62.5 us runs keep 6.84 N.
    with pytest.raises(LiftOffError, match="use smaller torques or speeds"):
        simulate(DynamicModel.of(_swerve(com_height=0.8)), path_program(DynamicModel.of(_swerve(0.8)), "turn",
                                                                         speed=8.0)[0], 1.0)


def test_steering_limits_are_torques_above_zero():
    model = DynamicModel.of(double_unit_robot(actuated=STEERED))
    inputs, _ = path_program(model, "straight", speed=0.5)
    assert np.isfinite(inputs.steer_limit[0]) and np.isinf(inputs.steer_limit[1:]).all()  # the castors: none
    assert inputs.steer_limit[0] == pytest.approx(model.normal_loads()[:2].sum() * 0.06)
    for bad in ([0.0, 1.0, 1.0], [np.nan, 1.0, 1.0], [1.0, 1.0]):
        with pytest.raises(ShapeError, match="steer_limit: expected 3 torques > 0 N m"):
            simulate(model, dataclasses.replace(inputs, steer_limit=np.array(bad)), 0.01)


def test_steering_gains_refuse_columns_that_are_not_joints():
    from wmrkit.dynamics.programs import steering_gains, twist_program

    model = DynamicModel.of(tricycle())
    for held in ([99], [-1], ["a"], [1.5], [2]):
        with pytest.raises(ShapeError, match="held: expected joint columns"):
            model.steering_inertia(held)
    with pytest.raises(ShapeError, match="servoed: expected steering columns"):
        steering_gains(model, [3])
    for bandwidth in (float("nan"), 0.0, -30.0):
        with pytest.raises(ShapeError, match="bandwidth: expected a natural frequency"):
            steering_gains(model, list(model.steer_columns), bandwidth=bandwidth)
        with pytest.raises(ShapeError, match="bandwidth: expected a natural frequency"):
            twist_program(model, [0.0], [(1.0, 0.0, 0.0)], bandwidth=bandwidth)
