"""A ``linkage`` coupling held by the dynamics: ``beta_j = f(beta_i)``, the ideal Ackermann law where fixed wheels
share an axle (their axles meet on it), the wheels turning together without a fixed wheel. Checked against the
Ackermann geometry written here independently, a hand-derived 1-DOF equation of motion, the conservation of energy
and momentum, never against the simulator's own output."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from dynamics_robots import castor_robot, frictionless_coast, least_energy_inertia, linked_car
from scipy.integrate import solve_ivp

from wmrkit import Robot
from wmrkit.couplings import Coupling
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program, twist_program
from wmrkit.dynamics.simulate import Inputs, Stepper, initial_state, simulate
from wmrkit.dynamics.tyres import Tyre
from wmrkit.errors import WmrkitError

FROZEN = Tyre.of("linear", {"c_lat": 0.0, "c_long": 0.0})  # no friction at all
WHEELBASE, HALF = 0.6, 0.2  # linked_car's
I_STEER = 0.05  # each front wheel's inertia.steer


def ackermann(h_left: float) -> float:
    """The right front wheel's heading whose axle meets the left one's on the rear axle line (the ICR)."""
    if h_left == 0.0:
        return 0.0
    icr = HALF + WHEELBASE / math.tan(h_left)  # the ICR's y on the rear axle (x = 0)
    return math.atan2(WHEELBASE, icr + HALF) if icr + HALF > 0 else math.atan2(-WHEELBASE, -(icr + HALF))


def slopes(h: float, e: float = 1e-4) -> tuple[float, float]:
    """``(f', f'')`` of :func:`ackermann` by central differences (fourth order for f')."""
    f = ackermann
    d1 = (8 * (f(h + e) - f(h - e)) - (f(h + 2 * e) - f(h - 2 * e))) / (12 * e)
    d2 = (f(h + e) - 2 * f(h) + f(h - e)) / e ** 2
    return d1, d2


def _columns(model):
    return model.names.index("fl.steer"), model.names.index("fr.steer")


def test_the_law_is_the_ackermann_geometry_and_a_broken_description_is_refused():
    model = DynamicModel.of(linked_car(front_heading=0.3))
    i, j = _columns(model)
    for h in (0.3, -0.2, 0.0, 0.6, 1.2):
        beta = model.robot.beta_of_heading([h, ackermann(h)])
        nu = np.zeros(model.n)
        nu[i], nu[j] = 0.7, 0.7 * slopes(h)[0]
        model.accelerations(beta, nu, forces=np.zeros(8))  # held: accepted
        nu[j] *= 1.001
        with pytest.raises(WmrkitError, match=r"the steering linkage of wheels 'fl' and 'fr' turns fr's steering "
                                              r"at [-\d.e]+ rad/s with fl's at 0.7 rad/s, not "):
            model.accelerations(beta, nu, forces=np.zeros(8))
        bad = model.robot.beta_of_heading([h, ackermann(h) + 1e-6])
        with pytest.raises(WmrkitError, match=r"the steering linkage of wheels 'fl' and 'fr' sets fr at heading "
                                              rf"{ackermann(h):.6g} rad with fl at {h:.6g} rad, not "):
            model.accelerations(bad, np.zeros(model.n), forces=np.zeros(8))
    data = linked_car(front_heading=0.3).to_dict()
    data["wheels"][3]["heading"] = 0.3
    data["wheels"][3].pop("beta", None)
    with pytest.raises(WmrkitError, match=r"the steering linkage of wheels 'fl' and 'fr': at the described headings "
                                          r".*\(fr would be at 14.38 deg"):  # atan(0.6 / (0.6 / tan 0.3 + 0.4))
        DynamicModel.of(Robot.from_dict(data))


def test_steering_inertia_reflects_the_linked_wheel_through_the_law():
    """Straight ahead each front wheel turns alone about its contact: the leader's servo moves ``I + f'^2 I`` (f' = 1).
    Steered, the car rolling about its ICR lowers that (the wheels' ``I beta' omega`` terms): the KKT solution of the
    least-energy rolling motion with the linkage's row ``nu_j = f' nu_i`` (f' of the Ackermann geometry). Holding
    one locks the other: its own inertia."""
    model = DynamicModel.of(linked_car())
    assert model.steering_inertia() == pytest.approx([2 * I_STEER, 2 * I_STEER], rel=1e-12)
    model = DynamicModel.of(linked_car(front_heading=0.3))
    i, j = _columns(model)
    row = np.zeros(model.n)
    row[i], row[j] = slopes(0.3)[0], -1.0
    rows = np.vstack([model.slip_matrix(), row])
    expected = [least_energy_inertia(model, rows, c)[0] for c in (i, j)]
    assert expected[0] < I_STEER * (1 + slopes(0.3)[0] ** 2) * (1 - 1e-4)  # the car rolls a little
    assert model.steering_inertia() == pytest.approx(expected, rel=1e-9)
    assert model.steering_inertia([j])[0] == pytest.approx(I_STEER)  # locked: its own


@pytest.mark.parametrize("method", ["rk4", "adaptive"])
def test_one_steering_torque_turns_the_linkage_as_its_one_dof_equation_says(method):
    """Frictionless tyres, a torque tau on the left steering alone, from rest at 0.3 rad. The centre of mass stays
    put and the angular momentum ``I theta' + (I + f' I) beta'`` stays 0 (``I`` the body's inertia; each front wheel's
    ``I (beta' + theta')^2 / 2`` beyond its share of it), so the Routhian gives one equation in the left heading:
    ``J beta'' + J' beta'^2 / 2 = tau``, ``J = I (1 + f'^2) - I^2 (1 + f')^2 / I_body``. Integrated here with f', f''
    of the Ackermann geometry; the simulation must follow it (without the linkage's velocity-product term
    ``f'' beta'^2`` it left it by 0.0096 rad)."""
    robot = linked_car(front_heading=0.3)
    model = DynamicModel.of(robot, FROZEN)
    tau, i_body = 0.05, robot.body.inertia

    def rhs(_, y):
        h, w = y[0], y[1]
        d1, d2 = slopes(h)
        j = I_STEER * (1 + d1 ** 2) - (I_STEER * (1 + d1)) ** 2 / i_body
        dj = 2 * I_STEER * d1 * d2 - 2 * I_STEER ** 2 * (1 + d1) * d2 / i_body
        return [w, (tau - 0.5 * dj * w * w) / j, -I_STEER * (1 + d1) * w / i_body]

    sim = simulate(model, Inputs.torques_only(model, [0.0], {"fl.steer": tau}), 1.0, step=1e-4, method=method,
                   record_step=0.01, rtol=1e-10, allow_lift_off=True)
    ref = solve_ivp(rhs, (0, 1.0), [0.3, 0.0, 0.0], t_eval=sim.t, rtol=1e-11, atol=1e-13, method="DOP853").y
    k = sim.steered.index("fl")
    assert ref[0, -1] - 0.3 > 0.2  # a large motion
    np.testing.assert_allclose(sim.heading[:, k], ref[0], atol=1e-7)
    np.testing.assert_allclose(sim.pose[:, 2], ref[2], atol=1e-7)
    np.testing.assert_allclose([ackermann(h) for h in sim.heading[:, k]], sim.heading[:, 1 - k], atol=1e-12)
    com = sim.pose[:, :2] + np.column_stack([np.cos(sim.pose[:, 2]), np.sin(sim.pose[:, 2])]) * robot.body.com[0]
    np.testing.assert_allclose(com - com[0], 0.0, atol=1e-9)  # no external force: the centre of mass stays put


def test_a_linkage_conserves_energy_without_friction():
    """Frictionless, no torque, the body moving and the linkage swinging (the basis changes with the angle): the
    kinetic energy stays constant, and the follower on the law at every step."""
    model = DynamicModel.of(linked_car(front_heading=0.3), FROZEN)
    i, j = _columns(model)
    s0 = initial_state(model)
    n = model.n
    s0[n:n + 3] = (0.4, -0.2, 0.9)
    s0[n + i], s0[n + j] = 1.5, 1.5 * slopes(0.3)[0]
    steer = list(model.steer_columns)
    e0 = model.kinetic_energy(s0[steer], s0[n:])
    for s, energy in frictionless_coast(model, s0):
        assert energy == pytest.approx(e0, rel=1e-9)
        h = model.robot.heading_of_beta(s[steer])
        assert h[1] == pytest.approx(ackermann(h[0]), abs=1e-12)


@pytest.mark.parametrize("method", ["semi-implicit", "rk4", "adaptive"])
def test_the_linkage_holds_to_round_off_on_a_long_turn(method):
    """Tyres with friction, the turn program driving both steering servos: at every record the right heading is
    the Ackermann one of the left (to round-off, the integrators setting the follower from its leader) and
    turns at f' times its rate; the 3 m turn is the one programmed (the rear axle's ICR)."""
    model = DynamicModel.of(linked_car())
    inputs, duration = path_program(model, "turn", speed=1.0)
    step = 1e-4 if method == "rk4" else 1e-3
    sim = simulate(model, inputs, duration + (8.0 if method == "semi-implicit" else 0.0), step=step, method=method,
                   record_step=0.01)
    i, j = (sim.joint_names.index(c) for c in ("fl.steer", "fr.steer"))
    left, right = sim.heading[:, 0], sim.heading[:, 1]
    np.testing.assert_allclose(right, [ackermann(h) for h in left], atol=1e-12)
    np.testing.assert_allclose(sim.joint_rates[:, j], [slopes(h)[0] for h in left] * sim.joint_rates[:, i],
                               rtol=1e-6, atol=1e-12)
    assert left[-1] == pytest.approx(math.atan(WHEELBASE / (3.0 - HALF)), abs=2e-3)


def test_a_state_the_linkage_forbids_is_refused():
    model = DynamicModel.of(linked_car())
    s = initial_state(model)
    s[model.names.index("fr.steer")] += 0.01
    with pytest.raises(WmrkitError, match=r"^state: the steering linkage of wheels 'fl' and 'fr' sets fr at heading "
                                          r"0 rad with fl at 0 rad, not 0.01 rad: the dynamics hold the linkage"):
        Stepper(model, s)  # by wheel, as Coupling.words() names them (it said 'sets fr.steer ... from fl.steer')


def _synchro() -> Robot:
    """Three steerable wheels on one chain (a synchro drive): no fixed wheel, so the linkage turns them together."""
    robot = castor_robot()
    wheel = {"type": "steerable", "r": 0.08, "actuated": ["spin", "steer"], "inertia": {"spin": 0.004, "steer": 0.01},
             "tyre": "dugoff"}
    data = {**robot.to_dict(), "name": "synchro", "body": {"mass": 20, "inertia": 1.2, "com": [0, 0],
                                                             "com_height": 0.05}, "wheels": [
        {**wheel, "name": "a", "position": [0.25, 0.0]}, {**wheel, "name": "b", "position": [-0.15, 0.2]},
        {**wheel, "name": "c", "position": [-0.15, -0.2]}],
        "couplings": [{"kind": "linkage", "joints": ["a.steer", "b.steer", "c.steer"]}]}
    return Robot.from_dict(data)


def test_a_chain_turns_its_wheels_together_and_refuses_a_turn():
    """Without a fixed wheel the linked wheels stay parallel: a turn on the spot (their IK headings apart) is
    refused by twist_program and initial_state, naming the linkage; a translation is allowed and steering one wheel
    turns all three by the same angle."""
    model = DynamicModel.of(_synchro())
    assert model.steering_inertia()[0] == pytest.approx(3 * 0.01)
    a, b = math.atan2(0.5 * 0.25, 0.3), math.atan2(-0.5 * 0.15, 0.3 - 0.5 * 0.2)  # their IK headings (v + w x r)
    with pytest.raises(WmrkitError, match=rf"the steering linkage of wheels 'a', 'b' and 'c' sets b at heading "
                                          rf"{a:.6g} rad with a at {a:.6g} rad, not {b:.6g} rad\)"):
        twist_program(model, [0.0], [(0.3, 0.0, 0.5)])
    with pytest.raises(WmrkitError, match=r"initial twist .*the steering linkage of wheels 'a', 'b' and 'c'"):
        initial_state(model, (0.3, 0.0, 0.5))
    inputs = twist_program(model, [0.0, 1.0], [(0.0, 0.0, 0.0), (0.2, 0.2, 0.0)])
    sim = simulate(model, inputs, 2.0)
    np.testing.assert_allclose(sim.heading - sim.heading[:, :1], 0.0, atol=1e-12)
    assert sim.heading[-1, 0] == pytest.approx(math.pi / 4, abs=1e-3)  # steered diagonally, all three


def test_robots_without_a_linkage_keep_an_empty_table():
    model = DynamicModel.of(dataclasses.replace(castor_robot(), couplings=(Coupling("gear", ("left.spin",
                                                                                          "right.spin"), (1, 1)),)))
    assert model.pack[17].shape == (0, 10) and model.pack[16].shape == (model.n, model.n - 1)
