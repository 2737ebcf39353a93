"""The minimal actuator and sensor sets of a robot whose gear leaves m = 2 of its wheels' 3 motions, against brute
force done here: every pair of spins whose rates, with the gear held, fix every velocity (the rows of a null-space
basis of the no-slip matrix (3.22) with the gear's row appended have rank m). A regression check: kinematics
already lists them; analyze's isotropy was the door left (tests/analysis/test_gear_isotropy.py)."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from scipy.linalg import null_space

from wmrkit import Robot, catalog
from wmrkit.kinematics.actuation import minimal_actuator_sets
from wmrkit.kinematics.sensing import minimal_sensor_sets


def geared_omni(tmp_path, ratios) -> Robot:
    d = catalog.load("omni-3").to_dict()
    d["couplings"] = [{"kind": "gear", "joints": ["front_left.spin", "back.spin"], "ratios": list(ratios)}]
    path = tmp_path / "omni.json"
    path.write_text(json.dumps(d))
    return Robot.from_file(path)


def brute_force(robot: Robot, ratios) -> list[tuple[str, ...]]:
    a = robot.constraint_matrix()
    names = robot.velocity_names
    gear = np.zeros(len(names))
    gear[names.index("front_left.spin")], gear[names.index("back.spin")] = 1 / ratios[0], -1 / ratios[1]
    basis = null_space(np.vstack([a, gear]))
    m = basis.shape[1]
    spins = [n for n in names if n.endswith(".spin")]
    return [s for s in itertools.combinations(spins, m)
            if np.linalg.matrix_rank(basis[[names.index(n) for n in s]], tol=1e-9) == m]


@pytest.mark.parametrize("ratios", [(1.0, 1.0), (1.0, -2.0)])
def test_minimal_sets_are_the_pairs_that_fix_every_velocity(tmp_path, ratios):
    robot = geared_omni(tmp_path, ratios)
    expected = brute_force(robot, ratios)
    assert expected == [("front_left.spin", "front_right.spin"), ("back.spin", "front_right.spin")]
    assert list(minimal_actuator_sets(robot)) == expected
    assert list(minimal_sensor_sets(robot)) == expected
