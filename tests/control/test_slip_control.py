"""The inverse slip model (control through the slip models, thesis future work 4): commands whose MQE/MCD motion is
the desired twist, checked against the forward models, a closed form, and the no-slip limit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.control.points import ControlError
from wmrkit.control.slip_control import SlipCommander, output_weights, slip_commands, slip_inverse
from wmrkit.kinematics.wheel_ik import wheel_commands
from wmrkit.slip.models import LinearFriction, mcd, mqe, tyre_friction
from wmrkit.slip.weights import SlipWeights

FORK = catalog.load("forklift")
SKID = catalog.load("skid-steer-4")


def _forward(robot, inverse, commands, model="mqe", friction=None):
    """The forward slip model at the commands, called here on its own (default start)."""
    friction = tyre_friction(robot) if friction is None else friction
    beta = np.asarray(commands.beta) if len(robot.steer_names) else None
    if model == "mqe":
        return mqe(robot, inverse.assigned, commands.rates, friction, beta)
    return mcd(robot, inverse.assigned, commands.rates, friction, beta)


def _ik_rates(robot, inverse, twist, beta=None):
    ik = wheel_commands(robot, twist, beta)
    return np.array([ik.rates[robot.rate_names.index(j)] for j in inverse.assigned]), np.asarray(ik.beta)


def _admissible(robot, v, curvature):
    """The forklift's no-slip twist at speed v and curvature (vy = omega e: the fixed axle 1 m behind the origin)."""
    omega = v * curvature
    return np.array([v, omega * 1.0, omega])


@pytest.mark.parametrize("v, curvature", [(1.0, 0.3), (2.0, -0.25), (-1.0, 0.2)])
@pytest.mark.parametrize("whole", [False, True])
def test_forklift_commands_give_the_desired_motion_through_the_forward_mqe(v, curvature, whole):
    """Default: the controlled point's velocity (the fork tips, the origin: vx, vy) with the differential's equal
    drive torques; `whole`: the whole twist, the drive wheels free (with a differential it is one equation too many)."""
    inv = slip_inverse(FORK, weights=np.eye(3) if whole else None, differential=not whole)
    twist = _admissible(FORK, v, curvature)
    c = slip_commands(inv, twist)
    assert c.converged
    sol = _forward(FORK, inv, c)
    assert bool(sol.converged)
    np.testing.assert_allclose(sol.twist if whole else sol.twist[:2], twist if whole else twist[:2], atol=1e-7)
    np.testing.assert_allclose(output_weights(FORK), [[1, 0, 0], [0, 1, 0]], atol=1e-15)
    drive = sol.forces[[1, 3]]  # longitudinal forces of right_drive, left_drive (same radius)
    if not whole:
        assert drive[0] == pytest.approx(drive[1], abs=1e-6 * np.max(np.abs(sol.forces)))
    else:
        assert abs(drive[0] - drive[1]) > 10.0  # the whole twist makes them fight for the yaw moment
    # not vacuous: the no-slip IK's commands drift under the centripetal load
    rates, beta = _ik_rates(FORK, inv, twist)
    drift = mqe(FORK, inv.assigned, rates, tyre_friction(FORK), beta).twist - twist
    assert np.max(np.abs(drift)) > 2e-3


def test_skid_steer_ik_is_inconsistent_and_the_slip_model_resolves_it():
    inv = slip_inverse(SKID)
    twist = np.array([1.0, 0.0, 0.5])
    rates, _ = _ik_rates(SKID, inv, twist)
    no_slip = mqe(SKID, inv.assigned, rates, tyre_friction(SKID))
    assert bool(no_slip.converged)
    c = slip_commands(inv, twist)
    sol = _forward(SKID, inv, c)
    assert c.converged and bool(sol.converged)
    point = inv.weights  # the controlled point ahead of the centre: its velocity in the robot frame
    np.testing.assert_allclose(point @ sol.twist, point @ twist, atol=1e-7)
    assert np.linalg.norm(point @ (no_slip.twist - twist)) > 0.05
    assert no_slip.twist[2] < 0.8 * twist[2]  # the IK's commands turn much less than asked
    left = [inv.assigned.index(j) for j in ("front_left.spin", "rear_left.spin")]
    right = [inv.assigned.index(j) for j in ("front_right.spin", "rear_right.spin")]
    assert np.mean(c.rates[right] - c.rates[left]) > 1.2 * np.mean(rates[right] - rates[left])  # turns harder


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_skid_steer_under_linear_friction_matches_the_effective_track_closed_form(ratio):
    """MCD with the linear law (7.59), mu_lat / mu_long = ratio, on wheels at (+-a, +-b): force and moment balance
    give vx = r mean(phi_dot) and omega = (v_R - v_L) / (2 b (1 + ratio a^2 / b^2)) (the effective track)."""
    law = LinearFriction.from_weights(SKID, SlipWeights.uniform(ratio, 1.0))
    inv = slip_inverse(SKID, "mcd", friction=law, weights=np.eye(3))  # the whole twist, not only a point's velocity
    twist = np.array([0.8, 0.0, 0.6])
    c = slip_commands(inv, twist)
    assert c.converged
    a = b = 0.25
    r = 0.10
    rates = dict(zip(inv.assigned, c.rates, strict=True))
    v_left = r * (rates["front_left.spin"] + rates["rear_left.spin"]) / 2
    v_right = r * (rates["front_right.spin"] + rates["rear_right.spin"]) / 2
    assert (v_left + v_right) / 2 == pytest.approx(twist[0], abs=1e-8)
    assert (v_right - v_left) / (2 * b * (1 + ratio * a * a / (b * b))) == pytest.approx(twist[2], abs=1e-8)
    # the internal front/rear mode is free: minimum-norm steps from the IK leave it untouched
    assert rates["front_left.spin"] == pytest.approx(rates["rear_left.spin"], abs=1e-6)


@pytest.mark.parametrize("whole", [False, True])
def test_commands_tend_to_the_no_slip_ik_as_the_friction_stiffens(whole):
    """Linear friction k mu: the slip needed for the centripetal force is O(1/k), and so is the correction."""
    twist = _admissible(FORK, 1.5, 0.3)
    rates, beta = _ik_rates(FORK, slip_inverse(FORK), twist)
    sizes = []
    for k in (1e5, 1e6, 1e7):
        law = LinearFriction.from_weights(FORK, SlipWeights.uniform(k, k))
        inv = slip_inverse(FORK, friction=law, weights=np.eye(3) if whole else None, differential=not whole)
        c = slip_commands(inv, twist, tol=1e-12)
        assert c.converged
        u_ik = np.concatenate([rates, beta])
        np.testing.assert_allclose(c.inputs - c.correction, u_ik, atol=1e-12)
        sizes.append(np.linalg.norm(c.correction))
    assert sizes[0] > 1e-4
    assert sizes[1] / sizes[0] == pytest.approx(0.1, rel=0.03)
    assert sizes[2] / sizes[1] == pytest.approx(0.1, rel=0.03)


@settings(max_examples=20, deadline=None)
@given(st.floats(0.3, 2.0), st.floats(-0.35, 0.35))
def test_forklift_inverse_then_forward_is_the_identity(v, curvature):
    inv = slip_inverse(FORK)
    twist = _admissible(FORK, v, curvature)
    c = slip_commands(inv, twist)
    np.testing.assert_allclose(_forward(FORK, inv, c).twist[:2], twist[:2], atol=1e-7)


def test_commander_warm_start_and_standstill():
    cmd = SlipCommander(slip_inverse(SKID))
    still = cmd([0.0, 0.0, 0.0])
    np.testing.assert_array_equal(still.rates, 0.0)
    first = cmd([0.5, 0.0, 0.4])
    second = cmd([0.52, 0.0, 0.41])
    assert first.converged and second.converged and cmd.failures == 0
    assert second.evaluations < first.evaluations  # the previous answer's correction and Jacobian carry over


def test_refusals():
    with pytest.raises(ControlError, match="slip model"):
        slip_inverse(FORK, "magic")
    with pytest.raises(ControlError, match="mass properties"):
        slip_inverse(catalog.load("swerve-4"))
