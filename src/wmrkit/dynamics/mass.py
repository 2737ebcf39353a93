"""Mass properties and tyres in robot descriptions (thesis Table 7.2): parsing, validation and serialisation.

A description may carry, all optional (``docs/dynamics.md``, ``docs/description-format.md``)::

    body: {mass: 2500, inertia: 1500, com: [-1.45, 0], com_height: 0.7}   # kg, kg m^2, m, m
    wheels:
      - name: left_drive
        ...
        inertia: {spin: 1.0}              # kg m^2 about the axle; 'steer' about the steering axis; 'roller'
        tyre: {model: pacejka, shifts: 1} # a model of wmrkit.dynamics.tyres.TYRES and its parameters
        mass: 3.0                         # kg, castor units only (their CM at the wheel centre)

``body`` is the thesis's vehicle* (7.17): mass ``M_T`` and z-inertia ``I_T`` about the centre of mass, without the
castor units (which carry their own ``mass`` and ``inertia.steer``) but with the z-inertia of the centred steering
units (steerable and double wheels: their ``inertia.steer`` enters as ``I_os (beta_dot^2 + 2 beta_dot omega)/2``).
The functions here are called from :mod:`wmrkit.description` with its located-error checker.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..limits import MAX_SIZE
from .tyres import TYRES, Tyre, param_problem

BODY_FIELDS = ("mass", "inertia", "com", "com_height")
#: Heaviest body [kg]: a thousand tonnes, whose whole weight (9.8e6 N) one tyre still takes (``tyres.MAX_LOAD``, 1e7 N);
#: a body of 1e300 kg was simulated with normal loads of 1e300 N and printed slip speeds of 2e295 m/s.
MAX_MASS = 1e6
INERTIA_JOINTS = {"spin": "spin", "steer": "steer", "roller": "roller"}
CASTOR_TYPES = ("castor", "double_castor")
CENTRED_STEER_TYPES = ("steerable", "double")


_HEAVY = f"at most {MAX_MASS:g} kg (a thousand tonnes: its weight on one tyre within the largest load a tyre takes)"


@dataclass(frozen=True, slots=True)
class Body:
    """Mass properties of the vehicle* (thesis Table 7.2), SI: kg, kg m^2, m (robot frame R)."""

    mass: float
    inertia: float  # z-inertia about the centre of mass
    com: tuple[float, float] = (0.0, 0.0)  # centre of mass (x, y) in R
    com_height: float = 0.0  # height of the centre of mass above the ground (load transfer, 7.64)


def body_problem(body: Body) -> str:
    """Why `body` cannot be a robot's mass properties (a phrase for a one-line error naming the field), or ``""``:
    what a description's ``body`` section allows (:func:`body_from_dict`)."""
    if not 0 < body.mass < math.inf:  # NaN included
        return f"body.mass: expected a finite number > 0 kg, got {body.mass}"
    if body.mass > MAX_MASS:
        return f"body.mass: {_HEAVY}, got {body.mass:g} kg"
    if not 0 < body.inertia < math.inf:
        return f"body.inertia: expected a finite number > 0 kg m^2, got {body.inertia}"
    if len(body.com) != 2 or not all(abs(c) <= MAX_SIZE for c in body.com):
        return f"body.com: expected two lengths within {MAX_SIZE:g} m, got {tuple(body.com)}"
    if not 0 <= body.com_height <= MAX_SIZE:
        return f"body.com_height: expected a length in [0, {MAX_SIZE:g}] m, got {body.com_height}"
    return ""


def body_from_dict(data: Mapping[str, Any], check: Any) -> Body | None:
    """The ``body`` section of a description, or None when absent; errors located by `check` (a ``FieldReader``)."""
    if "body" not in data:
        return None
    loc: tuple[str | int, ...] = ("body",)
    item = data["body"]
    if not isinstance(item, Mapping):
        check.fail("must be a mapping {mass, inertia, com: [x, y], com_height}", loc)
    check.reject_unknown(item, BODY_FIELDS, loc)
    mass = _positive(check, check.require(item, "mass", loc), (*loc, "mass"), "kg")
    if mass > MAX_MASS:
        check.fail(f"{_HEAVY}, got {mass:g} kg", (*loc, "mass"))
    inertia = _positive(check, check.require(item, "inertia", loc), (*loc, "inertia"), "kg m^2")
    com = item.get("com", [0.0, 0.0])
    if not isinstance(com, list | tuple) or len(com) != 2:
        check.fail("must be a list [x, y] of two lengths", (*loc, "com"))
    x, y = (check.quantity(v, "length", (*loc, "com", j)) for j, v in enumerate(com))
    height = check.quantity(item.get("com_height", 0.0), "length", (*loc, "com_height"))
    if height < 0:
        check.fail(f"must be >= 0, got {height} m", (*loc, "com_height"))
    for key, value in ((("com", 0), x), (("com", 1), y), (("com_height",), height)):  # the envelope of limits.py
        if abs(value) > MAX_SIZE:
            check.fail(f"{value:g} m: farther than {MAX_SIZE:g} m, outside the lengths wmrkit handles", (*loc, *key))
    return Body(mass, inertia, (x, y), height)


def body_to_dict(body: Body | None) -> dict[str, Any]:
    """``{"body": {...}}`` in SI numbers, or ``{}``."""
    if body is None:
        return {}
    return {"body": {"mass": body.mass, "inertia": body.inertia, "com": list(body.com),
                     "com_height": body.com_height}}


def wheel_dynamics_from_dict(item: Mapping[str, Any], check: Any, loc: tuple, type_name: str) -> dict[str, Any]:
    """The Wheel fields ``spin_inertia, steer_inertia, roller_inertia, mass, tyre`` given in a wheel mapping."""
    out: dict[str, Any] = {}
    if "inertia" in item:
        inertia = item["inertia"]
        if not isinstance(inertia, Mapping) or not inertia:
            check.fail("must be a mapping of joint inertias [kg m^2], e.g. {spin: 1.0, steer: 0.8}", (*loc, "inertia"))
        check.reject_unknown(inertia, inertia_joints(type_name), (*loc, "inertia"))
        for joint in inertia:
            value = check.quantity(inertia[joint], "number", (*loc, "inertia", joint))
            if value < 0:
                check.fail(f"must be >= 0, got {value} kg m^2", (*loc, "inertia", joint))
            out[f"{joint}_inertia"] = value
    if "mass" in item:
        if type_name not in CASTOR_TYPES:
            check.fail(f"'mass' applies to castor units only (a {type_name} wheel belongs to the body mass)",
                       (*loc, "mass"))
        out["mass"] = check.quantity(item["mass"], "number", (*loc, "mass"))
        if out["mass"] < 0:
            check.fail(f"must be >= 0, got {out['mass']} kg", (*loc, "mass"))
    if "tyre" in item:
        out["tyre"] = tyre_from_dict(item["tyre"], check, (*loc, "tyre"))
    return out


def inertia_joints(type_name: str) -> tuple[str, ...]:
    """The joints whose ``inertia`` a wheel kind's description takes: those among its rates (``spin1``, ``spin2``:
    ``spin``) and ``steer`` where it steers."""
    from ..wheels import KINDS

    kind = KINDS[type_name]
    return tuple(j for j in INERTIA_JOINTS if j in kind.rates or any(r.startswith(j) for r in kind.rates)
                 or (j == "steer" and kind.steers))


def tyre_from_dict(item: Any, check: Any, loc: tuple) -> Tyre:
    """A :class:`Tyre` from ``{model: NAME, PARAM: VALUE, ...}`` (or just the model's name)."""
    if isinstance(item, str):
        item = {"model": item}
    if not isinstance(item, Mapping):
        check.fail(f"must be a mapping {{model: NAME, ...parameters}} (models: {', '.join(TYRES)})", loc)
    model = check.text(item, "model", loc)
    if model not in TYRES:
        check.fail(f"unknown tyre model '{model}' (models: {', '.join(TYRES)})", (*loc, "model"))
    kind = TYRES[model]
    check.reject_unknown(item, ("model", *kind.defaults), loc)
    params = {}
    for name, _, unit in kind.params:
        if name in item:
            value = check.quantity(item[name], "number", (*loc, name))
            problem = param_problem(name, value)
            if problem:
                check.fail(f"{problem} {unit}".rstrip(), (*loc, name))
            params[name] = value
    return Tyre.of(model, params)


def wheel_dynamics_to_dict(wheel: Any) -> dict[str, Any]:
    """The wheel mapping's ``inertia``, ``mass`` and ``tyre`` entries (only those set)."""
    out: dict[str, Any] = {}
    inertia = {j: getattr(wheel, f"{j}_inertia") for j in INERTIA_JOINTS if getattr(wheel, f"{j}_inertia")}
    if inertia:
        out["inertia"] = inertia
    if wheel.mass:
        out["mass"] = wheel.mass
    if wheel.tyre is not None:
        out["tyre"] = {"model": wheel.tyre.model, **wheel.tyre.as_dict()}
    return out


def _positive(check: Any, value: Any, loc: tuple, unit: str) -> float:
    number = check.quantity(value, "number", loc)
    if number <= 0:
        check.fail(f"must be > 0, got {number} {unit}", loc)
    return number
