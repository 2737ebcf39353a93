"""Mass properties and tyres in descriptions: values, round trips, hashing, located one-line errors."""

from __future__ import annotations

import pickle

import pytest
from dynamics_robots import castor_robot

from wmrkit import Robot, catalog
from wmrkit.description import robot_from_text
from wmrkit.dynamics.mass import Body
from wmrkit.dynamics.tyres import Tyre
from wmrkit.errors import DescriptionError


def test_forklift_has_the_thesis_values():
    robot = catalog.load("forklift")
    assert robot.body == Body(2500.0, 1500.0, (-1.45, 0.0), 0.7)
    assert [w.spin_inertia for w in robot.wheels] == [1.0, 1.0, 1.5]
    assert robot.wheel("steer").steer_inertia == 0.8
    assert all(w.tyre == Tyre.of("pacejka") for w in robot.wheels)
    # l_CM = 0.45 m behind the drive axle (x = -1 at the fork-tip origin), between the axle and the steer wheel
    axle = robot.wheel("left_drive").position[0]
    assert axle - robot.body.com[0] == pytest.approx(0.45)


@pytest.mark.parametrize("robot", [catalog.load("forklift"), catalog.load("skid-steer-4"), castor_robot()])
def test_round_trip_hash_and_pickle(robot, tmp_path):
    assert Robot.from_dict(robot.to_dict()) == robot
    assert hash(Robot.from_dict(robot.to_dict())) == hash(robot)
    for suffix in (".yaml", ".json"):
        robot.to_file(tmp_path / f"r{suffix}")
        assert Robot.from_file(tmp_path / f"r{suffix}") == robot
    again = pickle.loads(pickle.dumps(robot))
    assert again == robot and hash(again) == hash(robot) and again.body == robot.body


def test_without_mass_properties_nothing_changes():
    robot = catalog.load("diff-drive")
    assert robot.body is None and all(w.tyre is None and w.spin_inertia == 0 for w in robot.wheels)
    assert "body" not in robot.to_dict() and all("inertia" not in w for w in robot.to_dict()["wheels"])


BASE = """name: t
body: {mass: 10, inertia: 1, com: [0, 0], com_height: 0.1}
wheels:
  - name: a
    type: fixed
    position: [0, 0.2]
    beta: 90 deg
    r: 0.1
"""


@pytest.mark.parametrize("text,where,message", [
    (BASE.replace("mass: 10", "mass: -10"), "body.mass", "must be > 0"),
    (BASE.replace("inertia: 1,", ""), "body", "missing field 'inertia'"),
    (BASE.replace("com: [0, 0]", "com: [0]"), "body.com", "list [x, y]"),
    (BASE.replace("com_height: 0.1", "com_height: 1 deg"), "body.com_height", "expected a length"),
    (BASE.replace("com_height", "cm_height"), "body.cm_height", "did you mean 'com_height'"),
    (BASE + "    inertia: {spin: -1}\n", "wheels[0].inertia.spin", "must be >= 0"),
    (BASE + "    inertia: {steer: 1}\n", "wheels[0].inertia.steer", "unknown field 'steer'"),
    (BASE + "    mass: 2\n", "wheels[0].mass", "castor units only"),
    (BASE + "    tyre: {model: michelin}\n", "wheels[0].tyre.model", "unknown tyre model"),
    (BASE + "    tyre: {model: dugoff, cz: 1}\n", "wheels[0].tyre.cz", "unknown field 'cz'"),
    (BASE + "    tyre: {model: dugoff, mu: 0}\n", "wheels[0].tyre.mu", "must be > 0"),
    (BASE + "    tyre: {model: pacejka, shifts: 0.5}\n", "wheels[0].tyre.shifts", "0 or 1"),
])
def test_bad_mass_properties_give_one_located_line(text, where, message):
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="t.yaml")
    line = str(err.value)
    assert "\n" not in line and where in line and message in line and line.startswith("t.yaml:")


def test_tyre_shorthand_and_units():
    robot = robot_from_text(BASE.replace("com: [0, 0]", "com: ['20 mm', 0]") + "    tyre: dugoff\n",
                            source="t.yaml")
    assert robot.body.com == (0.02, 0.0) and robot.wheels[0].tyre == Tyre.of("dugoff")
