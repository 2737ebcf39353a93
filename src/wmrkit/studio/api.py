"""The studio's endpoints as pure functions: request JSON in, response JSON out, every number from the library.

The page (``static/app.js``) only draws and edits; robot descriptions travel as the mappings of
:func:`wmrkit.description.robot_from_dict` (numbers in SI or strings with units, ``"250 mm"``), validated there,
so an invalid field fails with the same :class:`~wmrkit.errors.DescriptionError` message the CLI prints.
Steering angles cross this boundary as *headings* (rolling direction, 0 = straight ahead,
:func:`wmrkit.wheels.heading_from_beta`); a wheel may be given ``heading`` instead of ``beta``.

Per edit the page calls :func:`analyze_live` (chapters 4-6 at the described configuration, without the singular
sets over the whole steering space, which :func:`configurations` gives on demand): see ``docs/studio.md``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

import numpy as np

from .._shapes import as_angles
from ..analysis.classification import classify
from ..analysis.icr import ICRSet, icr_of_twist
from ..analysis.isotropy import condition_map, described_condition
from ..analysis.optimize import isotropic_configurations
from ..analysis.singularity import SINGULAR_RTOL, robot_size, singularity_distance
from ..analysis.summary import describe_singular, described_analysis, model_rates, model_singular_set, singular_dict
from ..description import DescriptionWarning, accepted_fields, kind_of_type, robot_from_dict, robot_to_dict
from ..documents import hint
from ..dynamics.mass import inertia_joints
from ..errors import ShapeError, WmrkitError, said_warnings
from ..kinematics.wheel_ik import rate_kind, wheel_commands
from ..limits import MAX_QUERY_RATE
from ..odometry.integrators import integrate_exact
from ..robot import TWIST_NAMES, Robot
from ..units import Kind, UnitError, parse_quantity
from ..wheels import KINDS

#: Distance to singularity (``sigma_min / sigma_max`` of the constraint lines, 6.17) below which the page warns.
NEAR_SINGULAR = 0.05
#: Largest κ-map grid per axis and largest trajectory sample count a request may ask for.
MAX_RESOLUTION = 181
#: Most steering wheels for which /api/configurations searches the isotropic configurations (about 2 s at 4 on
#: the 2-core machine; the search grows with every steering angle): beyond, not searched, with a note.
MAX_ISOTROPIC_STEERING = 4
SOURCE = "studio"
T = TypeVar("T")


class StudioError(WmrkitError, ValueError):
    """A request the studio cannot answer (wrong shape of JSON, bad number); the message says which field."""


# ---- descriptions ------------------------------------------------------------------------------------------
def robot_of(request: Any) -> Robot:
    """The :class:`Robot` of ``request["description"]`` (the description format reads ``heading`` or ``beta``);
    its warnings are :func:`read_robot`'s (the page shows them from /api/analyze), not the server's stderr."""
    return read_robot(request)[0]


def read_robot(request: Any) -> tuple[Robot, list[str]]:
    """:func:`robot_of` and the description's warnings (``source: field: message`` lines)."""
    data = _field(request, "description", Mapping)
    return with_warnings(lambda: robot_from_dict(data, source=SOURCE))


def with_warnings(read: Callable[[], T]) -> tuple[T, list[str]]:
    """``read()`` and the :class:`~wmrkit.description.DescriptionWarning` lines it raised (the answer's
    ``warnings``, as ``--json`` gives them), said nowhere else (:func:`wmrkit.errors.said_warnings`)."""
    return said_warnings(read, DescriptionWarning)


def description_of(robot: Robot) -> dict[str, Any]:
    """The description mapping of `robot` (SI numbers, exactly what ``Robot.to_file`` writes)."""
    return robot_to_dict(robot)


def geometry(robot: Robot) -> dict[str, Any]:
    """What the plan view draws, in robot coordinates [m] and radians: per wheel its joint, heading, elements, and
    ``fields``: its geometry as read (a mecanum wheel's gamma from its quadrant, r_r; a retype keeps them)."""
    from ..plotting.robot import element_geometry  # the drawing's own geometry (eq. 3.8), not re-derived here

    wheels = []
    for w in robot.wheels:
        els = element_geometry(w, w.beta)
        wheels.append({
            "name": w.name, "type": w.type, "steers": w.kind.steers,
            "joint": [float(v) for v in els[0].joint], "heading": float(w.heading), "beta": w.beta,
            "actuated": list(w.actuated), "sensed": list(w.sensed),
            "fields": {f: getattr(w, f) for f in (*w.kind.required, *w.kind.optional) if f != "beta"},
            "elements": [{"centre": [float(v) for v in e.centre], "axle": float(e.axle),
                          "roller": None if e.roller is None else float(e.roller), "r": float(e.r),
                          "spin_joint": e.spin_joint} for e in els],
        })
    return {"wheels": wheels, "size": robot_size(robot)}


def kinds() -> dict[str, Any]:
    """The wheel types a description may use: fields (required, optional with defaults), joints, whether they
    steer, a summary; ``fields``: every field the type takes and ``inertia``: the joints of its ``inertia`` (a
    retype keeps those, :func:`wmrkit.description.accepted_fields`). ``mecanum`` is a Swedish wheel whose
    ``gamma`` (from its quadrant) and ``r_r`` (``r / 4``) are optional without a fixed default (null)."""
    out = {k.name: {"required": list(k.required), "optional": dict(k.optional), "joints": list(k.joints),
                    "rates": list(k.rates), "steers": k.steers, "summary": k.summary} for k in KINDS.values()}
    out["mecanum"] = out["swedish"] | {
        "required": ["r"], "optional": {"gamma": None, "r_r": None},
        "summary": "Swedish wheel of the standard X layout: gamma +-45 deg from its quadrant, r_r = r / 4 unless given"}
    for name, kind in out.items():
        kind["fields"] = list(accepted_fields(name))
        kind["inertia"] = list(inertia_joints(kind_of_type(name)))
    return out


# ---- analysis ----------------------------------------------------------------------------------------------
def analyze_live(request: Any) -> dict[str, Any]:
    """Per-edit analysis: type (m, s), degeneracy, verdicts, condition number, ICR set, distance to singularity;
    ``warnings``: the description's (a ``mecanum`` wheel whose ``gamma`` is not +-45 deg), as ``analyze --json``.

    The same numbers as :func:`wmrkit.analysis.analyze` (its ``to_dict`` keys), minus the singular sets over
    the steering space (:func:`configurations`), plus ``singular_here`` and the drawing's ``geometry``.
    """
    check_fields(request, "description")
    robot, said = read_robot(request)
    return {"robot": robot.name, "description": description_of(robot), "geometry": geometry(robot),
            "analysis": live_summary(robot), "warnings": said}


def live_summary(robot: Robot) -> dict[str, Any]:
    """The live analysis of :func:`analyze_live` as a mapping (JSON-ready; headings in radians): the numbers of
    :func:`~wmrkit.analysis.summary.described_analysis`, which ``analyze`` gives (the gears held)."""
    a = described_analysis(robot)
    cls, full = a.classification, a.to_dict()
    here = {}
    for key, names in (("actuated", robot.actuated), ("sensed", robot.sensed)):
        assigned = model_rates(robot, names)
        dist = float(singularity_distance(robot, None, assigned, coupled=key == "actuated"))
        # singular: the line test's own threshold (is_singular), sigma_min <= SINGULAR_RTOL sigma_max
        here[key] = {"assigned": list(assigned), "distance": dist, "singular": dist <= SINGULAR_RTOL,
                     "near": dist < NEAR_SINGULAR}
    same = ("mobility", "coupled_mobility", "steerability", "commanded_steerability", "type", "type_name",
            "degenerate", "reasons", "coordinated_steering", "instantaneous_mobility", "condition_joints",
            "natural_length")
    return {key: full[key] for key in same} | {
        "special_configurations": [{"heading": _headings(robot, s.beta), "mobility": s.mobility,
                                    "description": s.description} for s in cls.special],
        "icr": icr_dict(a.icr),
        "actuation": full["actuation"] | {"joints": list(robot.actuated)},
        "sensing": full["sensing"] | {"joints": list(robot.sensed)},
        "condition_number": _finite(full["condition_number"]),  # inf (undetermined twist): null, as JSON has no inf
        "characteristic_length": _finite(full["characteristic_length"]),
        "isotropy_note": a.isotropy_note(),  # m <= 1, of the wheels or left by gears: no condition number to give
        # what analyze says of the type beyond the wheels' m and d: the gears' m, the ICRs held linkages leave
        "type_notes": [n for n in (a.gears_note(), a.linkage_note()) if n is not None],
        "linkages": full["linkages"],
        "steering": dict(zip(robot.steer_names, robot.heading.tolist(), strict=True)),
        "singular_here": here,
    }


def icr_dict(s: ICRSet) -> dict[str, Any]:
    """An :class:`ICRSet` as plain data, with its sentence."""
    return {"kind": s.kind, "point": s.point, "direction": s.direction, "line": s.line, "text": s.describe()}


def configurations(request: Any) -> dict[str, Any]:
    """Singular sets of the actuated and sensed models (ch. 6) and isotropic configurations (5.29), as headings.

    Slower than :func:`analyze_live` for robots with several steering angles; the page asks after an edit settles.
    """
    check_fields(request, "description")
    robot = robot_of(request)
    cls = classify(robot)
    out: dict[str, Any] = {"singular": {}}
    for key, names in (("actuated", robot.actuated), ("sensed", robot.sensed)):
        s = model_singular_set(robot, model_rates(robot, names), cls, 90, coupled=key == "actuated")
        out["singular"][key] = singular_dict(s, robot) | {"text": describe_singular(s, robot)}  # as analyze --json
    # The library's search refines each grid minimum at its own natural length: quick for m = 2 or one steering
    # angle, but tens of seconds for m = 3 with several (a 1-D length search inside Nelder-Mead), and growing
    # with every steering angle for m = 2: not searched then, with a note saying why.
    n_steer = len(robot.steer_names)
    if not n_steer:
        note = "the robot does not steer: its condition number is the one above"
    elif cls.mobility <= 1:
        note = f"m = {cls.mobility}: no two motions to balance"
    elif cls.mobility != 2 and n_steer > 1:
        note = f"not searched for m = {cls.mobility} with {n_steer} steering wheels (see the κ map)"
    elif n_steer > MAX_ISOTROPIC_STEERING:
        note = (f"not searched: {n_steer} steering wheels, the studio searches up to {MAX_ISOTROPIC_STEERING} "
                "(see the κ map; wmrkit.analysis.isotropic_configurations searches any number)")
    else:
        note = None
    searched = note is None
    iso = isotropic_configurations(robot) if searched else ()
    out["isotropic_searched"] = searched
    out["isotropic_note"] = note
    out["isotropic_wheels"] = list(robot.steer_names)  # whose headings each configuration lists, in order
    out["isotropic"] = [{"heading": _headings(robot, c.beta), "length": c.length,
                         "condition_number": c.condition_number} for c in iso]
    return out


def kappa_map(request: Any) -> dict[str, Any]:
    """Condition number (5.28) over the headings of one or two steering wheels (the others as described).

    ``request``: ``description``, optional ``wheels`` (1-2 steering wheel names; default the first two) and
    ``resolution`` (points per turn). κ at the natural length of the described configuration; null where the
    robot cannot move (uncoordinated steering) or the model is singular (κ infinite).
    """
    check_fields(request, "description", "wheels", "resolution")
    robot = robot_of(request)
    steer = robot.steer_names
    if not steer:
        raise StudioError(f"robot '{robot.name}' does not steer: no κ map over steering angles")
    names = request.get("wheels", list(steer[:2]))
    if (not isinstance(names, list) or not 1 <= len(names) <= 2 or any(n not in steer for n in names)
            or len(set(names)) != len(names)):  # a wheel twice: its second angle overwrote the first axis
        other = next((n for n in names if n not in steer), None) if isinstance(names, list) else None
        said = f"{hint(other, steer)}" if isinstance(other, str) and len(other) <= 80 else ""
        raise StudioError(f"wheels: one or two different steering wheels of {', '.join(steer)}{said}")
    res = _integer(request.get("resolution", 72), "resolution", 8, MAX_RESOLUTION)
    axis = np.linspace(-np.pi, np.pi, res, endpoint=False)
    grids = np.meshgrid(*([axis] * len(names)), indexing="ij")
    headings = np.broadcast_to(robot.heading, (*grids[0].shape, len(steer))).copy()
    for name, g in zip(names, grids, strict=True):
        headings[..., steer.index(name)] = g
    joints, length = described_condition(robot)[:2]  # analyze's joints and natural length, the gears held
    kappa = condition_map(robot, robot.beta_of_heading(headings), joints=joints, length=length, geared=True)
    finite = np.where(np.isfinite(kappa), kappa, np.nan)
    best = int(np.nanargmin(finite)) if np.isfinite(finite).any() else None
    return {"wheels": names, "axis": axis.tolist(), "length": length,
            "kappa": [_finite(v) for v in kappa.ravel().tolist()], "shape": list(kappa.shape),
            "current": [float(robot.heading[steer.index(n)]) for n in names],
            "best": None if best is None else {"kappa": float(finite.ravel()[best]),
                                               "heading": [float(g.ravel()[best]) for g in grids]}}


# ---- driving -----------------------------------------------------------------------------------------------
def drive(request: Any) -> dict[str, Any]:
    """Per-wheel commands for ``twist`` (vx [m/s], vy [m/s], omega [rad/s]) from the current ``heading`` mapping
    (steering wheel -> heading, radians or a string with a unit, ``"30 deg"``).

    Per wheel: heading [rad] and spin [rad/s] (§8.4), the rolling speed ``r * spin`` [m/s] for the arrows, the
    lateral slip of fixed wheels, its other joint rates (``spin1``/``spin2`` of double wheels, ``roller``) [rad/s];
    ``feasible``, why not (``slips``: the residual ``|A q_dot|`` [m/s] of the no-slip equations (3.22) is not zero;
    ``out_of_range``: the wheels whose heading is beyond their ``steer_range``); the ICR of the twist; and the poses
    of the robot holding the twist for ``duration`` s (exact SE(2)).
    """
    check_fields(request, "description", "twist", "heading", "duration", "samples")
    robot = robot_of(request)
    twist = _twist(request.get("twist"))
    steering = request.get("heading", {})
    if not isinstance(steering, Mapping):
        raise StudioError("heading: a mapping {steering wheel: heading [rad]}")
    unknown = [n for n in steering if n not in robot.steer_names]
    if unknown:
        raise StudioError(f"heading: '{unknown[0][:80]}' is not a steering wheel of '{robot.name}'"
                          f"{hint(unknown[0][:80], robot.steer_names)} "
                          f"(steering: {', '.join(robot.steer_names) or 'none'})")
    current = robot.heading.copy()
    for name, value in steering.items():  # an angle: "30 deg" accepted, a bare number beyond a turn refused
        try:
            current[robot.steer_names.index(name)] = parse_quantity(value, "angle")
            as_angles(robot.beta_of_heading(current), len(current), "beta")  # beta = heading + 90 deg - delta too
        except (UnitError, ShapeError) as err:
            raise StudioError(f"heading.{name}: {err}") from None
    beta = robot.beta_of_heading(current)
    c = wheel_commands(robot, twist, beta)
    now_heading = robot.heading_of_beta(c.beta)
    residual = float(np.linalg.norm(robot.slip_velocity(c.velocity(twist), c.beta)))
    wheels = {}
    data = c.to_dict()
    joints = data["wheels"]  # the other joint rates (spin1, spin2, roller), as `wmrkit ik --json`
    for i, w in enumerate(robot.wheels):
        h = float(now_heading[robot.steer_names.index(w.name)]) if w.kind.steers else float(w.heading)
        spin = float(c.spin[i])
        wheels[w.name] = {"heading": h, "spin": _finite(spin), "speed": _finite(spin * w.r),
                          "steer_rate": _finite(float(c.steer_rate[i])), "slip": float(c.slip[i])}
        wheels[w.name] |= {k: _finite(v) for k, v in joints[w.name].items() if k not in wheels[w.name]}
    scale = max(1.0, float(np.abs(twist[:2]).sum() + abs(twist[2]) * robot_size(robot)))
    slips = not residual <= 1e-9 * scale
    out_of_range = [w.name for w, ok in zip(robot.wheels, c.in_range.tolist(), strict=True) if not ok]
    duration = _quantity(request.get("duration", 4.0), "time", "duration")
    samples = _integer(request.get("samples", 120), "samples", 2, 2000)
    if not 0 < duration <= 600:
        raise StudioError(f"duration: between 0 and 600 s, got {duration}")
    t = np.linspace(0.0, duration, samples)
    poses = integrate_exact(np.zeros(3), twist, t)
    return {"twist": twist.tolist(), "wheels": wheels, "heading": dict(zip(robot.steer_names, now_heading.tolist(),
                                                                           strict=True)),
            "feasible": bool(c.feasible) and not slips, "slips": slips, "out_of_range": out_of_range,
            "out_of_gear": data["out_of_gear"], "out_of_steer_gear": data["out_of_steer_gear"],
            "out_of_linkage": data["out_of_linkage"],
            "residual": residual,
            "icr": twist_icr(twist), "times": t.tolist(), "poses": poses.tolist()}


def twist_icr(twist: np.ndarray) -> dict[str, Any]:
    """ICR of one twist (§5.3): a point [m], a direction at infinity (pure translation), or none (at rest)."""
    x, y, w = icr_of_twist(twist).tolist()
    if max(abs(x), abs(y), abs(w)) < 1e-12:
        return {"kind": "none", "text": "at rest: no ICR"}
    if abs(w) < 1e-9 * max(abs(x), abs(y)):
        n = math.hypot(twist[0], twist[1])
        return {"kind": "infinity", "direction": [twist[0] / n, twist[1] / n],
                "text": "ICR at infinity: pure translation"}
    return {"kind": "point", "point": [x / w, y / w], "text": ICRSet("point", point=(x / w, y / w)).describe()}


# ---- helpers -----------------------------------------------------------------------------------------------
def _headings(robot: Robot, beta: Any) -> list[float]:
    return [float(v) for v in robot.heading_of_beta(np.asarray(beta, dtype=float))]


def _finite(x: float | None) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def check_fields(request: Any, *fields: str) -> None:
    """Refuse a field of the request that the endpoint does not read (a typo, ``"sample"``, was ignored)."""
    if not isinstance(request, Mapping):
        raise StudioError("the request body must be a JSON object")
    unknown = [k for k in request if k not in fields]
    if unknown:
        word = unknown[0][:80]
        raise StudioError(f"unknown field {word!r}{hint(word, fields)} (this request takes {', '.join(fields)})")


def _field(request: Any, key: str, kind: type) -> Any:
    if not isinstance(request, Mapping):
        raise StudioError("the request body must be a JSON object")
    if key not in request:
        raise StudioError(f"missing field '{key}'")
    value = request[key]
    if not isinstance(value, kind):
        raise StudioError(f"{key}: expected a JSON {'object' if kind is Mapping else kind.__name__}")
    return value


def _twist(value: Any) -> np.ndarray:
    """``[vx, vy, omega]``: SI numbers, or each with a unit of its kind as ``wmrkit ik --twist`` reads them
    (``"500 mm/s"``, ``"30 deg/s"``), within :data:`MAX_QUERY_RATE`; a refusal names the component."""
    if not isinstance(value, list) or len(value) != 3:
        raise StudioError("twist: expected a list [vx, vy, omega] of 3 numbers (m/s, m/s, rad/s)")
    twist = np.array([_quantity(v, rate_kind(n), f"twist.{n}") for n, v in zip(TWIST_NAMES, value, strict=True)])
    if np.abs(twist).max() > MAX_QUERY_RATE:
        name = TWIST_NAMES[int(np.abs(twist).argmax())]
        raise StudioError(f"twist.{name}: beyond {MAX_QUERY_RATE:g} (m/s or rad/s), no wheeled robot moves so fast")
    return twist


def _quantity(value: Any, kind: Kind, what: str) -> float:
    """`value` in SI (a number, or a string with a unit of `kind`); a :class:`StudioError` naming `what`."""
    try:
        return parse_quantity(value, kind)
    except UnitError as err:
        raise StudioError(f"{what}: {err}") from None


def _integer(value: Any, what: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise StudioError(f"{what}: an integer from {lo} to {hi}, got {_shown(value)}")
    return value


def _shown(value: Any) -> str:
    """`value` quoted for a message: at most 40 characters (a request may hold a value of a megabyte)."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
