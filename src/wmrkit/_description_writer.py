"""A :class:`~wmrkit.robot.Robot` written back as a description mapping (:func:`robot_to_dict`), losslessly: each
wheel as users write it (``position``, ``heading``, ``type: mecanum``) where that reads back to exactly it, else in
the thesis's parameters. :mod:`wmrkit.description` re-exports it and writes the files.
"""

from __future__ import annotations

import itertools
import math
import numbers
from collections.abc import Callable
from typing import Any

from ._description_wheels import _wheel_from_dict
from .documents import DescriptionError, FieldReader
from .dynamics import mass
from .robot import Robot
from .units import BARE_ANGLE_LIMIT
from .wheels import GEOMETRY_FIELDS, Wheel, beta_from_heading

#: ulps around a heading computed back from beta and delta where the writer looks for the heading that gave them
#: (``beta = heading - delta + 90 deg`` and back round twice each way: castors with delta != 0 came out an ulp off).
HEADING_SPREAD = 4


def robot_to_dict(robot: Robot, *, thesis: bool = False) -> dict[str, Any]:
    """The description mapping of `robot` in SI numbers and radians, its wheels as users write them where that is
    exact (:func:`_wheel_to_dict`), or with `thesis` in the thesis's parameters (``l``, ``alpha``, ``beta``, the
    fields ``wmrkit sweep --vary`` sets); ``robot_from_dict(robot_to_dict(r)) == r`` either way."""
    out: dict[str, Any] = {"name": robot.name}
    if robot.notes:
        out["notes"] = robot.notes
    out |= mass.body_to_dict(robot.body)
    out["wheels"] = [_thesis_form(w) if thesis else _wheel_to_dict(w) for w in robot.wheels]
    if robot.odometry is not None:
        from .slip.settings import settings_to_dict

        entries = settings_to_dict(robot.odometry)
        out |= {k: v for k, v in entries.items() if k == "odometry"}
        for w in out["wheels"]:
            w |= entries.get("wheels", {}).get(w["name"], {})
    if robot.couplings:
        out["couplings"] = [{"kind": c.kind, "joints": list(c.joints), "ratios": list(c.ratios)}
                            | ({"law": c.law} if c.law is not None else {}) for c in robot.couplings]
    return out


def described_type(w: Wheel) -> str:
    """The wheel's type as a description would write it: ``mecanum`` for a Swedish wheel with the rollers of
    ``type: mecanum`` (the standard X layout of WPILib and ROS 2, from its quadrant), else its kind."""
    return _wheel_to_dict(w)["type"] if w.type == "swedish" else w.type


def _wheel_to_dict(w: Wheel) -> dict[str, Any]:
    """The wheel as users write it where that reads back to exactly this wheel (:func:`_users_form`), else in the
    thesis's parameters."""
    thesis = _thesis_form(w)
    if any(hasattr(getattr(w, k), "free_symbols") for k in ("l", "alpha", "beta", "delta")):
        return thesis  # symbolic parameters (wmrkit.kinematics.symbolic): no numbers to round
    users = _users_form(w, thesis)
    return users if _reads_back(users) == w else thesis


def _users_form(w: Wheel, thesis: dict[str, Any]) -> dict[str, Any]:
    """`thesis` (the wheel's fields in the thesis's parameters) with ``position: [x, y]`` for ``l``, ``alpha`` and
    ``heading`` [rad] (0 = straight ahead) for ``beta``, each rounded to the fewest decimals that give back the exact
    parameters (a wheel read from ``position: [0.25, -0.3]`` is written so); a Swedish wheel with the rollers of
    ``type: mecanum`` as one. A parameter that no such number gives back stays as it is."""
    position = _fewest_digits(w.position, w.l, lambda x, y: math.hypot(x, y) == w.l and math.atan2(y, x) == w.alpha)

    def gives_beta(h: float) -> bool:  # within a turn: a bare angle beyond reads as degrees
        return abs(h) <= BARE_ANGLE_LIMIT and float(beta_from_heading(h, w.delta)) == w.beta

    # the heading in (-180, 180] deg, else as written beyond it (-180 deg, a steer_range's 200 deg, ...)
    heading = (_fewest_digits((w.heading,), math.pi, gives_beta, HEADING_SPREAD)
               or _fewest_digits((w.beta + w.delta - math.pi / 2,), math.pi, gives_beta, HEADING_SPREAD))
    out = {"name": w.name, "type": w.type}
    out |= {"l": thesis["l"], "alpha": thesis["alpha"]} if position is None else {"position": list(position)}
    out |= {"beta": thesis["beta"]} if heading is None else {"heading": heading[0]}
    out |= {k: v for k, v in thesis.items() if k not in out and k not in ("l", "alpha", "beta")}
    if w.type == "swedish":  # type: mecanum takes gamma from the quadrant, r_r = r / 4 by default
        mecanum = {k: v for k, v in out.items() if k != "gamma" and (k != "r_r" or v != w.r / 4)} | {"type": "mecanum"}
        if _reads_back(mecanum) == w:
            return mecanum
    return out


def _fewest_digits(values: tuple[float, ...], scale: float, exact: Callable[..., bool],
                   spread: int = 0) -> tuple[float, ...] | None:
    """`values` rounded to the fewest decimals (1 to 18 significant digits of `scale`, each value its own: the x of
    ``position: [0, 0.30000000000000004]`` is 0, not 2e-17) for which ``exact(*values)`` holds, or None. With
    `spread`, the floats up to `spread` ulps from each value are rounded too: a number computed back from the
    wheel's parameters may be a few ulps off the one that gave them."""
    top = math.floor(math.log10(scale)) if 0 < scale < math.inf else 0
    # a number farther than 64 ulps of `scale` from its value changes a parameter of that size by more than its
    # float spacing: it cannot be exact, and is not tried (each `exact` call costs; a 64-wheel robot has 128 numbers)
    near = 64 * math.ulp(scale) if 0 < scale < math.inf else math.inf
    rounded = [[[c for c in dict.fromkeys(round(v, n - 1 - top) + 0.0 for v in _floats_near(float(value), spread))
                 if abs(c - value) <= near] for n in range(1, 19)]  # rounded[i][n - 1]: values[i] to n digits
               for value in values]  # (+ 0.0: no -0.0)
    usable = [[n for n in range(1, 19) if r[n - 1]] for r in rounded]  # digit counts with a candidate left
    if not all(usable):
        return None
    # fewest digits first: the largest count, then their sum, then in order
    for digits in sorted(itertools.product(*usable), key=lambda c: (max(c), sum(c), c)):
        for candidate in itertools.product(*(r[n - 1] for r, n in zip(rounded, digits, strict=True))):
            if exact(*candidate):
                return candidate
    return None


def _floats_near(value: float, spread: int) -> list[float]:
    """`value` and the floats up to `spread` ulps either side of it."""
    out, up, down = [value], value, value
    for _ in range(spread):
        up, down = math.nextafter(up, math.inf), math.nextafter(down, -math.inf)
        out += [up, down]
    return out


def _reads_back(item: dict[str, Any]) -> Wheel | None:
    """The wheel that `item` describes, as a description reads it; None if it does not read."""
    try:
        return _wheel_from_dict(item, FieldReader("<written>", lambda loc: None), ("wheels", 0))
    except DescriptionError:
        return None


def _thesis_form(w: Wheel) -> dict[str, Any]:
    kind = w.kind
    out: dict[str, Any] = {"name": w.name, "type": w.type, "l": _plain(w.l), "alpha": _plain(w.alpha)}
    for key in GEOMETRY_FIELDS:
        if key in kind.required or key in kind.optional:
            out[key] = _plain(getattr(w, key))
    for key, value in out.items():  # a bare angle beyond a turn reads as degrees written bare: keep the unit
        if GEOMETRY_FIELDS.get(key) == "angle" and abs(value) > BARE_ANGLE_LIMIT:
            out[key] = f"{value!r} rad"
    if w.actuated:
        out["actuated"] = list(w.actuated)
    if w.sensed:
        out["sensed"] = list(w.sensed)
    if w.steer_range is not None:
        out["steer_range"] = [_plain(v) for v in w.steer_range]
    return out | mass.wheel_dynamics_to_dict(w)


def _plain(value: Any) -> Any:
    """A NumPy number of a wheel built in Python (``Wheel(..., r=np.float32(0.1))``) as a Python float, which YAML
    and JSON can write; other values as they are."""
    return float(value) if isinstance(value, numbers.Real) and type(value) not in (int, float) else value
