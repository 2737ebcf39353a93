"""The actuated inverse (4.26) and the sensed direct solution (4.32) are refused where they are one of many: the
pseudo-inverse of ``partitioned_solution`` returned its minimum-norm choice silently. Checked against the null space
of the no-slip matrix (3.22), computed here by SVD."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from wmrkit import SingularError, catalog
from wmrkit.cli.main import main
from wmrkit.kinematics.actuation import actuated_inverse_matrix, actuation_analysis, actuation_equation, split_jacobian
from wmrkit.kinematics.sensing import sensed_direct_matrix, sensed_full_matrix, sensing_analysis, sensing_equation
from wmrkit.kinematics.trees import jacobian_names, reduced_equation, select_columns


def _null_space(a: np.ndarray) -> np.ndarray:
    """Orthonormal basis ``(k, n)`` of the motions that roll without slip, by SVD."""
    _, s, vh = np.linalg.svd(a)
    return vh[int(np.sum(s > 1e-9 * s[0])):].T


def _tricycle_icr_at_f1():
    """thesis-tricycle-ch4 with its steered axle through the rear wheel f1: it turns about f1, whose spin is then 0."""
    robot = catalog.load("thesis-tricycle-ch4")
    d = np.subtract(robot.wheel("f1").position, robot.wheel("o3").position)
    return robot, float(np.arctan2(d[1], d[0]))


def test_one_rear_encoder_does_not_give_the_twist_where_the_robot_turns_about_that_wheel():
    """Before: sensing_analysis(...).twist([1.0]) returned (0.0075, -0.0438, -0.0219), a minimum-norm pick, while
    the leaf said underdetermined."""
    robot, beta = _tricycle_icr_at_f1()
    names = robot.velocity_names
    null = _null_space(robot.constraint_matrix(np.array([beta])))
    at_rest = null[:, np.abs(null[names.index("f1.spin")]) < 1e-9]  # motions with f1.spin = 0 ...
    assert np.abs(at_rest[:3]).max() > 1e-3  # ... that move the body: the sensed rate does not fix the twist
    sensing = sensing_analysis(robot, np.array([beta]), sensed=["f1.spin"])
    assert not sensing.twist_determined
    for method in (sensing.twist, sensing.direct):
        with pytest.raises(SingularError, match=r"the sensed rates \(f1\.spin\) do not determine the twist"):
            method([1.0])
    assert sensing.as_dict()["direct_matrix"] is None and sensing.as_dict()["twist_determined"] is False


def test_one_rear_encoder_gives_the_twist_elsewhere():
    """0.3 rad away the twist for f1.spin = 1 rad/s is the no-slip motion (3.22) with that spin (one-dimensional)."""
    robot, beta = _tricycle_icr_at_f1()
    beta = np.array([beta + 0.3])
    null = _null_space(robot.constraint_matrix(beta))
    assert null.shape[1] == 1
    expected = null[:3, 0] / null[robot.velocity_names.index("f1.spin"), 0]
    sensing = sensing_analysis(robot, beta, sensed=["f1.spin"])
    assert sensing.twist_determined
    np.testing.assert_allclose(sensing.twist([1.0]), expected, atol=1e-12)


def test_a_drive_unit_s_two_spins_are_not_fixed_by_the_twist():
    """agv-drive-unit: turning the unit on the spot moves its spins with the body at rest (a motion of (3.22)), so
    one twist has many actuated spins. Before, inverse((0.3, 0, 0)) returned (3, 3) (the unit held straight) and
    `wmrkit kinematics agv-drive-unit --json` printed that matrix."""
    robot = catalog.load("agv-drive-unit")
    names = robot.velocity_names
    null = _null_space(robot.constraint_matrix())
    spins = [names.index("unit.spin1"), names.index("unit.spin2")]
    _, s, vh = np.linalg.svd(null[:3])
    body_at_rest = null @ vh[int(np.sum(s > 1e-9 * s[0])):].T  # the motions with the twist 0
    assert np.abs(body_at_rest[spins]).max() > 0.1
    actuation = actuation_analysis(robot)
    assert not actuation.inverse_determined
    with pytest.raises(SingularError, match=r"the twist does not determine the actuated rates \(unit\.spin1, "):
        actuation.inverse([0.3, 0.0, 0.0])


def test_the_json_answer_has_no_matrix_that_is_one_of_many(capsys):
    assert main(["kinematics", "agv-drive-unit", "--json"]) == 0
    actuation = json.loads(capsys.readouterr().out)["actuation"]
    assert actuation["inverse_matrix"] is None and actuation["inverse_determined"] is False


def test_a_determined_inverse_is_the_no_slip_solution():
    """diff-drive: the twist fixes both spins; (4.26) gives the rates of the no-slip motion with that twist."""
    robot = catalog.load("diff-drive")
    actuation = actuation_analysis(robot)
    assert actuation.inverse_determined and actuation.as_dict()["inverse_matrix"] is not None
    null = _null_space(robot.constraint_matrix())
    twist = np.array([0.4, 0.0, -0.7])
    motion = null @ np.linalg.lstsq(null[:3], twist, rcond=None)[0]
    np.testing.assert_allclose(motion[:3], twist, atol=1e-12)  # a feasible twist
    spins = [robot.velocity_names.index(n) for n in actuation.actuated]
    np.testing.assert_allclose(actuation.inverse(twist), motion[spins], atol=1e-12)



def _residual(robot, i_sel: np.ndarray, j_sel: np.ndarray, selected: list[str]) -> float:
    """Largest violation of ``I_sel twist = J_sel q_sel`` over the no-slip motions (3.22) of `robot` (by SVD)."""
    null = _null_space(robot.constraint_matrix())
    rows = [robot.velocity_names.index(n) for n in selected]
    return float(np.abs(i_sel @ null[:3] - j_sel @ null[rows]).max())


@pytest.mark.parametrize(("equation", "role"), [(actuation_equation, "actuated"), (sensing_equation, "sensed")])
def test_the_reduced_equation_is_refused_where_the_split_leaves_the_other_rates_free(equation, role):
    """agv-drive-unit with its two spins selected: the unit's steering turns with the spins, so (4.26)'s substitution
    of it is one of many. Before, actuation_equation and sensing_equation returned the pseudo-inverse's I_u, which
    the motions of the no-slip equations (3.22) break by 0.04 (a real equation holds to round-off)."""
    robot, spins = catalog.load("agv-drive-unit"), ["unit.spin1", "unit.spin2"]
    columns, _ = select_columns(robot, spins, role)
    i_bar, j_sel, j_rest = split_jacobian(robot, columns)
    assert _residual(robot, reduced_equation(i_bar, j_sel, j_rest), j_sel, spins) > 0.01  # the pick breaks (3.22)
    with pytest.raises(SingularError, match=rf"robot 'agv-drive-unit': the {role} rates \(unit\.spin1, unit\.spin2\)"
                                            r" and the twist do not determine the other joints' rates"):
        equation(robot, spins)


@pytest.mark.parametrize("name", catalog.names())
def test_a_reduced_equation_is_returned_exactly_where_it_holds_on_every_no_slip_motion(name):
    """Every catalog robot and selection of up to two rates: actuation_equation returns (4.28) where it holds on the
    no-slip motions (3.22), and refuses it where the pseudo-inverse's pick breaks them (the agv's unit spins; its
    rear spins, or nothing selected, are returned although the unit's J is rank deficient, 4.69)."""
    robot = catalog.load(name)
    rates = [n for n in robot.rate_names if not n.endswith(".roller")]
    for selected in [[], *([n] for n in rates), *(list(p) for p in itertools.combinations(rates, 2))]:
        columns, _ = select_columns(robot, selected, "actuated")
        i_bar, j_sel, j_rest = split_jacobian(robot, columns)
        holds = _residual(robot, reduced_equation(i_bar, j_sel, j_rest), j_sel, selected) < 1e-12
        assert holds or _residual(robot, reduced_equation(i_bar, j_sel, j_rest), j_sel, selected) > 1e-3, selected
        if holds:
            i_sel, _ = actuation_equation(robot, selected)
            np.testing.assert_array_equal(i_sel, reduced_equation(i_bar, j_sel, j_rest))
        else:
            with pytest.raises(SingularError, match="do not determine the other joints' rates"):
                actuation_equation(robot, selected)


def _kernel(a: np.ndarray) -> np.ndarray:
    """Orthonormal basis ``(n, k)`` of the null space of `a` ``(r, n)`` by SVD (every direction when ``r = 0``)."""
    if a.shape[0] == 0:
        return np.eye(a.shape[1])
    _, s, vh = np.linalg.svd(a)
    return vh[int(np.sum(s > 1e-9 * max(s[0], 1.0))):].T


def _selections(robot) -> list[list[str]]:
    rates = [n for n in robot.rate_names if not n.endswith(".roller")]
    return [[], *([n] for n in rates), *(list(p) for p in itertools.combinations(rates, 2))]


def test_the_actuated_inverse_matrix_of_a_drive_unit_s_spins_is_refused():
    """Before: actuated_inverse_matrix(agv-drive-unit) returned [[10, 0, 0], [10, 0, 0]], the pseudo-inverse's pick
    (the unit held straight) while its spins also turn it on the spot (4.69), as ActuationAnalysis.inverse refuses."""
    with pytest.raises(SingularError, match=r"robot 'agv-drive-unit': the twist does not determine the actuated "
                                            r"rates \(unit\.spin1, unit\.spin2\)"):
        actuated_inverse_matrix(catalog.load("agv-drive-unit"))


def test_the_sensed_direct_matrix_of_one_rear_encoder_is_refused_where_the_robot_turns_about_it():
    """Before: sensed_direct_matrix returned the minimum-norm twist per f1.spin, (0.0075, -0.0438, -0.0219), as
    SensingAnalysis.twist refuses; diff-drive with one spin sensed the same."""
    robot, beta = _tricycle_icr_at_f1()
    with pytest.raises(SingularError, match=r"the sensed rates \(f1\.spin\) do not determine the twist"):
        sensed_direct_matrix(robot, ["f1.spin"], np.array([beta]))
    with pytest.raises(SingularError, match=r"robot 'diff-drive': the sensed rates \(left\.spin\) do not determine"):
        sensed_direct_matrix(catalog.load("diff-drive"), ["left.spin"])


@pytest.mark.parametrize("name", catalog.names())
def test_the_matrices_4_26_and_4_32_are_returned_exactly_where_they_are_the_no_slip_solution(name):
    """Every catalog robot and selection of up to two rates, against the no-slip motions (3.22) by SVD: (4.26) is
    returned where no motion with the body at rest moves a selected rate, and then gives a motion's selected rates
    from its twist; (4.32) where no motion with the selected rates at rest moves the body, and then gives the twist."""
    robot = catalog.load(name)
    null = _null_space(robot.constraint_matrix())
    motion = null @ np.random.default_rng(7).normal(size=null.shape[1])  # a generic no-slip motion
    for selected in _selections(robot):
        rows = [robot.velocity_names.index(n) for n in selected]
        moved = np.abs((null @ _kernel(null[:3]))[rows])  # selected rates of the motions with the body at rest
        assert moved.size == 0 or moved.max() < 1e-9 or moved.max() > 1e-3, selected
        if moved.size == 0 or moved.max() < 1e-9:
            np.testing.assert_allclose(actuated_inverse_matrix(robot, selected) @ motion[:3], motion[rows], atol=1e-9)
        else:
            with pytest.raises(SingularError, match="the twist does not determine the actuated rates"):
                actuated_inverse_matrix(robot, selected)
        body = np.abs((null @ _kernel(null[rows]))[:3])  # twists of the motions with the selected rates at rest
        assert body.size == 0 or body.max() < 1e-9 or body.max() > 1e-3, selected
        if body.size == 0 or body.max() < 1e-9:
            np.testing.assert_allclose(sensed_direct_matrix(robot, selected) @ motion[rows], motion[:3], atol=1e-9)
        else:
            with pytest.raises(SingularError, match="do not determine the twist"):
                sensed_direct_matrix(robot, selected)


def test_the_full_sensed_solution_of_a_drive_unit_s_rear_encoders_is_refused():
    """agv-drive-unit sensing its rear spins: they fix the twist, but the unit turns on the spot with them at rest
    (a motion of (3.22) by SVD), so its steering and spin rates are not fixed. Before, sensed_full_matrix returned
    the pinv pick (driving straight at 1 rad/s: unit.steer 0, unit spins 1 and 1)."""
    robot, rear = catalog.load("agv-drive-unit"), ["rear_left.spin", "rear_right.spin"]
    null = _null_space(robot.constraint_matrix())
    at_rest = null @ _kernel(null[[robot.velocity_names.index(n) for n in rear]])
    assert at_rest.shape[1] == 1 and np.abs(at_rest[:3]).max() < 1e-9  # the twist is fixed ...
    assert np.abs(at_rest[robot.velocity_names.index("unit.steer")]).max() > 0.1  # ... the unit's steering is not
    with pytest.raises(SingularError, match=r"the sensed rates \(rear_left\.spin, rear_right\.spin\) fix the twist "
                                            r"but not the unsensed rates"):
        sensed_full_matrix(robot, rear)
    r = robot.wheel("rear_left").r  # both rear wheels roll at 1 rad/s: straight ahead at r m/s
    np.testing.assert_allclose(sensing_analysis(robot, sensed=rear).direct([1.0, 1.0])[0], [r, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("name", catalog.names())
def test_the_full_sensed_solution_4_31_is_returned_exactly_where_the_sensed_rates_fix_every_velocity(name):
    """Every catalog robot and selection of up to two rates: (4.31) is returned where no no-slip motion (3.22, by
    SVD) keeps the sensed rates at rest, and then gives a generic motion's twist and unsensed rates; refused
    elsewhere."""
    robot = catalog.load(name)
    null = _null_space(robot.constraint_matrix())
    motion = null @ np.random.default_rng(8).normal(size=null.shape[1])
    for selected in _selections(robot):
        rows = [robot.velocity_names.index(n) for n in selected]
        free = null @ _kernel(null[rows])  # the motions with the sensed rates at rest
        if free.shape[1] == 0:
            full = sensed_full_matrix(robot, selected) @ motion[rows]
            unknowns = [n for n in jacobian_names(robot) if n not in selected]
            expected = [motion[robot.velocity_names.index(n)] if n in robot.velocity_names else motion[2]
                        for n in unknowns]  # omega@wheel: the body's omega
            np.testing.assert_allclose(full, [*motion[:3], *expected], atol=1e-9)
        else:
            with pytest.raises(SingularError, match=r"do not determine the twist|but not the unsensed rates"):
                sensed_full_matrix(robot, selected)
