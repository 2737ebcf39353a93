"""Quantities with units in descriptions and on the command line ("90 deg", "250 mm", "0.5 rad").

Everything inside wmrkit is SI: metres, radians and seconds. A plain number is taken as SI. Strings are parsed with a
small fixed grammar (number, optional space, unit); nothing is ever evaluated.
"""

from __future__ import annotations

import decimal
import math
import numbers
import re
import unicodedata
from typing import Literal

from ._numbers import NUMBER

Kind = Literal["length", "angle", "speed", "angular rate", "time", "frequency", "number"]

#: Factor to SI for every unit accepted, by kind.
UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "dm": 0.1, "km": 1e3, "um": 1e-6, "\u00b5m": 1e-6, "in": 0.0254,
               "ft": 0.3048},
    "angle": {"rad": 1.0, "mrad": 1e-3, "deg": math.pi / 180, "°": math.pi / 180, "turn": 2 * math.pi},
    "speed": {"m/s": 1.0, "mm/s": 1e-3, "cm/s": 1e-2, "km/h": 1 / 3.6, "mph": 0.44704, "ft/s": 0.3048,
              "in/s": 0.0254},
    "angular rate": {"rad/s": 1.0, "mrad/s": 1e-3, "deg/s": math.pi / 180, "°/s": math.pi / 180,
                     "rpm": 2 * math.pi / 60, "rev/s": 2 * math.pi, "turn/s": 2 * math.pi},
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "\u00b5s": 1e-6, "ns": 1e-9},
    "frequency": {"Hz": 1.0, "kHz": 1e3},
    "number": {},
}
_SI = {"length": "m", "angle": "rad", "speed": "m/s", "angular rate": "rad/s", "time": "s", "frequency": "Hz",
       "number": ""}
#: The units whose factor is 1, or no decimal (pi's, 1/3.6): a quantity in them is the number times the factor.
_NOT_DECIMAL = ("m", "rad", "deg", "°", "turn", "m/s", "km/h", "rad/s", "deg/s", "°/s", "rpm", "rev/s", "turn/s", "s",
                "Hz")
#: The units whose factor is a decimal number, exactly: a quantity in them is read as the decimal it is ("9 mm" is
#: 0.009, the float nearest 9e-3), not as the product of two rounded floats (9 * 1e-3 = 0.009000000000000001):
#: every unit of UNITS but those of _NOT_DECIMAL, its factor as the decimal it was written as (repr gives it back).
_DECIMAL = {unit: decimal.Decimal(repr(factor)) for table in UNITS.values() for unit, factor in table.items()
            if unit not in _NOT_DECIMAL}
#: Enough digits for any number a description holds; no traps: an overflow gives inf, refused as not finite.
_CONTEXT = decimal.Context(prec=10_000, Emax=decimal.MAX_EMAX, Emin=decimal.MIN_EMIN, traps=[])
#: The number of the tables' fields (ASCII digits only: ``\d`` also matched '٣' and '１', which float() read as 3 and
#: 1), then a unit.
_QUANTITY = re.compile(rf"^\s*({NUMBER})\s*([^\s0-9.+-][^\s]*)?\s*$")


class UnitError(ValueError):
    """A value that is not a number of the expected kind; the message says why."""


def parse_quantity(value: object, kind: Kind) -> float:
    """Return `value` in SI units (m, rad, m/s, rad/s or s) as a finite float.

    Accepts real numbers (Python's, NumPy's of any precision) and strings such as ``"90 deg"``, ``"250 mm"``,
    ``"-0.5rad"``, ``"1e-3"``, ``"30 deg/s"``, ``"120 rpm"``, ``"3.6 km/h"``, ``"10 ms"``.
    Raises :class:`UnitError` for booleans, NaN, infinities, unknown units and units of the wrong kind, and for
    a bare angle (no unit, so radians) beyond a turn, ``|angle| > 2 pi``: almost surely degrees written bare; and
    for an angle beyond :data:`MAX_TURNS` turns in any unit.
    """
    if isinstance(value, bool):
        raise UnitError(f"expected {_a(kind)}, got a boolean")
    if isinstance(value, numbers.Real):  # int, float, and NumPy's float32, int64, ... (not its bool_)
        try:
            number = si = float(value)
        except OverflowError:
            raise UnitError(f"expected {_a(kind)}, got an integer too large for a float") from None
    elif isinstance(value, str):
        match = _QUANTITY.match(value)
        if match is None:
            raise UnitError(f"cannot read {value!r} as {_a(kind)} (write e.g. {_example(kind)}){_foreign(value)}")
        number, unit = float(match.group(1)), (match.group(2) or "").replace("\u03bc", "\u00b5")  # μm as µm
        factor = _factor(unit, kind, value)
        exact = _DECIMAL.get(unit) if number and math.isfinite(number) else None  # '1e99999 mm': inf, refused below
        si = number * factor if exact is None else float(_CONTEXT.multiply(decimal.Decimal(match.group(1)), exact))
    else:
        got = "no value (null)" if value is None else type(value).__name__  # YAML's 'H:' or 'H: null'
        raise UnitError(f"expected {_a(kind)}, got {got}")
    if not math.isfinite(si):  # "1e308 km" overflows only in SI
        raise UnitError(f"must be finite, got {value!r}")
    if kind == "angle" and abs(si) > MAX_ANGLE:
        raise UnitError(f"{value!r} is more than {MAX_TURNS:g} turns: no angle to steer, turn or roll by (its sine and "
                        "cosine would be round-off)")
    if kind == "angle" and _bare(value) and abs(number) > BARE_ANGLE_LIMIT:
        raise UnitError(f"a bare angle is read in radians, and {_plain(number)} rad is more than a turn: "
                        f"write '{_plain(number)} deg' for degrees (or '{_plain(number)} rad' if you mean it)")
    return si


#: A bare angle (no unit: radians) beyond this is refused as probably degrees [rad].
BARE_ANGLE_LIMIT = 2 * math.pi
#: Largest angle in any unit: 1e6 turns [rad]. '1e308 deg' was read as 1.7e306 rad, whose sine and cosine are noise
#: (and which wheels.wrap_angle gave back as 0).
MAX_TURNS = 1e6
MAX_ANGLE = 2 * math.pi * MAX_TURNS


def _bare(value: object) -> bool:
    return not isinstance(value, str) or _QUANTITY.match(value).group(2) in (None, "")  # type: ignore[union-attr]


def _foreign(text: str) -> str:
    """The first character of `text` that is no ASCII nor a unit's symbol, named: a minus sign copied from a PDF
    (U+2212) or a full-width digit looks like the example the message gives; '' when there is none."""
    char = next((c for c in text if not c.isascii() and not c.isspace() and c not in "\u00b0\u00b5\u03bc"), None)
    return "" if char is None else f": {char!a} ({unicodedata.name(char, 'no name')}) is no ASCII character"


def _plain(number: float) -> str:
    return f"{number:g}"


def _factor(unit: str, kind: Kind, text: str) -> float:
    if not unit:
        return 1.0
    if unit in UNITS[kind]:
        return UNITS[kind][unit]
    for other, table in UNITS.items():
        if unit in table:
            raise UnitError(f"{text!r} is {_a(other)}, expected {_a(kind)}")
    accepted = ", ".join(UNITS[kind]) or "none (a plain number)"
    raise UnitError(f"unknown unit {unit!r} in {text!r} (accepted: {accepted})")


def _a(kind: str) -> str:
    return f"an {kind}" if kind[0] in "aeiou" else f"a {kind}"


def _example(kind: Kind) -> str:
    return {"length": "'0.25' or '250 mm'", "angle": "'1.57' or '90 deg'", "speed": "'0.5' or '500 mm/s'",
            "angular rate": "'0.5' or '30 deg/s' or '60 rpm'", "time": "'0.01' or '10 ms'",
            "frequency": "'20' or '1 kHz'", "number": "'0.5'"}[kind]


#: A CSV column name carrying its unit in brackets: ``time [ms]``, ``left.spin [N m]``.
_BRACKETED = re.compile(r"^\s*([^\[\]]*?)\s*\[\s*([^\[\]]+?)\s*\]\s*$")


def split_unit(column: str) -> tuple[str, str] | None:
    """``(name, unit)`` of a column name ending in a bracketed unit (``'time [ms]'`` -> ``('time', 'ms')``), else
    None; the CSV headers of logs and of torque files."""
    match = _BRACKETED.match(column)
    return None if match is None else (match.group(1), match.group(2))


def si_unit(kind: Kind) -> str:
    """The SI unit wmrkit uses inside for `kind` ("m", "rad", "m/s", "rad/s", "s", "Hz" or "")."""
    return _SI[kind]
