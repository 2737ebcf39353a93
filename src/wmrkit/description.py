"""Robot description files: load, validate with located one-line errors, save losslessly.

The format (YAML or JSON) is documented in ``docs/description-format.md``. YAML goes through ``safe_load``
only; user text is never evaluated. Every error names the file, the line where known, the wheel and the field.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ._description_wheels import (  # noqa: F401  (the wheel entries' names are part of the description format)
    ALL_WHEEL_FIELDS,
    COMMON_WHEEL_FIELDS,
    MECANUM_GAMMA,
    WHEEL_NAME,
    WHEEL_TYPES,
    DescriptionWarning,
    _warn_coincident,
    _wheel_from_dict,
    accepted_fields,
    kind_of_type,
)
from ._description_writer import HEADING_SPREAD, described_type, robot_to_dict  # noqa: F401  (re-exported)
from .couplings import (
    COUPLING_KINDS,
    LINKAGE_LAWS,
    Coupling,
    axle_problem,
    joint_problem,
    law_problem,
    ratios_problem,
)
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
from .wheels import Wheel

TOP_FIELDS = ("name", "wheels", "notes", "couplings", "body", "odometry")  # odometry: wmrkit.slip.settings
#: Names derived from the wheels that ``wmrkit show --json`` adds (``cli.robots.summary``); a description copied
#: from it may keep them, and each must then equal what the wheels give (:func:`_check_derived`).
DERIVED_FIELDS = {"velocity_names": "velocity_names", "steer_names": "steer_names", "actuated_joints": "actuated",
                  "sensed_joints": "sensed"}
#: Keys of every command's JSON answer that ``wmrkit show --json`` has too (docs/limits.md, JSON answers): ``robot``
#: (the name) and ``warnings`` (a list of text); a copy may keep them (:func:`_check_derived`).
ANSWER_FIELDS = ("robot", "warnings")


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
    _warn_coincident(robot, wheels_data, check)
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
        check.reject_unknown(item, ("kind", "joints", "ratios", "law"), loc)
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
        problem = ratios_problem(ratios)
        if problem is not None:
            index, reason = problem
            check.fail(reason, (*loc, "ratios") if index is None else (*loc, "ratios", index))
        out.append(Coupling(kind, tuple(joints), ratios, _law(item, kind, joints, wheels, check, loc)))
    return tuple(out)


def _law(item: Mapping[str, Any], kind: str, joints: list[str], wheels: list[Wheel], check: FieldReader,
         loc: Loc) -> str | None:
    """A linkage's ``law`` (``wmrkit.couplings.LINKAGE_LAWS``), None when absent; ``ackermann`` needs the fixed
    wheels' axle line, on which the linked wheels' axles meet."""
    if "law" not in item:
        return None
    law = check.text(item, "law", loc)
    if kind != "linkage" or law not in LINKAGE_LAWS:
        check.fail(f"'{law}': {law_problem(kind, law)}{hint(law, LINKAGE_LAWS) if kind == 'linkage' else ''}",
                   (*loc, "law"))
    problem = axle_problem(wheels) if law == "ackermann" else None
    if problem is not None:
        check.fail(f"{kind}({', '.join(joints)}): law ackermann: {problem}", (*loc, "law"))
    return law


def _joint_names(wheels: list[Wheel]) -> list[str]:
    return [f"{w.name}.{j}" for w in wheels for j in w.kind.joints]



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
