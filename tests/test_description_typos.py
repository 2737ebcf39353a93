"""Descriptions that are probably typos. Two wheels at one place (a wheel copied and renamed but not moved) loaded
without a word: now one warning per such wheel names both wheels and the place (``wmrkit: warning:``, the JSON
answer's ``warnings``, a ``DescriptionWarning`` in Python), never on a robot the repository holds. And of several
wheels too far from the origin the error named the farthest, the last of equal ones: now the first in file order,
as every other check does."""

from __future__ import annotations

import json
import subprocess
import warnings
from pathlib import Path

import pytest
import yaml

from doc_examples import ROOT
from wmrkit import Robot, catalog
from wmrkit.cli.main import main
from wmrkit.description import DescriptionWarning, robot_from_dict


def _write(tmp_path: Path, rows: list[str], couplings: str = "") -> str:
    path = tmp_path / "r.yaml"
    path.write_text("name: r\nwheels:\n" + "".join(f"  - {{{row}}}\n" for row in rows) + couplings, encoding="utf-8")
    return str(path)


DIFF = ["name: left, type: fixed, position: [0, 0.2], heading: 0, r: 0.1",
        "name: right, type: fixed, position: [0, -0.2], heading: 0, r: 0.1"]


def test_a_wheel_copied_but_not_moved_is_said_once(tmp_path, capsys):
    path = _write(tmp_path, [*DIFF, "name: left2, type: fixed, position: [0, 20 cm], heading: 0, r: 0.1"])
    assert main(["show", path]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"wmrkit: warning: {path}:5: wheels[2].position: wheels 'left' and 'left2' are mounted at one "
                   "place, (0, 0.2) m: a wheel copied and renamed but not moved? Read as written; a double wheel or "
                   "double castor is one wheel of type double or double_castor (docs/description-format.md)"]
    assert main(["show", path, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["warnings"] == [err[0].removeprefix("wmrkit: warning: ")]
    with pytest.warns(DescriptionWarning, match=r"wheels\[2\]\.position: wheels 'left' and 'left2' are mounted"):
        robot = Robot.from_file(path)
    assert robot.wheel("left2").position == pytest.approx((0.0, 0.2))  # read as written


def test_each_wheel_at_an_earlier_place_is_named_with_the_first_there(tmp_path):
    """Three at one place: two warnings, each naming the first; `l`/`alpha` located at `l`; a gap of round-off of
    the robot's size (1e-14 m of 0.4 m) is one place, one of 1e-9 of it is not (``wmrkit analyze``'s band)."""
    rows = [*DIFF, "name: b, type: fixed, l: 0.2, alpha: 90 deg, heading: 0, r: 0.1",
            "name: c, type: fixed, position: [1e-14, 0.2], heading: 0, r: 0.1",
            "name: d, type: fixed, position: [4e-10, -0.2], heading: 0, r: 0.1"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        Robot.from_file(_write(tmp_path, rows))
    said = [str(w.message) for w in caught if w.category is DescriptionWarning]
    assert len(said) == 2, said
    assert ":5: wheels[2].l: wheels 'left' and 'b' " in said[0] and ":6: wheels[3].position: wheels 'left' and 'c' " \
        in said[1]


def test_two_castors_steered_as_one_are_not_said(tmp_path):
    """A double castor written as its two castors on one steering axis, their steering geared together: on
    purpose. Without the gear the same two castors are said."""
    castors = [f"name: {n}, type: castor, position: [-0.3, 0], d: 0.05, delta: {s}30 deg, r: 0.05"
               for n, s in (("c1", ""), ("c2", "-"))]
    gear = "couplings:\n  - {kind: gear, joints: [c1.steer, c2.steer]}\n"
    with warnings.catch_warnings():
        warnings.simplefilter("error", DescriptionWarning)
        Robot.from_file(_write(tmp_path, [*DIFF, *castors], gear))
    with pytest.warns(DescriptionWarning, match="wheels 'c1' and 'c2' are mounted at one place"):
        Robot.from_file(_write(tmp_path, [*DIFF, *castors]))


def _repository_descriptions() -> list[str]:
    listed = subprocess.run(["git", "ls-files", "*.yaml", "*.yml", "*.json"], cwd=ROOT, capture_output=True,
                            text=True, check=True).stdout.split()
    out = []
    for name in listed:
        try:
            data = yaml.safe_load((ROOT / name).read_text(encoding="utf-8"))
        except (yaml.YAMLError, UnicodeDecodeError, ValueError):
            continue
        if isinstance(data, dict) and isinstance(data.get("wheels"), list):
            out.append(name)
    return out


@pytest.mark.parametrize("spec", [*catalog.names(), *_repository_descriptions()])
def test_no_robot_of_the_repository_is_said_to_have_wheels_at_one_place(spec):
    """Every catalog robot and every description file the repository holds (those that load: the hostile ones
    are refused) loads without that warning."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            catalog.resolve(spec if spec in catalog.names() else str(ROOT / spec))
        except Exception as err:  # a hostile file: refused, never said
            assert spec.startswith("tests/hostile/"), err
    assert not [w for w in caught if "at one place" in str(w.message)]


def test_catalog_robots_moved_onto_one_place_are_said():
    """The check is not vacuous on the catalog: each robot with a wheel moved onto another's place is said."""
    for name in catalog.names():
        data = catalog.load(name).to_dict()
        first, second = data["wheels"][:2]
        second.pop("l", None), second.pop("alpha", None)
        second["position"] = list(catalog.load(name).wheels[0].position)
        with pytest.warns(DescriptionWarning, match=f"wheels '{first['name']}' and '{second['name']}' are mounted"):
            robot_from_dict(data)


@pytest.mark.parametrize(("xs", "named"), [((2000, 5000), 0), ((5000, 2000), 0), ((1, 2000, -2000), 1),
                                           ((1, 1500, 1e4, 1500), 1)])
def test_of_several_wheels_too_far_the_first_is_named(tmp_path, capsys, xs, named):
    path = _write(tmp_path, [f"name: w{i}, type: fixed, position: [{x}, {i}], heading: 0, r: 0.1"
                             for i, x in enumerate(xs)])
    assert main(["show", path]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"wmrkit: error: {path}:{3 + named}: wheels[{named}].position[0]: "
                                               f"{xs[named]:g} m from the robot's origin: longer than 1000 m"), err


def test_of_wheels_all_too_small_the_first_largest_is_named(tmp_path, capsys):
    path = _write(tmp_path, [f"name: w{i}, type: fixed, position: [{x}, 0], heading: 0, r: 1e-7"
                             for i, x in enumerate(("1e-7", "4e-7", "-4e-7"))])
    assert main(["show", path]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"wmrkit: error: {path}:4: wheels[1].position[0]: the robot's size (4e-07 m"), err


def test_one_place_is_where_analyze_stops_saying_wheels_too_close():
    """The description's one place and ``wmrkit analyze``'s ill-conditioned gaps meet: every gap is said once."""
    from wmrkit.analysis.conditioning import ROUNDING
    from wmrkit.limits import ONE_PLACE

    assert ONE_PLACE == ROUNDING


@pytest.mark.parametrize(("rows", "named"), [
    # a roller angle on the first wheel and a radius too small for the robot's size on the second
    (["name: s, type: swedish, position: [0.2, 0], heading: 0, gamma: 0.5 deg, r: 0.05, r_r: 0.01",
      "name: f, type: fixed, position: [0, 0.2], heading: 0, r: 1e-6"], "wheels[0].gamma: gamma = 0.5 deg"),
    # a castor axle along its arm on the first wheel and a name too long on the second
    (["name: c, type: castor, position: [0.2, 0], d: 0.05, delta: 89.9 deg, r: 0.05",
      f"name: {'n' * 65}, type: fixed, position: [0, 0.2], heading: 0, r: 0.05"], "wheels[0].delta: delta = 89.9 deg"),
    # a wheel too far: named, not the other wheels' radii, too small for that size
    (["name: a, type: fixed, position: [0, 0.2], heading: 0, r: 0.05",
      "name: b, type: fixed, position: [0, 1e308], heading: 0, r: 0.05"], "wheels[1].position[1]: 1e+308 m from"),
])
def test_the_envelope_names_the_first_wheel_in_file_order(tmp_path, capsys, rows, named):
    """The envelope's checks ran one after the other over all wheels: the second wheel's radius was named before
    the first wheel's roller angle. Now wheel by wheel, after the robot's size."""
    path = _write(tmp_path, rows)
    assert main(["show", path]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f": {named}" in err[0], err
