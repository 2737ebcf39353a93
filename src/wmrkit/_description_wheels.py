"""One wheel entry of a robot description, read and checked: its fields, place, heading, ``steer_range`` and the
``type: mecanum`` shorthand (:func:`_wheel_from_dict`, used by :mod:`wmrkit.description` for each of ``wheels:`` and
by :mod:`wmrkit._description_writer` to check that a written wheel reads back). Each error is a located one-line
:class:`~wmrkit.documents.DescriptionError` naming the wheel and the field.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from .documents import DescriptionError, FieldReader, Loc, hint
from .dynamics import mass
from .kinematics.linalg import characteristic_length
from .limits import ONE_PLACE
from .units import MAX_TURNS
from .wheels import (
    GEOMETRY_FIELDS,
    KINDS,
    Wheel,
    beta_from_heading,
    geometry_problem,
    heading_from_beta,
    heading_in_range,
    heading_limit,
)

if TYPE_CHECKING:
    from .robot import Robot

#: Types a description may use: the wheel kinds, and ``mecanum`` (a Swedish wheel with the standard rollers).
WHEEL_TYPES = (*KINDS, "mecanum")
COMMON_WHEEL_FIELDS = ("name", "type", "position", "l", "alpha", "actuated", "sensed", "heading",
                       "inertia", "mass", "tyre",  # these three: wmrkit.dynamics.mass
                       "steer_range",  # _steer_range_from_dict
                       "slip")  # wmrkit.slip.settings
ALL_WHEEL_FIELDS = COMMON_WHEEL_FIELDS + tuple(f for f in GEOMETRY_FIELDS if f not in ("l", "alpha"))

#: ``type: mecanum``: a Swedish wheel with the rollers of the standard layout (WPILib, ROS 2): ``gamma`` of
#: magnitude 45 deg, its sign from the wheel's quadrant (``docs/conventions.md``); r_r defaults to r / 4.
MECANUM_GAMMA = math.pi / 4

WHEEL_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")


def kind_of_type(type_name: str) -> str:
    """The wheel kind a description type reads as: ``mecanum`` is a ``swedish`` wheel."""
    return "swedish" if type_name == "mecanum" else type_name


def accepted_fields(type_name: str) -> tuple[str, ...]:
    """The fields a wheel of description type `type_name` may have, by the rules :func:`_wheel_from_dict` reads it
    with: the common ones (``mass`` for castor units only, ``steer_range`` where it steers) and its kind's geometry
    (``inertia`` takes the joints of :func:`wmrkit.dynamics.mass.inertia_joints`)."""
    kind = KINDS[kind_of_type(type_name)]
    common = tuple(f for f in COMMON_WHEEL_FIELDS
                   if (f != "mass" or kind.name in mass.CASTOR_TYPES) and (f != "steer_range" or kind.steers))
    return common + kind.required + tuple(kind.optional)


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
    delta = values.get("delta", 0.0)
    if not abs(heading) <= heading_limit(delta):  # 1e6 turns passed, and its beta failed later, unlocated
        check.fail(f"{item['heading']!r} is beyond +-{heading_limit(delta) / (2 * math.pi):.10g} turns, where the "
                   f"thesis's beta (heading - delta + 90 deg) of one sign reaches {MAX_TURNS:g} turns: no angle to "
                   "steer by", (*loc, "heading"))
    values["beta"] = float(beta_from_heading(heading, delta))


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
        _warn(check, f"wheel '{wheel.name}' is of type mecanum with gamma {math.degrees(wheel.gamma):g} deg, not the "
              "+-45 deg of Mecanum rollers" + (" (an omni wheel)" if abs(math.cos(wheel.gamma)) < 1e-6 else "") +
              ": write 'type: swedish' for this roller angle, or leave gamma out for the standard layout",
              (*loc, "gamma"))
    return wheel


def _warn(check: FieldReader, message: str, loc: Loc) -> None:
    """Say `message` as a :class:`DescriptionWarning` located at `loc` (``source:line: field: message``)."""
    warnings.warn(str(DescriptionError(message, source=check.source, loc=loc, line=check.line_of(loc))),
                  DescriptionWarning, stacklevel=3)


class DescriptionWarning(UserWarning):
    """A description read whose field is likely not what its author meant: ``source:line: field: message`` naming
    the wheel (the CLI says it as a ``wmrkit: warning:`` line and in the JSON answer's ``warnings``)."""


def _check_geometry(type_name: str, v: dict[str, float], check: FieldReader, loc: Loc) -> None:
    problem = geometry_problem(type_name, v)
    if problem is not None:
        check.fail(problem[1], (*loc, problem[0]))


def _warn_coincident(robot: Robot, items: list[Any], check: FieldReader) -> None:
    """Say each wheel mounted where an earlier wheel is (closer than the round-off of the robot's size,
    ``limits.ONE_PLACE`` ``L``; ``wmrkit analyze`` says the wider gaps up to ``analysis.conditioning.NEAR L``): a
    wheel copied and renamed but not moved, read as written. Not said for two wheels whose steering joints one gear
    or linkage turns together (a double castor written as its two castors): the description says it on purpose."""
    within = ONE_PLACE * characteristic_length(robot)
    steered = [{w.name for w in robot.wheels if f"{w.name}.steer" in c.joints} for c in robot.couplings
               if c.kind in ("gear", "linkage")]
    for j, b in enumerate(robot.wheels):
        a = next((a for a in robot.wheels[:j] if math.dist(a.position, b.position) <= within
                  and not any({a.name, b.name} <= names for names in steered)), None)
        if a is not None:
            x, y = (f"{v if abs(v) > within else 0.0:.6g}" for v in a.position)  # cos(90 deg): 6e-17
            field = "position" if "position" in items[j] else "l"
            _warn(check, f"wheels '{a.name}' and '{b.name}' are mounted at one place, ({x}, {y}) m: a wheel copied "
                  "and renamed but not moved? Read as written; a double wheel or double castor is one wheel of type "
                  "double or double_castor (docs/description-format.md)", ("wheels", j, field))
