"""The minimal sensor sets honour a ``gear`` as the sensing analysis does (its unsensed joints known from its
sensed ones, ``couplings.gear_fill``; m counts the motions it allows): one encoder on a solid axle is a set. Checked
against brute force: every set of m rates is listed iff ``sensing_analysis`` of that set says determined with
nothing left undriven."""

from __future__ import annotations

import itertools
import math

import pytest

from geared import cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.actuation import selectable_rates
from wmrkit.kinematics.sensing import minimal_sensor_sets, sensing_analysis
from wmrkit.kinematics.trees import jacobian_names

# ratio 2: vx = 1.5 r q, omega = 2.5 r q; the front wheel at x = 0.6 rolls along (vx, 0.6 omega): heading pi/4
STEERED = f"front, type: steerable, position: [0.6, 0], heading: {math.pi / 4!r}, r: 0.1, sensed: [steer]}}"
SYNCHRO = """name: synchro-3
wheels:
  - {name: a, type: steerable, position: [0.2, 0], heading: 0.4, r: 0.05, actuated: [spin], sensed: [spin, steer]}
  - {name: b, type: steerable, position: [-0.1, 0.1732], heading: 0.4, r: 0.05, sensed: [steer]}
  - {name: c, type: steerable, position: [-0.1, -0.1732], heading: 0.4, r: 0.05, sensed: [steer]}
couplings:
  - {kind: gear, joints: [a.spin, b.spin, c.spin]}
  - {kind: linkage, joints: [a.steer, b.steer, c.steer]}
"""
ROBOTS = {"cart-castor-1": cart_yaml(1),
          "cart-castor-2": cart_yaml(2),
          "cart-steered-2": cart_yaml(2, STEERED),
          "synchro-3": SYNCHRO}


def brute_force(robot: Robot, size: int) -> list[tuple[str, ...]]:
    """Every set of `size` selectable rates whose sensing analysis determines the twist, nothing undriven."""
    names, steer = jacobian_names(robot), tuple(f"{w.name}.steer" for w in robot.wheels if w.type == "steerable")
    out = []
    for s in itertools.combinations(selectable_rates(robot), size):
        joints = tuple(names[c] for c in s) + steer
        a = sensing_analysis(robot, sensed=joints)
        if bool(a.leaf == "determined") and int(a.unsensed) == 0:
            out.append(joints)
    return out


@pytest.mark.parametrize("name", list(ROBOTS))
def test_minimal_sensor_sets_are_the_sets_the_sensing_analysis_accepts(tmp_path, name):
    path = tmp_path / "robot.yaml"
    path.write_text(ROBOTS[name])
    robot = Robot.from_file(path)
    m = int(sensing_analysis(robot).mobility)
    found = minimal_sensor_sets(robot)
    assert found.complete and list(found) == brute_force(robot, m) != []
    assert m == 1  # the gear's one motion (each robot would have m = 2 without it)


def test_kinematics_lists_one_encoder_of_a_solid_axle(tmp_path, capsys):
    """Before: 'minimal sensor sets (6): (left.spin, right.spin)  (left.spin, caster.steer) ...' (the gear ignored),
    next to 'sensing [left.spin]: basic sensing ... (1 sensed rate, m = 1)'."""
    path = tmp_path / "cart.yaml"
    path.write_text(ROBOTS["cart-castor-1"])
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    assert "  minimal sensor sets (3):\n    (left.spin)  (right.spin)  (caster.spin)\n" in out  # the gear held unsensed
