"""Robot description files: load, validate with located one-line errors, save losslessly.

The format (YAML or JSON) is documented in ``docs/description-format.md``. YAML goes through ``safe_load``
only; user text is never evaluated. Every error names the file, the line where known, the wheel and the field.
"""

from __future__ import annotations

import itertools
import math
import numbers
import os
import re
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from .couplings import COUPLING_KINDS, Coupling, joint_problem
from .documents import (
    DescriptionError,
    FieldReader,
    LineOf,
    Loc,
    hint,
    read_document,
    read_file,
    short_repr,
    write_document,
)
from .dynamics import mass
from .limits import (  # noqa: F401  (the limits are part of the description format)
    ANGLE_MARGIN,
    MAX_COUPLING_RATIO,
    MAX_FILE_SIZE,
    MAX_NAME,
    MAX_NOTES,
    MAX_SIZE,
    MAX_WHEELS,
    MIN_COUPLING_RATIO,
    MIN_RATIO,
    MIN_SIZE,
    _check_envelope,
    _check_size,
    _check_text_fields,
)
from .robot import Robot
from .units import BARE_ANGLE_LIMIT, MAX_ANGLE, MAX_TURNS
from .wheels import (
    GEOMETRY_FIELDS,
    KINDS,
    Wheel,
    beta_from_heading,
    geometry_problem,
    heading_from_beta,
    heading_in_range,
)

#: Types a description may use: the wheel kinds, and ``mecanum`` (a Swedish wheel with the standard rollers).
WHEEL_TYPES = (*KINDS, "mecanum")

TOP_FIELDS = ("name", "wheels", "notes", "couplings", "body", "odometry")  # odometry: wmrkit.slip.settings
#: Names derived from the wheels that ``wmrkit show --json`` adds (``cli.robots.summary``); a description copied
#: from it may keep them, and each must then equal what the wheels give (:func:`_check_derived`).
DERIVED_FIELDS = {"velocity_names": "velocity_names", "steer_names": "steer_names", "actuated_joints": "actuated",
                  "sensed_joints": "sensed"}
#: Keys of every command's JSON answer that ``wmrkit show --json`` has too (docs/limits.md, JSON answers): ``robot``
#: (the name) and ``warnings`` (a list of text); a copy may keep them (:func:`_check_derived`).
ANSWER_FIELDS = ("robot", "warnings")
COMMON_WHEEL_FIELDS = ("name", "type", "position", "l", "alpha", "actuated", "sensed", "heading",
                       "inertia", "mass", "tyre",  # these three: wmrkit.dynamics.mass
                       "steer_range",  # _steer_range_from_dict
                       "slip")  # wmrkit.slip.settings
ALL_WHEEL_FIELDS = COMMON_WHEEL_FIELDS + tuple(f for f in GEOMETRY_FIELDS if f not in ("l", "alpha"))

#: ``type: mecanum``: a Swedish wheel with the rollers of the standard layout (WPILib, ROS 2): ``gamma`` of
#: magnitude 45 deg, its sign from the wheel's quadrant (``docs/conventions.md``); r_r defaults to r / 4.
MECANUM_GAMMA = math.pi / 4

WHEEL_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
#: ulps around a heading computed back from beta and delta where the writer looks for the heading that gave them
#: (``beta = heading - delta + 90 deg`` and back round twice each way: castors with delta != 0 came out an ulp off).
HEADING_SPREAD = 4



def robot_from_dict(data: Any, *, source: str = "<dict>", line_of: LineOf | None = None) -> Robot:
    """Validate a description mapping and build the :class:`Robot` (SI units; strings with units accepted)."""
    check = FieldReader(source, line_of or (lambda loc: None))
    if not isinstance(data, Mapping):
        check.fail("a robot description is a mapping with the fields 'name' and 'wheels'", ())
    check.reject_unknown(data, TOP_FIELDS + tuple(DERIVED_FIELDS) + ANSWER_FIELDS, ())
    name = check.text(data, "name", ())
    notes = check.text(data, "notes", (), required=False)
    _check_text_fields(name, notes, check)
    wheels_data = check.require(data, "wheels", ())
    if not isinstance(wheels_data, list) or not wheels_data:
        check.fail("must be a non-empty list of wheels", ("wheels",))
    if len(wheels_data) > MAX_WHEELS:
        check.fail(f"{len(wheels_data)} wheels: wmrkit analyses at most {MAX_WHEELS} (docs/limits.md)", ("wheels",))
    wheels: list[Wheel] = []
    names: set[str] = set()
    for i, item in enumerate(wheels_data):
        wheel = _wheel_from_dict(item, check, ("wheels", i))
        if wheel.name in names:
            check.fail(f"duplicate wheel name '{wheel.name}'", ("wheels", i, "name"))
        names.add(wheel.name)
        wheels.append(wheel)
    _check_envelope(wheels, check, {i for i, item in enumerate(wheels_data) if isinstance(item, Mapping)
                                    and "position" in item})
    couplings = _couplings_from_dict(data.get("couplings", []), wheels, check)
    odometry = None
    if "odometry" in data or any(isinstance(w, Mapping) and "slip" in w for w in wheels_data):
        from .slip.settings import settings_from_dict

        odometry = settings_from_dict(data, check)
    robot = Robot(name=name, wheels=tuple(wheels), notes=notes, couplings=couplings,
                  body=mass.body_from_dict(data, check), odometry=odometry)
    _check_derived(data, robot, check)
    return robot


def _check_derived(data: Mapping[str, Any], robot: Robot, check: FieldReader) -> None:
    """The derived names of ``wmrkit show --json`` (:data:`DERIVED_FIELDS`), when present, equal the robot's: they
    are read back, never used, so a copy whose wheels were edited is refused instead of silently contradicted. So
    does its ``robot`` the name; its ``warnings`` are a list of text (:data:`ANSWER_FIELDS`)."""
    for key, attribute in DERIVED_FIELDS.items():
        if key in data:
            expected = list(getattr(robot, attribute))
            if data[key] != expected:
                check.fail(f"derived from the wheels (wmrkit show --json writes it), so it must be {expected}, got "
                           f"{short_repr(data[key])}: correct it or delete it", (key,))
    if "robot" in data and data["robot"] != robot.name:  # the answer's name of the robot, as every command's
        check.fail(f"the robot's name (wmrkit show --json writes it), so it must be '{robot.name}' as 'name' says, got "
                   f"{short_repr(data['robot'])}: correct it or delete it", ("robot",))
    said = data.get("warnings", [])
    if not (isinstance(said, list) and all(isinstance(w, str) for w in said)):
        check.fail(f"the warnings of a wmrkit show --json answer: a list of text, got {short_repr(said)}",
                   ("warnings",))


def _couplings_from_dict(items: Any, wheels: list[Wheel], check: FieldReader) -> tuple[Coupling, ...]:
    """``couplings:``: joints moved by one mechanism (``wmrkit.couplings``), each joint in one coupling at most."""
    if not isinstance(items, list):
        check.fail("must be a list of couplings {kind, joints, ratios}", ("couplings",))
    by_name = {w.name: w for w in wheels}
    used: set[str] = set()
    out = []
    for i, item in enumerate(items):
        loc: Loc = ("couplings", i)
        if not isinstance(item, Mapping):
            check.fail("a coupling is a mapping {kind, joints, ratios}", loc)
        check.reject_unknown(item, ("kind", "joints", "ratios"), loc)
        kind = check.text(item, "kind", loc)
        if kind not in COUPLING_KINDS:
            check.fail(f"unknown coupling kind '{kind}'{hint(kind, COUPLING_KINDS)} (kinds: "
                       f"{', '.join(COUPLING_KINDS)})", (*loc, "kind"))
        joints = check.require(item, "joints", loc)
        if not isinstance(joints, list) or len(joints) < 2 or not all(isinstance(j, str) for j in joints):
            check.fail("must be a list of two or more joint names 'wheel.joint'", (*loc, "joints"))
        for j, joint in enumerate(joints):
            problem = joint_problem(kind, joint, by_name, lambda joint=joint: hint(joint, _joint_names(wheels)))
            if problem is not None:
                check.fail(problem, (*loc, "joints", j))
            if joint in used:
                where = "twice in this coupling" if joint in joints[:j] else "in two couplings"
                check.fail(f"joint '{joint}' is {where}", (*loc, "joints", j))
            used.add(joint)
        default = [1.0 / len(joints)] * len(joints) if kind == "differential" else [1.0] * len(joints)
        raw = item.get("ratios", default)
        if not isinstance(raw, list) or len(raw) != len(joints):
            check.fail(f"must be a list of {len(joints)} numbers, one per joint", (*loc, "ratios"))
        ratios = tuple(check.quantity(v, "number", (*loc, "ratios", j)) for j, v in enumerate(raw))
        if any(r == 0 for r in ratios):
            check.fail("ratios must be non-zero (a joint with ratio 0 is not coupled)", (*loc, "ratios"))
        sizes = [abs(r) for r in ratios]
        for j, size in enumerate(sizes):
            if not MIN_COUPLING_RATIO <= size <= MAX_COUPLING_RATIO:
                check.fail(f"{ratios[j]:g}: outside the ratios wmrkit handles ({MIN_COUPLING_RATIO:g} to "
                           f"{MAX_COUPLING_RATIO:g} in magnitude, docs/limits.md)", (*loc, "ratios", j))
        if max(sizes) > min(sizes) / MIN_RATIO:
            check.fail(f"the largest ratio is more than {1 / MIN_RATIO:g} times the smallest: rank decisions would "
                       "lose the smaller to round-off (docs/limits.md)", (*loc, "ratios"))
        out.append(Coupling(kind, tuple(joints), ratios))
    return tuple(out)


def _joint_names(wheels: list[Wheel]) -> list[str]:
    return [f"{w.name}.{j}" for w in wheels for j in w.kind.joints]


def _wheel_from_dict(item: Any, check: FieldReader, loc: Loc, kind_name: str | None = None) -> Wheel:
    """The wheel `item`; `kind_name`: the wheel kind of its type (``swedish`` for ``type: mecanum``, which the
    messages keep saying)."""
    if not isinstance(item, Mapping):
        check.fail("a wheel is a mapping with at least 'name', 'type' and its geometry", loc)
    name = check.text(item, "name", loc)  # first: every later error names the wheel
    if len(loc) == 2 and isinstance(loc[1], int):
        check.wheels[loc[1]:] = [name]
    if not WHEEL_NAME.fullmatch(name):
        check.fail("wheel names are ASCII letters, digits, '_' and '-', starting with a letter or '_' (they name "
                   f"velocities 'wheel.joint'), got {name!r}", (*loc, "name"))
    type_name = check.text(item, "type", loc)
    if type_name == "mecanum" and kind_name is None:
        return _mecanum_from_dict(item, check, loc)
    if type_name not in KINDS and kind_name is None:
        check.fail(f"unknown wheel type '{type_name}'{hint(type_name, WHEEL_TYPES)} (types: {', '.join(WHEEL_TYPES)})",
                   (*loc, "type"))
    kind_name = kind_name or type_name
    kind = KINDS[kind_name]
    allowed = COMMON_WHEEL_FIELDS + kind.required + tuple(kind.optional)
    for key in item:
        if key not in allowed and key in ALL_WHEEL_FIELDS:
            check.fail(f"field '{key}' does not apply to a {type_name} wheel", (*loc, key))
    check.reject_unknown(item, allowed, loc)

    values: dict[str, float] = {}
    if "position" in item:
        if "l" in item or "alpha" in item:
            check.fail("give either 'position' or 'l' and 'alpha', not both", (*loc, "position"))
        pos = item["position"]
        if not isinstance(pos, list | tuple) or len(pos) != 2:
            check.fail("must be a list [x, y] of two lengths", (*loc, "position"))
        x, y = (check.quantity(v, "length", (*loc, "position", j)) for j, v in enumerate(pos))
        values["l"], values["alpha"] = math.hypot(x, y), math.atan2(y, x)
    elif "l" in item or "alpha" in item:
        values["l"] = check.quantity(check.require(item, "l", loc), "length", (*loc, "l"))
        values["alpha"] = check.quantity(check.require(item, "alpha", loc), "angle", (*loc, "alpha"))
    else:
        check.fail("missing the wheel's place: 'position: [x, y]' or 'l' and 'alpha'", loc)
    for key, default in kind.optional.items():
        values[key] = check.quantity(item[key], GEOMETRY_FIELDS[key], (*loc, key)) if key in item else default
    for key in kind.required:
        if key == "beta" and "heading" in item:
            continue
        if key == "beta" and "beta" not in item:  # files are written with heading (README): name it, not only beta
            check.fail("missing field 'heading' (rolling direction, 0 = straight ahead; or the thesis's 'beta')", loc)
        values[key] = check.quantity(check.require(item, key, loc), GEOMETRY_FIELDS[key], (*loc, key))
    _read_heading(item, values, check, loc, "beta" in kind.optional)
    _check_geometry(kind_name, values, check, loc)
    actuated = check.joints(item, "actuated", kind.joints, loc)
    sensed = check.joints(item, "sensed", kind.joints, loc)
    steer_range = _steer_range_from_dict(item, check, loc, kind.steers)
    if steer_range is not None:
        _check_heading_in_range(item, values, steer_range, check, loc)
    return Wheel(name=name, type=kind_name, actuated=actuated, sensed=sensed, **values,
                 **mass.wheel_dynamics_from_dict(item, check, loc, kind_name), steer_range=steer_range)


def _check_heading_in_range(item: Mapping[str, Any], values: dict[str, float], steer_range: tuple[float, float],
                            check: FieldReader, loc: Loc) -> None:
    """A steered wheel described at a heading its own ``steer_range`` does not reach is refused: the robot would
    start where its steering cannot be (controllers hold it at an end, odometry refuses its logs)."""
    heading = float(heading_from_beta(values["beta"], values.get("delta", 0.0)))
    if bool(heading_in_range(heading, *steer_range)):
        return
    field = next((key for key in ("heading", "beta") if key in item), "steer_range")
    given = "" if field != "steer_range" else " (no heading given: straight ahead)"
    lo, hi = (f"{math.degrees(v):g}" for v in steer_range)
    check.fail(f"heading {math.degrees(heading):g} deg{given} is outside the wheel's steer_range [{lo}, {hi}] deg",
               (*loc, field))


def _steer_range_from_dict(item: Mapping[str, Any], check: FieldReader, loc: Loc,
                           steers: bool) -> tuple[float, float] | None:
    """``steer_range: [min, max]``: the HEADINGS the steering joint reaches (0 = straight ahead), e.g. +-90 deg."""
    if "steer_range" not in item:
        return None
    where = (*loc, "steer_range")
    if not steers:
        check.fail(f"a {item.get('type')} wheel does not steer: 'steer_range' does not apply", where)
    value = item["steer_range"]
    if not isinstance(value, list | tuple) or len(value) != 2:
        check.fail("must be a list [min, max] of two headings (e.g. [-90 deg, 90 deg])", where)
    lo, hi = (check.quantity(v, "angle", (*where, j)) for j, v in enumerate(value))
    if not (-2 * math.pi <= lo < hi <= 2 * math.pi) or hi - lo > 2 * math.pi:
        check.fail(f"must be min < max within one turn, got [{lo}, {hi}] rad", where)
    return (lo, hi)


def _read_heading(item: Mapping[str, Any], values: dict[str, float], check: FieldReader, loc: Loc,
                  optional: bool) -> None:
    """``heading:`` (the users' steering angle: rolling direction, 0 = straight ahead) sets the thesis's β; a
    steered wheel given neither (`optional`) rolls straight ahead, as a fixed wheel is written with ``heading: 0``
    (the thesis's default β = 0 would roll it to the right)."""
    if "heading" not in item:
        if optional and "beta" not in item:
            values["beta"] = float(beta_from_heading(0.0, values.get("delta", 0.0)))
        return
    if "beta" in item:
        check.fail("give either 'heading' (rolling direction, 0 = straight ahead) or 'beta' (the thesis's axle "
                   "angle, heading + 90 deg), not both", (*loc, "heading"))
    heading = check.quantity(item["heading"], "angle", (*loc, "heading"))
    values["beta"] = float(beta_from_heading(heading, values.get("delta", 0.0)))
    if abs(values["beta"]) > MAX_ANGLE:  # a heading of 1e6 turns passed, and its beta failed later, unlocated
        check.fail(f"{item['heading']!r} is more than {MAX_TURNS:g} turns as the thesis's beta (heading - delta + "
                   "90 deg): no angle to steer by", (*loc, "heading"))


def _mecanum_from_dict(item: Mapping[str, Any], check: FieldReader, loc: Loc) -> Wheel:
    """``type: mecanum``: the Swedish wheel of the standard X layout; gamma from the wheel's quadrant.

    Seen from above with every wheel rolling forward, the contact rollers of the front-left and rear-right wheels
    run at +45 deg to the axle and those of the front-right and rear-left at -45 deg (the thesis's γ): WPILib's
    ``MecanumDriveKinematics`` and ROS 2's ``mecanum_drive_controller``. ``gamma`` overrides it.
    """
    data = {k: v for k, v in item.items()}
    if "beta" not in data and "heading" not in data:
        data["heading"] = 0.0
    if "gamma" not in data:
        probe = {**data, "gamma": MECANUM_GAMMA, "r_r": data.get("r_r", data.get("r"))}  # r_r <= r: read as given
        probe = _wheel_from_dict(probe, check, loc, "swedish")
        x, y = probe.position
        if abs(x * y) <= 1e-12 * max(probe.l * probe.l, 1e-300):  # l * l: inf, never OverflowError
            check.fail("a mecanum wheel on an axis of the robot frame has no quadrant to take its roller angle "
                       "from: give 'gamma' (the thesis's roller angle, +-45 deg)", (*loc, "gamma"))
        data["gamma"] = math.copysign(MECANUM_GAMMA, x * y)
    if "r_r" not in data:
        r = check.quantity(check.require(item, "r", loc), "length", (*loc, "r"))
        data["r_r"] = r / 4
    wheel = _wheel_from_dict(data, check, loc, "swedish")
    if abs(abs(math.remainder(wheel.gamma, math.pi)) - MECANUM_GAMMA) > 1e-6:  # a roller line: gamma mod 180 deg
        where = (*loc, "gamma")
        warnings.warn(str(DescriptionError(
            f"wheel '{wheel.name}' is of type mecanum with gamma {math.degrees(wheel.gamma):g} deg, not the +-45 deg "
            "of Mecanum rollers" + (" (an omni wheel)" if abs(math.cos(wheel.gamma)) < 1e-6 else "") + ": write "
            "'type: swedish' for this roller angle, or leave gamma out for the standard layout",
            source=check.source, loc=where, line=check.line_of(where))), DescriptionWarning, stacklevel=2)
    return wheel


class DescriptionWarning(UserWarning):
    """A description read whose field is likely not what its author meant: ``source:line: field: message`` naming
    the wheel (the CLI says it as a ``wmrkit: warning:`` line and in the JSON answer's ``warnings``)."""


def _check_geometry(type_name: str, v: dict[str, float], check: FieldReader, loc: Loc) -> None:
    problem = geometry_problem(type_name, v)
    if problem is not None:
        check.fail(problem[1], (*loc, problem[0]))


# ---- serialisation ---------------------------------------------------------------------------------------
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
                            for c in robot.couplings]
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


def load_robot_file(path: str | os.PathLike[str]) -> Robot:
    """Load a ``.yaml``/``.yml``/``.json`` description, with located errors."""
    path = Path(path)
    return robot_from_text(read_file(path), source=str(path), fmt="json" if path.suffix.lower() == ".json" else "yaml")


def robot_from_text(text: str, *, source: str, fmt: str = "yaml") -> Robot:
    """Parse description `text` (``fmt`` "yaml" or "json") into a :class:`Robot`.

    Parsed once (:func:`wmrkit.documents.read_document`); duplicate keys are refused in both formats.
    """
    _check_size(len(text), "characters", source)
    data, line_of = read_document(text, source, fmt)
    return robot_from_dict(data, source=source, line_of=line_of)


def save_robot_file(robot: Robot, path: str | os.PathLike[str]) -> None:
    """Write `robot` as YAML or JSON (by the file's extension); a robot built in Python that a description refuses
    (a negative mass, a radius too small for the rank tests) raises :class:`DescriptionError` and nothing is
    written: the file would not load back."""
    path = Path(path)
    data = robot_to_dict(robot)
    try:
        robot_from_dict(data, source=str(path))
    except DescriptionError as err:
        raise DescriptionError(err.message, source=f"robot '{robot.name}' is not written to {path}: it would not "
                               "load back", loc=err.loc, wheel=err.wheel) from None
    write_document(path, data)  # in one step: a failed write leaves the old description whole
