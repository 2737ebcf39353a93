"""Quantities with units: "250 mm", "90 deg"; plain numbers are SI; nothing else is accepted."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import parse_quantity
from wmrkit.units import UNITS, UnitError, si_unit

# Factors to SI written out independently of units.py.
FACTORS = {
    "length": {"m": 1.0, "mm": 0.001, "cm": 0.01, "dm": 0.1, "km": 1000.0, "um": 1e-6, "\u00b5m": 1e-6, "in": 0.0254,
               "ft": 0.3048},
    "angle": {"rad": 1.0, "mrad": 0.001, "deg": math.pi / 180, "°": math.pi / 180, "turn": 2 * math.pi},
    "speed": {"m/s": 1.0, "mm/s": 0.001, "cm/s": 0.01, "km/h": 1000 / 3600, "mph": 1609.344 / 3600,
              "ft/s": 0.3048, "in/s": 0.0254},
    "angular rate": {"rad/s": 1.0, "mrad/s": 0.001, "deg/s": math.pi / 180, "°/s": math.pi / 180,
                     "rpm": 2 * math.pi / 60, "rev/s": 2 * math.pi, "turn/s": 2 * math.pi},
    "time": {"s": 1.0, "ms": 0.001, "us": 1e-6, "\u00b5s": 1e-6, "ns": 1e-9},
    "frequency": {"Hz": 1.0, "kHz": 1000.0},
}


def _kind(unit: str) -> str:
    return next(kind for kind, table in FACTORS.items() if unit.replace("\u03bc", "\u00b5") in table)


def test_the_unit_tables_are_the_documented_ones():
    assert {k: set(v) for k, v in UNITS.items()} == {**{k: set(v) for k, v in FACTORS.items()}, "number": set()}
    assert [si_unit(k) for k in ("length", "angle", "speed", "angular rate", "time", "frequency", "number")] == [
        "m", "rad", "m/s", "rad/s", "s", "Hz", ""]


@pytest.mark.parametrize(("text", "kind", "si"), [
    ("250 mm", "length", 0.25), ("25cm", "length", 0.25), ("1 in", "length", 0.0254), ("2 ft", "length", 0.6096),
    ("0.5 km", "length", 500.0), ("3 dm", "length", 0.3), ("  1.5 m ", "length", 1.5), ("1e-3", "length", 0.001),
    ("90 deg", "angle", math.pi / 2), ("90°", "angle", math.pi / 2), ("0.25 turn", "angle", math.pi / 2),
    ("1500 mrad", "angle", 1.5), ("-0.5rad", "angle", -0.5), ("+.5 rad", "angle", 0.5),
    ("-45 deg", "angle", -math.pi / 4), ("3.6 km/h", "speed", 1.0), ("500 mm/s", "speed", 0.5),
    ("10 mph", "speed", 4.4704), ("60 rpm", "angular rate", 2 * math.pi), ("30 deg/s", "angular rate", math.pi / 6),
    ("-0.5 rev/s", "angular rate", -math.pi), ("1e3", "angular rate", 1000.0), ("1.5 kHz", "frequency", 1500.0),
    ("20Hz", "frequency", 20.0),
    (3, "angle", 3.0), (0.25, "length", 0.25), ("0.5", "number", 0.5), (-2, "number", -2.0),
])
def test_examples(text, kind, si):
    assert parse_quantity(text, kind) == pytest.approx(si, rel=1e-15)


@settings(max_examples=500)
@given(x=st.floats(-1e6, 1e6), data=st.data())
def test_any_number_with_any_unit(x, data):
    kind = data.draw(st.sampled_from(sorted(FACTORS)))
    unit = data.draw(st.sampled_from(sorted(FACTORS[kind])))
    text = data.draw(st.sampled_from(["{}{}", "{} {}", " {}  {} "])).format(repr(x), unit)
    assert parse_quantity(text, kind) == pytest.approx(x * FACTORS[kind][unit], rel=1e-15, abs=1e-300)
    if kind != "angle" or abs(x) <= 2 * math.pi:  # only a bare angle has a limit (a turn: degrees written bare)
        assert parse_quantity(x, kind) == x  # a plain number is SI
    else:  # a bare angle beyond a turn is refused (issue 8: "beta: 90" read as 90 rad)
        with pytest.raises(UnitError, match="more than a turn"):
            parse_quantity(x, kind)


@pytest.mark.parametrize("value", [90, "90", -60, "7", 6.3, "1e3"])
def test_a_bare_angle_beyond_a_turn_suggests_degrees(value):
    with pytest.raises(UnitError, match=r"write '-?[\d.e+]+ deg' for degrees"):
        parse_quantity(value, "angle")


@pytest.mark.parametrize("value", [6.28, -6.28, "1.5", "-3.14", "90 deg", "400 rad", "-720 deg"])
def test_angles_within_a_turn_or_with_a_unit_are_read(value):
    assert math.isfinite(parse_quantity(value, "angle"))


@pytest.mark.parametrize(("value", "kind", "message"), [
    ("90 mm", "angle", "'90 mm' is a length, expected an angle"),
    ("5 deg", "length", "'5 deg' is an angle, expected a length"),
    ("1 m", "number", "'1 m' is a length, expected a number"),
    ("3 furlong", "length", "unknown unit 'furlong' in '3 furlong' (accepted: m, mm, cm, dm, km, um, \u00b5m, in, ft)"),
    ("3 x", "number", "unknown unit 'x' in '3 x' (accepted: none (a plain number))"),
    ("10 m", "time", "'10 m' is a length, expected a time"),  # 'm' is no minute
    ("10 ms", "speed", "'10 ms' is a time, expected a speed"),  # nor 'ms' a metre per second
    ("10 min", "time", "unknown unit 'min' in '10 min' (accepted: s, ms, us, \u00b5s, ns)"),
    ("pi/2", "angle", "cannot read 'pi/2' as an angle (write e.g. '1.57' or '90 deg')"),
    ("90 deg deg", "angle", "cannot read '90 deg deg' as an angle (write e.g. '1.57' or '90 deg')"),
    ("", "length", "cannot read '' as a length (write e.g. '0.25' or '250 mm')"),
    ("nan", "length", "cannot read 'nan' as a length (write e.g. '0.25' or '250 mm')"),
    ("\u221230 deg", "angle", "cannot read '\u221230 deg' as an angle (write e.g. '1.57' or '90 deg'): "
     "'\\u2212' (MINUS SIGN) is no ASCII character"),  # a minus copied from a PDF looked like the example it refused
    ("\uff13 mm", "length", "cannot read '\uff13 mm' as a length (write e.g. '0.25' or '250 mm'): '\\uff13' "
     "(FULLWIDTH DIGIT THREE) is no ASCII character"),
    (float("nan"), "length", "must be finite, got nan"),
    (float("-inf"), "angle", "must be finite, got -inf"),
    ("1e999 m", "length", "must be finite, got '1e999 m'"),
    ("1e308 km", "length", "must be finite, got '1e308 km'"),
    ("1e308 deg", "angle", "'1e308 deg' is more than 1e+06 turns: no angle to steer, turn or roll by (its sine and "
     "cosine would be round-off)"),  # read as 1.7e306 rad: a fixed wheel shown at 0 deg, computed at about 104 deg
    (10**400, "length", "expected a length, got an integer too large for a float"),
    (True, "angle", "expected an angle, got a boolean"),
    (None, "length", "expected a length, got no value (null)"),  # was NoneType: YAML "H:" or "H: null"
    ([1.0], "length", "expected a length, got list"),
])
def test_rejections_say_why(value, kind, message):
    with pytest.raises(UnitError) as err:
        parse_quantity(value, kind)
    assert str(err.value) == message
    assert isinstance(err.value, ValueError)


@settings(max_examples=500)
@given(st.text(max_size=20) | st.from_type(object), st.sampled_from(["length", "angle", "number"]))
def test_anything_else_is_a_unit_error_or_a_finite_float(value, kind):
    try:
        out = parse_quantity(value, kind)
    except UnitError as err:
        assert len(str(err).splitlines()) <= 1
    else:
        assert isinstance(out, float) and math.isfinite(out)


@pytest.mark.parametrize("text", ["5 um", "5um", "5 \u00b5m", "5 \u03bcm"])
def test_micrometres_are_read(text):
    """The envelope's message says '1 um to 1 km': 'um' (and the micro sign, either code point) is a unit."""
    assert parse_quantity(text, "length") == pytest.approx(5e-6, rel=1e-12)


# Exact decimal factors of the units that have one, written out independently of units.py.
DECIMAL_FACTORS = {"mm": "0.001", "cm": "0.01", "dm": "0.1", "km": "1000", "um": "0.000001", "\u00b5m": "0.000001",
                   "\u03bcm": "0.000001", "in": "0.0254", "ft": "0.3048", "mrad": "0.001", "mm/s": "0.001",
                   "cm/s": "0.01", "mph": "0.44704", "ft/s": "0.3048", "in/s": "0.0254", "mrad/s": "0.001",
                   "ms": "0.001", "us": "0.000001", "\u00b5s": "0.000001", "ns": "0.000000001",
                   "kHz": "1000"}


@pytest.mark.parametrize("unit", sorted(DECIMAL_FACTORS))
def test_decimal_units_give_the_float_nearest_the_quantity_written(unit):
    """'9 mm' is 0.009, the float nearest 9/1000 (as '0.009' is), not 9 * 1e-3 = 0.009000000000000001: one reading in
    seven of a whole number of millimetres was an ulp off, and `wmrkit show --json` wrote 'r: 3 dm' back as
    0.30000000000000004. Fraction -> float rounds once, to the nearest."""
    from fractions import Fraction

    kind = _kind(unit)
    for text in [*(str(n) for n in range(1, 1001)), "0.1", "2.5", "12.7", "1e3", "-7", "3.3e-2"]:
        assert parse_quantity(f"{text} {unit}", kind) == float(Fraction(text) * Fraction(DECIMAL_FACTORS[unit])), text


@settings(max_examples=500)
@given(st.decimals(allow_nan=False, allow_infinity=False, places=6, min_value=-10**6, max_value=10**6),
       st.sampled_from(sorted(DECIMAL_FACTORS)))
def test_any_decimal_with_a_decimal_unit_is_read_exactly(number, unit):
    from fractions import Fraction

    kind = _kind(unit)
    assert parse_quantity(f"{number}{unit}", kind) == float(Fraction(number) * Fraction(DECIMAL_FACTORS[unit]))
