"""The Lagrange model (thesis §7.2): the tricycle (7.61), conservation laws, the mass matrix, the normal loads."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dynamics_robots import castor_robot, tricycle

from wmrkit import catalog
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, simulate
from wmrkit.dynamics.tyres import Tyre
from wmrkit.errors import WmrkitError

FROZEN = Tyre.of("linear", {"c_lat": 0.0, "c_long": 0.0})  # no friction at all


def _rot(a):
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


@pytest.mark.parametrize("beta3", [0.0, 0.3, -1.1])
def test_tricycle_7_61(beta3):
    """The generated equations equal the thesis's hand-written tricycle model (7.61) for any forces and torques."""
    model = DynamicModel.of(tricycle(beta3))
    rng = np.random.default_rng(1)
    nu = rng.normal(size=model.n)
    f = rng.normal(scale=2000, size=(3, 2))  # (lateral E_x, longitudinal E_y) per wheel
    tau = np.zeros(model.n)
    tau[[3, 4, 6]] = rng.normal(scale=50, size=3)  # tau_r1, tau_r2, tau_s3
    acc = model.accelerations([beta3], nu, tau, f)
    vx, vy, w = nu[:3]
    ax, ay, dw = acc[:3]
    m_t, i_t, l12, l3, l_cm, r, i_s3 = 2500.0, 1500.0, 0.45, 1.35, 0.45, 0.23, 0.8
    c = np.array([0.0, -l_cm])
    a_cm = np.array([ax, ay]) + w * np.array([-vy, vx]) + dw * np.array([-c[1], c[0]]) - w * w * c
    assert np.allclose(m_t * a_cm, f[0] + f[1] + _rot(beta3) @ f[2])
    cb, sb = math.cos(beta3), math.sin(beta3)
    moment = (l3 - l_cm) * (cb * f[2, 0] - sb * f[2, 1]) + l12 * (f[0, 1] - f[1, 1]) - l_cm * (f[0, 0] + f[1, 0])
    assert i_t * dw + i_s3 * acc[6] == pytest.approx(moment)
    assert 1.0 * acc[3] == pytest.approx(tau[3] + r * f[0, 1])
    assert 1.0 * acc[4] == pytest.approx(tau[4] + r * f[1, 1])
    assert 1.5 * acc[5] == pytest.approx(r * f[2, 1])
    assert i_s3 * (acc[6] + dw) == pytest.approx(tau[6])


def test_slip_matrix_is_the_robot_constraint_matrix_7_60():
    model = DynamicModel.of(tricycle(0.4))
    a = model.slip_matrix([0.4])
    r, l12, l3, c, s = 0.23, 0.45, 1.35, math.cos(0.4), math.sin(0.4)
    expected = np.array([[1, 0, 0, 0, 0, 0], [0, 1, l12, r, 0, 0], [1, 0, 0, 0, 0, 0], [0, 1, -l12, 0, r, 0],
                         [c, s, l3 * c, 0, 0, 0], [-s, c, -l3 * s, 0, 0, r]])
    assert np.allclose(a[:, :6], expected) and np.all(a[:, 6] == 0)


def _world_momentum(model, s):
    n = model.n
    beta = s[list(model.steer_columns)]
    p = model.mass_matrix(beta) @ s[n:]
    x, y, th = s[:3]
    px, py = _rot(th) @ p[:2]
    return np.array([px, py, p[2] + x * py - y * px])


def test_no_friction_no_torque_keeps_energy_and_momentum():
    model = DynamicModel.of(castor_robot(), FROZEN)
    rng = np.random.default_rng(3)
    nu0 = rng.normal(size=model.n)
    inputs = Inputs.torques_only(model, [0.0, 1.0], {})
    sim = simulate(model, inputs, 1.5, method="adaptive", rtol=1e-10, record_step=0.05,
                   initial_twist=nu0[:3], allow_lift_off=True)  # no friction: the loads do not act
    # restart from a state with every joint moving (the IK state rolls; here the castor also swings)
    from wmrkit.dynamics._integrate import work_arrays  # noqa: F401 (compiled with the sim above)
    states = np.column_stack([sim.pose, sim.joint_positions, sim.twist, sim.joint_rates])
    energy = [model.kinetic_energy(s[list(model.steer_columns)], s[model.n:]) for s in states]
    assert np.ptp(energy) < 1e-7 * energy[0]
    momentum = np.array([_world_momentum(model, s) for s in states])
    assert np.allclose(momentum, momentum[0], atol=1e-7 * np.abs(momentum[0]).max())
    assert np.ptp(sim.joint_positions[:, model.names.index("caster.steer") - 3]) > 0.01  # the castor did swing


def test_energy_balance_work_of_torques_equals_kinetic_energy_plus_dissipation():
    model = DynamicModel.of(castor_robot({"model": "dugoff", "cs": 3000, "calpha": 2000}))
    inputs = Inputs.torques_only(model, [0.0, 0.5, 1.0, 2.0], {"left.spin": [0.0, 0.3, 0.3, -0.2],
                                                                 "right.spin": [0.0, 0.5, 0.1, 0.2]})
    sim = simulate(model, inputs, 2.0, method="adaptive", rtol=1e-9, record_step=1e-3, initial_twist=[0.5, 0, 0.2])
    states = np.column_stack([sim.pose, sim.joint_positions, sim.twist, sim.joint_rates])
    energy = np.array([model.kinetic_energy(s[list(model.steer_columns)], s[model.n:]) for s in states])
    power_in = np.einsum("nj,nj->n", sim.torques, sim.joint_rates)
    dissipation = sim.friction_power()
    assert np.all(dissipation <= 1e-9)
    work = np.concatenate([[0], np.cumsum(np.diff(sim.t) * (power_in + dissipation)[1:] * 0.5
                                          + np.diff(sim.t) * (power_in + dissipation)[:-1] * 0.5)])
    assert np.allclose(energy - energy[0], work, atol=2e-3 * energy.max())


def test_mass_matrix_is_the_kinetic_energy_of_the_moving_masses():
    """Numeric derivative check of (7.17): T = nu' M nu / 2 against finite differences of the mass points' positions."""
    model = DynamicModel.of(castor_robot())
    robot = model.robot
    rng = np.random.default_rng(7)
    q = np.array([0.3, -0.2, 0.7, 0.9])  # x, y, theta, castor beta
    nu = rng.normal(size=model.n)
    caster = robot.wheel("caster")
    com = np.array(robot.body.com)

    def points(q):
        x, y, th, b = q
        pc = np.array([caster.l * math.cos(caster.alpha) - caster.d * math.sin(b),
                       caster.l * math.sin(caster.alpha) + caster.d * math.cos(b)])
        return np.array([x, y]) + _rot(th) @ com, np.array([x, y]) + _rot(th) @ pc

    i_steer = model.names.index("caster.steer")
    q_dot = np.concatenate([_rot(q[2]) @ nu[:2], [nu[2], nu[i_steer]]])
    h = 1e-6
    (b1, c1), (b0, c0) = points(q + h * q_dot), points(q - h * q_dot)
    vb, vc = (b1 - b0) / (2 * h), (c1 - c0) / (2 * h)
    spins = sum(w.spin_inertia * nu[model.names.index(f"{w.name}.spin")] ** 2 for w in robot.wheels)
    t_numeric = 0.5 * (robot.body.mass * vb @ vb + robot.body.inertia * nu[2] ** 2 + caster.mass * vc @ vc
                       + caster.steer_inertia * (nu[2] + nu[i_steer]) ** 2 + spins)
    assert model.kinetic_energy([q[3]], nu) == pytest.approx(t_numeric, rel=1e-8)
    m = model.mass_matrix([q[3]])
    assert np.allclose(m, m.T) and np.all(np.linalg.eigvalsh(m) > 0)


def test_forklift_static_loads_are_equal_and_sum_to_the_weight():
    """Digest §5.8: with l_CM / l3 = 1/3 the three static loads are 8175 N (g = 9.81)."""
    model = DynamicModel.of(catalog.load("forklift"))
    assert np.allclose(model.normal_loads(), 2500 * 9.81 / 3)
    castor = DynamicModel.of(castor_robot())
    assert castor.normal_loads().sum() == pytest.approx((20 + 1.5) * 9.81)


def test_load_transfer_matches_the_closed_form_of_7_64():
    """Accelerating forward at 1 m/s^2 moves h M a / l3 onto the rear steer wheel (digest §5.8 closed form)."""
    model = DynamicModel.of(tricycle())
    acc = np.zeros(model.n)
    acc[1] = 1.0  # forward in the ch. 7 frame, omega = 0
    loads = model.normal_loads(None, np.zeros(model.n), acc)
    f3 = (0.45 * 2500 * 9.81 + 0.7 * 2500 * 1.0) / 1.35
    assert loads[2] == pytest.approx(f3)
    assert loads[0] == pytest.approx(loads[1]) == pytest.approx(0.5 * (2500 * 9.81 - f3))
    acc[:] = 0
    acc[0] = 2.0  # to the right (x): the right wheel w1 unloads by h M a / (2 l12)
    loads = model.normal_loads(None, np.zeros(model.n), acc)
    assert loads[1] - loads[0] == pytest.approx(0.7 * 2500 * 2.0 / 0.45)


def test_errata_7_64_drive_torque_does_not_shift_static_loads():
    """(7.64) adds tau_r1 + tau_r2 to the pitch balance; in steady motion (no acceleration, no spin acceleration)
    the whole vehicle is in equilibrium and the loads are the static ones whatever the torques."""
    model = DynamicModel.of(tricycle())
    nu = model.velocity([0, 2, 0], [-2 / 0.23] * 3 + [0])
    assert np.allclose(model.normal_loads(None, nu, np.zeros(model.n)), model.normal_loads())
    acc = np.zeros(model.n)
    acc[3] = acc[4] = 10.0  # spin accelerations: their angular momentum rate, along the axle (x)
    loads = model.normal_loads(None, nu, acc)
    assert np.sum(loads * np.array([0.45, 0.45, -0.9])) == pytest.approx(2 * 1.0 * 10.0)


def test_missing_mass_properties_are_one_line_errors():
    with pytest.raises(WmrkitError, match="no mass properties"):
        DynamicModel.of(catalog.load("diff-drive"))
    robot = castor_robot().to_dict()
    del robot["wheels"][2]["inertia"]
    from wmrkit import Robot

    with pytest.raises(WmrkitError, match=r"caster.*inertia.spin"):
        DynamicModel.of(Robot.from_dict(robot))


@pytest.mark.parametrize("com", [[1.0, 0.0], [0.0, 0.0], [-1.0, 1.0]])
def test_a_centre_of_mass_the_wheels_do_not_support_is_refused(com):
    """The forklift's wheels stand at x = -2.35 (steer) and x = -1 (drive), so a centre of mass at the fork tips
    or ahead of them (or far to a side) tips the truck: the model clipped the negative load to 0 and ran with loads
    that summed to 2.5 times the weight (60.9 kN against 24.5 kN, exit 0)."""
    from wmrkit import Robot

    data = catalog.load("forklift").to_dict()
    data["body"]["com"] = com
    with pytest.raises(WmrkitError, match=r"is not supported by its wheels.*tips over"):
        DynamicModel.of(Robot.from_dict(data))
    data["body"]["com"] = [-1.6, 0.1]  # inside: the loads balance the weight
    model = DynamicModel.of(Robot.from_dict(data))
    assert np.all(model.normal_loads() > 0)
    assert model.normal_loads().sum() == pytest.approx(2500 * model.gravity)


@pytest.mark.parametrize("keep", [("left", "right"), ("left",)])
def test_contacts_on_one_line_are_refused(keep):
    """Two wheels on one axle (or one wheel) cannot hold a body up about that line: the least-squares loads of
    (7.64) left the pitch moment unbalanced, and 'simulate' accelerated such a robot at 2 m/s^2 with equal loads
    (exit 0). With the castor it stands."""
    from wmrkit import Robot

    data = castor_robot().to_dict()
    DynamicModel.of(Robot.from_dict(data))
    data["wheels"] = [w for w in data["wheels"] if w["name"] in keep]
    with pytest.raises(WmrkitError, match=rf"contacts of its wheels \({', '.join(keep)}\) lie on one line"):
        DynamicModel.of(Robot.from_dict(data))


def test_the_slip_matrix_stays_batched_while_the_other_methods_take_one_state():
    model = DynamicModel.of(tricycle(0.4))
    beta = np.array([[0.4], [-0.2]])
    batch = model.slip_matrix(beta)
    assert batch.shape == (2, 6, model.n)
    np.testing.assert_array_equal(batch[1], model.slip_matrix(beta[1]))
    with pytest.raises(WmrkitError, match=r"^beta: expected shape \(1,\), one state at a time, got \(2, 1\)"):
        model.mass_matrix(beta)  # a numba TypingError before
