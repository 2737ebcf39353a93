"""Parking problems as data: YAML/JSON files with ``vehicle:`` and ``space:``, units accepted, located errors.

``vehicle:`` either gives the planner's parameters directly (``a1, b1, c1, h1, d1, phi_max``; Fig. 9.19) or names
a car-like robot (``robot:`` a catalog name or a description file) plus the body (``a1, b1, c1, phi_max``): the
wheelbase ``h1`` and track ``d1`` then come from the robot's wheels (fixed wheels = the rear axle, P_f their
midpoint; steerable wheels = the front axle). ``space:`` gives ``H, J, MS, dx2, final_gap`` (Fig. 9.18).
Built-in problems (the thesis's Tables 9.1 and 9.2) load by name: ``thesis-9.1``, ``thesis-9.2``.
"""

from __future__ import annotations

import difflib
import math
import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from ..catalog import resolve as resolve_robot
from ..documents import FieldReader, read_document, read_file
from ..errors import UnknownNameError, WmrkitError
from ..limits import _check_text_fields
from ..robot import Robot
from ..wheels import Wheel, heading_from_beta, heading_in_range
from .geometry import Space, Vehicle, gap_too_wide, no_free_length, wheels_outside

VEHICLE_FIELDS = ("a1", "b1", "c1", "h1", "d1", "phi_max")
ROBOT_VEHICLE_FIELDS = ("robot", "a1", "b1", "c1", "phi_max")
SPACE_FIELDS = ("H", "J", "MS", "dx2", "final_gap")


@dataclass(frozen=True, slots=True)
class ParkingProblem:
    """A vehicle, a space, and the robot the vehicle came from (None when given by parameters)."""

    name: str
    vehicle: Vehicle
    space: Space
    robot: Robot | None = None


def builtin_names() -> tuple[str, ...]:
    """Names of the problems shipped with wmrkit (the thesis's examples)."""
    files = resources.files(__package__).joinpath("problems")
    return tuple(sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".yaml")))


def load_problem(spec: str | os.PathLike[str]) -> ParkingProblem:
    """A problem from a ``.yaml``/``.yml``/``.json`` file, or a built-in name (:func:`builtin_names`)."""
    path = Path(spec)
    if path.suffix.lower() in (".yaml", ".yml", ".json") or path.exists():
        fmt = "json" if path.suffix.lower() == ".json" else "yaml"
        return problem_from_text(read_file(path, "parking problem"), source=str(path), fmt=fmt, base=path.parent)
    name = str(spec)
    if name not in builtin_names():
        close = difflib.get_close_matches(name, builtin_names(), n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise UnknownNameError(f"no parking problem '{name}'{hint}: give a .yaml/.json file or one of "
                               f"{', '.join(builtin_names())}")
    text = resources.files(__package__).joinpath("problems", f"{name}.yaml").read_text(encoding="utf-8")
    return problem_from_text(text, source=f"problem:{name}")


def problem_from_text(text: str, *, source: str, fmt: str = "yaml", base: Path | None = None) -> ParkingProblem:
    """Parse problem `text` (YAML through ``safe_load`` only, or JSON)."""
    data, line_of = read_document(text, source, fmt)  # duplicate keys refused there, in both formats
    return problem_from_dict(data, source=source, line_of=line_of, base=base)


def problem_from_dict(data: Any, *, source: str = "<dict>", line_of=None, base: Path | None = None) -> ParkingProblem:
    """Validate a problem mapping; every error is one located line (:class:`DescriptionError`)."""
    check = FieldReader(source, line_of or (lambda loc: None))
    if not isinstance(data, dict):
        check.fail("a parking problem is a mapping with the sections 'vehicle' and 'space'", ())
    check.reject_unknown(data, ("name", "vehicle", "space"), ())
    name = check.text(data, "name", (), required=False)
    _check_text_fields(name, "", check)  # printed in every answer: a robot's name's rules (one line, 64 characters)
    name = name or Path(source).stem
    vehicle, robot = _vehicle(check, check.require(data, "vehicle", ()), base)
    space = _space(check, check.require(data, "space", ()))
    return ParkingProblem(name, vehicle, space, robot)


def _section(check: FieldReader, data: Any, key: str, allowed: tuple[str, ...]) -> dict[str, Any]:
    if not isinstance(data, dict):
        check.fail(f"must be a mapping with the fields {', '.join(allowed)}", (key,))
    check.reject_unknown(data, allowed, (key,))
    return data


#: Largest length a problem may give [m]: beyond it a "parking" problem is a typo (and would sample forever).
MAX_LENGTH = 1000.0


def _lengths(check: FieldReader, data: dict[str, Any], section: str, names: tuple[str, ...]) -> dict[str, float]:
    out = {}
    for name in names:
        kind = "angle" if name == "phi_max" else "length"
        out[name] = check.quantity(check.require(data, name, (section,)), kind, (section, name))
        if kind == "length" and abs(out[name]) > MAX_LENGTH:
            check.fail(f"{out[name]:.6g} m is not a parking length (at most {MAX_LENGTH:g} m)", (section, name))
    return out


def _vehicle(check: FieldReader, data: Any, base: Path | None) -> tuple[Vehicle, Robot | None]:
    robot = None
    if isinstance(data, dict) and "robot" in data:
        data = _section(check, data, "vehicle", ROBOT_VEHICLE_FIELDS)
        v = _lengths(check, data, "vehicle", ROBOT_VEHICLE_FIELDS[1:])
        spec = data["robot"]
        if not isinstance(spec, str) or not spec:
            check.fail("must be a catalog name or a description file", ("vehicle", "robot"))
        if base is not None and Path(spec).suffix.lower() in (".yaml", ".yml", ".json"):
            spec = str(base / spec)
        try:
            robot = resolve_robot(spec)
            v["h1"], v["d1"] = car_axles(robot)
        except WmrkitError as err:
            check.fail(str(err), ("vehicle", "robot"))
    else:
        data = _section(check, data, "vehicle", VEHICLE_FIELDS)
        v = _lengths(check, data, "vehicle", VEHICLE_FIELDS)
    for name in ("a1", "c1", "h1"):
        if v[name] <= 0:
            check.fail(f"must be > 0, got {v[name]} m", ("vehicle", name) if name in data else ("vehicle",))
    for name in ("b1", "d1"):
        if v[name] < 0:
            check.fail(f"must be >= 0, got {v[name]} m", ("vehicle", name) if name in data else ("vehicle",))
    if not 0 < v["phi_max"] < math.pi / 2:
        check.fail(f"must be in (0, 90) deg, got {math.degrees(v['phi_max']):.6g} deg", ("vehicle", "phi_max"))
    beyond = None if robot is None else _beyond_steer_range(robot, v["phi_max"])
    if beyond is not None:
        check.fail(beyond, ("vehicle", "phi_max"))
    problem = wheels_outside(v["a1"], v["c1"], v["h1"], v["d1"])
    if problem is not None:
        check.fail(problem[1], ("vehicle", problem[0] if problem[0] in data else "c1"))  # d1 of a robot
    vehicle = Vehicle(a1=v["a1"], b1=v["b1"], c1=v["c1"], h1=v["h1"], track=v["d1"], phi_max=v["phi_max"])
    return vehicle, robot


def _beyond_steer_range(robot: Robot, phi_max: float) -> str | None:
    """Why `phi_max` [rad] turns `robot`'s steerable wheels beyond their ``steer_range``, or None."""
    limit = steering_limit(robot)
    if phi_max <= limit + 1e-12:
        return None
    h1 = car_axles(robot)[0]
    kappa = math.tan(phi_max) / h1
    rear, front, _ = _axles(robot)
    rx, ry = (sum(p[0] for p in rear) / len(rear), sum(p[1] for p in rear) / len(rear))
    worst = ""
    for w, (x, y) in zip([w for w in robot.wheels if w.type == "steerable"], front, strict=True):
        if w.steer_range is not None:
            for k in (kappa, -kappa):
                h = math.atan2((x - rx) * k, 1 - (y - ry) * k)
                if not (heading_in_range(h, *w.steer_range) or heading_in_range(h + math.pi, *w.steer_range)):
                    lo, hi = (math.degrees(a) for a in w.steer_range)
                    worst = worst or f"wheel '{w.name}' to {math.degrees(h):.4g} deg, range [{lo:g}, {hi:g}] deg"
    return (f"{math.degrees(phi_max):.4g} deg turns the front wheels of robot '{robot.name}' beyond their "
            f"steer_range ({worst}): at most {math.floor(math.degrees(limit) * 100) / 100:.2f} deg with this robot")


def _space(check: FieldReader, data: Any) -> Space:
    data = _section(check, data, "space", SPACE_FIELDS)
    s = _lengths(check, data, "space", SPACE_FIELDS)
    for name in ("H", "J", "final_gap"):
        if s[name] <= 0:
            check.fail(f"must be > 0, got {s[name]} m", ("space", name))
    for name in ("MS", "dx2"):
        if s[name] < 0:
            check.fail(f"must be >= 0, got {s[name]} m", ("space", name))
    problem = no_free_length(s["H"], s["MS"])
    if problem is not None:
        check.fail(problem, ("space", "MS"))
    problem = gap_too_wide(s["final_gap"], s["J"])  # 'final_gap: 7' (metres, not cm)
    if problem is not None:
        check.fail(problem, ("space", "final_gap"))
    return Space(**s)


def car_axles(robot: Robot) -> tuple[float, float]:
    """Wheelbase ``h1`` and rear track ``d1`` of a car-like robot [m] (Fig. 9.19; Ackermann-equivalent wheel).

    The fixed wheels form the rear axle (P_f their midpoint), the steerable wheels the front one; ``h1`` is the
    distance between the two axles' midpoints. The car drives along the robot's +x (its fixed wheels roll along x,
    the steering axle lies ahead of P_f on the x axis through it). Raises :class:`WmrkitError` for robots that are
    not such cars (a rear-steered forklift, the thesis's Y-forward tricycle).
    """
    rear, front, fixed = _axles(robot)
    tol = 1e-9 * max(1.0, *(abs(c) for p in (*rear, *front) for c in p))
    for w in fixed:
        heading = float(heading_from_beta(w.beta, w.delta))
        if abs(math.sin(heading)) > 1e-9:
            raise WmrkitError(f"robot '{robot.name}' does not drive along its x axis: fixed wheel '{w.name}' rolls at "
                              f"heading {math.degrees(heading):.4g} deg; the planner's car drives forward along +x "
                              "(x forward, y left), its fixed wheels rolling at heading 0")
    if len(rear) == 2 and abs(rear[0][0] - rear[1][0]) > tol:
        raise WmrkitError(f"robot '{robot.name}': its fixed wheels are not on one axle (x = {rear[0][0]:.6g} and "
                          f"{rear[1][0]:.6g} m): a car has one rear axle")
    rx, ry = _midpoint(rear)
    fx, fy = _midpoint(front)
    track = math.dist(rear[0], rear[1]) if len(rear) == 2 else 0.0
    wheelbase = fx - rx
    if wheelbase <= tol:
        where = (f"{-wheelbase:.4g} m behind its fixed axle (rear-steered)" if wheelbase < -tol
                 else "on its fixed axle (no wheelbase)")
        raise WmrkitError(f"robot '{robot.name}': its steerable wheels are {where}; the planner's car (Fig. 9.19) "
                          "steers with wheels ahead of its rear axle along +x")
    if abs(fy - ry) > tol:
        raise WmrkitError(f"robot '{robot.name}': its steerable wheels' midpoint is {fy - ry:.4g} m to the side of "
                          "the rear axle's: the planner's equivalent steering wheel lies on the car's centre line")
    return wheelbase, track


def _axles(robot: Robot) -> tuple[list[tuple[float, float]], list[tuple[float, float]], list[Wheel]]:
    """Positions of the fixed and the steerable wheels [m, robot frame], and the fixed wheels; or the error of a
    robot that is not car-like."""
    fixed = [w for w in robot.wheels if w.type == "fixed"]
    steer = [w for w in robot.wheels if w.type == "steerable"]
    if not 1 <= len(fixed) <= 2 or not steer or len(fixed) + len(steer) != len(robot.wheels):
        raise WmrkitError(f"robot '{robot.name}' is not car-like (one rear axle of fixed wheels and steerable "
                          f"front wheels; it has {', '.join(w.type for w in robot.wheels)})")

    def xy(w: Wheel) -> tuple[float, float]:
        return w.l * math.cos(w.alpha), w.l * math.sin(w.alpha)

    return [xy(w) for w in fixed], [xy(w) for w in steer], fixed


def rear_axle_midpoint(robot: Robot) -> tuple[float, float]:
    """P_f, the midpoint of a car-like `robot`'s rear axle (its fixed wheels) [m, robot frame]."""
    return _midpoint(_axles(robot)[0])


def _midpoint(points: list[tuple[float, float]]) -> tuple[float, float]:
    return sum(p[0] for p in points) / len(points), sum(p[1] for p in points) / len(points)


def curvature_limit(robot: Robot) -> float:
    """Largest path curvature of P_f [1/m] the car-like `robot`'s steerable wheels reach within their
    ``steer_range`` (either root of (8.9): a wheel may also roll reversed), turning either way; inf without ranges.

    For curvature ``kappa`` (ICR on the rear axle at ``1/kappa`` to the left of P_f) a wheel at ``(u, v)`` from P_f
    rolls at heading ``atan2(u kappa, 1 - v kappa)``, monotone in ``kappa``: it reaches a range end ``h`` at
    ``kappa = sin h / (u cos h + v sin h)`` (never when that denominator is not positive).
    """
    rear, front, _ = _axles(robot)
    car_axles(robot)
    rx, ry = _midpoint(rear)
    limit = math.inf
    for w, (x, y) in zip([w for w in robot.wheels if w.type == "steerable"], front, strict=True):
        if w.steer_range is None or w.steer_range[1] - w.steer_range[0] >= math.pi:  # one root always fits
            continue
        lo, hi = w.steer_range
        shift = next((s for s in (0.0, -math.pi, math.pi, -2 * math.pi, 2 * math.pi) if lo + s <= 0 <= hi + s), None)
        if shift is None:  # it cannot roll straight ahead
            return 0.0
        u, v = x - rx, y - ry
        for end in (lo + shift, hi + shift):
            den = u * math.cos(end) + v * math.sin(end)
            if den > 0:
                limit = min(limit, abs(math.sin(end) / den))
    return limit


def steering_limit(robot: Robot) -> float:
    """Largest equivalent steering angle ``phi`` [rad] (9.27) the car-like `robot` reaches within its wheels'
    ``steer_range``: ``atan(h1 kappa)`` at :func:`curvature_limit`; ``pi/2`` without ranges."""
    return math.atan(car_axles(robot)[0] * curvature_limit(robot))
