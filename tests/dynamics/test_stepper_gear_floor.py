"""A ``Stepper`` judges a state's gear with ik's slip floor, as ``fk`` judges its given rates.

Before: ``Stepper(model, state)`` with a solid axle (both spins on a 1:1 gear) at rest but ``left.spin`` 1e-320 rad/s
raised "state: the joints of gear(left.spin, right.spin) ... do not turn together": the state was judged relatively
only (``GEAR_EXACT_RTOL``), so any nonzero rate beside a zero one broke the gear. Checked against the closed form:
spins ``a`` and ``-a`` on a 1:1 gear have the least-squares turn 0, so each contact departs from the gear by ``a r``
(``r`` the description's wheel radius); departures of 0.5 and 0.9 ``SLIP_TOL`` are accepted, 1.1 and 2 refused.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dynamics_robots import castor_robot

from wmrkit.couplings import Coupling
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, Stepper, initial_state
from wmrkit.errors import WmrkitError
from wmrkit.kinematics.wheel_ik import SLIP_TOL

SPINS = ("left.spin", "right.spin")


def _model() -> DynamicModel:
    robot = castor_robot()
    return DynamicModel.of(dataclasses.replace(robot, couplings=(*robot.couplings, Coupling("gear", SPINS, (1, 1)))))


def _state(model: DynamicModel, left: float, right: float) -> np.ndarray:
    s = initial_state(model)
    n = model.n
    s[n + model.names.index("left.spin")], s[n + model.names.index("right.spin")] = left, right
    return s


@pytest.mark.parametrize(("left", "right"), [(1e-320, 0.0), (1e-320, -1e-320), (0.0, 2e-320)])
def test_a_tiny_state_is_in_the_gear(left, right):
    model = _model()
    stepper = Stepper(model, _state(model, left, right))
    inputs = Inputs.torques_only(model, [0.0, 1.0], {"left.spin": [0.0, 0.0]})
    assert np.all(np.isfinite(stepper.advance(inputs, 0.01)))


@pytest.mark.parametrize(("f", "holds"), [(0.5, True), (0.9, True), (1.1, False), (2.0, False)])
def test_the_state_gear_floor_is_the_contact_speed(f, holds):
    model = _model()
    a = f * SLIP_TOL / model.robot.wheel("left").r  # each contact a r off the gear's turn 0
    state = _state(model, a, -a)
    if holds:  # the dynamics hold the gear's accelerations: the departure stays as given, within the floor
        stepper = Stepper(model, state)
        s = stepper.advance(Inputs.torques_only(model, [0.0, 1.0], {"left.spin": [0.0, 0.0]}), 0.1)
        n, i, j = model.n, model.names.index("left.spin"), model.names.index("right.spin")
        assert s[n + i] - s[n + j] == pytest.approx(2 * a, rel=1e-6)
    else:
        with pytest.raises(WmrkitError, match=r"state: the joints of the gear of wheels 'left' and 'right' "):
            Stepper(model, state)


@pytest.mark.parametrize("v", [1e-6, 1.0, 10.0])
def test_a_real_departure_is_refused_at_every_speed(v):
    """Spins 5 % apart, the left contact at `v` [m/s]: refused however slow."""
    model = _model()
    u = v / model.robot.wheel("left").r
    with pytest.raises(WmrkitError, match=r"the gear of wheels 'left' and 'right'"):
        Stepper(model, _state(model, u, 1.05 * u))
