"""A ``gear`` of double wheels' steering rates (their free inputs, 3.24): the inverse model takes the gear's turn once,
and a gear that leaves no twist is refused in words (it raised ``ValueError: r must be non-negative``)."""

from __future__ import annotations

import json

import numpy as np
import scipy.linalg

from geared import held_constraints
from wmrkit import Robot
from wmrkit.cli.main import main

_TWO = """name: dbl
wheels:
  - {name: d1, type: double, position: [0.3, 0], heading: 0, b: 0.1, r: 0.05, sensed: [spin1, spin2, steer]}
  - {name: d2, type: double, position: [-0.3, 0], heading: 0, b: 0.1, r: 0.05, sensed: [spin1]}
couplings:
  - {kind: gear, joints: [d1.steer, d2.steer]}
"""




def test_geared_steering_of_double_wheels_is_one_input_of_the_inverse_model(tmp_path, capsys):
    path = tmp_path / "dbl.yaml"
    path.write_text(_TWO)
    robot = Robot.from_file(path)
    held = held_constraints(robot)
    assert scipy.linalg.null_space(held).shape[1] == 2  # a translation along x and the geared steering
    assert main(["kinematics", str(path), "--json"]) == 0
    model = json.loads(capsys.readouterr().out)["inverse_model"]
    assert model["assigned"] == ["vx", "d1.steer"]  # was an error: "no 0 of (vx, vy, omega) with d1.steer, d2.steer"
    for given in ([1.0, 0.0], [0.0, 1.0], [0.3, -2.0]):
        q = np.zeros(len(robot.velocity_names))
        q[[robot.velocity_index(n) for n in model["assigned"]]] = given
        q[[robot.velocity_index(n) for n in model["solved"]]] = np.array(model["matrix"]) @ given
        assert np.abs(held @ q).max() < 1e-12  # no slip, the gear held


def test_a_gear_leaving_no_twist_beside_the_steering_is_refused_in_words(tmp_path, capsys):
    path = tmp_path / "dbl.yaml"
    path.write_text(_TWO + "  - {kind: gear, joints: [d1.spin1, d1.spin2], ratios: [1, -1]}\n")  # d1 turns on the spot
    robot = Robot.from_file(path)
    motions = scipy.linalg.null_space(held_constraints(robot))
    assert motions.shape[1] == 1 and np.abs(motions[:3]).max() < 1e-12  # only the steering, the body at rest
    for extra in ([], ["--codegen", "python", str(tmp_path / "gen")]):
        assert main(["kinematics", str(path), "--json", *extra]) == 0  # was a traceback
        out = json.loads(capsys.readouterr().out)
        if not extra:
            assert out["inverse_model"]["error"] == ("robot 'dbl': no set of (vx, vy, omega) with d1.steer can be "
                                                     "assigned at heading (d1=0 deg, d2=0 deg): the body cannot move "
                                                     "(its degree of freedom moves the joints with the body at "
                                                     "rest; the direct model assigns them)")
