"""The slip package's Python doors refuse a bad value or type of an argument with a ShapeError (a ValueError) naming
it, as docs/conventions.md says (they raised a bare WmrkitError, which ``except ValueError`` missed); the messages
are those the CLI prints. Name choices (a model, a source) stay as they are."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from wmrkit import catalog, slip
from wmrkit.errors import ShapeError, WmrkitError
from wmrkit.slip import metrics
from wmrkit.slip.calibration import calibrate_slip, effective_track_model
from wmrkit.slip.drivetrain import TractionLoop
from wmrkit.slip.models import LinearFriction
from wmrkit.slip.skid import segment_run
from wmrkit.slip.study import forklift_study
from wmrkit.slip.synthetic import wheel_speed_run

SPINS = ["front_left.spin", "front_right.spin"]


def _skid():
    return catalog.load("skid-steer-4")


def _law(v_slip, v_body, loads):
    return -v_slip


def _mcd(**options):
    return slip.mcd(_skid(), SPINS, [1.0, 2.0], options.pop("friction", _law), **options)


PATH = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [0.0, 0.0, 1.0]])

DOORS = [
    (lambda: LinearFriction((1.0,)), r"LinearFriction: expected a \(lateral, longitudinal\) pair per contact"),
    (lambda: LinearFriction(("1", "2")), r"LinearFriction: got the text '1', but the Python API reads no units"),
    (lambda: LinearFriction((1.0, -1.0)), r"LinearFriction: every coefficient must be a finite number > 0"),
    (lambda: _mcd(friction=LinearFriction((1.0,) * 4)), r"LinearFriction: 2 pairs of coefficients for 4 contacts"),
    (lambda: _mcd(friction=lambda v, b, f: np.zeros(3)), r"friction law: expected finite forces of shape \(4, 2\)"),
    (lambda: _mcd(friction=lambda v, b, f: v[7]), r"friction law: fails on 4 contacts"),
    (lambda: slip.wls(_skid(), "front_left.spin", [1.0]), r"assigned: expected a sequence of velocity names"),
    (lambda: slip.wls(_skid(), [SPINS[0]] * 2, [1.0, 2.0]), r"assigned: expected distinct velocity names"),
    (lambda: slip.wls(_skid(), SPINS, [1.0]), r"q_assigned: expected shape \(\.\.\., 2\), one value per assigned"),
    (lambda: slip.wls(_skid(), SPINS, [np.nan, 1.0]), r"q_assigned: front_left\.spin: expected finite numbers"),
    (lambda: _mcd(tol=math.nan), r"tol: expected a finite tolerance > 0, got nan"),
    (lambda: _mcd(tol="1e-9"), r"tol: expected a finite tolerance > 0, got 1e-9"),  # text: a TypeError
    (lambda: _mcd(loads=[1.0] * 3), r"loads: expected 4 normal loads, one per contact, got shape \(3,\)"),
    (lambda: _mcd(loads=[-1.0] * 4), r"loads: expected finite normal loads >= 0, not all 0"),
    (lambda: _mcd(start=slip.wls(_skid(), SPINS, [[1.0, 2.0]] * 2)),
     r"start: expected velocities of shape \(7,\) \(one solution per sample"),
    (lambda: slip.mqe(catalog.load("forklift"), ["right_drive.spin", "left_drive.spin"], [1.0, 1.0], _law, g=-9.81),
     r"g: expected a finite gravity > 0 m/s\^2, got -9.81"),
    (lambda: slip.normal_loads(catalog.load("forklift"), g=math.nan), r"normal_loads: expected a gravity g > 0"),
    (lambda: slip.normal_loads(catalog.load("forklift"), g="9.81"), r"normal_loads: expected a gravity g > 0"),
    (lambda: slip.normal_loads(catalog.load("forklift"), accel_cm=(1.0,)), r"normal_loads: expected a gravity"),
    (lambda: slip.normal_loads(catalog.load("forklift"), body=replace(catalog.load("forklift").body, mass=-5.0)),
     r"body\.mass: expected a finite number > 0 kg, got -5\.0"),
    (lambda: metrics.j_model(np.zeros((2, 3)), np.zeros((3, 3))), r"j_model: expected two \(N, 3\) twist arrays"),
    (lambda: metrics.j_model(np.zeros((0, 3)), np.zeros((0, 3))), r"j_model: expected at least one sample"),
    (lambda: metrics.closure_error(PATH[:1]), r"closure_error: poses must be a path of at least 2 poses"),
    (lambda: metrics.closure_error([*PATH, [np.nan] * 3]), r"closure_error: poses must be finite, pose 3 is not"),
    (lambda: metrics.closure_error(PATH, [0.0, 0.0, np.nan]), r"closure_error: truth_final: must be finite"),
    (lambda: metrics.j_closure([]), r"j_closure: no runs"),
    (lambda: metrics.j_closure([PATH], [PATH[0]] * 2), r"j_closure: 1 runs and 2 true final poses"),
    (lambda: effective_track_model(_skid(), 0.0), r"wheel separation multiplier must be a finite number > 0"),
    (lambda: effective_track_model(_skid(), "2"), r"wheel separation multiplier must be a finite number > 0"),
    (lambda: calibrate_slip(_skid(), None, (), heading_weight=-1.0), r"heading_weight: expected a finite number"),
    (lambda: calibrate_slip(_skid(), None, (), heading_weight="1"), r"heading_weight: expected a finite number"),
    (lambda: TractionLoop.tuned(100.0, 1.0, 1.5, 1e3), r"traction loop: inertia, settling and torque limit > 0"),
    (lambda: TractionLoop.tuned("100", 1.0, 0.1, 1e3), r"traction loop: inertia, settling and torque limit > 0"),
    (lambda: segment_run(_skid(), [(1.0, 1.0, 0.0)], 0.0), r"rate must be a finite number > 0 \[Hz\], got 0.0"),
    (lambda: segment_run(_skid(), [(1.0, 1.0, 0.0)], "50"), r"rate must be a finite number > 0 \[Hz\], got '50'"),
    (lambda: wheel_speed_run(catalog.load("forklift"), [(1.0, [1.0, 1.0, 1.0])], 10.0),
     r"segments: need finite durations > 0 and 2 finite rates each"),
    (lambda: wheel_speed_run(catalog.load("forklift"), [(1.0, [1.0, 1.0])], 0.0), r"rate 0 Hz over the segments'"),
    (lambda: wheel_speed_run(catalog.load("forklift"), [(1.0, [1.0, 1.0])], "10"), r"rate '10' Hz over the segments'"),
    (lambda: forklift_study(seed=-1), r"seed must be an integer >= 0, got -1"),
]


@pytest.mark.parametrize(("call", "message"), DOORS)
def test_a_bad_argument_is_a_shape_error_naming_it(call, message):
    with pytest.raises(ShapeError, match=f"^{message}"):
        call()


def test_name_choices_and_impossible_requests_stay_wmrkit_errors():
    """A model name, or loads that lift a wheel off: not an argument's value or type (no ShapeError)."""
    for call in (lambda: wheel_speed_run(catalog.load("forklift"), [(1.0, [1.0, 1.0])], 10.0, model="wls"),
                 lambda: segment_run(_skid(), [(1.0, 1.0, 0.0)], 50.0, source="kinematic"),
                 lambda: slip.normal_loads(catalog.load("forklift"), accel_cm=(0.0, 30.0)),
                 lambda: slip.normal_loads(replace(catalog.load("forklift"), body=None)),
                 lambda: slip.mqe(catalog.load("forklift"), ["vx", "right_drive.spin"], [1.0, 1.0], _law)):
        with pytest.raises(WmrkitError) as err:
            call()
        assert not isinstance(err.value, ShapeError), err.value
