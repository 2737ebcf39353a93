"""The chapter-4 models hold a description's gears: mobility, assignable sets and the direct / inverse models derive
from the no-slip matrix (3.22) with a row ``q_i / ratio_i - q_j / ratio_j = 0`` per pair of a gear's joints.

Every expectation is computed here, independently of wmrkit's ranks code: the null space of the augmented matrix by
an SVD (mobility), a brute-force rank check of every candidate set (assignable sets), and the no-slip and gear rows
evaluated on the models' velocities for random assigned values.
"""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
import yaml

from geared import STEERED, SYNCHRO, cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.models import (
    assignable_sets,
    direct_model,
    inverse_model,
    is_assignable,
    kinematic_model,
    mobility,
)
from wmrkit.kinematics.summary import kinematics_summary

STEERED_SYNCHRO = SYNCHRO.replace("heading: 0,", "heading: 0.4,")  # all three wheels at 0.4 rad (one linkage)
ROBOTS = {"cart-1": cart_yaml(1.0), "cart-2": cart_yaml(2.0), "cart-minus-1": cart_yaml(-1.0),
          "synchro": SYNCHRO, "synchro-0.4": STEERED_SYNCHRO}


def load(text: str) -> Robot:
    return Robot.from_dict(yaml.safe_load(text))


def gear_rows(robot: Robot) -> np.ndarray:
    """``q_i / k_i - q_j / k_j`` for each pair of consecutive joints of each gear, over the velocity vector."""
    names, rows = robot.velocity_names, []
    for c in robot.couplings:
        if c.kind != "gear":
            continue
        for (i, ki), (j, kj) in itertools.pairwise(zip(c.joints, c.ratios, strict=True)):
            row = np.zeros(len(names))
            row[names.index(i)], row[names.index(j)] = 1.0 / ki, -1.0 / kj
            rows.append(row)
    return np.array(rows).reshape(len(rows), len(names))


def null_space(a: np.ndarray) -> np.ndarray:
    """An orthonormal basis of the null space of `a` ``(R, k)``, ``(k, m)``, from its SVD."""
    _, s, vt = np.linalg.svd(a)
    rank = int(np.sum(s > 1e-9 * s[0]))
    return vt[rank:].T


def augmented(robot: Robot) -> np.ndarray:
    return np.vstack([robot.constraint_matrix(), gear_rows(robot)])


@pytest.mark.parametrize("name", list(ROBOTS))
def test_mobility_is_the_null_space_of_the_matrix_with_the_gear_rows(name):
    robot = load(ROBOTS[name])
    m = null_space(augmented(robot)).shape[1]
    assert int(mobility(robot)) == m
    assert int(mobility(robot, gears=False)) == null_space(robot.constraint_matrix()).shape[1]
    summary = kinematics_summary(robot)
    assert summary["coupled_mobility"] == m
    assert summary["mobility"] == null_space(robot.constraint_matrix()).shape[1]


def test_the_cart_loses_one_motion_to_its_gear():
    robot = load(cart_yaml(2.0))
    assert (int(mobility(robot, gears=False)), int(mobility(robot))) == (2, 1)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_assignable_sets_are_the_brute_force_sets_of_the_geared_null_space(name):
    robot = load(ROBOTS[name])
    basis = null_space(augmented(robot))  # q = basis @ z: a set is assignable iff its rows of basis are invertible
    m, names = basis.shape[1], robot.velocity_names
    expected = [tuple(names[i] for i in s) for s in itertools.combinations(range(len(names)), m)
                if np.linalg.matrix_rank(basis[list(s)], tol=1e-9) == m]
    assert list(assignable_sets(robot)) == expected != []
    assert kinematics_summary(robot)["assignable_sets"] == [list(s) for s in expected]
    for s in itertools.combinations(names, m):
        assert bool(is_assignable(robot, s)) == (s in expected)


def check_model(robot: Robot, model, seed: int = 0) -> None:
    """The model's whole velocity vector satisfies the wheels' no-slip rows and the gear rows, at random values."""
    q = model.velocities(np.random.default_rng(seed).uniform(-2.0, 2.0, (5, len(model.assigned))))
    scale = np.abs(q).max()
    assert np.abs(q @ robot.constraint_matrix().T).max() <= 1e-9 * scale
    assert np.abs(q @ gear_rows(robot).T).max() <= 1e-9 * scale


@pytest.mark.parametrize("name", list(ROBOTS))
def test_direct_and_inverse_models_turn_the_geared_joints_together(name):
    robot = load(ROBOTS[name])
    direct, inverse = direct_model(robot), inverse_model(robot)
    assert direct.kind == "direct" and inverse.kind == "inverse"
    check_model(robot, direct)
    check_model(robot, inverse, seed=1)


@pytest.mark.parametrize("method", ["ranks", "nullspace", "rref"])
@pytest.mark.parametrize("ratio", [1.0, 2.0, -1.0])
def test_every_method_holds_the_gear(method, ratio):
    robot = load(cart_yaml(ratio))
    model = kinematic_model(robot, ["left.spin"], method=method)
    check_model(robot, model)
    q = model.velocities([1.0])  # closed form: the spins' contact speeds give the twist of a differential drive
    v_left, v_right = 0.075 * 1.0, 0.075 * ratio
    assert q[robot.velocity_index("right.spin")] == pytest.approx(ratio)
    assert q[:3] == pytest.approx([(v_left + v_right) / 2, 0.0, (v_right - v_left) / 0.4], abs=1e-12)


def test_assigning_both_geared_spins_is_refused():
    robot = load(cart_yaml(2.0))
    with pytest.raises(Exception, match=r"assigns exactly m = 1 velocities here, got 2"):
        kinematic_model(robot, ["left.spin", "right.spin"])


def test_a_steering_that_meets_the_gears_turning_point_is_a_special_configuration():
    # ratio 2: the axle's instantaneous centre is at y = -0.6 (vR = 2 vL); a front wheel at x = 0.6 rolls about it
    # only at heading pi/4: there m = 1 with the gear, at generic steering 0 (the wheels alone: 1 everywhere)
    front = f"front, type: steerable, position: [0.6, 0], heading: {math.pi / 4!r}, r: 0.1, sensed: [steer]}}"
    robot = load(cart_yaml(2.0, front))
    summary = kinematics_summary(robot)
    assert (summary["mobility"], summary["coupled_mobility"], summary["generic_mobility"]) == (1, 1, 0)
    assert null_space(augmented(robot)).shape[1] == 1
    check_model(robot, direct_model(robot))


def test_cli_says_both_mobilities_and_that_the_models_hold_the_gear(tmp_path, capsys):
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(2.0))
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    assert "  mobility m = 2 of the wheels alone\n" in out
    assert ("  with its gear couplings m = 1 (gear of left and right, q_j = ratio_j * u): the sets and models "
            "below hold them") in out
    sets = "(vx)  (omega)  (left.spin)  (right.spin)  (caster.steer)  (caster.spin)"
    assert f"  assignable sets (6):\n    {sets}\n" in out
    assert main(["kinematics", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert (data["mobility"], data["coupled_mobility"], data["gears"]) == (2, 1, ["gear(left.spin, right.spin)"])
    assert data["direct_model"]["assigned"] == ["left.spin"]
    assert main(["analyze", str(path), "--json"]) == 0  # the same two numbers as analyze
    analysis = json.loads(capsys.readouterr().out)
    assert analysis["coupled_mobility"] == data["coupled_mobility"]
    assert analysis["instantaneous_mobility"] == data["mobility"]


def test_a_gear_that_locks_the_cart_leaves_no_motion(tmp_path, capsys):
    # ratio -1: the axle only turns on the spot, which the front wheel (heading 0, at x = 0.6) forbids
    robot = load(cart_yaml(-1.0, STEERED))
    assert null_space(augmented(robot)).shape[1] == 0 == int(mobility(robot))
    assert int(mobility(robot, gears=False)) == null_space(robot.constraint_matrix()).shape[1] == 1
    assert list(assignable_sets(robot)) == [()]
    path = tmp_path / "locked.yaml"
    path.write_text(cart_yaml(-1.0, STEERED))
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    assert "  with its gear couplings m = 0 (gear of left and right," in out
    assert "  with its 1 steering angle (extended solutions, §4.5), 1 velocity can be assigned\n" in out
    assert "    the robot cannot move (m = 0): every velocity is zero" in out
    assert "  direct model:\n" in out and "  inverse model:\n" in out and "assigned: )" not in out  # was "(inverse,
    # assigned: )" for both


def test_the_extended_count_says_a_linkage_is_not_used(tmp_path, capsys):
    """The synchro drive's three steered wheels on one linkage: extended_dof counts each steered wheel (the linkage's
    geometry is not modelled, test_gear_extended.py checks the count); the text said "3 velocities can be assigned"
    without saying so, and the JSON had no linkage."""
    path = tmp_path / "synchro.yaml"
    path.write_text(SYNCHRO)
    assert main(["kinematics", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["linkages"] == ["linkage(a.steer, b.steer, c.steer)"] and data["extended_dof"] == 3
    assert main(["kinematics", str(path)]) == 0
    out = capsys.readouterr().out
    assert ("3 velocities can be assigned (each steered wheel counted, the steering linkage of wheels 'a', 'b' and "
            "'c' not as one: the solutions judge their angles against its law)\n") in out  # the description's terms
