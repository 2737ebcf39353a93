"""The symbolic constraint matrix (3.22) with exact numbers (private; public API in ``symbolic``).

Each wheel's contact elements go through :func:`wmrkit.wheels.slip_row_entries` with sympy's sin/cos, the same
kernel as :meth:`wmrkit.Robot.constraint_matrix`. Numbers are made exact; offsets are expanded so that only one
pair (sin, cos) per steering angle (or geometry symbol) remains for the exact linear algebra.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Literal

import sympy as sp

from ..errors import WmrkitError
from ..robot import Robot
from ..wheels import GEOMETRY_FIELDS, Wheel, _double_castor, slip_row_entries


class AssignmentError(WmrkitError, ValueError):
    """An assigned-velocity set or a geometry substitution that cannot be used (names the culprit)."""


# ---- exact numbers ---------------------------------------------------------------------------------------
def exact_number(x: float, kind: Literal["length", "angle"]) -> sp.Expr:
    """A float made exact for clean closed forms: ``0.45 -> 9/20``, ``1.5707963267948966 -> pi/2``.

    Angles that are a simple fraction of pi (denominator <= 720) become that multiple of pi; other values become
    the rational with a small denominator (<= 10^4) within 1e-12, else the float's shortest decimal, exactly.
    """
    x = float(x)
    if not math.isfinite(x):
        raise AssignmentError(f"cannot make {x!r} exact")
    nice = _nice_number(x, kind)
    if nice is not None:
        return nice
    q = Fraction(repr(x))
    return sp.Rational(q.numerator, q.denominator)


def _nice_number(x: float, kind: str) -> sp.Expr | None:
    """``x`` as a simple multiple of pi (angles) or a rational of denominator <= 10^4, if within 1e-12."""
    if kind == "angle":
        q = Fraction(x / math.pi).limit_denominator(720)
        if abs(float(q) * math.pi - x) <= 1e-12 * max(1.0, abs(x)):
            return sp.Rational(q.numerator, q.denominator) * sp.pi
    q = Fraction(x).limit_denominator(10_000)
    if abs(float(q) - x) <= 1e-12 * max(1.0, abs(x)):
        return sp.Rational(q.numerator, q.denominator)
    return None


def geometry_fields(wheel: Wheel) -> tuple[str, ...]:
    """The geometric fields a wheel's type uses (its place ``l, alpha`` first); a steering angle is not one."""
    kind = wheel.kind
    fields = ("l", "alpha", *kind.required, *kind.optional)
    return tuple(f for f in dict.fromkeys(fields) if not (f == "beta" and kind.steers))



def _trig(name: str, place: Mapping[sp.Expr, sp.Expr]):
    """sin or cos that expands constant offsets: ``sin(beta + pi/4) -> sqrt(2)/2 (sin beta + cos beta)``.

    A place given as an exact position ``(x, y)`` enters as symbols ``L, A`` with ``place = {cos A: x/L,
    sin A: y/L}``; splitting ``A`` off makes ``L*sin(theta - A)`` exactly ``x sin(theta) - y cos(theta)``. What
    remains is sin/cos of the steering angles, of geometry symbols and of constants (see :func:`_constants`),
    so that one pair (sin, cos) per steering angle enters the exact linear algebra.
    """

    def sin(a: sp.Expr) -> sp.Expr:
        return _split(a, sp.sin, lambda r, t: sin(r) * sp.cos(t) + cos(r) * sp.sin(t), place)

    def cos(a: sp.Expr) -> sp.Expr:
        return _split(a, sp.cos, lambda r, t: cos(r) * sp.cos(t) - sin(r) * sp.sin(t), place)

    return sin if name == "sin" else cos


def _split(a: sp.Expr, fn, addition, place: Mapping[sp.Expr, sp.Expr]) -> sp.Expr:
    terms = sp.Add.make_args(a)
    angles = {atom.args[0] for atom in place}
    special = sp.Add(*(t for t in terms if t.free_symbols & angles))
    if special == a:
        return fn(a).xreplace(place)
    if special != 0:
        return sp.expand(addition(a - special, special).xreplace(place))
    offset = sp.Add(*(t for t in terms if not t.free_symbols))
    if offset != 0 and offset != a:
        return sp.expand(addition(a - offset, offset))
    return fn(a)


def _wheel_blocks(wheel: Wheel, beta: sp.Expr | None, table: dict[str, sp.Expr]) -> list[list[sp.Expr]]:
    """Rows of one wheel over ``(vx, vy, omega, its own rates)``: (3.10) per element, rates through rate_map."""
    given = {f: table[f"{wheel.name}.{f}"] for f in geometry_fields(wheel) if f"{wheel.name}.{f}" in table}
    symbolic = {k: v for k, v in given.items() if k not in ("l", "alpha")}
    unit = wheel.__class__(**{**_wheel_fields(wheel), **symbolic})
    skew_place: dict[sp.Expr, sp.Expr] = {}
    if wheel.type == "double_castor":  # (3.31) exactly: cos(skew) = d / arm, sin(skew) = b / arm, as for a place
        d, b = _exact(unit.d, "length"), _exact(unit.b, "length")
        arm, skew = sp.sqrt(d * d + b * b), sp.Dummy("S", real=True)
        skew_place = {sp.cos(skew): d / arm, sp.sin(skew): b / arm}
        elements = _double_castor(unit, arm, skew)
    else:
        elements = unit.elements()
    rows: list[list[sp.Expr]] = []
    for e in elements:
        l_e, alpha_e, place = _place(e.l, e.alpha, given)
        place = {**place, **skew_place}
        beta_w = beta if beta is not None else _exact(given.get("beta", wheel.beta), "angle")
        args = [beta_w + _exact(e.beta_offset, "angle"), l_e, alpha_e] + [
            _exact(v, GEOMETRY_FIELDS[f]) for f, v in zip(("d", "delta", "gamma", "r", "r_r"), e[3:8], strict=True)
        ]
        entries = slip_row_entries(*args, sin=_trig("sin", place), cos=_trig("cos", place))
        rate_map = sp.Matrix(e.rate_map)
        for row in entries:
            own = (sp.Matrix([list(row[3:])]) * rate_map)[0, :]
            rows.append([_constants(sp.expand(_expr(v))) for v in (*row[:3], *own)])
    return rows


def _place(l: float, alpha: float, given: dict[str, sp.Expr]) -> tuple[sp.Expr, sp.Expr, dict]:
    """Exact ``(l, alpha)``: given symbols, else nice numbers, else from the exact position ``(x, y)``.

    A position ``[-1, 0.45]`` has no nice ``l, alpha``: they become symbols ``L, A`` that :func:`_trig` replaces
    by ``cos A = x/L, sin A = y/L``, so the entries are in -1 and 9/20 (no square roots, no atan).
    """
    if "l" in given or "alpha" in given:
        return given.get("l", exact_number(l, "length")), given.get("alpha", exact_number(alpha, "angle")), {}
    nice_l, nice_alpha = _nice_number(l, "length"), _nice_number(alpha, "angle")
    if nice_l is not None and nice_alpha is not None:
        return nice_l, nice_alpha, {}
    x, y = _snap(l * math.cos(alpha), l), _snap(l * math.sin(alpha), l)
    big_l, big_a = sp.Dummy("L", positive=True), sp.Dummy("A", real=True)
    return big_l, big_a, {sp.cos(big_a): x / big_l, sp.sin(big_a): y / big_l}


def _constants(e: sp.Expr) -> sp.Expr:
    """sin/cos of a number that sympy leaves unevaluated (a fixed axle at 0.3 rad or 52 deg) -> its float, exactly.

    ``sin(pi/6) = 1/2`` and ``cos(pi/4) = sqrt(2)/2`` are exact already; ``cos(3/10)`` or ``cos(13 pi/45)`` would
    be two more variables of the rational-function field each (eight Swedish wheels at odd angles: minutes).
    A nested root (``sin(2 pi/5) = sqrt(5/8 + sqrt(5)/8)``) becomes its float too: no generator covers it.
    """
    table = {}
    for atom in e.atoms(sp.sin, sp.cos):
        if not atom.args[0].free_symbols:
            table[atom] = exact_number(float(atom), "length")
    for atom in e.atoms(sp.Pow):  # a nested root (sin(2 pi/5)): no generator, the algebra would fall back to EX
        if not atom.free_symbols and atom.exp.is_Rational and not atom.base.is_Rational:
            table[atom] = exact_number(float(atom), "length")
    return e.xreplace(table) if table else e


def _expr(v) -> sp.Expr:
    return v if isinstance(v, sp.Basic) else exact_number(v, "length")


def _wheel_fields(wheel: Wheel) -> dict:
    return {f: getattr(wheel, f) for f in wheel.__dataclass_fields__}


def _snap(v: float, scale: float) -> sp.Expr:
    return sp.Integer(0) if abs(v) <= 1e-12 * max(scale, 1e-300) else exact_number(v, "length")


def _exact(v, kind: str) -> sp.Expr:
    return v if isinstance(v, sp.Basic) else exact_number(v, "angle" if kind == "angle" else "length")


@functools.lru_cache(maxsize=64)
def constraint(robot: Robot, beta: tuple[sp.Expr, ...], geometry: tuple) -> sp.ImmutableMatrix:
    table = dict(geometry)
    steer = dict(zip(robot.steer_names, beta, strict=True))
    n_rates = len(robot.rate_names)
    rows, start = [], 0
    for w in robot.wheels:
        n = len(w.kind.rates)
        for row in _wheel_blocks(w, steer.get(w.name), table):
            rows.append([*row[:3], *([0] * start), *row[3:], *([0] * (n_rates - start - n))])
        start += n
    return sp.ImmutableMatrix(rows)


def gear_rows(robot: Robot) -> sp.ImmutableMatrix:
    """``q_i / ratio_i - q_j / ratio_j`` (exact) per pair of consecutive joints of each ``gear`` coupling of
    `robot`, over ``robot.velocity_names``: the rows a gear adds under ``A`` (3.22). ``(n_pairs, k)``."""
    names, rows = robot.velocity_names, []
    for c in (c for c in robot.couplings if c.kind == "gear"):
        for (i, ki), (j, kj) in itertools.pairwise(zip(c.joints, c.ratios, strict=True)):
            row = [sp.Integer(0)] * len(names)
            row[names.index(i)], row[names.index(j)] = 1 / exact_number(ki, "length"), -1 / exact_number(kj, "length")
            rows.append(row)
    return sp.ImmutableMatrix(len(rows), len(names), [v for row in rows for v in row])
