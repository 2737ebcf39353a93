"""Extended solutions (§4.5) on robots other than the tricycle: root finding of (4.83) in general form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmrkit import Robot, ShapeError, SingularError, Wheel
from wmrkit.kinematics.extended import (
    extended_dof,
    extended_solution,
    no_slip_extended_solution,
    solve_steering,
)
from wmrkit.kinematics.models import kinematic_model

HALF_PI = math.pi / 2


def bicycle() -> Robot:
    return Robot("bike", (Wheel("front", "steerable", 0.6, 0.0, HALF_PI, 0.3),
                          Wheel("rear", "steerable", 0.6, math.pi, HALF_PI, 0.3)))


def car_with_castor() -> Robot:
    return Robot("cc", (Wheel("rl", "fixed", 0.3, HALF_PI, HALF_PI, 0.1),
                        Wheel("rr", "fixed", 0.3, -HALF_PI, HALF_PI, 0.1),
                        Wheel("front", "steerable", 1.0, 0.0, HALF_PI, 0.1),
                        Wheel("caster", "castor", 0.8, math.pi, 0.3, 0.05, d=0.05)))


def test_extended_dof_is_m_plus_the_steerable_wheels():
    assert extended_dof(bicycle()) == 1 + 2
    assert extended_dof(car_with_castor()) == 1 + 1
    assert extended_dof(Robot("d", (Wheel("l", "fixed", 0.2, HALF_PI, HALF_PI, 0.05),
                                    Wheel("r", "fixed", 0.2, -HALF_PI, HALF_PI, 0.05)))) == 2


def test_an_assignable_set_has_no_slip_and_matches_the_model():
    robot = car_with_castor()
    q = np.random.default_rng(0).normal(size=(5, 1))
    sol = extended_solution(robot, ["rl.spin"], q)
    np.testing.assert_allclose(sol.slip, 0, atol=1e-12)
    np.testing.assert_allclose(sol.q_dot, kinematic_model(robot, ["rl.spin"]).velocities(q), atol=1e-12)


@pytest.mark.parametrize(("robot", "assigned"), [
    (bicycle(), ("vx", "vy", "omega")),  # a bicycle with both wheels steered reaches any twist
    (bicycle(), ("front.spin", "rear.spin", "omega")),
    (car_with_castor(), ("rl.spin", "rr.spin")),  # differential drive, the front wheel follows
    (car_with_castor(), ("vx", "omega")),
])
def test_roots_found_near_a_true_configuration_are_slip_free(robot, assigned):
    rng = np.random.default_rng(1)
    n = 12
    true_beta = robot.beta + rng.uniform(-0.6, 0.6, size=(n, len(robot.steer_names)))
    true_beta[:, [i for i, s in enumerate(robot.steer_names) if robot.wheel(s).type != "steerable"]] = 0.3
    model = kinematic_model(robot, [robot.rate_names[0]], true_beta)
    q_dot = model.velocities(rng.uniform(0.5, 2.0, size=(n, 1)))  # feasible motions at the true angles
    q_assigned = q_dot[:, [robot.velocity_index(a) for a in assigned]]
    guess = true_beta + rng.uniform(-0.1, 0.1, size=true_beta.shape) * [robot.wheel(s).type == "steerable"
                                                                        for s in robot.steer_names]
    sol = no_slip_extended_solution(robot, assigned, q_assigned, guess)
    assert sol.beta.shape == (n, len(robot.steer_names))
    np.testing.assert_allclose(sol.slip, 0, atol=1e-9)
    np.testing.assert_allclose(sol.values(assigned), q_assigned)
    np.testing.assert_allclose(robot.slip_velocity(sol.q_dot, sol.beta), 0, atol=1e-9)
    np.testing.assert_allclose(np.cos(sol.beta - true_beta), 1, atol=1e-9)  # the root closest to the guess


def test_no_root_raises_with_the_configuration():
    with pytest.raises(SingularError, match=r"no steering angles make \(rl\.spin, rr\.spin, vy\)"):
        solve_steering(car_with_castor(), ["rl.spin", "rr.spin", "vy"], [1.0, 1.0, 0.5])


def test_without_steerable_wheels_the_guess_is_returned():
    robot = Robot("d", (Wheel("l", "fixed", 0.2, HALF_PI, HALF_PI, 0.05),
                        Wheel("c", "castor", 0.3, math.pi, 0.1, 0.03, d=0.04)))
    np.testing.assert_array_equal(solve_steering(robot, ["l.spin"], [[1.0], [2.0]], [0.7]), [[0.7], [0.7]])


def test_shapes_are_checked():
    with pytest.raises(ShapeError, match=r"q_assigned: expected shape \(\.\.\., 2\)"):
        extended_solution(bicycle(), ["vx", "vy"], [1.0])


@pytest.mark.parametrize("q", [[np.nan, 1.0], [1.0, np.inf], [1e300, -1e300], [2e6, 0.0]])
def test_assigned_values_must_be_finite_and_bounded(q):
    """NaN gave a NaN slip, 1e300 an infinite one, and solve_steering returned the guess as a 'root' of 1e300."""
    robot = car_with_castor()
    with pytest.raises(ShapeError, match=r"q_assigned: (rl|rr)\.spin: expected finite numbers within 1e\+06"):
        extended_solution(robot, ["rl.spin", "rr.spin"], q)
    with pytest.raises(ShapeError, match=r"q_assigned: (rl|rr)\.spin: expected finite numbers within 1e\+06"):
        solve_steering(robot, ["rl.spin", "rr.spin"], q)


def test_starts_iterations_and_names_are_checked():
    with pytest.raises(ShapeError, match="starts >= 1 and iterations >= 0"):
        solve_steering(bicycle(), ["vx", "vy", "omega"], [1.0, 0.0, 0.0], starts=0)
    with pytest.raises(ShapeError, match="starts >= 1 and iterations >= 0"):
        solve_steering(bicycle(), ["vx", "vy", "omega"], [1.0, 0.0, 0.0], iterations=-1)
    with pytest.raises(ShapeError, match="at least one velocity name"):  # was numpy's 'cannot reshape' ValueError
        solve_steering(bicycle(), [], np.zeros(0))


def test_the_grid_of_starts_is_bounded(monkeypatch):
    """8 starts on 6 steered wheels are 262,144 starts per problem (minutes and gigabytes where no root exists):
    at most MAX_STARTS, a seeded sample of the grid, and the problems in chunks."""
    from wmrkit.kinematics import extended

    robot = Robot("six", tuple(Wheel(f"w{i}", "steerable", 0.5, i * math.pi / 3, HALF_PI, 0.05) for i in range(6)))
    monkeypatch.setattr(extended, "MAX_STARTS", 16, raising=False)
    lm, sizes = extended._levenberg_marquardt, []

    def counted(f, x, iterations, tol):
        sizes.append(x.shape[0] * x.shape[1])
        assert sizes[-1] <= 4 * 16, "too many starts at once"
        return lm(f, x, 5, tol)

    monkeypatch.setattr(extended, "_levenberg_marquardt", counted)
    with pytest.raises(SingularError, match="no steering angles make"):  # the spin contradicts the twist
        solve_steering(robot, ["vx", "vy", "omega", "w0.spin"], [[1.0, 0.0, 0.0, 100.0]] * 5)
    assert sizes[0] == 5 and len(sizes) == 1 + 2  # the guesses, then 5 problems x 16 starts in chunks of 4
