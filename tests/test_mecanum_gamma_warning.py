"""``type: mecanum`` exists for the +-45 deg rollers of the standard layout; a ``gamma`` of another magnitude (90 deg:
an omni wheel) under that name was read silently. It is read as written and said: one ``wmrkit: warning:`` line
naming the file, line, wheel and field, and the same text in the JSON answer's ``warnings``."""

from __future__ import annotations

import json
import math
import warnings

import pytest

from wmrkit import Robot
from wmrkit.cli.main import main
from wmrkit.description import DescriptionWarning

CORNERS = {"fl": (0.2, 0.15), "fr": (0.2, -0.15), "rl": (-0.2, 0.15), "rr": (-0.2, -0.15)}


def _write(tmp_path, gamma: str | None) -> str:
    lines = ["name: mg", "wheels:"]
    for name, (x, y) in CORNERS.items():
        g = f"gamma: {gamma}, " if name == "fl" and gamma is not None else ""
        lines.append(f"  - {{name: {name}, type: mecanum, position: [{x}, {y}], {g}r: 0.05, actuated: spin}}")
    path = tmp_path / "mg.yaml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return str(path)


@pytest.mark.parametrize("gamma", ["90 deg", "-90 deg", "30 deg", "60 deg", "1 rad", None, "45 deg", "-45 deg",
                                   "135 deg", "-135 deg", "225 deg", "0.7853981633974483"])
def test_a_mecanum_wheel_without_45_deg_rollers_is_said(tmp_path, capsys, gamma):
    path = _write(tmp_path, gamma)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)  # said below
        g = Robot.from_file(path).wheel("fl").gamma
    standard = math.isclose(abs(math.sin(2 * g)), 1.0, abs_tol=1e-12)  # the roller line at +-45 deg to the axle
    assert main(["show", path]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    if standard:
        assert err == []
    else:
        assert len(err) == 1 and err[0].startswith(f"wmrkit: warning: {path}:3: wheels[0].gamma: wheel 'fl' is of "
                                                   "type mecanum with gamma "), err
        assert "'type: swedish'" in err[0] and ("omni" in err[0]) == (abs(math.cos(g)) < 1e-9)
    assert main(["analyze", path, "--json"]) == 0
    said = json.loads(capsys.readouterr().out)["warnings"]
    assert said == ([] if standard else [err[0].removeprefix("wmrkit: warning: ")])


def test_the_library_says_it_as_a_description_warning(tmp_path):
    path = _write(tmp_path, "90 deg")
    with pytest.warns(DescriptionWarning, match=r"wheels\[0\]\.gamma: wheel 'fl' is of type mecanum with gamma 90 deg"):
        robot = Robot.from_file(path)
    assert robot.wheel("fl").gamma == pytest.approx(math.pi / 2)  # read as written
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Robot.from_file(_write(tmp_path, None))
        Robot.from_dict(robot.to_dict())  # written back as a swedish wheel: nothing to say
