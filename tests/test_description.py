"""Description files: every bad input gives one located line; valid ones load, save and load back unchanged."""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import KINDS, DescriptionError, Robot, Wheel, catalog
from wmrkit.cli.main import main
from wmrkit.description import robot_from_text
from wmrkit.dynamics.mass import Body

DOC = Path(__file__).resolve().parents[1] / "docs" / "description-format.md"
SRC = "robots/test.yaml"
BASE = """\
name: test-bot
wheels:
  - name: left
    type: fixed
    position: [0, 0.3]
    beta: 90 deg
    r: 0.1
    actuated: [spin]
  - name: caster
    type: castor
    l: 0.5
    alpha: 180 deg
    d: 0.05
    r: 0.04
  - name: omni
    type: swedish
    position: [0.2, -0.1]
    beta: 0
    gamma: 90 deg
    r: 0.05
    r_r: 0.01
"""
TYPES = ", ".join((*KINDS, "mecanum"))
LENGTHS = "m, mm, cm, dm, km, um, \u00b5m, in, ft"

# (find, replace with, expected 1-based line, expected message after "file:line: "); BASE's lines counted by hand
BAD = {
    "malformed-yaml": ("type: fixed", "type: fixed: x", 4, "malformed YAML: mapping values are not allowed here"),
    "unknown-type": ("type: castor", "type: castr", 10,
                     f"wheels[1].type: unknown wheel type 'castr' (did you mean 'castor'?) (types: {TYPES})"),
    "unknown-field": ("alpha: 180 deg", "alpah: 180 deg", 12,
                      "wheels[1].alpah: unknown field 'alpah' (did you mean 'alpha'?)"),
    "unknown-top-field": ("name: test-bot", "nmae: test-bot", 1, "nmae: unknown field 'nmae' (did you mean 'name'?)"),
    "field-not-for-type": ("    r: 0.1\n", "    r: 0.1\n    d: 0.1\n", 8,
                           "wheels[0].d: field 'd' does not apply to a fixed wheel"),
    "duplicate-name": ("name: caster", "name: left", 9, "wheels[1].name: duplicate wheel name 'left'"),
    "duplicate-key": ("    r: 0.1\n", "    r: 0.1\n    r: 0.2\n", 8, "wheels[0].r: field 'r' given twice"),
    "zero-radius": ("r: 0.1", "r: 0", 7, "wheels[0].r: must be > 0, got 0.0 m"),
    "negative-radius": ("r: 0.1", "r: -0.1", 7, "wheels[0].r: must be > 0, got -0.1 m"),
    "negative-roller": ("r_r: 0.01", "r_r: -1 mm", 21, "wheels[2].r_r: must be > 0, got -0.001 m"),
    "nan": ("r: 0.1", "r: .nan", 7, "wheels[0].r: must be finite, got nan"),
    "inf": ("r: 0.1", "r: .inf", 7, "wheels[0].r: must be finite, got inf"),
    "minus-inf": ("beta: 90 deg", "beta: -.inf", 6, "wheels[0].beta: must be finite, got -inf"),
    "unknown-unit": ("r: 0.1", "r: 10 furlong", 7,
                     f"wheels[0].r: unknown unit 'furlong' in '10 furlong' (accepted: {LENGTHS})"),
    "angle-in-mm": ("beta: 90 deg", "beta: 90 mm", 6, "wheels[0].beta: '90 mm' is a length, expected an angle"),
    "length-in-deg": ("d: 0.05", "d: 5 deg", 13, "wheels[1].d: '5 deg' is an angle, expected a length"),
    "not-a-number": ("r: 0.1", "r: big", 7,
                     "wheels[0].r: cannot read 'big' as a length (write e.g. '0.25' or '250 mm')"),
    "boolean": ("r: 0.1", "r: yes", 7, "wheels[0].r: expected a length, got a boolean"),
    "castor-d-zero": ("d: 0.05", "d: 0", 13,
                      "wheels[1].d: a castor needs an offset d != 0 (with d = 0 it is a 'steerable' wheel)"),
    "castor-delta-90": ("d: 0.05", "delta: 90 deg\n    d: 0.05", 13,
                        "wheels[1].delta: a castor with delta = +-90 deg has its axle along the arm and cannot steer "
                        "itself (det J_c = -r d cos(delta) = 0, eq. 3.19)"),
    "swedish-gamma-zero": ("gamma: 90 deg", "gamma: 0", 19,
                           "wheels[2].gamma: a Swedish wheel with gamma = 0 (or 180 deg) has rollers parallel to the "
                           "axle and does not roll (det J_s = r r_r sin(gamma) = 0, eq. 3.19); omni: 90 deg, Mecanum: "
                           "45 deg"),
    "swedish-gamma-180": ("gamma: 90 deg", "gamma: 180 deg", 19, None),
    "position-and-l": ("    position: [0, 0.3]\n", "    position: [0, 0.3]\n    l: 0.3\n", 5,
                       "wheels[0].position: give either 'position' or 'l' and 'alpha', not both"),
    "bad-position": ("[0, 0.3]", "[0, 0.3, 1]", 5, "wheels[0].position: must be a list [x, y] of two lengths"),
    "joint-not-on-type": ("actuated: [spin]", "actuated: [steer]", 8,
                          "wheels[0].actuated[0]: no joint 'steer' on a fixed wheel (joints: spin)"),
    "bad-date": ("r: 0.1", "r: 2020-13-45", 7,
                 "wheels[0].r: malformed YAML: cannot read '2020-13-45' as timestamp (month must be in 1..12)"),
    "slip-zero": ("    actuated: [spin]\n", "    actuated: [spin]\n    slip: {lateral: 0, longitudinal: 1}\n", 9,
                  "wheels[0].slip.lateral: must be a number > 0, got 0.0"),
    "slip-missing": ("    actuated: [spin]\n", "    actuated: [spin]\n    slip: {lateral: 2}\n", 9,
                     "wheels[0].slip: missing field 'longitudinal'"),
    "slip-noise-unit": ("    actuated: [spin]\n", "    actuated: [spin]\n    slip:\n      lateral: 1\n"
                        "      longitudinal: 1\n      noise: {lateral: 2 deg, longitudinal: 1}\n", 12,
                        "wheels[0].slip.noise.lateral: '2 deg' is an angle, expected a number"),
    "odometry-method": ("name: test-bot\n", "name: test-bot\nodometry: {method: wsl}\n", 2,
                        "odometry.method: must be one of exact, rk2, euler, paper002, wls, fk1, fk2, got 'wsl'"),
    "odometry-noise": ("name: test-bot\n", "name: test-bot\nodometry:\n  noise: {process: -1}\n", 3,
                       "odometry.noise.process: must be a number > 0, got -1.0"),
    "odometry-noise-spread": ("name: test-bot\n", "name: test-bot\nodometry:\n  noise: {lateral: 1e-9}\n", 3,
                              "odometry.noise: Kalman noise lateral (1e-09) and process (1) differ by more than a "
                              "factor 1e+06: the filter would lose the smaller to round-off (only ratios matter)"),
    "slip-noise-spread": ("    actuated: [spin]\n", "    actuated: [spin]\n    slip:\n      lateral: 1\n"
                          "      longitudinal: 1\n      noise: {lateral: 1e9, longitudinal: 1}\n", 12,
                          "wheels[0].slip.noise: Kalman noise process (1) and left (lateral) (1e+09) differ by "
                          "more than a factor 1e+06: the filter would lose the smaller to round-off (only ratios "
                          "matter)"),
}


def _line_of(text: str, fragment: str) -> int:
    """1-based line where `fragment` starts in `text`."""
    return text[: text.index(fragment)].count("\n") + 1


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_gives_one_located_line(case, tmp_path):
    find, replace, line, message = BAD[case]
    assert BASE.count(find) == 1
    text = BASE.replace(find, replace)
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source=SRC)
    assert err.value.line == line
    if message is not None:
        assert str(err.value) == f"{SRC}:{line}: {message}"
    assert len(str(err.value).splitlines()) == 1
    path = tmp_path / "bot.yaml"
    path.write_text(text)
    with pytest.raises(DescriptionError, match=rf"^{re.escape(str(path))}:{line}: "):
        Robot.from_file(path)


def test_missing_field_names_the_wheel_and_field():
    text = BASE.replace("    r: 0.1\n", "")
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source=SRC)
    assert str(err.value) == f"{SRC}:3: wheels[0]: missing field 'r'"
    with pytest.raises(DescriptionError, match=rf"^{SRC}:9: wheels\[1\]: missing field 'd'$"):
        robot_from_text(BASE.replace("    d: 0.05\n", ""), source=SRC)
    with pytest.raises(DescriptionError, match=rf"^{SRC}: wheels: missing field 'wheels'$"):
        robot_from_text("name: x\n", source=SRC)
    with pytest.raises(DescriptionError, match=rf"^{SRC}:2: wheels: must be a non-empty list of wheels$"):
        robot_from_text("name: x\nwheels: []\n", source=SRC)
    with pytest.raises(DescriptionError, match=rf"^{SRC}:3: wheels\[0\]: missing the wheel's place"):
        robot_from_text(BASE.replace("    position: [0, 0.3]\n", ""), source=SRC)


def test_malformed_json_and_json_nan():
    with pytest.raises(DescriptionError, match=r"^bot\.json:2: malformed JSON: Expecting value \(column 13\)$"):
        robot_from_text('{"name": "x",\n "wheels": [}', source="bot.json", fmt="json")
    data = yaml.safe_load(BASE)
    text = json.dumps(data, indent=1).replace('"r": 0.1', '"r": NaN')
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="bot.json", fmt="json")
    assert str(err.value) == f"bot.json:{_line_of(text, 'NaN')}: wheels[0].r: must be finite, got nan"
    for bad in ("Infinity", "-Infinity", "1e999", "1" * 400):
        with pytest.raises(DescriptionError, match=r"wheels\[0\]\.r: "):
            robot_from_text(text.replace("NaN", bad), source="bot.json", fmt="json")
    with pytest.raises(DescriptionError, match=r"^bot\.json:\d+: wheels\[0\]\.r: field 'r' given twice$"):
        robot_from_text(text.replace('"r": NaN', '"r": 0.1, "r": 0.2'), source="bot.json", fmt="json")



@pytest.mark.parametrize(("text", "message"), [
    ('{"name": ' + "[" * 100000 + "]" * 100000 + "}", "malformed JSON: nesting too deep"),
    ('{"name": "x", "wheels": [{"r": ' + "1" * 5000 + "}]}", "malformed JSON: a number of more than 4300 digits"),
])
def test_json_beyond_the_parser_s_limits_is_refused_in_the_user_s_terms(text, message):
    """The JSON door answered with Python's words: 'maximum recursion depth exceeded while decoding a JSON array from
    a unicode string', '... use sys.set_int_max_str_digits() to increase the limit' (YAML: 'nesting too deep')."""
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="bot.json", fmt="json")
    assert str(err.value) == f"bot.json: {message}"

@pytest.mark.parametrize("fmt", ["json", "yaml"])
def test_a_field_given_twice_names_its_wheel_like_every_other_wheel_error(fmt, tmp_path, capsys):
    """The JSON error's `wheel` is the wheel's name (as for a wrong value), not its index in the list."""
    data = yaml.safe_load(BASE)
    text = json.dumps(data, indent=1) if fmt == "json" else BASE
    name = data["wheels"][0]["name"]
    twice = text.replace('"r": 0.1', '"r": 0.1, "r": 0.2', 1) if fmt == "json" else \
        text.replace("    r: 0.1\n", "    r: 0.1\n    r: 0.2\n", 1)
    assert twice != text
    with pytest.raises(DescriptionError) as err:
        robot_from_text(twice, source=f"bot.{fmt}", fmt=fmt)
    assert err.value.wheel == name and err.value.loc == ("wheels", 0, "r")
    path = tmp_path / f"bot.{fmt}"
    path.write_text(twice)
    assert main(["show", str(path), "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["wheel"] == name


def test_unreadable_files(tmp_path):
    with pytest.raises(DescriptionError, match=r"cannot read the file \(FileNotFoundError"):
        Robot.from_file(tmp_path / "none.yaml")
    bad = tmp_path / "latin1.yaml"
    bad.write_bytes("name: r\u00f6ver\n".encode("latin-1"))
    with pytest.raises(DescriptionError, match=r"latin1\.yaml: cannot read the file \(UnicodeDecodeError"):
        Robot.from_file(bad)



@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_a_file_saved_with_a_byte_order_mark_loads(suffix, tmp_path):
    """Windows editors start UTF-8 files with a BOM: YAML skipped it, JSON answered "Unexpected UTF-8 BOM (decode
    using utf-8-sig)", advice for Python programmers."""
    robot = robot_from_text(BASE, source=SRC)
    path = tmp_path / f"bot{suffix}"
    robot.to_file(path)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    assert Robot.from_file(path) == robot


# ---- the documented format ----------------------------------------------------------------------------------------
def _doc_blocks(lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", DOC.read_text(), flags=re.S | re.M)


def test_issue_example_from_the_doc_loads():
    """The first example a newcomer copies is a real tricycle: type 4, sufficient and consistent actuators."""
    from wmrkit.analysis import classify
    from wmrkit.kinematics import actuation_analysis

    text = next(b for b in _doc_blocks("yaml") if b.startswith("name: tricycle-example"))
    robot = robot_from_text(text, source="doc")
    assert robot.wheel_names == ("front", "rear_left", "rear_right")
    front, rear, _ = robot.wheels
    assert (front.type, front.l, front.alpha, front.r) == ("steerable", 0.9, 0.0, 0.15)
    assert front.beta == pytest.approx(math.radians(110)) and front.heading == pytest.approx(math.radians(20))
    assert (rear.type, rear.beta, rear.heading) == ("fixed", math.pi / 2, 0.0)
    assert robot.velocity_names == ("vx", "vy", "omega", "front.spin", "rear_left.spin", "rear_right.spin")
    c = classify(robot)
    assert (c.type, c.mobility, c.steerability, c.degenerate) == (4, 1, 1, False)
    act = actuation_analysis(robot)
    assert bool(act.sufficient) and bool(act.consistent)


def test_every_doc_example_loads_and_every_doc_error_is_exact():
    examples = [b for b in _doc_blocks("yaml") if "wheels:" in b]
    assert len(examples) >= 3
    errors = 0
    for block in examples:
        first = block.splitlines()[0]
        if first.startswith("# file: "):  # an error example: the next ```text block is the message
            source = first.removeprefix("# file: ")
            expected = re.search(rf"```yaml\n{re.escape(block)}```\n+```text\n(.*?)\n```", DOC.read_text(), re.S)
            with pytest.raises(DescriptionError) as err:
                robot_from_text(block, source=source)
            assert f"wmrkit: error: {err.value}" == expected.group(1)
            errors += 1
        else:
            assert isinstance(robot_from_text(block, source="doc"), Robot)
    assert errors >= 3
    json_blocks = _doc_blocks("json")
    assert json_blocks
    for block in json_blocks:
        assert isinstance(robot_from_text(block, source="doc.json", fmt="json"), Robot)


def test_doc_lists_every_type_field_and_unit():
    doc = DOC.read_text()
    for name, kind in KINDS.items():
        assert f"`{name}`" in doc
        for field in (*kind.required, *kind.optional, *kind.joints):
            assert f"`{field}`" in doc, (name, field)
    from wmrkit.units import UNITS

    for unit in (u for table in UNITS.values() for u in table):
        assert f"`{unit}`" in doc, unit


# ---- properties: random valid descriptions ------------------------------------------------------------------------
FACTORS = {"length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254, "ft": 0.3048},
           "angle": {"rad": 1.0, "deg": math.pi / 180, "turn": 2 * math.pi}}
KIND_OF = {"l": "length", "alpha": "angle", "beta": "angle", "d": "length", "delta": "angle", "gamma": "angle",
           "r": "length", "r_r": "length", "b": "length"}
RANGES = {"l": (0, 2), "alpha": (-3, 3), "beta": (-3, 3), "d": (0.01, 0.3), "delta": (-1.2, 1.2),
          "gamma": (0.3, 2.8), "r": (0.01, 0.5), "r_r": (0.002, 0.05), "b": (0.01, 0.4)}


@st.composite
def _quantity(draw, field: str, signed: bool = False) -> tuple[object, float]:
    """A value as written in a file (number or string with units) and its SI value."""
    lo, hi = RANGES[field]
    si = draw(st.floats(lo, hi)) * (draw(st.sampled_from([-1, 1])) if signed or field in ("d", "gamma") else 1)
    if draw(st.booleans()):
        return si, si
    unit = draw(st.sampled_from(sorted(FACTORS[KIND_OF[field]])))
    number = si / FACTORS[KIND_OF[field]][unit]
    return f"{number!r}{draw(st.sampled_from(['', ' ']))}{unit}", number * FACTORS[KIND_OF[field]][unit]


@st.composite
def descriptions(draw) -> tuple[dict, list[dict]]:
    """A random valid description and the SI values each wheel must get."""
    items, expected = [], []
    for i in range(draw(st.integers(1, 4))):
        type_name = draw(st.sampled_from(list(KINDS)))
        kind = KINDS[type_name]
        item: dict = {"name": f"w{i}", "type": type_name}
        si: dict = {"name": f"w{i}", "type": type_name}
        if draw(st.booleans()):
            (x, x_si), (y, y_si) = draw(_quantity("l", signed=True)), draw(_quantity("l", signed=True))
            item["position"] = [x, y]
            si["l"], si["alpha"] = math.hypot(x_si, y_si), math.atan2(y_si, x_si)
        else:
            for field in ("l", "alpha"):
                item[field], si[field] = draw(_quantity(field))
        for field in (*kind.required, *kind.optional):
            if field in kind.required or draw(st.booleans()):
                item[field], si[field] = draw(_quantity(field))
            else:
                si[field] = kind.optional[field]
        if si.get("r_r", 0.0) > si["r"]:  # the rollers sit on the rim: r_r <= r (r_r = r: a ball's rollers)
            item["r_r"], si["r_r"] = item["r"], si["r"]
        if "beta" in kind.optional and "beta" not in item:  # a steered wheel given no angle rolls straight ahead
            si["beta"] = math.pi / 2 - si.get("delta", 0.0)
        for role in ("actuated", "sensed"):
            joints = draw(st.lists(st.sampled_from(kind.joints), unique=True))
            if joints or draw(st.booleans()):
                item[role] = joints
            si[role] = tuple(j for j in kind.joints if j in joints)
        items.append(item)
        expected.append(si)
    data = {"name": draw(st.sampled_from(["bot", "yes", "1.5", "a robot: x"])), "wheels": items}
    if draw(st.booleans()):
        data["notes"] = draw(st.text(st.characters(codec="utf-8", exclude_categories=("Cs", "Cc")), max_size=20))
    return data, expected


@settings(max_examples=200)
@given(description=descriptions())
def test_valid_descriptions_load_with_si_values_and_round_trip(description, tmp_path_factory):
    data, expected = description
    robot = Robot.from_dict(data)
    for wheel, si in zip(robot.wheels, expected, strict=True):
        for field, value in si.items():
            got = getattr(wheel, field)
            assert got == (pytest.approx(value, rel=1e-12, abs=1e-15) if isinstance(value, float) else value)
    # the text forms of the same description give the same robot
    assert robot_from_text(yaml.safe_dump(data, allow_unicode=True), source="t.yaml") == robot
    assert robot_from_text(json.dumps(data), source="t.json", fmt="json") == robot
    # saving and loading is lossless, in both formats
    folder = tmp_path_factory.mktemp("rt")
    for name in ("bot.yaml", "bot.json", "bot.yml"):
        robot.to_file(folder / name)
        assert Robot.from_file(folder / name) == robot
    assert Robot.from_dict(robot.to_dict()) == robot


@settings(max_examples=300)
@given(descriptions(), st.data())
def test_line_numbers_are_one_based_and_right(description, data):
    """Break one field of a dumped description: the error is on that field's line, found by scanning the text."""
    doc, _ = description
    i = data.draw(st.integers(0, len(doc["wheels"]) - 1))
    field = data.draw(st.sampled_from(sorted(k for k in doc["wheels"][i] if k in KIND_OF)))
    doc["wheels"][i][field] = "1 furlong"
    text = yaml.safe_dump(doc, sort_keys=False)
    lines = text.splitlines()
    starts = [n for n, s in enumerate(lines) if s.startswith("- ")]
    line = next(n for n in range(starts[i], len(lines)) if re.match(rf"^(- |  ){field}:", lines[n])) + 1
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="t.yaml")
    assert err.value.line == line
    assert str(err.value).startswith(f"t.yaml:{line}: wheels[{i}].{field}: unknown unit 'furlong'")


# ---- properties: broken descriptions never raise anything but DescriptionError ------------------------------------
_text = st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=12)
_garbage = st.recursive(
    st.none() | st.booleans() | st.integers() | st.integers(10**300, 10**400) | st.floats() | _text
    | st.sampled_from(["90 deg", "1 mm", "nan", ".inf", "1e999", "-0", "spin", "steer", "castor", "2020-01-01"]),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(_text, inner, max_size=3),
    max_leaves=6,
)


def _assert_only_description_errors(load) -> None:
    try:
        robot = load()
    except DescriptionError as err:
        message = str(err)
        assert len(message.splitlines()) == 1 and message.strip() == message
        assert err.line is None or err.line >= 1
    else:
        assert isinstance(robot, Robot)


@st.composite
def _broken(draw) -> dict:
    data, _ = draw(descriptions())
    for _ in range(draw(st.integers(1, 3))):
        wheels = data.get("wheels")
        target = draw(st.sampled_from([data, *(wheels if isinstance(wheels, list) else [])]))
        if not isinstance(target, dict) or not target:
            continue
        key = draw(st.sampled_from(sorted(target, key=str)))
        op = draw(st.sampled_from(["drop", "rename", "retype", "add", "wheels"]))
        if op == "drop":
            del target[key]
        elif op == "rename":
            target[draw(_text)] = target.pop(key)
        elif op == "retype":
            target[key] = draw(_garbage)
        elif op == "add":
            target[draw(_text)] = draw(_garbage)
        else:
            old = data.get("wheels")
            data["wheels"] = [*old, draw(_garbage)] if isinstance(old, list) and draw(st.booleans()) else draw(_garbage)
    return data


@settings(max_examples=300)
@given(_broken())
def test_broken_descriptions_raise_only_description_errors(data):
    _assert_only_description_errors(lambda: Robot.from_dict(data))
    _assert_only_description_errors(lambda: robot_from_text(yaml.safe_dump(data, allow_unicode=True), source="b"))
    _assert_only_description_errors(lambda: robot_from_text(json.dumps(data), source="b", fmt="json"))


@settings(max_examples=500)
@given(st.text(max_size=300), st.sampled_from(["yaml", "json"]))
def test_random_text_raises_only_description_errors(text, fmt):
    _assert_only_description_errors(lambda: robot_from_text(text, source="r", fmt=fmt))


@settings(max_examples=300)
@given(st.data())
def test_damaged_valid_text_raises_only_description_errors(data):
    text = yaml.safe_dump(data.draw(descriptions())[0], sort_keys=False)
    for _ in range(data.draw(st.integers(1, 4))):
        at = data.draw(st.integers(0, len(text)))
        cut = data.draw(st.integers(0, 5))
        text = text[:at] + data.draw(st.sampled_from(["", ":", "-", "[", "'", "\t", "&a", "*a", "!!", "#", "\n  "]))\
            + text[at + cut:]
    _assert_only_description_errors(lambda: robot_from_text(text, source="d"))


def test_save_then_load_catalog_style_robot(tmp_path):
    robot = Robot("r", (Wheel("a", "double_castor", l=0.3, alpha=1.0, beta=0.2, r=0.1, d=-0.05, b=0.1,
                              actuated=("steer", "spin2")),))
    for name in ("a.yaml", "a.json"):
        robot.to_file(tmp_path / name)
        assert Robot.from_file(tmp_path / name) == robot
    assert np.isfinite(robot.constraint_matrix()).all()


@pytest.mark.parametrize("wheel", [
    {"type": "steerable", "heading": 6.0},  # beta = heading + 90 deg = 7.57 rad: beyond a turn
    {"type": "castor", "d": 0.05, "delta": "-30 deg", "heading": "-350 deg"},
    {"type": "steerable", "alpha": "400 deg", "beta": "720 deg"},
])
def test_angles_beyond_a_turn_are_saved_so_that_they_load_again(wheel, tmp_path):
    # a valid description (heading: 6.0, beta: 720 deg) was saved as 'beta: 7.57...' or '12.56...', a bare angle
    # beyond a turn, which loading refuses as degrees written bare: to_file wrote a file wmrkit could not read back
    robot = Robot.from_dict({"name": "r", "wheels": [{"name": "w", "l": 0.3, "alpha": 0.5, "r": 0.1} | wheel]})
    for name in ("a.yaml", "a.json"):
        robot.to_file(tmp_path / name)
        assert Robot.from_file(tmp_path / name) == robot
    assert Robot.from_dict(robot.to_dict()) == robot
    steered = robot.with_steering({"w": 90.0}) if robot.wheels[0].kind.steers else robot
    assert Robot.from_dict(steered.to_dict()) == steered


@pytest.mark.parametrize("bad", ["a.b", "left wheel", "x=1", "", "1st", "é"])
def test_wheel_names_must_be_identifiers(bad):
    """Wheel names make velocity names 'wheel.joint' and CLI arguments NAME=VALUE: no dots, spaces or '='."""
    data = {"name": "r", "wheels": [{"name": bad, "type": "fixed", "position": [0, 0], "beta": 0, "r": 0.1}]}
    rule = "must be a non-empty string" if not bad else r"wheel names are ASCII letters, digits, '_' and '-', starting"
    with pytest.raises(DescriptionError, match=r"wheels\[0\]\.name: " + rule):
        Robot.from_dict(data, source="x.yaml")


def test_odometry_settings_are_read_kept_and_saved(tmp_path):
    """The documented ``odometry`` example: its settings read back as written (the thesis's optimised forklift
    weights); the Robot keeps them (``robot.odometry``) and saving it writes them back."""
    from wmrkit.slip.settings import odometry_settings

    text = next(b for b in _doc_blocks("yaml") if b.startswith("name: forklift-wls"))
    path = tmp_path / "fk.yaml"
    path.write_text(text)
    s = odometry_settings(str(path))
    assert (s.method, s.scheme, s.slip, s.noise) == ("wls", "exact", (1.0, 1.0), (1.0, 1.0, 1.0))
    w = s.weights()
    (lat12, lon12), (lat3, _) = w.of_wheel("left_drive"), w.of_wheel("steer")
    assert (lon12 / lat12, lat3 / lat12) == (pytest.approx(3.2e-3), pytest.approx(19.2))  # k11, k12 (7.67)
    assert s.kalman_noise().of_wheel("steer") == (0.28, 0.28)
    data = yaml.safe_load(text)
    bare = {**{k: v for k, v in data.items() if k != "odometry"},
            "wheels": [{k: v for k, v in w.items() if k != "slip"} for w in data["wheels"]]}
    robot = Robot.from_file(path)
    assert robot.odometry == s and robot != Robot.from_dict(bare)
    assert robot.wheels == Robot.from_dict(bare).wheels
    assert robot.to_dict()["odometry"] == data["odometry"] and Robot.from_dict(robot.to_dict()) == robot


@pytest.mark.parametrize("item", [{"type": "steerable", "r": 0.2}, {"type": "castor", "d": 0.05, "r": 0.1},
                                  {"type": "castor", "d": 0.05, "r": 0.1, "delta": "20 deg"},
                                  {"type": "double", "b": 0.1, "r": 0.1},
                                  {"type": "double_castor", "d": 0.05, "b": 0.1, "r": 0.1}])
def test_a_steered_wheel_given_no_angle_rolls_straight_ahead(item):
    """The thesis's default beta = 0 put the axle along +x: the wheel rolled to the right (heading -90 deg), and the
    car example of docs/description-format.md, whose front wheels give no angle, had no ICR."""
    robot = Robot.from_dict({"name": "t", "wheels": [{"name": "w", "position": [1.0, 0.5], **item}]})
    assert robot.heading == pytest.approx([0.0], abs=1e-15)
    wheel = robot.wheels[0]
    axle = wheel.beta + wheel.delta  # the axle of the rolling wheel (3.12): perpendicular to straight ahead
    assert (np.cos(axle), np.sin(axle)) == pytest.approx((0.0, 1.0), abs=1e-15)


@pytest.mark.parametrize("text", ["\u0663", "\uff11", "0.\u0665 m", "\u0661\u0662 deg", "1e\u0663"])
def test_digits_other_than_ascii_are_not_read_as_numbers(text):
    """float() reads '٣' (Arabic-Indic three) as 3 and '１' (fullwidth one) as 1, and the quantity grammar's \\d
    let them through: 'r: ٣' gave a 3 m wheel. The grammar is ASCII digits only."""
    with pytest.raises(DescriptionError, match=r"wheels\[0\]\.r: "):
        robot_from_text(f"name: x\nwheels:\n  - {{name: a, type: fixed, position: [0, 0.2], heading: 0, "
                        f"r: '{text}'}}\n", source=SRC)


@pytest.mark.parametrize(("kind", "extra"), [("steerable", ""), ("fixed", ""), ("castor", ", d: 0.05, delta: 30 deg")])
def test_a_heading_whose_beta_passes_the_angle_limit_is_located(kind, extra):
    """'heading: 1e6 turn' passed the quantity check (at most 1e6 turns) and its beta = heading + 90 deg did not:
    the error came later as "beta: angles must be finite numbers of at most 1e+06 turns [rad], got 6283186.87...",
    with no file, wheel or field."""
    with pytest.raises(DescriptionError, match=r"^robots/test\.yaml:3: wheels\[0\]\.heading: .*1e\+06 turns"):
        robot_from_text(f"name: x\nwheels:\n  - {{name: a, type: {kind}, position: [0.3, 0.2], heading: 1e6 turn, "
                        f"r: 0.1{extra}}}\n", source=SRC)


def test_numpy_numbers_in_a_description_mapping_are_numbers():
    """A mapping built with NumPy (a design sweep's values) was refused: 'position[0]: expected a length, got
    float32'. NumPy's reals of any precision are read as Python's are; its booleans stay refused."""
    from wmrkit import catalog

    forklift = catalog.load("forklift")

    def numpy_numbers(x, kind):
        if isinstance(x, dict):
            return {k: numpy_numbers(v, kind) for k, v in x.items()}
        if isinstance(x, list):
            return [numpy_numbers(v, kind) for v in x]
        return kind(x) if isinstance(x, int | float) and not isinstance(x, bool) else x

    assert Robot.from_dict(numpy_numbers(forklift.to_dict(), np.float64)) == forklift
    single = Robot.from_dict(numpy_numbers(forklift.to_dict(), np.float32))
    assert single.wheels[0].r == float(np.float32(forklift.wheels[0].r))
    assert all(type(w.l) is float and type(w.r) is float for w in single.wheels)
    data = {"name": "a", "wheels": [
        {"name": "l", "type": "fixed", "position": [np.int64(0), np.float32(0.25)], "heading": np.int8(0), "r": 0.1},
        {"name": "r", "type": "fixed", "position": [0, -0.25], "heading": 0, "r": np.float16(0.125)}]}
    assert Robot.from_dict(data).wheel("l").l == 0.25 and Robot.from_dict(data).wheel("r").r == 0.125
    data["wheels"][0]["r"] = np.bool_(True)
    with pytest.raises(DescriptionError, match=r"^<dict>: wheels\[0\]\.r: expected a length, got bool"):
        Robot.from_dict(data)


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_a_robot_built_with_numpy_numbers_saves_and_loads(suffix, tmp_path):
    """Wheel(..., r=np.float32(0.1)) is a valid wheel, but saving it raised yaml's RepresenterError ('cannot
    represent an object') or json's TypeError ('Object of type float32 is not JSON serializable')."""
    robot = Robot("np", (
        Wheel("l", "fixed", l=np.float32(0.25), alpha=np.float64(math.pi / 2), beta=np.float32(0.0), r=np.float32(0.1)),
        Wheel("c", "castor", l=np.int64(1), alpha=math.pi, beta=np.float64(math.pi / 2), r=0.05, d=np.float16(0.125),
              steer_range=(np.float32(-1.5), np.float32(1.5))),
    ))
    path = tmp_path / f"np{suffix}"
    robot.to_file(path)
    assert Robot.from_file(path) == robot


@pytest.mark.parametrize("name", ["ackermann", "mecanum-4", "swerve-4", "forklift", "skid-steer-4", "agv-drive-unit"])
def test_robots_are_saved_as_their_users_wrote_them(name, capsys):
    """to_dict (and show --json, and every saved file) writes a wheel's place as ``position`` and its angle as
    ``heading``, the numbers of the catalog file (read independently from its text), a Mecanum wheel as ``type:
    mecanum``: not the thesis's l, alpha, beta that a user would have to convert back. Still exact."""
    from wmrkit import catalog
    from wmrkit.units import parse_quantity

    robot = catalog.load(name)
    written = robot.to_dict()
    source = yaml.safe_load(catalog.source_text(name))["wheels"]
    for got, typed in zip(written["wheels"], source, strict=True):
        assert got["type"] == typed["type"]
        assert got["position"] == [parse_quantity(v, "length") for v in typed["position"]]
        assert got["heading"] == parse_quantity(typed.get("heading", 0), "angle")
        assert not {"l", "alpha", "beta"} & set(got)
    assert Robot.from_dict(written) == robot
    assert main(["show", name, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["wheels"] == json.loads(json.dumps(written["wheels"]))


def test_a_parameter_no_users_number_gives_back_is_saved_as_the_thesis_wrote_it():
    """beta = 20 deg has finer bits than any heading near -70 deg (heading = beta - 90 deg) can carry: the wheel keeps
    'beta' (exact), its place still 'position'."""
    robot = Robot.from_dict({"name": "r", "wheels": [
        {"name": "o", "type": "steerable", "l": 0.5, "alpha": "90 deg", "beta": "20 deg", "r": 0.1}]})
    (wheel,) = robot.to_dict()["wheels"]
    assert wheel["beta"] == math.radians(20) and "heading" not in wheel
    assert wheel["position"] == [0.0, 0.5] and "l" not in wheel
    assert Robot.from_dict(robot.to_dict()) == robot
    import sympy

    symbolic = Robot("s", (Wheel("a", "fixed", l=sympy.Symbol("l"), alpha=0.0, beta=0.0, r=0.1),))
    assert symbolic.to_dict()["wheels"][0]["l"] == sympy.Symbol("l")  # no numbers to round: as they are


@pytest.mark.parametrize(("type_name", "extra"), [
    ("steerable", {}), ("fixed", {}), ("double", {"b": 0.1}), ("castor", {"d": 0.05, "delta": "10 deg"}),
    ("castor", {"d": -0.05, "delta": "-33 deg"}), ("double_castor", {"d": 0.05, "b": 0.1}),
])
def test_every_heading_of_a_turn_either_way_is_saved_as_a_heading(type_name, extra):
    """A heading of -180 deg, or beyond 180 deg (a steer_range's 200 deg), was saved as the thesis's beta, as was one
    castor heading in seven with delta = 10 deg (beta + delta - 90 deg came back an ulp off the heading written);
    docs/description-format.md promises beta only where no heading gives the wheel back. Whole degrees from -360 to
    360: the heading written is the one read, to the few ulps by which two headings give the same beta, and gives the
    same wheel bit for bit."""
    from wmrkit.units import parse_quantity

    for degrees in range(-360, 361):
        robot = Robot.from_dict({"name": "r", "wheels": [{"name": "w", "type": type_name, "position": [0.3, -0.2],
                                                          "heading": f"{degrees} deg", "r": 0.1, **extra}]})
        (written,) = robot.to_dict()["wheels"]
        assert "beta" not in written, degrees
        assert written["heading"] == pytest.approx(parse_quantity(f"{degrees} deg", "angle"), abs=4e-15), degrees
        assert Robot.from_dict(robot.to_dict()) == robot


@pytest.mark.parametrize(("position", "written"), [
    ([0, 0.30000000000000004], [0.0, 0.30000000000000004]), ([-0.1 - 0.2, 0], [-0.30000000000000004, 0.0]),
    ([0, "9 mm"], [0.0, 0.009]), (["0.5 in", "-3 dm"], [0.0127, -0.3]),
])
def test_a_position_is_saved_with_the_fewest_decimals_of_each_coordinate(position, written):
    """Both coordinates were rounded to the same number of decimals: the 0 of [0, 0.30000000000000004] came out as
    2e-17 (the cosine of alpha = 90 deg, times l), and [0, 9 mm] as [1e-18, 0.009000000000000001]."""
    robot = Robot.from_dict({"name": "r", "wheels": [{"name": "w", "type": "fixed", "position": position, "heading": 0,
                                                      "r": 0.1}]})
    assert robot.to_dict()["wheels"][0]["position"] == written
    assert Robot.from_dict(robot.to_dict()) == robot


@pytest.mark.parametrize(("extra", "field", "message"), [
    ({"d": 0.1}, "d", "field 'd' does not apply to a mecanum wheel"),
    ({"actuated": ["steer"]}, "actuated[0]", "no joint 'steer' on a mecanum wheel (joints: spin)"),
    ({"steer_range": ["-90 deg", "90 deg"]}, "steer_range", "a mecanum wheel does not steer"),
])
def test_errors_on_a_mecanum_wheel_name_the_type_written(extra, field, message):
    """A ``type: mecanum`` wheel is read as a Swedish one, and its errors said 'a swedish wheel', a type the file
    does not hold."""
    with pytest.raises(DescriptionError) as err:
        Robot.from_dict({"name": "r", "wheels": [{"name": "fl", "type": "mecanum", "position": [0.2, 0.15], "r": 0.05,
                                                  **extra}]})
    assert f"wheels[0].{field}: {message}" in str(err.value)
    assert "swedish" not in str(err.value)


@pytest.mark.parametrize("item", [{"name": "front", "type": "fixd"}, {"name": "front", "r": 0.1},
                                  {"name": "front", "type": 3}])
def test_an_error_in_a_wheel_s_type_names_the_wheel(item, tmp_path, capsys):
    """The type was read before the name: a misspelt or missing type gave the JSON error "wheel": 0, every later
    field "wheel": "front"."""
    path = tmp_path / "r.yaml"
    path.write_text(yaml.safe_dump({"name": "r", "wheels": [item]}))
    assert main(["show", str(path), "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["wheel"] == "front"


@pytest.mark.parametrize(("written", "read_as"), [("010", "8"), ("-010", "-8"), ("1:30", "90"), ("1:30.5", "90.5")])
def test_numbers_yaml_1_1_reads_otherwise_than_they_look_are_refused(written, read_as):
    """PyYAML follows YAML 1.1: 'position: [010, 0]' put the wheel 8 m ahead (octal), 'r: 1:30' made a 90 m wheel
    (base 60), without a word. JSON refuses both; YAML 1.2 reads 010 as 10. Now a located error says what YAML read,
    naming the field and the wheel (it gave the file and line only: 'r.yaml:3: malformed YAML: ...')."""
    text = f"name: r\nwheels:\n  - {{name: w, type: fixed, position: [{written}, 0.2], r: 0.1, heading: 0}}\n"
    with pytest.raises(DescriptionError) as err:
        robot_from_text(text, source="r.yaml")
    assert str(err.value).startswith("r.yaml:3: wheels[0].position[0]: malformed YAML: ")
    assert (err.value.loc, err.value.wheel) == (("wheels", 0, "position", 0), "w")
    text = f"name: r\nwheels:\n  - name: w\n    type: fixed\n    position: [0.3, 0.2]\n    r: {written}\n"
    with pytest.raises(DescriptionError, match=r"^r\.yaml:6: wheels\[0\]\.r: malformed YAML: "):
        robot_from_text(text, source="r.yaml")
    assert f"YAML 1.1 reads it as {read_as}, not as it looks" in str(err.value)
    for plain in ("0", "00", "007", "08", "1_0", "0.5", "00.5", "'010'"):  # read as they look: kept
        text = f"name: r\nwheels:\n  - {{name: w, type: fixed, position: [{plain}, 0.2], r: 0.1, heading: 0}}\n"
        assert robot_from_text(text, source="r.yaml").wheels[0].position[1] == pytest.approx(0.2)


@pytest.mark.parametrize("change", [
    lambda r: replace(r, body=Body(-1.0, 1.0)),  # a negative mass
    lambda r: replace(r, wheels=(replace(r.wheels[0], r=1e-9), *r.wheels[1:])),  # a radius lost in the rank tests
])
def test_to_file_refuses_a_robot_its_file_would_not_load_as(change, tmp_path):
    # a robot built in Python that a description refuses was written, and the file failed only when read back
    robot = change(catalog.load("diff-drive"))
    for name in ("a.yaml", "a.json"):
        with pytest.raises(DescriptionError, match=rf"robot 'diff-drive' is not written to .*{name}: it would not "
                                                   r"load back: (body\.mass|wheels\[0\]\.r): "):
            robot.to_file(tmp_path / name)
        assert not (tmp_path / name).exists()


def test_to_file_that_fails_midway_leaves_the_old_file_whole(tmp_path, monkeypatch):
    """The description was written in place: a write that failed half-way (a full disk) left half a file where the
    robot was, which the studio's Save over an existing file would also do. Now it is written beside it and moved
    onto it in one step; the failed write leaves the old file as it was (permissions too) and no scratch file."""
    import os

    old = tmp_path / "r.yaml"
    catalog.load("diff-drive").to_file(old)
    os.chmod(old, 0o600)
    before = old.read_text()
    write_text = Path.write_text

    def full_disk(self, text, **kw):
        write_text(self, text[: len(text) // 2], **kw)
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Path, "write_text", full_disk)
    with pytest.raises(OSError, match="No space left"):
        catalog.load("omni-3").to_file(old)
    monkeypatch.undo()
    assert old.read_text() == before and sorted(os.listdir(tmp_path)) == ["r.yaml"]
    catalog.load("omni-3").to_file(old)
    assert Robot.from_file(old).name == "omni-3" and old.stat().st_mode & 0o777 == 0o600
    link = tmp_path / "link.yaml"
    link.symlink_to(old)
    catalog.load("swerve-4").to_file(link)  # through a link: the file it points to is replaced, the link kept
    assert link.is_symlink() and Robot.from_file(old).name == "swerve-4"


def test_conventions_md_says_how_a_file_is_written(tmp_path):
    """docs/conventions.md's examples of what `Robot.to_file` writes are what it writes: the page said a β of 7.57
    rad from `heading: 6` was written `"7.57... rad"`, while that wheel is written `heading: 6.0`."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "conventions.md").read_text()
    examples = re.findall(r"`heading: ([^`]+)` is written\s+`(\w+): ([^`]+)`", text)
    assert len(examples) == 2
    for heading, key, written in examples:
        wheel = {"name": "w", "type": "steerable", "position": [1, 0], "heading": heading, "r": 0.1}
        Robot.from_dict({"name": "r", "wheels": [wheel]}).to_file(tmp_path / "r.yaml")
        assert f"  {key}: {written}\n" in (tmp_path / "r.yaml").read_text()


@pytest.mark.parametrize(("extra", "field", "written"), [
    ({"heading": "50 deg"}, "heading", "heading 50 deg"),
    ({"heading": -0.8}, "heading", "heading -45.8366 deg"),
    ({"beta": "150 deg"}, "beta", "heading 60 deg"),
    ({}, "steer_range", "heading 0 deg (no heading given: straight ahead)"),
])
def test_a_heading_outside_the_wheel_s_own_steer_range_is_refused(extra, field, written, tmp_path, capsys):
    """A steered wheel described at a heading its steering cannot reach loaded silently (the robot then started
    out of its own range: controllers held it at an end, odometry refused its logs). Now one line naming the file,
    the wheel and the field; a heading within the range, or at an end, loads."""
    wheel = {"name": "front", "type": "steerable", "position": [0.5, 0], "r": 0.1,
             "steer_range": ["10 deg", "40 deg"]}
    path = tmp_path / "bot.yaml"
    text = yaml.safe_dump({"name": "bot", "wheels": [{**wheel, **extra}]}, sort_keys=False)
    path.write_text(text)
    assert main(["show", str(path), "--json"]) == 2
    error = json.loads(capsys.readouterr().err)
    line = _line_of(text, f"{field}:")
    assert (error["file"], error["wheel"], error["field"], error["line"]) == (str(path), "front", field, line)
    assert error["error"] == f"{written} is outside the wheel's steer_range [10, 40] deg"
    for inside in ("10 deg", "25 deg", "40 deg", "-335 deg"):  # -335 deg is 25 deg a turn away
        robot = Robot.from_dict({"name": "bot", "wheels": [{**wheel, "heading": inside}]})
        assert Robot.from_dict(robot.to_dict()) == robot
    across = {**wheel, "steer_range": ["170 deg", "190 deg"]}  # a range across 180 deg
    assert Robot.from_dict({"name": "bot", "wheels": [{**across, "heading": "-175 deg"}]}).wheels[0].heading == \
        pytest.approx(math.radians(-175))
    with pytest.raises(DescriptionError, match=r"wheels\[0\]\.heading: heading 160 deg is outside"):
        Robot.from_dict({"name": "bot", "wheels": [{**across, "heading": "160 deg"}]})


def test_to_dict_writes_what_the_description_format_page_says_it_writes():
    """docs/description-format.md's `robot.to_dict()` row: every geometric field of the type, defaults too, the other
    fields only when set. The row said 'every optional field written out', while a wheel without sensors has no
    `sensed` and a `type: mecanum` wheel no `gamma`."""
    row = " ".join(next(line for line in DOC.read_text().splitlines() if line.startswith("| `robot.to_dict()`"))
                   .split())
    assert "every optional field" not in row
    assert "every geometric field of the wheel's type written out, defaults too (a castor's `delta: 0.0`" in row
    shown = re.search(r"the other fields \(([^)]*)\) only when set", row)[1]
    others = [name.strip("` ") for name in shown.split(",")]
    robot = Robot.from_dict({"name": "r", "wheels": [
        {"name": "c", "type": "castor", "position": [-0.3, 0], "d": 0.05, "r": 0.1},
        {"name": "m", "type": "mecanum", "position": [0.2, 0.15], "r": 0.08}]})
    castor, mecanum = robot.to_dict()["wheels"]
    assert castor["delta"] == 0.0 and {"gamma", "r_r"}.isdisjoint(mecanum)
    assert not {*others} & ({*castor} | {*mecanum})
    full = catalog.load("forklift").to_dict()["wheels"][0]  # sensed, actuated, inertia, tyre set: written
    set_here = {"actuated", "sensed", "inertia", "tyre"}
    assert set_here <= {*full} and set_here <= {*others}
