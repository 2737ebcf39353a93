"""Extended solutions (thesis §4.5) hold a description's gears, as ``fk`` does.

tests/geared.py's cart with a steerable front wheel: its solid axle geared ``1 : ratio`` leaves no motion at a
generic heading (m = 0 with the gear, 1 of the wheels alone), so one velocity can be assigned with the front wheel's
steering (n_o = 1). The checks are independent of the code: the null space of the no-slip matrix (3.22) with the
gear's row ``q_left / 1 - q_right / ratio = 0`` by an SVD in the test.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
import yaml

from geared import STEERED, SYNCHRO, B, R, cart_yaml
from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.kinematics.extended import (
    GearWarning,
    extended_dof,
    extended_solution,
    no_slip_extended_solution,
    solve_steering,
)


def load(ratio: float) -> Robot:
    return Robot.from_dict(yaml.safe_load(cart_yaml(ratio, STEERED)))


def null_space(robot: Robot, ratio: float, beta: np.ndarray) -> np.ndarray:
    """An orthonormal basis ``(k, n)`` of the motions the wheels and the gear allow at `beta`."""
    a = robot.constraint_matrix(beta)
    gear = np.zeros(a.shape[1])
    gear[robot.velocity_index("left.spin")], gear[robot.velocity_index("right.spin")] = 1.0, -1.0 / ratio
    m = np.vstack([a, gear])
    _, s, vt = np.linalg.svd(m)
    rank = int(np.sum(s > 1e-10 * s[0]))
    return vt[rank:].T


# the velocity each cart can be asked for: the 1:-1 axle turns on the spot (vx = 0), the 1:1 goes straight
ASK = {1.0: ("vx", 0.4), 2.0: ("vx", 0.3), -1.0: ("omega", 0.5)}


@pytest.mark.parametrize("ratio", list(ASK))
def test_extended_dof_is_the_geared_nullity_plus_the_steered_wheel(ratio):
    robot = load(ratio)
    beta = np.random.default_rng(0).uniform(-np.pi, np.pi, (len(robot.steer_names),))
    assert null_space(robot, ratio, beta).shape[1] == 0  # generic: the gear and the front wheel disagree
    assert extended_dof(robot) == 0 + 1


@pytest.mark.parametrize("ratio", list(ASK))
def test_the_slip_free_extended_solution_is_a_geared_motion(ratio):
    robot = load(ratio)
    name, value = ASK[ratio]
    sol = no_slip_extended_solution(robot, [name], [value], heading=[0.3])
    q = sol.q_dot
    basis = null_space(robot, ratio, sol.beta)
    assert basis.shape[1] == 1  # the steering found makes one motion possible
    np.testing.assert_allclose(basis @ (basis.T @ q), q, atol=1e-9)  # q is in it
    assert q[robot.velocity_index(name)] == pytest.approx(value)
    assert float(sol.slip) < 1e-9
    if ratio == 2.0:  # closed form: omega = vx (k - 1) / (b (k + 1)) = 0.5 rad/s, ICR at y = 0.6 m, front at x = 0.6 m
        assert q[robot.velocity_index("omega")] == pytest.approx(0.5)
        assert robot.heading_of_beta(sol.beta)[0] == pytest.approx(np.pi / 4)


@pytest.mark.parametrize("ratio", list(ASK))
def test_extended_solution_holds_the_gear_at_any_heading(ratio):
    """Off the root the residual is the slip, and the axle still turns in its ratio (the wheels' least squares gave
    each spin its own)."""
    robot = load(ratio)
    name, value = ASK[ratio]
    sol = extended_solution(robot, [name], [value], heading=[[0.3], [-1.0], [2.0]])
    left, right = sol.values(["left.spin", "right.spin"]).T
    np.testing.assert_allclose(right, ratio * left, atol=1e-12)
    np.testing.assert_allclose(sol.slip, np.linalg.norm(np.einsum("...ij,...j->...i", robot.constraint_matrix(
        sol.beta), sol.q_dot), axis=-1), atol=1e-12)


def fk_answer(capsys, tmp_path, rates: dict[str, float]) -> dict:
    """`wmrkit fk cart.yaml --spin ... --json` on the ratio-2 cart: its residual, consistency and warnings."""
    path = tmp_path / "cart.yaml"
    path.write_text(cart_yaml(2.0, STEERED))
    spins = [a for n, v in rates.items() for a in ("--spin", f"{n}={v}")]
    assert main(["fk", str(path), *spins, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_an_assignment_out_of_the_gears_ratio_is_not_claimed_consistent(capsys, tmp_path):
    """Both joints of the 1:2 axle assigned 1, 1 rad/s: the gear wants right = 2 left. fk warns ("do not turn
    together") and says INCONSISTENT while its residual stays the wheels' slip; the extended solution the same
    (before: no warning, no flag, slip 5.5e-17 alone)."""
    robot = load(2.0)
    rates = {"left.spin": 1.0, "right.spin": 1.0}
    fk = fk_answer(capsys, tmp_path, rates)
    assert fk["consistent"] is False and len(fk["warnings"]) == 1
    with pytest.warns(GearWarning) as caught:
        sol = extended_solution(robot, list(rates), list(rates.values()), heading=[0.0])
    assert [str(w.message) for w in caught] == fk["warnings"]  # the same helper, the same words
    assert sol.in_gear.tolist() == [False] and sol.as_dict()["in_gear"] == [False]
    # the slip is the wheels' own, as fk's residual: straight ahead at 0.075 m/s, no wheel slips
    assert float(sol.slip) == pytest.approx(fk["residual"], abs=1e-12)
    np.testing.assert_allclose(sol.values(["vx", "vy", "omega"]), [R, 0.0, 0.0], atol=1e-12)


def test_a_batch_is_judged_row_by_row_and_warns_once_per_gear():
    robot = load(2.0)
    q = [[1.0, 2.0], [1.0, 1.0], [-0.5, -1.0], [1.0, 1.0]]  # in, out, in, out of the 1:2 ratio
    with pytest.warns(GearWarning) as caught:
        sol = extended_solution(robot, ["left.spin", "right.spin"], q, heading=[0.3])
    assert len(caught) == 1
    assert sol.in_gear[:, 0].tolist() == [True, False, True, False]


def test_the_slip_free_search_warns_once_on_a_broken_gear():
    robot = load(2.0)
    with pytest.warns(GearWarning) as caught:
        sol = no_slip_extended_solution(robot, ["left.spin", "right.spin"], [1.0, 1.0], heading=[0.3])
    assert len(caught) == 1 and sol.in_gear.tolist() == [False]
    with pytest.warns(GearWarning):
        solve_steering(robot, ["left.spin", "right.spin"], [1.0, 1.0], heading=[0.3])


def test_rates_in_the_gears_ratio_give_no_warning():
    robot = load(2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GearWarning)
        sol = no_slip_extended_solution(robot, ["left.spin", "right.spin"], [1.0, 2.0], heading=[0.3])
        one = extended_solution(robot, ["vx"], [0.3], heading=[0.3])  # one joint of the gear: nothing to judge
    assert sol.in_gear.tolist() == [True] and one.in_gear.tolist() == [True]
    # ratio 2: omega = vx (k - 1) / (b (k + 1)) with vx = r (1 + 2) / 2
    assert sol.values(["omega"])[0] == pytest.approx(R * 1.5 / (B * 3.0))


def test_extended_dof_counts_steering_joints_not_linkages():
    """The synchro's three steering angles are one linkage, but wmrkit does not model a linkage's geometry
    (description-format.md): extended_dof counts every steering joint, m (gears held, generic steering) + 3, the same
    as without the linkage."""
    text = SYNCHRO
    robot = Robot.from_dict(yaml.safe_load(text))
    unlinked = Robot.from_dict(yaml.safe_load(text.replace("  - {kind: linkage, joints: [a.steer, b.steer, c.steer]}\n",
                                                           "")))
    assert len(unlinked.couplings) == 1 and len(robot.couplings) == 2
    a = robot.constraint_matrix(np.random.default_rng(1).uniform(-np.pi, np.pi, 3))
    spin = [robot.velocity_index(f"{w}.spin") for w in "abc"]
    gear = np.zeros((2, a.shape[1]))  # ratios 1, 1, 1: a.spin = b.spin = c.spin
    gear[[0, 1], spin[0]], gear[0, spin[1]], gear[1, spin[2]] = 1.0, -1.0, -1.0
    held = np.vstack([a, gear])
    nullity = held.shape[1] - np.linalg.matrix_rank(held)
    assert extended_dof(robot) == extended_dof(unlinked) == nullity + 3
