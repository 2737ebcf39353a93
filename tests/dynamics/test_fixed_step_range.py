"""A fixed-step run whose state leaves the physical range (a point of the robot faster than limits.MAX_SPEED,
runs.escaped) stops there and says so, as the adaptive run does, after the re-check at a shorter step (runs._stop:
the robot's stop, not the step's). Before, 1000 N m on each wheel of a 20 kg robot spun them to 5e5 rad/s in 2 s
(a contact at 4e4 m/s) and the run printed those numbers as a result."""

from __future__ import annotations

import pytest
from dynamics_robots import castor_robot

from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, simulate
from wmrkit.errors import WmrkitError


@pytest.mark.parametrize("method", ["semi-implicit", "rk4"])
def test_a_wheel_spun_beyond_the_physical_range_stops_the_run_at_that_time(method):
    """The wheels (spin inertia 0.004 kg m^2, r = 0.08 m) reach 1000 m/s at their rims, 12 500 rad/s, by about
    ``I w / tau`` = 0.05 s once their tyres slip (later with the semi-implicit step's grip)."""
    model = DynamicModel.of(castor_robot())
    inputs = Inputs.torques_only(model, [0.0], {"left.spin": 1000.0, "right.spin": 1000.0})
    with pytest.raises(WmrkitError) as err:
        simulate(model, inputs, 2.0, method=method, allow_lift_off=True)
    message = str(err.value)
    assert message.startswith("the simulation left the physical range at t = 0.0")
    assert ".spin = 1.2" in message and "beyond 1000 m/s (limits.MAX_SPEED)); use smaller torques or speeds" in message
    assert "\n" not in message

