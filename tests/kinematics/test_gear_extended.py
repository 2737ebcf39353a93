"""Extended solutions (thesis §4.5) hold a description's gears, as ``fk`` does.

tests/geared.py's cart with a steerable front wheel: its solid axle geared ``1 : ratio`` leaves no motion at a
generic heading (m = 0 with the gear, 1 of the wheels alone), so one velocity can be assigned with the front wheel's
steering (n_o = 1). The checks are independent of the code: the null space of the no-slip matrix (3.22) with the
gear's row ``q_left / 1 - q_right / ratio = 0`` by an SVD in the test.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from geared import STEERED, cart_yaml
from wmrkit import Robot
from wmrkit.kinematics.extended import extended_dof, extended_solution, no_slip_extended_solution


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
