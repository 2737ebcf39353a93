"""The report's sample motions hold the robot's gears. Before: sample_icrs gave the geared omni-3 (front_left.spin and
back.spin on a gear, 1:2) the four samples of a robot with no axle, turns about (0, 0), (0.24, 0.30), (-0.50, 0.16) m
and a translation along y, none on the line of ICRs the gear leaves, and the solid-axle cart geared 1:2 turns about
(0, 0), (0, 0.35), (0, -0.65) m and a translation, where the gear allows only the turn about (0, 0.6) m. Checked
against the twists the geared robot admits at the steering drawn, from an SVD done here: the null space of the
no-slip rows (3.22) plus one row per geared joint after the first (q_0 / k_0 = q_i / k_i)."""

from __future__ import annotations

import numpy as np
import pytest
from test_gear_icr import off
from test_gear_isotropy import omni

from geared import STEERED, SYNCHRO, cart_yaml, held_constraints
from wmrkit import Robot
from wmrkit.analysis.classification import classify
from wmrkit.analysis.figures import motions_figure, sample_icrs
from wmrkit.analysis.icr import steer_to_icr, twist_of_icr


def admitted(robot: Robot, beta: np.ndarray) -> np.ndarray:
    """An orthonormal basis (rows) of the twists (vx, vy, omega) the wheels admit at `beta` with every gear held."""
    a = held_constraints(robot, beta)
    _, s, vh = np.linalg.svd(a)
    kernel = vh[int(np.sum(s > 1e-10 * s[0])):]
    _, s2, vt = np.linalg.svd(kernel[:, :3])
    return vt[:int(np.sum(s2 > 1e-10))]


def _robots(tmp_path):
    yield "omni 1:1", omni(tmp_path, (1.0, 1.0))
    yield "omni 1:2", omni(tmp_path, (1.0, 2.0))
    for ratio in (1.0, 2.0, -1.0):
        for front, name in ((None, "castor"), (STEERED, "steered")):
            path = tmp_path / "cart.yaml"
            path.write_text(cart_yaml(ratio) if front is None else cart_yaml(ratio, front))
            yield f"cart 1:{ratio} {name}", Robot.from_file(path)
    path = tmp_path / "synchro.yaml"
    path.write_text(SYNCHRO)
    yield "synchro", Robot.from_file(path)


def test_every_sample_motion_of_a_geared_robot_is_one_its_gears_allow(tmp_path):
    for name, robot in _robots(tmp_path):
        samples = sample_icrs(robot, classify(robot))
        assert samples, name  # each of them moves, so the figure shows some motion
        for h in samples:
            beta = steer_to_icr(robot, h) if robot.steer_names else robot.beta
            assert off(admitted(robot, beta), twist_of_icr(h)) < 1e-9, (name, h)


@pytest.mark.parametrize("ratio", [2.0, -1.0])
def test_the_geared_cart_is_drawn_turning_about_the_one_point_its_gear_fixes(tmp_path, ratio):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(ratio))
    robot = Robot.from_file(path)
    (vx, vy, omega), = admitted(robot, robot.beta)
    samples = sample_icrs(robot, classify(robot))
    assert len(samples) == 1
    assert samples[0][:2] / samples[0][2] == pytest.approx((-vy / omega, vx / omega), abs=1e-12)
    assert len(motions_figure(robot, classify(robot)).axes) == 1
