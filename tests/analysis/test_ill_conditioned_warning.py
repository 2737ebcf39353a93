"""A description whose wheels are so close, or whose axles so nearly one, that its rank decisions sit near their
cut-off (two parallel fixed axles 55 nm apart: a robot that cannot turn, or on one axle a differential drive) was
analysed without a word. ``analyze`` now says so: one ``wmrkit: warning:`` line naming the file and the two wheels,
and the same text in the JSON answer's ``warnings``; a clear description (one axle, or axles 1 mm apart) says
nothing, nor does any catalog robot."""

from __future__ import annotations

import json

import pytest

from wmrkit import catalog
from wmrkit.analysis.conditioning import ill_conditioned_pairs
from wmrkit.cli.main import main


def _write(tmp_path, left: str, right: str, second: str = "fixed") -> str:
    """Wheels 'left' and 'right' at the given YAML fields, and a castor behind (so the robot is not a line)."""
    path = tmp_path / "pair.yaml"
    path.write_text("name: pair\nwheels:\n"
                    f"  - {{name: left, type: fixed, r: 0.1, {left}}}\n"
                    f"  - {{name: right, type: {second}, r: 0.1, {right}}}\n"
                    "  - {name: caster, type: castor, position: [-0.3, 0.0], d: 0.05, r: 0.04}\n", encoding="utf-8")
    return str(path)


def _said(capsys, path: str) -> tuple[list[str], list[str]]:
    """(stderr lines of `analyze PATH`, the "warnings" of `analyze PATH --json`); both exit 0."""
    assert main(["analyze", path]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert main(["analyze", path, "--json"]) == 0
    return err, json.loads(capsys.readouterr().out)["warnings"]


@pytest.mark.parametrize(("left", "right", "second", "said"), [
    # axles x = 0 and x = 5.5e-8 m (heading 0: the axle along y), L = 0.2236 m (centroid (-0.1, 0))
    ("position: [0.0, 0.2], heading: 0 deg", "position: [5.5e-8, -0.2], heading: 0 deg", "fixed",
     "the axles of wheels 'left' and 'right' are parallel and 5.5e-08 m apart (2.5e-07 of the robot's size "
     "0.224 m)"),
    # axles through (0, +-0.2) at headings 0 and 1e-8 rad: sin(1e-8) = 1e-8 apart
    ("position: [0.0, 0.2], heading: 0 deg", "position: [0.0, -0.2], heading: 1.0e-8", "fixed",
     "the axles of wheels 'left' and 'right' are 1e-08 rad from parallel"),
    # a steerable wheel 55 nm from the fixed one's mount point, its axle across the fixed one's
    ("position: [0.0, 0.2], heading: 0 deg", "position: [5.5e-8, 0.2], heading: 90 deg", "steerable",
     "wheels 'left' and 'right' are mounted 5.5e-08 m apart"),
])
def test_an_ill_conditioned_pair_of_wheels_is_said_once_by_name(tmp_path, capsys, left, right, second, said):
    path = _write(tmp_path, left, right, second)
    err, warnings = _said(capsys, path)
    assert len(err) == 1 and err[0].startswith(f"wmrkit: warning: {path}: {said}"), err
    assert warnings == [err[0].removeprefix("wmrkit: warning: ")]


@pytest.mark.parametrize("right", ["position: [0.0, -0.2], heading: 0 deg",  # one axle: a differential drive
                                   "position: [1.0e-3, -0.2], heading: 0 deg",  # parallel axles 1 mm apart
                                   "position: [0.0, -0.2], heading: 1.0e-3"])  # 1 mrad from parallel
def test_a_clear_description_says_nothing(tmp_path, capsys, right):
    err, warnings = _said(capsys, _write(tmp_path, "position: [0.0, 0.2], heading: 0 deg", right))
    assert err == [] and warnings == []


@pytest.mark.parametrize("name", catalog.names())
def test_no_catalog_robot_is_ill_conditioned(name):
    assert ill_conditioned_pairs(catalog.resolve(name)) == []
