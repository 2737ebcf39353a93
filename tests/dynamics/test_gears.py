"""A ``gear`` coupling held by the dynamics: one generalised coordinate per gear (``q_j = ratio_j u``), torques on
any of its joints acting on the whole chain, inertias reflected through the ratios. Checked against closed forms,
the gear's ratios and conservation laws, never against the simulator's own output."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dynamics_robots import castor_robot, frictionless_coast, least_energy_inertia

from wmrkit import catalog
from wmrkit.couplings import Coupling
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import twist_program
from wmrkit.dynamics.simulate import Inputs, Stepper, initial_state, simulate
from wmrkit.dynamics.tyres import Tyre
from wmrkit.errors import WmrkitError

FROZEN = Tyre.of("linear", {"c_lat": 0.0, "c_long": 0.0})  # no friction at all
SPINS = ("left.spin", "right.spin")


def _geared(robot, joints, ratios=None):
    ratios = ratios or (1.0,) * len(joints)
    return dataclasses.replace(robot, couplings=(*robot.couplings, Coupling("gear", joints, ratios)))


def _rates(sim, joints):
    return sim.joint_rates[:, [sim.joint_names.index(j) for j in joints]]


@pytest.mark.parametrize("method", ["semi-implicit", "rk4"])
def test_a_torque_on_one_joint_turns_the_whole_gear_with_its_reflected_inertia(method):
    """Frictionless: a torque tau on the left spin of a gear (left = u, right = 2 u) gives u'' = tau / (I (1 + 4)),
    the right wheel at twice the left's rate at every step. Before, the left wheel spun alone at tau t / I."""
    robot = _geared(castor_robot(), SPINS, (1.0, 2.0))
    model = DynamicModel.of(robot, FROZEN)
    tau, inertia = 0.3, 0.004
    sim = simulate(model, Inputs.torques_only(model, [0.0], {"left.spin": tau}), 0.5, step=1e-3, method=method,
                   allow_lift_off=True)
    rates = _rates(sim, SPINS)
    u = tau * sim.t / (inertia * (1 + 2 ** 2))
    np.testing.assert_allclose(rates[:, 0], u, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(rates[:, 1], 2 * u, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sim.twist, 0.0, atol=1e-12)  # frictionless: the body feels nothing


def test_opposite_torques_on_a_solid_axle_cancel_so_it_cannot_turn_on_the_spot():
    """A solid axle (both spins on a 1:1 gear) takes +tau and -tau as no torque at all: from rest nothing moves.
    Before, the wheels turned apart and the robot spun on the spot."""
    model = DynamicModel.of(_geared(castor_robot(), SPINS))
    sim = simulate(model, Inputs.torques_only(model, [0.0], {"left.spin": 0.5, "right.spin": -0.5}), 1.0)
    assert np.abs(sim.joint_rates).max() == 0.0 and np.abs(sim.twist).max() == 0.0
    assert np.abs(sim.pose).max() == 0.0


def test_a_chain_driven_skid_steer_turns_each_side_together():
    """Each side's wheels on a chain: torques on the front wheels alone (turning on the spot, tyres slipping) turn
    the rear wheels at exactly their front wheel's rate, at every step; it still turns (by skidding)."""
    sides = (("front_left.spin", "rear_left.spin"), ("front_right.spin", "rear_right.spin"))
    robot = catalog.load("skid-steer-4")
    robot = dataclasses.replace(robot, couplings=tuple(Coupling("gear", s, (1.0, 1.0)) for s in sides))
    model = DynamicModel.of(robot)
    sim = simulate(model, Inputs.torques_only(model, [0.0], {"front_left.spin": -40.0, "front_right.spin": 40.0}),
                   1.0)
    for side in sides:
        rates = _rates(sim, side)
        np.testing.assert_allclose(rates[:, 1], rates[:, 0], rtol=1e-12, atol=1e-12)
        positions = sim.joint_positions[:, [sim.joint_names.index(j) for j in side]]
        np.testing.assert_allclose(positions[:, 1], positions[:, 0], rtol=1e-12, atol=1e-12)
    assert sim.twist[-1, 2] > 0.05  # it turns counter-clockwise, the left side backwards


def test_a_gear_conserves_energy_without_friction():
    """Frictionless, no torque, a heavy castor swinging (a configuration-dependent mass matrix): the kinetic energy
    stays constant and the gear's joints in ratio (the constraint does no work)."""
    model = DynamicModel.of(_geared(castor_robot(), SPINS, (1.0, -3.0)), FROZEN)
    s0 = initial_state(model)
    n = model.n
    s0[n:n + 3] = (0.4, -0.2, 0.9)
    s0[n + model.names.index("left.spin")] = 2.0
    s0[n + model.names.index("right.spin")] = -6.0
    s0[n + model.names.index("caster.steer")] = 1.5
    steer = list(model.steer_columns)
    e0 = model.kinetic_energy(s0[steer], s0[n:])
    for s, energy in frictionless_coast(model, s0):
        assert energy == pytest.approx(e0, rel=1e-9)
        left, right = s[n + model.names.index("left.spin")], s[n + model.names.index("right.spin")]
        assert right == pytest.approx(-3.0 * left, rel=1e-12)


def test_accelerations_hold_the_gear():
    """model.accelerations: the geared rates' accelerations are in ratio, and the constraint force (the difference
    from the ungeared accelerations, times M) is orthogonal to every motion the gear allows (it does no work)."""
    robot = _geared(castor_robot(), SPINS, (1.0, 2.0))
    model, free = DynamicModel.of(robot), DynamicModel.of(dataclasses.replace(robot, couplings=()))
    rng = np.random.default_rng(3)
    beta = [0.7]
    nu = rng.normal(size=model.n)
    nu[model.names.index("right.spin")] = 2 * nu[model.names.index("left.spin")]
    tau = rng.normal(size=model.n)
    f = rng.normal(scale=20, size=(len(model.contacts), 2))
    acc, acc_free = model.accelerations(beta, nu, tau, f), free.accelerations(beta, nu, tau, f)
    i, j = model.names.index("left.spin"), model.names.index("right.spin")
    assert acc[j] == pytest.approx(2 * acc[i], rel=1e-12)
    reaction = model.mass_matrix(beta) @ (acc - acc_free)
    allowed = np.eye(model.n)
    allowed[j, i] = 2.0
    allowed = np.delete(allowed, j, axis=1)
    np.testing.assert_allclose(allowed.T @ reaction, 0.0, atol=1e-9)


def test_the_start_is_in_gear_and_a_state_out_of_gear_is_refused():
    """initial_state at a twist the solid axle forbids keeps the twist and turns the axle at its least-squares
    rate (the mean); a Stepper given rates out of the gear's ratios refuses them, naming the coupling."""
    model = DynamicModel.of(_geared(castor_robot(), SPINS))
    s = initial_state(model, (0.5, 0.0, 1.0))
    n = model.n
    i, j = model.names.index("left.spin"), model.names.index("right.spin")
    assert s[n:n + 3].tolist() == [0.5, 0.0, 1.0]
    assert s[n + i] == pytest.approx(0.5 / 0.08) and s[n + j] == pytest.approx(0.5 / 0.08)
    s[n + i] += 1.0
    with pytest.raises(WmrkitError, match=r"the gear of wheels 'left' and 'right'"):
        Stepper(model, s)


def test_twist_program_refuses_a_twist_the_gear_forbids_unless_allowed_to_slip():
    """A solid axle turning about its middle rolls without side slip but turns its wheels apart: no motion of the
    robot; allow_slip lets the servos fight through the gear."""
    model = DynamicModel.of(_geared(castor_robot(), SPINS))
    with pytest.raises(WmrkitError, match=r"the gear of wheels 'left' and 'right' out of its ratios \(1, 1\)"):
        twist_program(model, [0.0], [(0.5, 0.0, 1.0)])
    inputs = twist_program(model, [0.0], [(0.5, 0.0, 1.0)], allow_slip=True)
    sim = simulate(model, inputs, 1.0, initial_twist=(0.5, 0.0, 0.0))  # rolling: no step at the grip
    rates = _rates(sim, SPINS)
    np.testing.assert_allclose(rates[:, 1], rates[:, 0], rtol=1e-12, atol=1e-12)
    twist_program(model, [0.0], [(0.5, 0.0, 0.0)])  # straight: the axle turns as one


def test_a_gear_named_by_its_joints_reads_as_the_gear_s_joints(tmp_path, capsys):
    """A double wheel's two spins geared 1:1 cannot turn the unit, which a turn on the spot needs (its pivot at
    x = 0.3 m keeps heading 90 deg in the body as the body turns): refused by twist_program, `simulate
    --initial-twist`, and a state with the spins apart by the Stepper, naming 'the gear's joints' (they said 'the
    joints of the gear of joints ...')."""
    from dynamics_robots import double_unit_robot

    from wmrkit.cli.main import main

    robot = _geared(double_unit_robot(), ("drive.spin1", "drive.spin2"))
    robot.to_file(tmp_path / "unit.yaml")
    assert main(["simulate", str(tmp_path / "unit.yaml"), "--path", "straight", "--initial-twist", "0", "0", "1"]) == 2
    assert capsys.readouterr().err == ("wmrkit: error: --initial-twist 0 0 1: it turns the gear's joints 'drive.spin1' "
                                       "and 'drive.spin2' out of its ratios (1, 1), which the gear holds together, and "
                                       "the simulation starts rolling without slip (wmrkit ik says which twists the "
                                       "gear allows)\n")
    model = DynamicModel.of(robot)
    with pytest.raises(WmrkitError, match=r"it would turn the gear's joints 'drive.spin1' and 'drive.spin2' out of "
                                          r"its ratios \(1, 1\), which the gear holds together"):
        twist_program(model, [0.0], [(0.0, 0.0, 1.0)])
    s = initial_state(model)
    s[model.n + model.names.index("drive.spin1")] = 1.0
    with pytest.raises(WmrkitError, match=r"^state: the gear's joints 'drive.spin1' and 'drive.spin2' \(ratios 1, "
                                          r"1\) do not turn together \(drive.spin1 1, drive.spin2 0 rad/s"):
        Stepper(model, s)


@pytest.mark.parametrize("ratios", [(1.0, 1.0), (1.0, 2.0)])
def test_steering_inertia_turns_the_joints_geared_to_the_steering(ratios):
    """A double wheel whose two spins are geared (ratios 1:1 or 1:2) cannot counter-rotate them to turn under the
    body: the least-energy rolling motion at unit steering rate moves the body. Checked against the KKT solution
    of that least-energy problem (rolling, the gear's row ``q_1 / k_1 - q_2 / k_2 = 0``), whose kinetic energy gives
    the inertia; holding one spin holds the gear. Before, the gear was ignored: 0.061 kg m^2 (the unit turning
    under the body with its spins apart) instead of 6.80 (1:1: the body turns about the pivot) and 1.44 (1:2)."""
    from dynamics_robots import double_unit_robot

    robot = _geared(double_unit_robot(), ("drive.spin1", "drive.spin2"), ratios)
    model = DynamicModel.of(robot)
    i, j = model.names.index("drive.spin1"), model.names.index("drive.spin2")
    c = model.names.index("drive.steer")
    gear = np.zeros(model.n)
    gear[i], gear[j] = 1 / ratios[0], -1 / ratios[1]
    a = model.slip_matrix()
    expected, nu = least_energy_inertia(model, np.vstack([a, gear]), c)
    assert np.abs(a @ nu).max() < 1e-9 and nu[j] == pytest.approx(ratios[1] / ratios[0] * nu[i], rel=1e-9)
    assert expected > 10 * robot.wheel("drive").steer_inertia  # the body turns with the unit
    assert model.steering_inertia()[0] == pytest.approx(expected, rel=1e-9)
    held, _ = least_energy_inertia(model, np.vstack([a, gear, np.eye(model.n)[i]]), c)
    assert model.steering_inertia([i])[0] == pytest.approx(held, rel=1e-9)
    assert model.steering_inertia([j])[0] == pytest.approx(held, rel=1e-9)
