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
from ..robot import Robot
from .geometry import Space, Vehicle, no_free_length, wheels_outside

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
    name = check.text(data, "name", (), required=False) or Path(source).stem
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
    problem = wheels_outside(v["a1"], v["c1"], v["h1"], v["d1"])
    if problem is not None:
        check.fail(problem[1], ("vehicle", problem[0] if problem[0] in data else "c1"))  # d1 of a robot
    vehicle = Vehicle(a1=v["a1"], b1=v["b1"], c1=v["c1"], h1=v["h1"], track=v["d1"], phi_max=v["phi_max"])
    return vehicle, robot


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
    return Space(**s)


def car_axles(robot: Robot) -> tuple[float, float]:
    """Wheelbase ``h1`` and rear track ``d1`` of a car-like robot [m] (Fig. 9.19; Ackermann-equivalent wheel).

    The fixed wheels form the rear axle (P_f their midpoint), the steerable wheels the front one; ``h1`` is the
    distance between the two axles' midpoints. Raises :class:`WmrkitError` for robots that are not car-like.
    """
    fixed = [w for w in robot.wheels if w.type == "fixed"]
    steer = [w for w in robot.wheels if w.type == "steerable"]
    if not 1 <= len(fixed) <= 2 or not steer or len(fixed) + len(steer) != len(robot.wheels):
        raise WmrkitError(f"robot '{robot.name}' is not car-like (one rear axle of fixed wheels and steerable "
                          f"front wheels; it has {', '.join(w.type for w in robot.wheels)})")

    def xy(w) -> tuple[float, float]:
        return w.l * math.cos(w.alpha), w.l * math.sin(w.alpha)

    rear = [xy(w) for w in fixed]
    front = [xy(w) for w in steer]
    rx, ry = (sum(p[0] for p in rear) / len(rear), sum(p[1] for p in rear) / len(rear))
    fx, fy = (sum(p[0] for p in front) / len(front), sum(p[1] for p in front) / len(front))
    track = math.dist(rear[0], rear[1]) if len(rear) == 2 else 0.0
    wheelbase = math.hypot(fx - rx, fy - ry)
    if wheelbase <= 0:
        raise WmrkitError(f"robot '{robot.name}': the steerable wheels sit on the rear axle (no wheelbase)")
    return wheelbase, track
