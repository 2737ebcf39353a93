"""Per-wheel IK (``wheel_commands``, ``wmrkit ik``, the studio's drive) under mechanical couplings: a ``gear``
turns its joints in its ratios, so a twist that needs other rates is not feasible; a differential never forbids one."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.couplings import Coupling
from wmrkit.kinematics.wheel_ik import gear_error, wheel_commands

R, W, L = 0.33, 0.775, 2.70  # the catalog car: tyre radius, half track, wheelbase


def geared(robot_name: str, joints: tuple[str, ...], ratios: tuple[float, ...]):
    """A catalog robot with one gear coupling (a solid axle, a chain) instead of its rate couplings."""
    robot = catalog.load(robot_name)
    keep = tuple(c for c in robot.couplings if not c.rates)
    return dataclasses.replace(robot, couplings=(*keep, Coupling("gear", joints, ratios)))


def test_a_solid_rear_axle_cannot_turn():
    """The car with its rear spins geared (1, 1) rolls straight only: turning needs (v -+ omega w) / r on the two
    rear wheels, which the gear cannot give. Before, every turn within the rack was 'feasible'."""
    car = geared("ackermann", ("rear_left.spin", "rear_right.spin"), (1.0, 1.0))
    twists = np.array([[1.0, 0, 0], [1.0, 0, 0.2], [-2.0, 0, 0], [0, 0, 0], [1.0, 0, -0.1]])
    c = wheel_commands(car, twists)
    assert c.in_gear.shape == (5, 2) and c.in_gear[:, 0].all()  # the linkage (first) is never checked
    assert c.in_gear[:, 1].tolist() == [True, False, True, True, False]
    assert c.feasible.tolist() == [True, False, True, True, False]
    v, w = 1.0, 0.2  # the rear spins by hand: they differ by 2 w W / r
    rl, rr = car.rate_names.index("rear_left.spin"), car.rate_names.index("rear_right.spin")
    assert c.rates[1, [rl, rr]] == pytest.approx([(v - w * W) / R, (v + w * W) / R], rel=1e-12)
    err = gear_error(car.couplings[1], car.rate_names, c.rates)
    assert err[1] == pytest.approx(w * W / R, rel=1e-12) and err[0] == 0  # distance to the mean: half the gap
    assert wheel_commands(car, twists[1]).to_dict()["out_of_gear"] == ["gear(rear_left.spin, rear_right.spin)"]


def test_the_catalog_differential_forbids_no_turn():
    """The catalog car's differential sets the mean of the rear spins (the engine, v / r) and leaves the difference
    free: the same turn is feasible, the engine's rate the mean."""
    car = catalog.load("ackermann")
    c = wheel_commands(car, [1.0, 0, 0.2])
    assert c.feasible and c.in_gear.all() and c.to_dict()["out_of_gear"] == []
    spins = c.rates[[car.rate_names.index(j) for j in car.couplings[0].joints]]
    assert np.dot(car.couplings[0].ratios, spins) == pytest.approx(1.0 / R, rel=1e-12)


def test_ratios_and_signs_are_honoured():
    """A diff drive whose wheels are geared to counter-rotate (1, -1) turns on the spot only; geared (1, 2) it
    drives on the circle where the right wheel turns twice the left: (v + w b) = 2 (v - w b), w = v / (3 b)."""
    robot = catalog.load("diff-drive")
    b = abs(robot.wheel("left").position[1])
    spin = geared("diff-drive", ("left.spin", "right.spin"), (1.0, -1.0))
    assert wheel_commands(spin, [[0, 0, 1.0], [1.0, 0, 0], [0.3, 0, 1.0]]).feasible.tolist() == [True, False, False]
    two = geared("diff-drive", ("left.spin", "right.spin"), (1.0, 2.0))
    v = 0.7
    c = wheel_commands(two, [[v, 0, v / (3 * b)], [v, 0, -v / (3 * b)], [v, 0, 0]])
    assert c.feasible.tolist() == [True, False, False]
    assert c.rates[0, 1] == pytest.approx(2 * c.rates[0, 0], rel=1e-12)


def test_a_castor_geared_to_its_spin():
    """A castor's swivel geared to its spin: the rates (8.24)/(8.25) must keep the ratio; rolling straight (swivel
    rate 0, spin non-zero) breaks a (1, 1) gear, turning on the spot about the right point keeps it."""
    robot = catalog.load("thesis-diff-castor")
    castor = next(w for w in robot.wheels if w.type == "castor")
    g = dataclasses.replace(robot, couplings=(Coupling("gear", (f"{castor.name}.steer", f"{castor.name}.spin"),
                                                       (1.0, 1.0)),))
    c = wheel_commands(g, [[1.0, 0, 0], [0, 0, 0]])
    assert c.feasible.tolist() == [False, True]  # at rest every rate is 0: in any ratio


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_ik_names_the_gear_and_the_rates(capsys, tmp_path):
    car = geared("ackermann", ("rear_left.spin", "rear_right.spin"), (1.0, 1.0))
    path = tmp_path / "kart.yaml"
    car.to_file(path)
    code, out, err = run(capsys, "ik", str(path), "--twist", "1", "0", "0.2")
    assert code == 1 and "feasible: NO (a gear coupling cannot turn its joints so)" in out
    assert ("a gear coupling cannot turn its joints so: the gear of wheels 'rear_left' and 'rear_right' turns them in "
            "the ratios 1, 1, the twist needs rear_left.spin 2.56061, rear_right.spin 3.5 rad/s") in err
    code, out, err = run(capsys, "ik", str(path), "--twist", "1", "0", "0.2", "--json")
    data = json.loads(out)
    assert data["feasible"] is False and data["out_of_gear"] == ["gear(rear_left.spin, rear_right.spin)"]
    code, out, err = run(capsys, "ik", str(path), "--twist", "1", "0", "0", "--json")
    assert json.loads(out)["feasible"] is True and err == ""


def test_studio_drive_says_the_gear():
    from wmrkit.studio.api import drive

    car = geared("ackermann", ("rear_left.spin", "rear_right.spin"), (1.0, 1.0))
    data = drive({"description": car.to_dict(), "twist": [1, 0, 0.2]})
    assert data["feasible"] is False and data["slips"] is False and data["out_of_range"] == []
    assert data["out_of_gear"] == ["gear(rear_left.spin, rear_right.spin)"]


@pytest.mark.parametrize("joints, ratios", [(("rear_left.spin", "rear_right.spin"), (1.0, 1.0)),
                                            (("rear_left.spin", "front_right.spin"), (1.0, -2.0))])
def test_realtime_ik_says_the_same(joints, ratios):
    """The compiled ik (``realtime``) judges a gear as ``wheel_commands`` does (it said feasible)."""
    from wmrkit.kinematics.realtime import realtime

    car = geared("ackermann", joints, ratios)
    rt = realtime(car)
    rng = np.random.default_rng(5)
    seen = set()
    for twist in [[1.0, 0, 0.2], [1.0, 0, 0], [0.0, 0, 0], *rng.uniform(-1, 1, (30, 3)) * [1, 0, 0.3]]:
        rates, out = np.empty(len(car.rate_names)), np.empty(2)
        feasible = rt.ik(*map(float, twist), car.heading.copy(), rates, out)
        ref = wheel_commands(car, twist)
        assert feasible == bool(ref.feasible)
        seen.add(feasible)
    assert seen == {True, False}


def test_closed_forms_say_a_gear_is_not_used(capsys, tmp_path):
    """kinematics --codegen holds the gear (tests/kinematics/test_gear_codegen.py): no warning. --symbolic holds the
    gear where an exact form can (tests/kinematics/test_gear_symbolic.py): not the direct model of both sensed spins
    (two assigned for m = 1: least squares), which it names."""
    path = tmp_path / "geared.yaml"
    geared("diff-drive", ("left.spin", "right.spin"), (1.0, 1.0)).to_file(path)
    code, _, err = run(capsys, "kinematics", str(path), "--codegen", "python", str(tmp_path / "out"))
    assert code == 0 and "warning" not in err
    code, _, err = run(capsys, "kinematics", str(path), "--symbolic")
    assert code == 0 and err == ("wmrkit: warning: the closed-form direct model (sensed) (left.spin, right.spin) is of "
                                 "the wheels alone, not holding the gear of wheels 'left' and 'right': it may give "
                                 "rates they forbid (check a twist with 'wmrkit ik')\n")
    code, _, err = run(capsys, "kinematics", str(path))
    assert code == 0 and err == ""
    code, _, err = run(capsys, "kinematics", "forklift", "--symbolic")  # a differential: nothing to say
    assert code == 0 and err == ""
