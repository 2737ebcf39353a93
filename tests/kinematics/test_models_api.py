"""Kinematic models as values: batches, shapes, errors, mobility oracles (digest PART D oracle 5), closed forms."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from wmrkit import Robot, ShapeError, SingularError, UnknownNameError, Wheel, WmrkitError, catalog
from wmrkit.kinematics.models import (
    assignable_sets,
    direct_model,
    generically_assignable_sets,
    inverse_model,
    is_assignable,
    kinematic_model,
    mobility,
)

HALF_PI = math.pi / 2
BATCHES = [(), (1,), (5,), (2, 3)]


def diff_drive(b: float = 0.2, r: float = 0.05) -> Robot:
    """Axles along +y (beta = 90 deg): a positive spin drives the robot forward."""
    return Robot("diff", (
        Wheel("left", "fixed", b, HALF_PI, HALF_PI, r, sensed=("spin",)),
        Wheel("right", "fixed", b, -HALF_PI, HALF_PI, r, sensed=("spin",)),
        Wheel("caster", "castor", 0.3, math.pi, 0.0, 0.03, d=0.04),
    ))


def bicycle(l: float = 1.0) -> Robot:
    return Robot("bike", (Wheel("front", "steerable", l / 2, 0.0, HALF_PI + 0.3, 0.3, sensed=("spin", "steer")),
                          Wheel("rear", "steerable", l / 2, math.pi, HALF_PI - 0.2, 0.3)))


def test_diff_drive_direct_model_is_the_closed_form():
    """v = r (phi_l + phi_r) / 2, omega = r (phi_r - phi_l) / (2 b): from rolling at (0, +-b), independent."""
    b, r = 0.2, 0.05
    model = kinematic_model(diff_drive(b, r), ["left.spin", "right.spin"])
    phi = np.random.default_rng(0).normal(size=(7, 2))
    twist = model.velocities(phi)[:, :3]
    expected = np.stack([r * phi.sum(1) / 2, 0 * phi[:, 0], r * (phi[:, 1] - phi[:, 0]) / (2 * b)], -1)
    np.testing.assert_allclose(twist, expected, atol=1e-12)
    assert model.kind == "direct" and model.assigned == ("left.spin", "right.spin")
    assert direct_model(diff_drive()).assigned == ("left.spin", "right.spin")  # the sensed rates


def test_diff_drive_inverse_model_is_the_closed_form():
    b, r = 0.2, 0.05
    model = inverse_model(diff_drive(b, r))
    assert model.assigned == ("vx", "omega") and model.kind == "inverse"
    rates = model.velocities([1.0, 0.5])
    assert rates[1] == pytest.approx(0.0, abs=1e-12)  # vy
    np.testing.assert_allclose(rates[3:5], [(1 - 0.5 * b) / r, (1 + 0.5 * b) / r])  # [18, 22] rad/s


@pytest.mark.parametrize(("wheels", "m"), [
    ([("castor", 0.4, a, dict(d=0.05)) for a in (0, 2.1, 4.2)], 3),  # three castors
    ([("swedish", 0.4, a, dict(gamma=math.pi / 4, r_r=0.01)) for a in (0.7, 2.4, 3.9, 5.5)], 3),
    ([("fixed", 0.4, a, {}) for a in (0.1, 2.0, 4.0)], 0),  # non-concurrent axles
    ([("fixed", 0.3, 0.0, {}), ("castor", 0.4, 2.0, dict(d=0.05)), ("castor", 0.4, 4.0, dict(d=0.05))], 2),
    ([("steerable", 0.5, 0.0, {}), ("steerable", 0.5, math.pi, {})], 1),
])
def test_mobility_oracles_of_part_d(wheels, m):
    rng = np.random.default_rng(1)
    robot = Robot("r", tuple(Wheel(f"w{i}", t, l, a, rng.uniform(-3, 3), 0.05, **extra)
                             for i, (t, l, a, extra) in enumerate(wheels)))
    assert int(mobility(robot)) == m
    assert all(len(s) == m for s in assignable_sets(robot))


@pytest.mark.parametrize("name", ["agv-drive-unit", "diff-drive", "forklift", "thesis-omni-castor", "mecanum-4",
                                  "thesis-two-steer-castor"])
def test_vehicle_dof_is_the_rank_of_the_twist_rows_of_a_null_space_basis(name):
    """Independent: scipy's null space B of A (4.2), rank of its (vx, vy, omega) rows; and at generic steering the
    classification's m (5.13). The drive unit turns on the spot under a still body: m = 2, one of them the body's."""
    from scipy.linalg import null_space

    from wmrkit import catalog
    from wmrkit.analysis import classify
    from wmrkit.kinematics.linalg import nondimensional
    from wmrkit.kinematics.trees import vehicle_dof

    robot = catalog.load(name)
    beta = np.random.default_rng(4).uniform(-3, 3, size=(5, len(robot.steer_names)))
    for b in beta:
        basis = null_space(nondimensional(robot).constraint_matrix(b))
        assert int(vehicle_dof(robot, b)) == np.linalg.matrix_rank(basis[:3], tol=1e-9)
    assert int(vehicle_dof(robot, beta).max()) == classify(robot).mobility
    if name == "agv-drive-unit":
        assert int(mobility(robot)) == 2 and int(vehicle_dof(robot)) == 1


@pytest.mark.parametrize("batch", BATCHES, ids=str)
def test_batch_equals_loop(batch):
    robot = bicycle()
    beta = np.random.default_rng(2).uniform(-1.2, 1.2, size=(*batch, 2)) + HALF_PI
    model = kinematic_model(robot, ["front.spin"], beta)
    assert model.matrix.shape == (*batch, 4, 1) and model.beta.shape == (*batch, 2)
    q = np.random.default_rng(3).normal(size=(*batch, 1))
    out = model.velocities(q)
    assert out.shape == (*batch, 5)
    for idx in np.ndindex(*batch):
        single = kinematic_model(robot, ["front.spin"], beta[idx])
        np.testing.assert_allclose(model.matrix[idx], single.matrix, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(out[idx], single.velocities(q[idx]), rtol=1e-12, atol=1e-14)
    assert mobility(robot, beta).shape == batch and is_assignable(robot, ["vy"], beta).shape == batch


def test_model_is_a_frozen_value_with_read_only_arrays():
    model = kinematic_model(diff_drive(), ["left.spin", "right.spin"])
    with pytest.raises(dataclasses.FrozenInstanceError):
        model.assigned = ("vx",)  # type: ignore[misc]
    with pytest.raises(ValueError, match="read-only"):
        model.matrix[0, 0] = 1.0
    data = model.as_dict()
    assert data["assigned"] == ["left.spin", "right.spin"] and np.shape(data["matrix"]) == (5, 2)


def test_wrong_shapes_name_the_argument():
    model = kinematic_model(diff_drive(), ["left.spin", "right.spin"])
    with pytest.raises(ShapeError, match=r"q_assigned: expected shape \(\.\.\., 2\)"):
        model.solve([1.0, 2.0, 3.0])
    with pytest.raises(ShapeError, match=r"beta: expected shape \(\.\.\., 2\)"):
        kinematic_model(bicycle(), ["front.spin"], [0.1])


def test_errors_name_the_velocity_and_the_set():
    with pytest.raises(UnknownNameError, match=r"no velocity 'left\.spinn'"):
        kinematic_model(diff_drive(), ["left.spinn", "vx"])
    with pytest.raises(WmrkitError, match="repeated"):
        kinematic_model(diff_drive(), ["vx", "vx"])
    with pytest.raises(SingularError, match=r"\(vy, omega\).*not assignable at generic"):
        kinematic_model(diff_drive(), ["vy", "omega"])
    with pytest.raises(SingularError, match=r"exactly m = 2 velocities here, got 1"):
        kinematic_model(diff_drive(), ["vx"])


def test_a_set_lost_at_a_singular_configuration_is_reported_as_such():
    """Bicycle: with both wheels parallel (front beta = rear beta) the ICR is at infinity and omega = 0."""
    robot = bicycle()
    assert ("omega",) in generically_assignable_sets(robot)
    parallel = [[HALF_PI + 0.3, HALF_PI - 0.2], [HALF_PI, HALF_PI]]
    assert is_assignable(robot, ["omega"], parallel).tolist() == [True, False]
    assert ("omega",) not in assignable_sets(robot, parallel)
    with pytest.raises(SingularError, match=r"configuration \[1\] heading \(front=0 deg, rear=0 deg\).*"
                                            r"generic steering angles but not at this singular configuration"):
        kinematic_model(robot, ["omega"], parallel)


@pytest.mark.parametrize("method", ["ranks", "nullspace", "rref"])
def test_mixed_models_of_every_method_solve_the_no_slip_equations(method):
    robot = diff_drive()
    sets = assignable_sets(robot, method=method)
    assert ("vx", "left.spin") in sets and ("vx", "omega") in sets and ("vx", "vy") not in sets
    model = kinematic_model(robot, ["vx", "left.spin"], method=method)
    assert model.kind == "mixed" and model.method == method
    q_dot = model.velocities(np.random.default_rng(4).normal(size=(6, 2)))
    np.testing.assert_allclose(robot.slip_velocity(q_dot), 0, atol=1e-12)


def test_a_robot_that_cannot_move_has_the_empty_model():
    robot = Robot("stuck", tuple(Wheel(f"w{i}", "fixed", 0.4, a, a + 0.3, 0.05) for i, a in enumerate((0.1, 2, 4))))
    assert int(mobility(robot)) == 0 and assignable_sets(robot) == ((),)
    model = kinematic_model(robot, [])
    assert model.matrix.shape == (6, 0)
    np.testing.assert_array_equal(model.velocities(np.zeros(0)), np.zeros(6))


@pytest.mark.parametrize("q", [[np.nan], [np.inf], [1e308], [[1.0], [-2e6]]])
def test_assigned_values_must_be_finite_and_bounded(q):
    """solve and velocities gave NaN for NaN and numbers near overflow (9e306) for 1e308, silently."""
    model = kinematic_model(catalog.load("thesis-tricycle-ch4"), ["o3.spin"])
    for method in (model.solve, model.velocities):
        with pytest.raises(ShapeError, match=r"q_assigned: o3\.spin: expected finite numbers within 1e\+06"):
            method(q)
