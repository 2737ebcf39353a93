"""The open differential of a ``differential`` coupling in the dynamic plant: one servo on the carrier rate, equal
torques, the speed difference left to the tyres (twist_program; the forklift's drive wheels)."""

from __future__ import annotations

import dataclasses

import numpy as np

from wmrkit import catalog
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import twist_program
from wmrkit.dynamics.simulate import simulate

FORK = catalog.load("forklift")
DRIVES = ("right_drive.spin", "left_drive.spin")


def _turn(robot):
    model = DynamicModel.of(robot)
    twists = np.array([[1.5, 0.0, 0.0], [1.5, 0.45, 0.45], [1.5, 0.45, 0.45]])  # onto a 3.3 m circle
    inputs = twist_program(model, [0.0, 1.0, 4.0], twists)
    sim = simulate(model, inputs, 4.0, step=1e-3, record_step=0.01, initial_twist=(1.5, 0.0, 0.0))
    cols = [sim.joint_names.index(j) for j in DRIVES]
    return sim, cols


def test_a_differential_drives_its_wheels_with_equal_torques_and_free_speeds():
    sim, cols = _turn(FORK)
    torques, rates = sim.torques[:, cols], sim.joint_rates[:, cols]
    np.testing.assert_allclose(torques[:, 0], torques[:, 1], rtol=0, atol=1e-9)  # one motor, split equally
    assert np.abs(torques).max() > 1.0  # and it works
    assert abs(rates[-1, 0] - rates[-1, 1]) > 0.5  # the outer wheel turns faster: the difference is free
    # the carrier (mean rate) follows the no-slip reference of the commanded twist
    want = twist_program(DynamicModel.of(FORK), [0.0], [[1.5, 0.45, 0.45]]).rate_reference[0]
    model = DynamicModel.of(FORK)
    carrier = rates[-1].mean()
    reference = np.mean([want[model.names.index(j)] for j in DRIVES])
    assert abs(carrier - reference) < 0.02 * abs(reference)


def test_without_the_coupling_each_wheel_has_its_own_servo():
    sim, cols = _turn(dataclasses.replace(FORK, couplings=()))
    torques = sim.torques[:, cols]
    assert np.abs(torques[:, 0] - torques[:, 1]).max() > 10.0  # the servos fight for the yaw moment
