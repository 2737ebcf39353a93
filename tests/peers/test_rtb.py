"""Agreement with Peter Corke's Robotics Toolbox vehicle models (roboticstoolbox-python): Bicycle, DiffSteer, Unicycle.

RTB's models give the *world-frame* state derivative ``(x_dot, y_dot, theta_dot)`` of pose ``(x, y, theta)``; ours
work in the robot frame, so each comparison rotates our twist by theta (3.15). Conventions mapped explicitly:
- Bicycle: input ``(v, gamma)``, v the speed of the rear axle centre (the reference point, our origin), gamma the
  steered wheel's angle from the body x axis; ours: rear fixed wheel at the origin, front steerable wheel at
  ``(L, 0)`` whose axle angle is ``beta = gamma + 90 deg``; rear spin ``v / r``.
- DiffSteer: input wheel speeds ``(v_L, v_R)`` [m/s] = ``spin * r``, track W; Unicycle: input ``(v, omega)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot
from wmrkit.kinematics.wheel_ik import forward_kinematics, wheel_commands

rtb = pytest.importorskip("roboticstoolbox")

R = 0.3


def _to_world(twist: np.ndarray, theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([c * twist[0] - s * twist[1], s * twist[0] + c * twist[1], twist[2]])


def _to_robot(rate_world: np.ndarray, theta: float) -> np.ndarray:
    return _to_world(rate_world, -theta)


def test_bicycle_forward_and_inverse():
    wheelbase = 2.1
    bike = Robot.from_dict({"name": "bike", "wheels": [
        {"name": "rear", "type": "fixed", "position": [0, 0], "beta": "90 deg", "r": R},
        {"name": "front", "type": "steerable", "position": [wheelbase, 0], "beta": "90 deg", "r": R},
    ]})
    peer = rtb.Bicycle(L=wheelbase, steer_max=1.5)
    rng = np.random.default_rng(0)
    for _ in range(40):
        v, gamma, theta = rng.uniform(-3, 3), rng.uniform(-1.4, 1.4), rng.uniform(-math.pi, math.pi)
        expected = _to_robot(peer.deriv([0.0, 0.0, theta], [v, gamma], limits=False), theta)
        fk, residual = forward_kinematics(bike, {"rear": v / R, "front": v / (R * math.cos(gamma))},
                                          [gamma + math.pi / 2])
        np.testing.assert_allclose(fk, expected, rtol=1e-10, atol=1e-12)
        assert residual < 1e-12
        ik = wheel_commands(bike, expected)  # current steering straight ahead: |gamma| < 90 deg is the closest
        assert ik.feasible
        assert ik.steer[1] == pytest.approx(gamma + math.pi / 2, abs=1e-12)
        np.testing.assert_allclose(ik.spin, [v / R, v / (R * math.cos(gamma))], rtol=1e-10)


def test_diffsteer_and_unicycle():
    track = 0.6
    diff = Robot.from_dict({"name": "diff", "wheels": [
        {"name": "left", "type": "fixed", "position": [0, track / 2], "beta": "90 deg", "r": R},
        {"name": "right", "type": "fixed", "position": [0, -track / 2], "beta": "90 deg", "r": R},
    ]})
    diffsteer, unicycle = rtb.DiffSteer(W=track), rtb.Unicycle(W=track)
    rng = np.random.default_rng(1)
    for _ in range(40):
        v_left, v_right, theta = rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-math.pi, math.pi)
        expected = _to_robot(diffsteer.deriv([0.0, 0.0, theta], [v_left, v_right], limits=False), theta)
        fk, _ = forward_kinematics(diff, {"left": v_left / R, "right": v_right / R})
        np.testing.assert_allclose(fk, expected, rtol=1e-10, atol=1e-12)
        ik = wheel_commands(diff, expected)
        np.testing.assert_allclose(ik.spin * R, [v_left, v_right], rtol=1e-10, atol=1e-12)
        v, omega = rng.uniform(-2, 2), rng.uniform(-3, 3)
        world = unicycle.deriv([0.0, 0.0, theta], [v, omega], limits=False)
        ik = wheel_commands(diff, _to_robot(world, theta))
        assert ik.feasible
        np.testing.assert_allclose(ik.spin * R, [v - omega * track / 2, v + omega * track / 2], rtol=1e-10,
                                   atol=1e-12)


def test_catalog_car_and_bicycle_are_the_toolboxs_bicycle():
    """The catalog's templates as users take them: `bicycle` (rear wheel at the origin) sensing its rear spin and
    front heading equals RTB's Bicycle at steer gamma = heading; the `ackermann` car (origin at the rear axle)
    driven at RTB's Bicycle rate steers its front wheels to the textbook Ackermann angles
    atan(L omega / (v -+ omega w)) (w = half the track, + left) and spins its rear ones at (v -+ omega w) / r."""
    from wmrkit import catalog

    bike, car = catalog.load("bicycle"), catalog.load("ackermann")
    length, r_bike = bike.wheel("front").position[0], bike.wheel("rear").r
    wheelbase, half = car.wheel("front_left").position
    r_car = car.wheel("rear_left").r
    rng = np.random.default_rng(2)
    for _ in range(40):
        v, gamma, theta = rng.uniform(0.2, 3.0) * rng.choice([-1, 1]), rng.uniform(-1.2, 1.2), rng.uniform(-3, 3)
        expected = _to_robot(rtb.Bicycle(L=length, steer_max=1.5).deriv([0, 0, theta], [v, gamma], limits=False),
                             theta)
        fk, residual = forward_kinematics(bike, {"rear": v / r_bike}, heading=[gamma])
        np.testing.assert_allclose(fk, expected, rtol=1e-10, atol=1e-12)
        assert residual < 1e-12
        gamma = gamma * 0.5  # within the car's +-40 deg rack on both sides
        twist = _to_robot(rtb.Bicycle(L=wheelbase, steer_max=1.5).deriv([0, 0, theta], [v, gamma], limits=False),
                          theta)
        ik = wheel_commands(car, twist)
        assert ik.feasible
        omega = twist[2]
        names = [w.name for w in car.wheels]
        heading = dict(zip(names, ik.heading, strict=True))
        for side, sign in (("left", 1), ("right", -1)):
            want = math.atan(wheelbase * omega / (v - sign * omega * half))
            assert heading[f"front_{side}"] == pytest.approx(want, abs=1e-12)
            assert ik.spin[names.index(f"rear_{side}")] * r_car == pytest.approx(v - sign * omega * half, abs=1e-12)
