"""Steering servos of linked wheels act as one servo on the linkage: their gains sum, through the law's slopes, to a
critically damped PD of natural frequency ``bandwidth`` on the linkage's reflected inertia (docs/dynamics.md,
steering servos). Checked against the least-energy inertia of the KKT system (``least_energy_inertia``), a numeric
derivative of the Ackermann geometry and the closed-form step response ``r (1 - (1 + w t) e^(-w t))``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dynamics_robots import least_energy_inertia, linked_car
from test_linkage_law import I_STEER, STEERS, four_wheel_steer

from wmrkit import Robot
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import BANDWIDTH, read_torques, steering_gains
from wmrkit.dynamics.simulate import simulate

STEP = 0.2  # [rad] the heading reference


def _synchro(servoed=("fl", "fr")) -> DynamicModel:
    """A synchro drive (one parallel linkage over its four steerable wheels) whose `servoed` wheels have a steering
    motor; every wheel has a spin motor."""
    data = four_wheel_steer(linkages=[STEERS])
    for w in data["wheels"]:
        w["actuated"] = ["spin", "steer"] if w["name"] in servoed else ["spin"]
    return DynamicModel.of(Robot.from_dict(data))


def test_two_servos_of_a_synchro_chain_sum_to_its_inertia():
    """Before, each servo was tuned on its own wheel (kp = I w^2: holding its partner locked the chain), so the two
    gave 2 I w^2 on the chain's 4 I: w / sqrt 2, damping ratio 0.71."""
    model = _synchro()
    servoed = [c for c in model.steer_columns if model.is_actuated(c)]
    kp, kd = steering_gains(model, servoed)
    chain = np.zeros((3, model.n))  # fr, rl, rr turn with fl
    for k, w in enumerate(STEERS[1:]):
        chain[k, model.names.index(f"{w}.steer")], chain[k, model.names.index("fl.steer")] = 1.0, -1.0
    inertia, _ = least_energy_inertia(model, np.vstack([model.slip_matrix(), chain]), model.names.index("fl.steer"))
    assert inertia == pytest.approx(4 * I_STEER, rel=1e-9)
    assert kp.sum() == pytest.approx(inertia * BANDWIDTH ** 2, rel=1e-9)
    assert kd.sum() == pytest.approx(2 * inertia * BANDWIDTH, rel=1e-9)
    assert kp[0] == kp[1] and kp[2] == kp[3] == 0.0


def test_the_linked_pair_steps_as_the_documented_critically_damped_servo(tmp_path):
    """A heading step on the two servoed wheels from rest: the chain follows ``r (1 - (1 + w t) e^(-w t))`` (before:
    0.022 rad off it, and a 4.3 % overshoot that a critically damped servo never has)."""
    model = _synchro()
    path = tmp_path / "h.csv"
    path.write_text(f"time,fl.heading,fr.heading\n0,{STEP},{STEP}\n")
    sim = simulate(model, read_torques(model, path), 0.5, step=1e-3, method="rk4", record_step=0.01)
    w = BANDWIDTH
    closed = STEP * (1 - (1 + w * sim.t) * np.exp(-w * sim.t))
    for k in range(4):
        np.testing.assert_allclose(sim.heading[:, k], closed, atol=2e-3 * STEP)
    assert sim.heading[:, 0].max() < STEP * (1 + 1e-3)


def test_one_servo_of_the_chain_is_tuned_as_before():
    model = _synchro(servoed=("fl",))
    kp, _ = steering_gains(model, [model.names.index("fl.steer")])
    assert kp[0] == pytest.approx(4 * I_STEER * BANDWIDTH ** 2, rel=1e-9)


def test_an_ackermann_pair_sums_through_the_slope_to_its_reflected_inertia():
    """Both front wheels servoed, the rear spins held: ``kp_fl + f'^2 kp_fr = J w^2``, with ``f'`` a numeric
    derivative of the Ackermann geometry and ``J`` the least-energy inertia under the linkage's rate constraint."""
    heading = 0.3
    model = DynamicModel.of(linked_car(front_heading=heading))
    wheelbase, track = 0.6, 0.4

    def right(left: float) -> float:  # fr's heading whose axle meets fl's on the rear axle line
        return math.atan2(wheelbase, wheelbase / math.tan(left) + track)

    slope = (right(heading + 1e-6) - right(heading - 1e-6)) / 2e-6
    fl, fr = model.names.index("fl.steer"), model.names.index("fr.steer")
    held = [model.names.index(j) for j in ("rl.spin", "rr.spin")]
    rows = np.zeros((3, model.n))
    rows[0, fr], rows[0, fl] = 1.0, -slope
    rows[1, held[0]] = rows[2, held[1]] = 1.0
    inertia, _ = least_energy_inertia(model, np.vstack([model.slip_matrix(), rows]), fl)
    kp, kd = steering_gains(model, [fl, fr], held=held)
    assert kp[0] + slope ** 2 * kp[1] == pytest.approx(inertia * BANDWIDTH ** 2, rel=1e-6)
    assert kd[0] + slope ** 2 * kd[1] == pytest.approx(2 * inertia * BANDWIDTH, rel=1e-6)


def _geared_units(ratios: tuple[float, float]) -> DynamicModel:
    """Two double wheels (differential steering units, spins free) whose steering is geared in `ratios`, each with
    a steering motor."""
    unit = {"type": "double", "heading": 0, "b": 0.06, "r": 0.08, "actuated": ["steer"],
            "inertia": {"spin": 0.01, "steer": 0.05},
            "tyre": {"model": "dugoff", "cs": 2000, "calpha": 1500, "mu": 0.8}}
    return DynamicModel.of(Robot.from_dict({
        "name": "geared-units", "body": {"mass": 50, "inertia": 2.0, "com": [0, 0], "com_height": 0.2},
        "wheels": [{**unit, "name": "front", "position": [0.3, 0.2]},
                   {**unit, "name": "rear", "position": [-0.3, -0.2]}],
        "couplings": [{"kind": "gear", "joints": ["front.steer", "rear.steer"], "ratios": list(ratios)}]}))


@pytest.mark.parametrize("ratios", [(1.0, 1.0), (1.0, 2.0), (3.0, -1.0)])
def test_two_servos_of_a_gear_sum_through_its_ratios_to_its_reflected_inertia(ratios):
    """Before, each servo of the gear was tuned on its own unit's inertia.steer (holding its partner locked the
    gear): for 1:2, kp_front + 4 kp_rear = 0.25 w^2 on the gear's 0.306 kg m^2, so 0.905 w and damping ratio 0.90.
    ``J``: the least-energy inertia of the KKT system under the gear's row ``q_f / k_f - q_r / k_r = 0``."""
    model = _geared_units(ratios)
    front, rear = model.names.index("front.steer"), model.names.index("rear.steer")
    gear = np.zeros(model.n)
    gear[front], gear[rear] = 1 / ratios[0], -1 / ratios[1]
    inertia, nu = least_energy_inertia(model, np.vstack([model.slip_matrix(), gear]), front)
    slope = ratios[1] / ratios[0]
    assert nu[rear] == pytest.approx(slope, rel=1e-9)
    kp, kd = steering_gains(model, [front, rear])
    assert kp[0] + slope ** 2 * kp[1] == pytest.approx(inertia * BANDWIDTH ** 2, rel=1e-9)
    assert kd[0] + slope ** 2 * kd[1] == pytest.approx(2 * inertia * BANDWIDTH, rel=1e-9)
