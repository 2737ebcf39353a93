"""The Python doors of `wmrkit.parking`, `wmrkit.analysis` and `wmrkit.odometry` read no units
(docs/conventions.md): text, booleans and arrays where one number goes are refused naming the argument, and so are a
name where a Vehicle or Space goes and NaN where it would be returned. Before, each raised a bare TypeError,
AttributeError or IndexError from deep inside, or read '1' as 1 (rad, m)."""

from __future__ import annotations

import re

import pytest

from wmrkit.errors import WmrkitError
from wmrkit.parking import Space, Vehicle, blackburn_min_length, length_ratio, plan_parking, shortest_slot

CAR = Vehicle(a1=3.5, b1=0.9, c1=1.7, h1=2.6, track=1.4, phi_max=0.6)
SLOT = Space(H=6.0, J=2.2, MS=0.2, dx2=0.5, final_gap=0.2)
TEXT = "got the text '1', but the Python API reads no units"
BOOLEANS = r"expected real numbers in SI units \(m, rad, m/s, rad/s\), got booleans$"


@pytest.mark.parametrize(("call", "name"), [
    (lambda v: plan_parking(CAR, SLOT, phi_step=v), "phi_step"),
    (lambda v: shortest_slot(CAR, SLOT, step=v), "step"),
    (lambda v: shortest_slot(CAR, SLOT, span=v), "span"),
    (lambda v: blackburn_min_length(CAR, v), "rho"),
])
def test_parking_numbers_refuse_text_and_booleans(call, name):
    """'1' raised "'<=' not supported between instances of 'float' and 'str'"; True was read as 1 rad (a plan) or
    1 m (a slot length)."""
    with pytest.raises(WmrkitError, match=f"^{name}: {re.escape(TEXT)}"):
        call("1")
    with pytest.raises(WmrkitError, match=f"^{name}: {BOOLEANS}"):
        call(True)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: plan_parking("example1", SLOT), "vehicle: expected a wmrkit.parking.Vehicle(a1, b1, c1, h1, track, "
                                             "phi_max), got str 'example1'"),
    (lambda: plan_parking(CAR, {"H": 6.0}), "space: expected a wmrkit.parking.Space(H, J, MS, dx2, final_gap), got "
                                            "dict {'H': 6.0}"),
    (lambda: shortest_slot(CAR, None), "space: expected a wmrkit.parking.Space"),
    (lambda: length_ratio(CAR, 6.0), "space: expected a wmrkit.parking.Space"),
    (lambda: blackburn_min_length(None), "vehicle: expected a wmrkit.parking.Vehicle"),
])
def test_parking_names_a_vehicle_or_space_that_is_none(call, message):
    """Each raised AttributeError: "'str' object has no attribute 'phi_max'"."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}"):
        call()


def test_parking_takes_numpy_numbers():
    import numpy as np

    assert blackburn_min_length(CAR, np.float32(4.0)) == blackburn_min_length(CAR, 4.0)
    assert plan_parking(CAR, SLOT, phi_step=np.float64(0.02)).arcs == plan_parking(CAR, SLOT, phi_step=0.02).arcs
