"""The closed forms' symbols and inputs made exact (private; public API in ``symbolic``).

Symbols ``beta_<wheel>``, velocity and geometry symbols; the users' `beta`, `heading` and `geometry` checked (one
located error each) and turned into exact sympy values, as :mod:`.symbolic` keys its cached derivations.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Literal

import numpy as np
import sympy as sp

from ..errors import UnknownNameError
from ..robot import Robot
from ..units import MAX_ANGLE, MAX_TURNS
from ..wheels import GEOMETRY_FIELDS, Wheel, WheelError
from ._symbolic_matrix import AssignmentError, exact_number, geometry_fields

Geometry = Literal["numeric", "symbolic"] | Mapping[str, sp.Expr]


# ---- symbols ---------------------------------------------------------------------------------------------
def steering_symbols(robot: Robot) -> tuple[sp.Symbol, ...]:
    """One real symbol ``beta_<wheel>`` per steering wheel, in the order of ``robot.steer_names`` [rad]."""
    return tuple(sp.Symbol(f"beta_{name}", real=True) for name in robot.steer_names)


def velocity_symbols(robot: Robot) -> tuple[sp.Symbol, ...]:
    """One real symbol per column of the constraint matrix, named as ``robot.velocity_names`` (``vx``, ``w.spin``)."""
    return tuple(sp.Symbol(name, real=True) for name in robot.velocity_names)


def geometry_symbols(robot: Robot) -> dict[str, sp.Symbol]:
    """``{"wheel.field": symbol}`` for every geometric field of every wheel: ``l_<wheel>``, ``alpha_<wheel>``...

    A roller radius is ``r_r_<wheel>``, or ``rr_<wheel>`` where a wheel named ``r_<wheel>`` gives its radius that
    name (equal names would be one sympy symbol: two parameters merged into one).
    """
    names, out = {w.name for w in robot.wheels}, {}
    for w in robot.wheels:
        for f in geometry_fields(w):
            assumptions = {"positive": True} if f in ("r", "r_r", "b") else {"real": True}
            prefix = "rr" if f == "r_r" and f"r_{w.name}" in names else f
            out[f"{w.name}.{f}"] = sp.Symbol(f"{prefix}_{w.name}", **assumptions)
    return out


def _geometry_table(robot: Robot, geometry: Geometry) -> dict[str, sp.Expr]:
    if isinstance(geometry, str):
        if geometry == "numeric":
            return {}
        if geometry == "symbolic":
            return dict(geometry_symbols(robot))
        raise AssignmentError(f"geometry: expected 'numeric', 'symbolic' or a mapping, got {geometry!r}")
    table = {}
    for key, value in geometry.items():
        wheel_name, _, field = str(key).partition(".")
        wheel = robot.wheel(wheel_name)
        if field not in geometry_fields(wheel):
            raise UnknownNameError(f"geometry: wheel '{wheel_name}' ({wheel.type}) has no geometric field "
                                   f"'{field}' (fields: {', '.join(geometry_fields(wheel))})")
        if isinstance(value, bool | np.bool_) or not isinstance(value, sp.Basic | numbers.Real):
            raise AssignmentError(f"geometry['{key}']: expected a sympy expression or a number, got "
                                  f"{type(value).__name__} (strings are never parsed)")
        if isinstance(value, sp.Basic) and value.free_symbols:
            table[key] = value
            continue
        _check_number(wheel, field, value, f"geometry['{key}']")
        table[key] = value if isinstance(value, sp.Basic) else exact_number(float(value), GEOMETRY_FIELDS[field])
    return table


def _check_number(wheel: Wheel, field: str, value: sp.Expr | float, what: str) -> None:
    """A number for a wheel's geometric field passes the rules of :class:`Wheel` (finite, angles of at most
    MAX_TURNS turns, radii > 0, l >= 0): NaN raised numpy's 'SVD did not converge', r = 0 a SingularError about
    the robot."""
    try:
        x = complex(value)
    except (TypeError, OverflowError):  # sympy's zoo, oo, 10**400
        x = complex(math.nan)
    try:
        replace(wheel, **{field: x.real if x.imag == 0 else math.nan})
    except WheelError as err:
        raise AssignmentError(f"{what}: {err}") from None


def _steering_values(robot: Robot, beta: Sequence[sp.Expr | float] | None, heading: Sequence[sp.Expr | float] | None,
                     geometry: tuple[tuple[str, sp.Expr], ...]) -> tuple[sp.Expr, ...]:
    """The thesis's beta per steering wheel: `beta` as given, or from the users' `heading` (0 = rolling straight
    ahead), ``beta = heading + pi/2 - delta`` (:func:`wmrkit.wheels.beta_from_heading`) with delta exact, or the
    wheel's delta symbol of `geometry`; symbols ``beta_<wheel>`` when neither is given."""
    if heading is None:
        return steering_symbols(robot) if beta is None else _angle_values(robot, beta, "beta")
    if beta is not None:
        raise AssignmentError("give the steering configuration as beta (thesis) or heading (rolling direction), "
                              "not both")
    table = dict(geometry)
    wheels = [robot.wheel(n) for n in robot.steer_names]
    delta = [table.get(f"{w.name}.delta", exact_number(w.delta, "angle")) for w in wheels]
    return tuple(h + sp.pi / 2 - d for h, d in zip(_angle_values(robot, heading, "heading"), delta, strict=True))


def _angle_values(robot: Robot, angles: Sequence[sp.Expr | float], what: str) -> tuple[sp.Expr, ...]:
    """One angle per steering wheel (sympy expressions or real numbers, numpy's too), numbers made exact."""
    listed = (isinstance(angles, Sequence) and not isinstance(angles, str)) or np.ndim(angles) == 1
    values = tuple(angles) if listed else None
    if values is None or len(values) != len(robot.steer_names):
        got = f"{len(values)}" if values is not None else f"{type(angles).__name__} {angles!r:.40}"
        raise AssignmentError(f"{what}: expected {len(robot.steer_names)} steering angles "
                              f"({', '.join(robot.steer_names) or 'none'}), got {got}")
    for i, (v, name) in enumerate(zip(values, robot.steer_names, strict=True)):
        if isinstance(v, bool | np.bool_) or not isinstance(v, sp.Basic | numbers.Real):
            raise AssignmentError(f"{what}: expected sympy expressions or numbers, got {type(v).__name__}")
        if not (isinstance(v, sp.Basic) and v.free_symbols) and not _within_turns(v):
            raise AssignmentError(f"{what}[{i}] ({name}): angles must be finite numbers of at most {MAX_TURNS:g} "
                                  f"turns [rad] (their sine is round-off beyond), got {v!r:.40}")
    return tuple(v if isinstance(v, sp.Basic) else exact_number(float(v), "angle") for v in values)


def _within_turns(v: sp.Expr | float) -> bool:
    """A number (sympy's too) that is finite and at most MAX_TURNS turns, as :func:`wmrkit._shapes.as_angles` asks."""
    try:
        x = complex(v)
    except (TypeError, OverflowError):  # zoo, oo, 10**400
        return False
    return x.imag == 0 and abs(x.real) <= MAX_ANGLE


def _geometry_key(robot: Robot, geometry: Geometry) -> tuple[tuple[str, sp.Expr], ...]:
    return tuple(sorted(_geometry_table(robot, geometry).items(), key=lambda kv: kv[0]))
