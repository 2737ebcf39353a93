"""wmrkit simulate holds a gear coupling (``couplings:``): a solid axle's wheels turn together, a start the gear
forbids is refused in one line, a program the gear forbids is named; a linkage is held too (its start refused)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
from dynamics_robots import castor_robot

from wmrkit.cli.main import main
from wmrkit.couplings import Coupling

AXLE = dataclasses.replace(castor_robot(), name="solid-axle",
                           couplings=(Coupling("gear", ("left.spin", "right.spin"), (1, 1)),))


def _axle(tmp_path):
    path = tmp_path / "axle.yaml"
    AXLE.to_file(path)
    return str(path)


def test_simulate_turns_a_solid_axle_together_and_says_nothing_of_it(tmp_path, capsys):
    """A torque on the left spin alone drives both wheels of a solid axle at one rate (the CSV's rates at every
    sample): the robot goes straight. Before, the left wheel turned alone with a warning that the gear was not
    modelled, and the robot turned."""
    torques = tmp_path / "t.csv"
    torques.write_text("time,left.spin\n0,0.4\n")
    out = tmp_path / "run.csv"
    assert main(["simulate", _axle(tmp_path), "--torques", str(torques), "--duration", "1", "--out", str(out),
                 "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert not any("gear" in w for w in answer["warnings"])
    header = out.read_text().splitlines()[0].split(",")
    run = np.genfromtxt(out, delimiter=",", skip_header=1)
    left, right = (run[:, header.index(f"{w}.spin.rate [rad/s]")] for w in ("left", "right"))
    assert left[-1] > 1.0 and np.array_equal(left, right)
    assert abs(answer["final_pose"][2]) < 1e-4 and answer["final_twist"][0] > 0.05  # (only the CM's 2 cm offset)


def test_simulate_refuses_a_start_the_gear_forbids_and_names_it_in_a_program(tmp_path, capsys):
    """--initial-twist turning a solid axle has no rolling start: exit 2, one line naming the gear. The turn
    program, which the gear forbids, leaves the robot on a straight line; the warning names the gear."""
    axle = _axle(tmp_path)
    assert main(["simulate", axle, "--path", "straight", "--initial-twist", "0.5", "0", "1", "--json"]) == 2
    error = json.loads(capsys.readouterr().err)["error"]
    assert "the gear of wheels 'left' and 'right' out of its ratios (1, 1)" in error and "\n" not in error
    assert main(["simulate", axle, "--path", "turn", "--speed", "0.5", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert abs(answer["final_pose"][2]) < 1e-3  # a solid axle does not turn (the turn programs 0.65 rad)
    assert any("the gear of wheels 'left' and 'right' out of its ratios" in w for w in answer["warnings"])


def test_simulate_holds_a_linkage_and_refuses_a_start_it_forbids(tmp_path, capsys):
    """A car steered at the back through a linkage: the turn program steers both wheels, the right one at the
    heading whose axle meets the left one's on the fixed axle (their ICR), in every sample of the CSV, with no
    warning. Before, each wheel followed its own servo and simulate warned 'linkage(...) is not held'. A chain
    without a fixed wheel cannot start turning on the spot: exit 2, one line naming the linkage."""
    robot = castor_robot()
    steer = {"type": "steerable", "r": 0.08, "actuated": ["steer"], "inertia": {"spin": 0.004, "steer": 0.01}}
    wheels = [w.to_dict() if hasattr(w, "to_dict") else w for w in robot.to_dict()["wheels"][:2]]
    front = [{"name": "fl", "position": [-0.3, 0.2], **steer}, {"name": "fr", "position": [-0.3, -0.2], **steer}]
    data = {**robot.to_dict(), "name": "linked", "wheels": wheels + front,
            "couplings": [{"kind": "linkage", "joints": ["fl.steer", "fr.steer"]}]}
    path, out = tmp_path / "linked.json", tmp_path / "run.csv"
    path.write_text(json.dumps(data))
    assert main(["simulate", str(path), "--path", "turn", "--speed", "0.5", "--out", str(out), "--json"]) == 0
    assert not any("linkage" in w for w in json.loads(capsys.readouterr().out)["warnings"])
    header = out.read_text().splitlines()[0].split(",")
    run = np.genfromtxt(out, delimiter=",", skip_header=1)
    left, right = (run[:, header.index(f"{w}.steer [rad]")] for w in ("fl", "fr"))  # headings
    # the left axle meets the fixed axle (x = 0) at y = 0.2 - 0.3 / tan(left); the right one, at (-0.3, -0.2),
    # points at it: its heading (mod pi) is that of (0.2 - 0.3 / tan(left) + 0.2, -0.3), or of (cos, sin) scaled
    expected = np.arctan2(-0.3 * np.sin(left), 0.4 * np.sin(left) - 0.3 * np.cos(left))
    expected = (expected + np.pi / 2) % np.pi - np.pi / 2
    assert np.abs(left).max() > 0.05  # it steered
    np.testing.assert_allclose(right, expected, atol=1e-8)  # the CSV's 9 digits
    chain = {**data, "name": "chain", "wheels": [{**w, "type": "steerable", "inertia": {"spin": 0.004, "steer": 0.01}}
                                                 for w in data["wheels"][:2]] + front}
    for w in chain["wheels"][:2]:
        w.pop("beta", None)
    chain["couplings"] = [{"kind": "linkage", "joints": ["left.steer", "right.steer", "fl.steer", "fr.steer"]}]
    path.write_text(json.dumps(chain))
    assert main(["simulate", str(path), "--path", "straight", "--initial-twist", "0.2", "0", "0.5", "--json"]) == 2
    error = json.loads(capsys.readouterr().err)["error"]
    assert "the steering linkage of wheels 'left', 'right', 'fl' and 'fr'" in error and "\n" not in error
