"""Heading set-points given in Python (``Inputs``) keep a held linkage's law as a torque file's must
(docs/dynamics.md, Couplings): ``simulate`` refuses a knot off it (``fight_linkages`` lets the servos fight), and
between knots the followers follow it. The law is written here independently, as the Ackermann ICR geometry of
``linked_car``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dynamics_robots import linked_car

from wmrkit.dynamics.inputs import compiled_inputs
from wmrkit.dynamics.linkages import SETPOINT_TOL
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import steering_gains, twist_program
from wmrkit.dynamics.simulate import Inputs, simulate
from wmrkit.errors import WmrkitError


def right_of(left: float) -> float:
    """fr's heading whose axle meets fl's (at `left`) on the rear axle line (wheelbase 0.6 m, track 0.4 m)."""
    return math.atan2(0.6, 0.6 / math.tan(left) + 0.4) if left else 0.0


def _servo_inputs(model: DynamicModel, time, headings, **kwargs) -> Inputs:
    """Steering servos on both front wheels following `headings` ``(K, 2)`` [rad] at the knots `time`."""
    k, n = len(time), model.n
    kp, kd = steering_gains(model, [model.names.index("fl.steer"), model.names.index("fr.steer")])
    return Inputs(np.array(time, float), np.zeros((k, n)), np.zeros((k, n)), np.zeros(n), np.full(n, np.inf),
                  np.array(headings, float), kp, kd, **kwargs)


def test_python_set_points_off_the_law_are_refused_naming_the_knot_and_the_wheels():
    """Before, simulate() ran these, the two servos fighting the linkage; read_torques refused the same headings in a
    file."""
    model = DynamicModel.of(linked_car())
    inputs = _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.3, 0.0]])
    with pytest.raises(WmrkitError) as err:
        simulate(model, inputs, 0.01)
    assert str(err.value).startswith(
        f"heading_reference: at t = 1 s, fr's 0 rad breaks the steering linkage of wheels 'fl' and 'fr', which sets fr "
        f"at heading {right_of(0.3):.6g} rad with fl's at 0.3 rad: the steering servos would fight")
    on_law = _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.3, right_of(0.3) + 0.5 * SETPOINT_TOL]])
    simulate(model, on_law, 0.01)


def test_fight_linkages_lets_the_servos_fight():
    model = DynamicModel.of(linked_car())
    simulate(model, _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.3, 0.0]], fight_linkages=True), 0.01)


def test_one_servo_per_linkage_is_never_refused():
    model = DynamicModel.of(linked_car())
    inputs = _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.3, 0.0]])
    one = Inputs(inputs.time, inputs.torques, inputs.rate_reference, inputs.rate_gain, inputs.torque_limit,
                 inputs.heading_reference, inputs.steer_kp * [1, 0], inputs.steer_kd)
    simulate(model, one, 0.01)  # fr has no servo: its reference is not a set-point


def test_a_twist_program_between_its_knots_keeps_the_law():
    """A turn programmed from straight ahead: the IK headings at the knots are on the law; before, linear between
    them, fr's set-point left it by up to 0.021 rad (0 -> 0.45 rad of fl)."""
    model = DynamicModel.of(linked_car())
    inputs = twist_program(model, [0.0, 1.0], [(1.0, 0.0, 0.0), (1.0, 0.0, 0.7)])
    compiled = compiled_inputs(model, inputs)
    headings = model.robot.heading_of_beta(compiled[5])
    t = np.linspace(0.0, 1.0, 1001)
    fl, fr = (np.interp(t, compiled[0], headings[:, k]) for k in (0, 1))
    assert fl[-1] == pytest.approx(math.atan2(0.6, 1 / 0.7 - 0.2), abs=1e-12)
    assert np.abs(fr - [right_of(h) for h in fl]).max() <= SETPOINT_TOL


def test_too_many_knots_is_a_one_line_error(monkeypatch):
    """Before, setpoint_knots raised a NameError (WmrkitError was not imported in dynamics/linkages.py) where the
    knots keeping a linkage's law between two knots would pass MAX_SETPOINT_KNOTS."""
    from wmrkit.dynamics import linkages

    monkeypatch.setattr(linkages, "MAX_SETPOINT_KNOTS", 3)
    model = DynamicModel.of(linked_car())
    with pytest.raises(WmrkitError, match=r"keeping a held linkage's followers on its law between the rows would"):
        compiled_inputs(model, _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.5, right_of(0.5)]]))


def test_a_stepper_refuses_what_simulate_refuses():
    """Before, Stepper.advance ran these set-points, the servos fighting the linkage, where simulate() refused them."""
    from wmrkit.dynamics.simulate import Stepper

    model = DynamicModel.of(linked_car())
    off = _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.3, 0.0]])
    with pytest.raises(WmrkitError) as err:
        Stepper(model).advance(off, 0.01)
    with pytest.raises(WmrkitError) as by_simulate:
        simulate(model, off, 0.01)
    assert str(err.value) == str(by_simulate.value)
    fight = _servo_inputs(model, [0.0, 1.0], [[0.0, 0.0], [0.3, 0.0]], fight_linkages=True)
    assert np.isfinite(Stepper(model).advance(fight, 0.01)).all()


@pytest.mark.parametrize("fight", [False, True])
def test_a_stepper_holds_headings_on_the_law_and_refuses_others(fight):
    """Before, hold() wrote any headings into the servos' references; now those off the law are refused (nothing is
    held: the state advances as before) unless the last inputs let the servos fight."""
    from wmrkit.dynamics.simulate import Stepper

    model = DynamicModel.of(linked_car())
    stepper = Stepper(model)
    stepper.advance(_servo_inputs(model, [0.0], [[0.0, 0.0]], fight_linkages=fight), 0.01)
    stepper.hold(heading_reference=[0.3, right_of(0.3)])  # on the law
    if fight:
        stepper.hold(heading_reference=[0.3, 0.0])
        return
    with pytest.raises(WmrkitError) as err:
        stepper.hold(heading_reference=[0.3, 0.0])
    assert str(err.value).startswith(
        f"hold: heading_reference: at t = 0.01 s, fr's 0 rad breaks the steering linkage of wheels 'fl' and 'fr', "
        f"which sets fr at heading {right_of(0.3):.6g} rad with fl's at 0.3 rad: the steering servos would fight")
    stepper.advance(None, 0.2)
    fl, fr = model.robot.heading_of_beta(stepper.state[list(model.steer_columns)])
    assert fl > 0.1 and fr == pytest.approx(right_of(fl), abs=1e-9)  # turning to the held on-law headings
