"""The Python doors of `wmrkit.parking`, `wmrkit.analysis` and `wmrkit.odometry` read no units
(docs/conventions.md): text, booleans and arrays where one number goes are refused naming the argument, and so are a
name where a Vehicle or Space goes and NaN where it would be returned. Before, each raised a bare TypeError,
AttributeError or IndexError from deep inside, or read '1' as 1 (rad, m)."""

from __future__ import annotations

import math
import re

import pytest

from wmrkit import catalog
from wmrkit.analysis import (
    analyze,
    best_configurations,
    condition_map,
    condition_number,
    is_singular,
    isotropy_matrix,
    optimize_geometry,
    singularity_distance,
    twist_condition_number,
)
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


SWERVE = catalog.load("swerve-4")
ACKERMANN = catalog.load("ackermann")
TWIST = ("vx", "vy", "omega")


@pytest.mark.parametrize(("call", "name"), [
    (lambda v: analyze(ACKERMANN, length=v), "length"),
    (lambda v: condition_map(SWERVE, length=v), "length"),
    (lambda v: twist_condition_number(SWERVE, length=v), "length"),
    (lambda v: singularity_distance(SWERVE, None, TWIST, length=v), "length"),
    (lambda v: isotropy_matrix(SWERVE, None, TWIST, ("front_left.spin",), length=v), "length"),
    (lambda v: best_configurations(SWERVE, length=v, resolution=8), "length"),
    (lambda v: is_singular(SWERVE, None, TWIST, rtol=v), "rtol"),
    (lambda v: optimize_geometry(lambda x: SWERVE, v), "x0"),
])
def test_analysis_numbers_refuse_text_and_booleans(call, name):
    """'1' raised "'<' not supported between instances of 'int' and 'str'" (or was read as 1 m by
    best_configurations, 1 by optimize_geometry); True was 1 m."""
    with pytest.raises(WmrkitError, match=f"^{name}: {re.escape(TEXT)}"):
        call("1")
    with pytest.raises(WmrkitError, match=f"^{name}: {BOOLEANS}"):
        call(True)


@pytest.mark.parametrize(("call", "message"), [
    (lambda: best_configurations(SWERVE, length=math.nan, resolution=8), "length: must be a finite number > 0 m, "
                                                                          "got nan"),
    (lambda: best_configurations(SWERVE, length=-1.0, resolution=8), "length: must be a finite number > 0 m, got -1"),
    (lambda: is_singular(SWERVE, None, TWIST, rtol=math.nan), "rtol: expected a finite relative tolerance >= 0, got "
                                                             "nan"),
    (lambda: is_singular(SWERVE, None, TWIST, rtol=-1.0), "rtol: expected a finite relative tolerance >= 0"),
    (lambda: is_singular(SWERVE, None, TWIST, rtol=[1e-8]), "rtol: expected one real number, got an array"),
    (lambda: condition_number("1 m"), "condition_number: h: got the text '1 m'"),
    (lambda: optimize_geometry(lambda x: SWERVE, None), "x0: expected a vector of finite numbers"),
    (lambda: optimize_geometry(lambda x: SWERVE, [math.nan]), "x0: expected a vector of finite numbers"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], bounds=1.0), "bounds: expected one finite (low, high) per "
                                                                      "parameter, shape (1, 2), got 1.0"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], starts=1e9), "starts must be an integer >= 1, got 1000000000"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], seed="1"), "seed must be an integer >= 0, got '1'"),
    (lambda: optimize_geometry(lambda x: SWERVE, [1.0], samples=10**9), "samples must be at most 100000"),
])
def test_analysis_values_that_were_taken_or_raised_bare_errors_are_named(call, message):
    """best_configurations returned configurations of length nan or -1 m; is_singular(rtol=nan) answered False,
    -1 False, [1e-8] an array; optimize_geometry returned x = [nan] from x0 = None or NaN and raised bare
    TypeErrors for bounds, starts and seed ('SeedSequence expects int ...')."""
    with pytest.raises(WmrkitError, match=f"^{re.escape(message)}"):
        call()


def test_analysis_takes_numpy_numbers():
    import numpy as np

    np.testing.assert_array_equal(twist_condition_number(SWERVE, length=np.float32(0.5)),
                                  twist_condition_number(SWERVE, length=float(np.float32(0.5))))
    assert is_singular(SWERVE, None, TWIST, rtol=np.float64(1e-8)) == is_singular(SWERVE, None, TWIST)
