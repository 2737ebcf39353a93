"""The dynamics' Python doors refuse a bad value or type of an argument with a ShapeError (a ValueError) naming it,
as docs/conventions.md says (they raised a bare WmrkitError, which ``except ValueError`` missed); the messages are
those the CLI prints. Name choices, impossible requests and states the model holds otherwise stay as they are."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.dynamics.inputs import Inputs
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program, steering_gains, twist_program
from wmrkit.dynamics.simulate import Stepper, initial_state, simulate
from wmrkit.errors import ShapeError, WmrkitError


def _model():
    return DynamicModel.of(catalog.load("forklift"))  # n = 7 (vx, vy, omega, two drives, steer.spin, steer.steer)


def _inputs(**fields):
    """The forklift at a standstill (K = 2 times), with `fields` replaced."""
    values = {"time": [0.0, 1.0], "torques": np.zeros((2, 7)), "rate_reference": np.zeros((2, 7)),
              "rate_gain": np.zeros(7), "torque_limit": np.full(7, np.inf), "heading_reference": np.zeros((2, 1)),
              "steer_kp": np.zeros(1), "steer_kd": np.zeros(1)}
    return Inputs(**{**values, **fields})


def _held(**references):
    stepper = Stepper(_model())
    stepper.advance(_inputs(), 0.0)
    stepper.hold(**references)


DOORS = [
    (lambda: DynamicModel.of(catalog.load("forklift"), gravity=-9.8), r"gravity: expected a finite number > 0 m/s\^2"),
    (lambda: DynamicModel.of(catalog.load("forklift"), gravity="9.81"), r"gravity: expected a finite number > 0"),
    (lambda: _model().contact_forces(None, np.ones(7), [-1.0] * 3), r"loads: expected normal loads >= 0 N"),
    (lambda: _model().kinetic_energy(None, [np.nan] * 7), r"nu: expected finite numbers"),
    (lambda: _model().steering_inertia([0]), r"held: expected joint columns of model.names \(3 to 6\), got \[0\]"),
    (lambda: path_program(_model(), "straight", speed=-1.0), r"speed: expected a program speed in \(0, 1000\] m/s"),
    (lambda: path_program(_model(), "straight", radius_scale=0.0), r"radius_scale: expected a number in \(0, 1000\]"),
    (lambda: path_program(_model(), "turn", speed=1e-306, radius_scale=1e3),
     r"speed: 1e-306 m/s: program 'turn' would never end"),
    (lambda: twist_program(_model(), [0.0, 1.0], [(1e9, 0.0, 0.0), (0.0, 0.0, 0.0)]),
     r"twist \(1000000000\.0, 0\.0, 0\.0\) at t = 0 s: expected finite speeds within 1000 m/s"),
    (lambda: twist_program(_model(), [0.0], [(1.0, 0.0, 0.0)], bandwidth=0.0), r"bandwidth: expected a natural"),
    (lambda: twist_program(_model(), [0.0], [(1.0, 0.0, 0.0)], bandwidth="10"), r"bandwidth: expected a natural"),
    (lambda: steering_gains(_model(), [3]), r"servoed: expected steering columns of model.names \[6\], got \[3\]"),
    (lambda: _inputs(time=[1.0, 0.0]), r"time: input times must be at least one, finite and strictly increasing"),
    (lambda: _inputs(rate_gain=[-1.0] * 7), r"rate_gain: expected finite numbers >= 0, got -1\.0"),
    (lambda: Stepper(_model()).advance(_inputs(steer_limit=[-1.0]), 0.0), r"steer_limit: expected 1 torques > 0"),
    (lambda: _held(rate_reference=[1.0]), r"hold: rate_reference must be 7 numbers, got shape \(1,\)"),
    (lambda: simulate(_model(), {}, 1.0), r"inputs: expected Inputs \(Inputs\.torques_only"),
    (lambda: simulate(_model(), _inputs(), -1.0), r"duration and step must be finite numbers \[s\]"),
    (lambda: simulate(_model(), _inputs(), 1e6, step=1e-6), r"duration 1e\+06 s at step 1e-06 s: more than 5e\+07"),
    (lambda: simulate(_model(), _inputs(), 1.0, record_step=-0.1), r"record_step: expected a finite number > 0"),
    (lambda: simulate(_model(), _inputs(), 1e3, method="adaptive", record_step=1e-9),
     r"record_step: 1e-09 s over 1000 s is more than 5e\+07 samples"),
    (lambda: simulate(_model(), _inputs(), 100.0, step=1e-5), r"record_step: 1e-05 s over 100 s records 10000001"),
    (lambda: simulate(_model(), _inputs(), 1.0, method="adaptive", rtol=math.nan), r"rtol: expected a relative"),
    (lambda: simulate(_model(), _inputs(), 1.0, method="adaptive", rtol="0.1"), r"rtol: expected a relative"),
    (lambda: Stepper(_model(), step=0.0), r"step must be finite and > 0 and t finite, got 0\.0, 0\.0"),
    (lambda: Stepper(_model(), step="0.001"), r"step must be finite and > 0 and t finite, got 0\.001, 0\.0"),
    (lambda: Stepper(_model(), jac_every=0), r"jac_every must be an integer >= 1, got 0"),
    (lambda: Stepper(_model(), np.full(14, np.nan)), r"state: every entry must be finite"),
    (lambda: Stepper(_model()).advance(_inputs(), -1.0), r"duration must be >= 0 and at most 5e\+07 steps"),
    (lambda: Stepper(_model()).advance(_inputs(), "1"), r"duration must be >= 0 and at most 5e\+07 steps"),
    (lambda: initial_state(_model(), (1e9, 0.0, 0.0)), r"initial twist \[1000000000\.0, 0\.0, 0\.0\]: expected"),
    (lambda: initial_state(_model(), pose=(1e30, 0.0, 0.0)), r"initial pose \[1e\+30, 0\.0, 0\.0\]: expected"),
]


@pytest.mark.parametrize(("call", "message"), DOORS)
def test_a_bad_argument_is_a_shape_error_naming_it(call, message):
    with pytest.raises(ShapeError, match=f"^{message}"):
        call()


def test_name_choices_and_sequence_stay_wmrkit_errors():
    """A method's name, a joint that does not exist, an advance before any inputs: no ShapeError."""
    for call in (lambda: simulate(_model(), _inputs(), 1.0, method="euler"),
                 lambda: path_program(_model(), "zigzag"),
                 lambda: Stepper(_model()).advance(None, 0.1),
                 lambda: DynamicModel.of(dataclasses.replace(catalog.load("forklift"), body=None))):
        with pytest.raises(WmrkitError) as err:
            call()
        assert not isinstance(err.value, ShapeError), err.value
