"""Every door of ``ik`` judges the held linkages: the compiled single-call ``realtime`` ik, as ``wheel_commands``'
``in_linkage`` (kinematics/linkage_check.py).

Before: only ``wheel_commands`` did; ``realtime(synchro).ik(1, 0, 0.5, ...)``, a synchro drive (one ``parallel``
linkage of its three wheels) asked to turn, returned True (feasible). The reference for the
random twists is ``wheel_commands``, itself checked against brute force (tests/kinematics/test_linkage_ik.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.kinematics.realtime import realtime
from wmrkit.kinematics.wheel_ik import wheel_commands

from .test_linkage_ik import ackermann_car, synchro


def linked_robots() -> list[Robot]:
    """The catalog car, synchro drives (one with rest headings apart), a random Ackermann car."""
    apart = Robot.from_dict({"name": "apart", "wheels": [
        {"name": f"w{k}", "type": "steerable", "position": list(p), "heading": h, "r": 0.05}
        for k, (p, h) in enumerate(zip([(0.3, 0.1), (-0.2, 0.25), (-0.1, -0.3)], [0.0, 0.5, -1.0], strict=True))],
        "couplings": [{"kind": "linkage", "joints": ["w0.steer", "w1.steer", "w2.steer"], "law": "parallel"}]})
    return [catalog.load("ackermann"), synchro(), synchro([(0.0, 0.2), (0.0, -0.2)]), apart,
            ackermann_car(1.7, 1.1, -0.4, 0.3)]


def twists(robot: Robot, rng) -> np.ndarray:
    """Random twists, translations, the ICR at each steering axis, on the fixed axle line, tiny turns."""
    out = [rng.uniform(-1, 1, (40, 3)), np.c_[rng.uniform(-1, 1, (10, 2)), np.zeros(10)], np.zeros((1, 3)),
           [[0.0, 0.0, 1e-10], [0.0, 0.0, 1e-8]]]
    for w in robot.wheels:
        if w.kind.steers:
            x, y = w.position
            out.append([[y, -x, 1.0], [-0.5 * y, 0.5 * x, -0.5]])
    if robot.name == "ackermann":  # the catalog car's fixed axle is x = 0: ICRs on it
        out.append(np.c_[rng.uniform(-1, 1, (10, 1)), np.zeros((10, 1)), rng.uniform(-1, 1, (10, 1))])
    return np.concatenate([np.asarray(t, dtype=float) for t in out])


def test_the_realtime_ik_says_a_synchro_drive_cannot_turn():
    robot = synchro()
    rt = realtime(robot)
    rates, out = np.empty(len(robot.rate_names)), np.empty(3)
    assert not rt.ik(1.0, 0.0, 0.5, np.zeros(3), rates, out)
    assert rt.ik(1.0, 0.3, 0.0, np.zeros(3), rates, out)
    np.testing.assert_allclose(out, math.atan2(0.3, 1.0))  # all three wheels along the translation


@pytest.mark.parametrize("index", range(5))
def test_the_realtime_ik_s_verdicts_are_wheel_commands(index):
    robot = linked_robots()[index]
    rt = realtime(robot)
    rng = np.random.default_rng(index)
    rates, out = np.empty(len(robot.rate_names)), np.empty(len(robot.steer_names))
    verdicts = []
    for twist in twists(robot, rng):
        heading = rng.uniform(-math.pi, math.pi, len(robot.steer_names))
        ref = wheel_commands(robot, twist, heading=heading)
        got = rt.ik(*map(float, twist), heading, rates, out)
        assert got == bool(ref.feasible), twist
        verdicts.append(bool(ref.in_linkage.all()))
    assert any(verdicts) and not all(verdicts)

