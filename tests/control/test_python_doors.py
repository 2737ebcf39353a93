"""The Python doors of `track` and `builtin_reference` read no units (docs/conventions.md): text, booleans and arrays
where one number goes are refused naming the argument. Text read as a number ('1' as 1 s) or raised a bare TypeError
from a comparison before."""

from __future__ import annotations

import math
import re

import pytest

from wmrkit.catalog import load
from wmrkit.control import ControlError, builtin_reference, track
from wmrkit.control.references import ReferenceError
from wmrkit.errors import ShapeError

ROBOT = load("diff-drive")
REFERENCE = builtin_reference("circle", speed=0.5, size=2.0, duration=1.0)
CONTROLLER = {"lookahead": "pure-pursuit", "stanley_gain": "stanley", "integral_gain": "pi"}
NAMES = ("gain", "integral_gain", "gate", "period", "duration", "lookahead", "stanley_gain", "output_dt")


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize(("value", "message"), [
    ("1", "got the text '1', but the Python API reads no units"),
    (True, "expected real numbers in SI units (m, rad, m/s, rad/s), got booleans"),
    ([1.0], "expected one real number, got an array of shape (1,)"),
])
def test_track_refuses_what_is_not_one_real_number(name, value, message):
    controller = CONTROLLER.get(name, "p")
    with pytest.raises(ShapeError, match=f"^{name}: {re.escape(message)}"):
        track(ROBOT, REFERENCE, controller=controller, **{name: value})


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"output_dt": math.nan}, "output_dt: expected a positive number of seconds, got nan"),
    ({"output_dt": -1.0}, "output_dt: expected a positive number of seconds, got -1"),
    ({"delay": "1"}, "delay: expected a number of samples >= 0, got '1'"),
    ({"delay": 1.5}, "delay: expected a number of samples >= 0, got 1.5"),
])
def test_track_names_the_argument_that_is_wrong(kwargs, message):
    """A NaN output step said 'more than 1000000 samples; give a shorter duration'; delay='1' without a period
    said 'a measurement delay in samples needs a sample period'."""
    with pytest.raises(ControlError, match=f"^{re.escape(message)}$"):
        track(ROBOT, REFERENCE, **kwargs)


def test_numpy_and_integer_numbers_are_taken_as_numbers():
    import numpy as np

    a = track(ROBOT, REFERENCE, gain=np.float32(2.0), output_dt=np.int64(1) / 10)
    b = track(ROBOT, REFERENCE, gain=2, output_dt=0.1)
    np.testing.assert_array_equal(a.pose, b.pose)


@pytest.mark.parametrize(("kwargs", "error", "message"), [
    ({"name": 1}, ReferenceError, "reference: expected a built-in reference's name"),
    ({"name": "circle", "speed": "1"}, ShapeError, "speed: got the text '1'"),
    ({"name": "circle", "size": "2"}, ShapeError, "size: got the text '2'"),
    ({"name": "circle", "dt": "0.1"}, ShapeError, "dt: got the text '0.1'"),
    ({"name": "circle", "duration": True}, ShapeError, "duration: expected real numbers"),
])
def test_builtin_reference_refuses_what_is_not_a_name_or_a_number(kwargs, error, message):
    with pytest.raises(error, match=f"^{re.escape(message)}"):
        builtin_reference(**kwargs)
