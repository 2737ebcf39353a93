"""models.generic_inputs, the inputs of ``--symbolic`` and ``--codegen``: the mobility at generic steering is the least
met over random configurations drawn in the robot's own axes (as classify's), so a nearly special robot gets the
same inputs in every frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from strategies import moved
from wmrkit import Robot, Wheel
from wmrkit.kinematics.models import generic_inputs

#: Three steerable wheels within 10 um of one another (and a ball): at generic steering their three axles do not
#: meet, m = 0 (rank of the three steering rows 3). (100 nm before: as far above the cut-off of then, 1e-9 times the
#: size, as 10 um is above ``linalg.RANK_RTOL``; 100 nm is one point now.)
_NEAR_THREE = Robot(name="r", wheels=(
    Wheel(name="w0", type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5),
    Wheel(name="w1", type="steerable", l=0.0, alpha=0.0, beta=0.0, r=0.5),
    Wheel(name="w2", type="ball", l=1.0, alpha=-1.0, beta=0.0, r=0.5),
    Wheel(name="w3", type="steerable", l=1e-5, alpha=0.0, beta=0.0, r=0.5)))

#: A castor, a ball and two fixed wheels on parallel axles 10 um apart (found by a random search, 91 nm apart then,
#: w3 moved off w2's axle since): two distinct parallel axles leave one translation, m = 1; the castor and the ball
#: follow any motion.
_TWIN_AXLES = Robot(name="r", wheels=(
    Wheel(name="w0", type="castor", l=0.8256726764394066, alpha=2.8639650658486033, beta=1.6374744563606294,
          r=0.30672468392880964, d=0.11561164731921601),
    Wheel(name="w1", type="ball", l=0.057451279341254935, alpha=-0.6296083902692327, beta=-2.279906567762249,
          r=0.20596498081983822),
    Wheel(name="w2", type="fixed", l=0.031025651168633428, alpha=1.4397510139203185, beta=-2.7943587338662157,
          r=0.35632642363143785),
    Wheel(name="w3", type="fixed", l=0.031022249612548656, alpha=1.4400541246318177, beta=-2.794661844577715,
          r=0.35632642363143785)))


def _axle_gap(robot: Robot, i: int, j: int) -> float:
    """Distance [m] between the parallel axle lines of wheels i and j (independent geometry)."""
    (xi, yi), (xj, yj) = robot.wheels[i].position, robot.wheels[j].position
    turn = robot.wheels[i].alpha + robot.wheels[i].beta
    return abs((xj - xi) * math.sin(turn) - (yj - yi) * math.cos(turn))


@pytest.mark.parametrize(("robot", "expected"), [(_NEAR_THREE, ((), 0)), (_TWIN_AXLES, ((), 1))],
                         ids=["three-steered-10um", "twin-axles-10um"])
def test_a_nearly_special_robot_gets_its_generic_inputs_in_every_frame(robot, expected):
    """Before: the largest m over three configurations drawn in the frame's axes: _NEAR_THREE had m = 1 in 36 of
    these 61 frames, and _TWIN_AXLES m = 2 in most frames, so ``kinematics --symbolic`` printed its inverse model as
    "assigned: vx, vy, omega, least squares" in one frame and "assigned: vx, exact" turned by 2 rad."""
    assert _axle_gap(_TWIN_AXLES, 2, 3) == pytest.approx(1e-5, rel=1e-3)  # far above the rank cut-off (1e-6 L)
    for phi in np.linspace(-3.0, 3.0, 61):
        assert generic_inputs(moved(robot, (0.3, -0.2), float(phi))) == expected, phi
