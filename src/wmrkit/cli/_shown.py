"""How the commands show results: round-off as 0, never a negative zero, and one line naming each file written.

A computed value within :data:`ROUNDOFF` of its quantity's scale (the largest magnitude among the values it is
computed from or printed with, in the same unit) is round-off, not a result: printed as 0 in text (a straight run's
``theta = -0.000000 rad``, ``rotation 3.5e-16 rad``). A value above it, however small in absolute terms (a slip of
1e-9 m on a 1 m step), is printed as computed. Files (CSV, JSON) keep the computed values, but never a ``-0``.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable

import numpy as np

from ..kinematics.summary import ROUNDOFF


def tidy(value: float, scale: float) -> float:
    """`value` as a result to print: 0.0 when ``|value| <= ROUNDOFF * |scale|``, the round-off of a quantity of
    magnitude `scale` (>= |value| is not required: pass the magnitudes it comes from); never -0.0."""
    value = float(value)
    return 0.0 if abs(value) <= ROUNDOFF * abs(float(scale)) else value + 0.0  # + 0.0: -0.0 becomes 0.0


def tidy_pose(pose: Iterable[float], travelled: float, size: float) -> tuple[float, float, float]:
    """A final pose ``(x [m], y [m], theta [rad])`` with its round-off printed as 0. x, y: the scale is the largest
    of |x|, |y| and the path length `travelled` [m] (what their round-off accumulates over); theta: the largest of
    |theta| and ``travelled / size`` [rad], the turn a relative round-off of the wheels' motion makes over the path
    on a robot of characteristic length `size` [m]."""
    x, y, theta = (float(v) for v in pose)
    reach = max(abs(x), abs(y), abs(travelled))
    return tidy(x, reach), tidy(y, reach), tidy(theta, max(abs(theta), abs(travelled) / size))


def tidy_twist(twist: Iterable[float], size: float) -> tuple[float, float, float]:
    """A twist ``(vx, vy [m/s], omega [rad/s])`` with its round-off printed as 0: the scale is the largest of |vx|,
    |vy| and ``|omega| size`` (in m/s; over `size` for omega), `size` the robot's characteristic length [m]."""
    vx, vy, omega = (float(v) for v in twist)
    speed = twist_speed((vx, vy, omega), size)
    return tidy(vx, speed), tidy(vy, speed), tidy(omega, speed / size)


def twist_speed(twist: Iterable[float], size: float) -> float:
    """The speed scale [m/s] of a twist ``(vx, vy, omega)``: the largest of |vx|, |vy| and ``|omega| size``."""
    vx, vy, omega = (abs(float(v)) for v in twist)
    return max(vx, vy, omega * size)


def cell(value: float, scale: float) -> str:
    """A table cell: ``-`` for an undefined value (NaN), else :func:`tidy` with 6 significant digits."""
    return "-" if value != value else f"{tidy(value, scale):.6g}"


def fixed(value: float, decimals: int) -> str:
    """`value` with `decimals` decimals, without the sign of a value that rounds to 0 (``-0.000000``)."""
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and not text.strip("-0.") else text


def no_negative_zero(values: np.ndarray) -> np.ndarray:
    """`values` with every -0.0 made 0.0 (``-0`` in a CSV cell, ``-0.0`` in JSON); other values unchanged."""
    return np.asarray(values, dtype=float) + 0.0


def written(what: str, path: object) -> None:
    """Say on stderr that the command wrote `what` (``plot``, ``animation``, ``samples``...) to `path`: one line
    ``wmrkit: WHAT written to PATH``, with or without ``--json`` (whose stdout stays the JSON answer alone)."""
    print(f"wmrkit: {what} written to {path}", file=sys.stderr)
