"""A start from rest at more torque than the tyres transmit: the semi-implicit step's linearised tyres (slope
``cs / eps`` at zero slip) gripped in its first step at many times ``mu Fz``, the load transfer of that acceleration
emptied the drive wheels, and every fixed step said "contact 'left' lifts off the ground at t = 0.001 s" where the
robot keeps its wheels down until t = 0.41 s. The step now re-linearises a tyre force beyond its grip (Newton
iterations of the implicit step, ``_newton.relinearise``), and its tyre forces take the loads of its own acceleration
(``_newton.loads_moved``), not the previous step's."""

from __future__ import annotations

import numpy as np
import pytest
from dynamics_robots import castor_robot

from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.runs import LiftOffError
from wmrkit.dynamics.simulate import Inputs, simulate


@pytest.fixture(scope="module")
def start():
    """The castor robot, 20 N m on each drive wheel from rest."""
    model = DynamicModel.of(castor_robot())
    return model, Inputs.torques_only(model, [0.0], {"left.spin": [20.0], "right.spin": [20.0]})


@pytest.fixture(scope="module")
def fine(start):
    """The reference: 10 us steps, the Jacobian at every step (within 2.5e-6 m/s and 4e-4 rad/s of LSODA at rtol
    1e-8 over its 0.3 s)."""
    model, inputs = start
    return simulate(model, inputs, 0.3, step=1e-5, jac_every=1, record_step=0.01)


def _errors(sim, ref) -> tuple[float, float]:
    """Largest twist error [m/s or rad/s] and drive-wheel rate error [rad/s] of `sim` against the first records of
    `ref` (same record times)."""
    k = sim.t.shape[0]
    return (np.abs(sim.twist - ref.twist[:k]).max(),
            np.abs(sim.joint_rates[:, :2] - ref.joint_rates[:k, :2]).max())


def test_the_start_stays_down_and_converges_on_the_fine_run_in_the_step(start, fine):
    model, inputs = start
    errors = {}
    for step in (1e-3, 2.5e-4, 1e-4):
        sim = simulate(model, inputs, 0.3, step=step, record_step=0.01)  # raised LiftOffError at t = step
        drive = sim.loads[:, :2]
        assert drive.min() > 4.0  # the right wheel: 5.2 N at t = 0.3 s, as the fine run's
        errors[step] = _errors(sim, fine)
    assert errors[1e-3][0] < 5e-4 and errors[1e-3][1] < 0.05  # 2.4e-4 m/s and 0.022 rad/s (of 1450) measured
    # first order from a quarter millisecond (1.4e-4 m/s, 5.2e-5 at 0.1 ms); the loads the step's own acceleration
    # transfers cut the error at 1 ms 15-fold (3.7e-3 m/s with the previous step's)
    assert errors[1e-4][0] < 0.5 * errors[2.5e-4][0] and errors[2.5e-4][0] < errors[1e-3][0]


def test_the_fine_run_agrees_with_lsoda_on_the_first_tenth_of_a_second(start, fine):
    model, inputs = start
    lsoda = simulate(model, inputs, 0.1, method="adaptive", rtol=1e-6, record_step=0.01)
    assert np.allclose(lsoda.t, fine.t[:11])
    twist, rates = _errors(lsoda, fine)
    assert twist < 1e-3 and rates < 0.3
    assert fine.loads[:, :2].min() > 4.0


def test_a_jacobian_kept_from_grip_is_relinearised_when_the_tyre_slides(start, fine):
    """Kept for 1000 steps, the zero-slip Jacobian held the wheels at the grip (the robot drove at 21.8 m/s^2 on
    unloaded wheels with allow_lift_off); a force it predicts beyond the grip now re-linearises the step."""
    model, inputs = start
    kept = simulate(model, inputs, 0.2, step=1e-3, jac_every=1000, record_step=0.01, allow_lift_off=True)
    assert kept.loads[1:, :2].min() > 8.0  # 8.8 N at t = 0.2 s (the fine run: 9.2 N)
    assert _errors(kept, fine)[0] < 5e-3  # 9.0e-4 m/s (2.4e-4 at jac_every 20)


def test_the_robot_s_own_lift_off_is_still_reported(start):
    """The right wheel's load falls as the robot turns right and reaches 0 at t = 0.407 s (LSODA, rtol 1e-8); the
    step agrees to a millisecond at a quarter millisecond and at 1 ms, where the explicit load transfer chattered and
    emptied it at 0.362 s."""
    model, inputs = start
    for step in (2.5e-4, 1e-3):
        with pytest.raises(LiftOffError, match=r"contact 'right' lifts off the ground at t = 0\.40[5-8]"):
            simulate(model, inputs, 0.5, step=step)


def test_a_little_more_torque_on_one_side_keeps_the_wheels_down_too():
    """20 and 25 N m: every fixed step (1 ms to 10 us) 'lifted off' the right wheel at its first step, whose tyre
    forces took the loads at rest (the previous step's acceleration, none), where LSODA keeps 16.3 and 6.0 N on the
    drive wheels over the first 0.1 s (rtol 1e-8; any of the three tyre models with a grip). The step's loads are now
    those of its own acceleration. Measured: within 3.6e-5 m/s and 1.3e-3 rad/s (of 110) of LSODA over the first 20
    ms at 1 ms, 1.4e-5 and 3.6e-4 at 0.25 ms; 6.02 N at 1 ms over 0.1 s."""
    model = DynamicModel.of(castor_robot())
    inputs = Inputs.torques_only(model, [0.0], {"left.spin": [20.0], "right.spin": [25.0]})
    lsoda = simulate(model, inputs, 0.02, method="adaptive", rtol=1e-7, record_step=0.002)  # 1.4 s of CPU
    assert lsoda.loads[:, :2].min() > 6.0
    errors = {}
    for step in (1e-3, 2.5e-4):
        sim = simulate(model, inputs, 0.02, step=step, record_step=0.002)  # raised LiftOffError at t = step
        assert sim.loads[:, :2].min() > 6.0  # 6.7 N at t = 0.02 s, LSODA 6.5 N
        errors[step] = _errors(sim, lsoda)
    assert errors[1e-3][0] < 1e-4 and errors[1e-3][1] < 5e-3
    assert errors[2.5e-4][0] < 0.5 * errors[1e-3][0] and errors[2.5e-4][1] < 0.5 * errors[1e-3][1]
    assert simulate(model, inputs, 0.1, step=1e-3, record_step=0.01).loads[:, :2].min() > 5.5  # LSODA 6.03 N
