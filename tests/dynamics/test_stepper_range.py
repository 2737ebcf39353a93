"""A ``Stepper`` (and ``advance``, the loops through the dynamics) stops where its state leaves the physical range
(a point of the robot faster than limits.MAX_SPEED: runs.first_escape, judged at the end of each advance and every
runs.RANGE_CHECK s), as the fixed-step and adaptive runs of ``simulate`` do, with their message; before, 1000 N m
on each wheel of the castor robot advanced for 2 s returned wheels at 5e5 rad/s (a contact at 4e4 m/s) as a
state."""

from __future__ import annotations

import re

import numpy as np
import pytest
from dynamics_robots import castor_robot

from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.runs import DivergedError
from wmrkit.dynamics.simulate import Inputs, Stepper, advance, initial_state
from wmrkit.limits import MAX_SPEED


@pytest.fixture(scope="module")
def spun():
    model = DynamicModel.of(castor_robot())
    return model, Inputs.torques_only(model, [0.0], {"left.spin": 1000.0, "right.spin": 1000.0})


#: The wheels' spin inertia [kg m^2] and radius [m] in castor_robot, and the torque on each [N m] of `spun`.
SPIN_INERTIA, RADIUS, TORQUE = 0.004, 0.08, 1000.0


@pytest.mark.parametrize("pieces", [(2.0,), (0.02,) * 100])
@pytest.mark.parametrize("recheck", [True, False])
def test_a_stepper_spun_beyond_the_physical_range_stops_there(spun, pieces, recheck):
    """Spinning freely the wheels' rims would gain TORQUE / SPIN_INERTIA x RADIUS = 2e4 m/s per second (the tyres,
    at most at their grip, only hold them back): 1000 m/s no sooner than 0.05 s; the stepper stops within
    runs.RANGE_CHECK of it, its state there. The message's speeds are printed by `.3g`: 2e+03 as well as 1.2e+03."""
    model, inputs = spun
    stepper = Stepper(model, step=1e-3, allow_lift_off=True, recheck=recheck)
    with pytest.raises(DivergedError) as err:
        for duration in pieces:
            stepper.advance(inputs, duration)
    assert re.fullmatch(r"the simulation left the physical range at t = 0\.\d+ s \((left|right)\.spin = "
                        r"\d(\.\d+)?e\+04 rad/s moves a point of the robot at \d(\.\d+)?e\+03 m/s, beyond 1000 m/s "
                        r"\(limits\.MAX_SPEED\)\); use smaller torques or speeds", str(err.value)), str(err.value)
    assert 0.05 <= err.value.t <= 0.1 + 1e-9 and err.value.t == pytest.approx(stepper.t)
    rim = np.abs(stepper.state[model.n + 3:model.n + 5]).max() * RADIUS  # its state where it stopped
    # at most free spinning: equal since the step's loads are those of its own acceleration, whose reaction tips
    # the robot onto its castor (the drive wheels unloaded, their tyres hold nothing)
    assert MAX_SPEED < rim <= TORQUE / SPIN_INERTIA * RADIUS * err.value.t


def test_advance_stops_there_too(spun):
    model, inputs = spun
    with pytest.raises(DivergedError, match=r"^the simulation left the physical range at t = 0\.1 s"):
        advance(model, initial_state(model), inputs, 2.0, allow_lift_off=True)


def test_a_stepper_within_the_range_runs_on(spun):
    model, _ = spun
    inputs = Inputs.torques_only(model, [0.0], {"left.spin": 2.0, "right.spin": 2.0})
    stepper = Stepper(model, step=1e-3)
    state = stepper.advance(inputs, 1.0)
    assert stepper.t == pytest.approx(1.0) and np.all(np.isfinite(state))
