"""A Swedish wheel's rollers sit on its rim: the roller axis of the contact roller is r - r_r above the ground
below the wheel's axle, so r_r <= r (r_r = r: the ball wheel, thesis §3.5.2). Before: ``r_r: 1`` on a 0.05 m
wheel was read silently (``wmrkit show`` exit 0)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import pytest

from wmrkit import Robot, Wheel
from wmrkit.cli.main import main
from wmrkit.wheels import WheelError

WHEEL = "{{name: {name}, type: {type}, position: [0.2, 0.15], {extra}r: 0.05, r_r: {r_r}, actuated: spin}}"


def _write(tmp_path, type_: str, r_r: str, extra: str = "heading: 0, gamma: 45 deg, ") -> str:
    others = "\n".join(f"  - {{name: w{i}, type: swedish, position: [{x}, {y}], heading: 0, gamma: -45 deg, r: 0.05, "
                       f"r_r: 0.01, actuated: spin}}" for i, (x, y) in enumerate([(0.2, -0.15), (-0.2, 0.15)]))
    path = tmp_path / "rollers.yaml"
    path.write_text(f"name: rollers\nwheels:\n  - {WHEEL.format(name='fl', type=type_, extra=extra, r_r=r_r)}\n"
                    f"{others}\n", encoding="utf-8")
    return str(path)


@pytest.mark.parametrize(("type_", "extra"), [("swedish", "heading: 0, gamma: 45 deg, "), ("mecanum", ""),
                                              ("mecanum", "gamma: 45 deg, ")])
@pytest.mark.parametrize("r_r", ["1", "0.0501", "51 mm"])
def test_a_roller_larger_than_its_wheel_is_refused(tmp_path, capsys, type_, extra, r_r):
    path = _write(tmp_path, type_, r_r, extra)
    assert main(["show", path]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"wmrkit: error: {path}:3: wheels[0].r_r: ") and "\n" not in err, err
    assert main(["show", path, "--json"]) == 2
    out = json.loads(capsys.readouterr().err)
    assert (out["file"], out["wheel"], out["field"], out["line"]) == (path, "fl", "r_r", 3)


@pytest.mark.parametrize("r_r", ["0.05", "50 mm", "0.0125"])
def test_a_roller_up_to_the_wheel_radius_is_read(tmp_path, capsys, r_r):
    """r_r = r is the ball wheel's equivalent roller (§3.5.2); smaller rollers are every real Swedish wheel."""
    path = _write(tmp_path, "swedish", r_r)
    assert main(["show", path]) == 0
    want = 0.05 if r_r in ("0.05", "50 mm") else 0.0125
    assert Robot.from_file(path).wheel("fl").r_r == pytest.approx(want, rel=1e-12)


def test_a_wheel_built_in_python_with_a_roller_larger_than_it_is_refused_in_the_same_words(tmp_path, capsys):
    """Before, ``Wheel(type='swedish', r=0.05, r_r=1)`` was built (only descriptions refused it); the rim bound
    r_r <= r holds for every wheel, with the description's words and the wheel and field named."""
    kw = {"name": "fl", "type": "swedish", "l": 0.25, "alpha": 0.6, "beta": 0.0, "gamma": math.pi / 4, "r": 0.05}
    with pytest.raises(WheelError) as err:
        Wheel(**kw, r_r=1.0)
    assert isinstance(err.value, ValueError) and "\n" not in str(err.value)
    assert str(err.value).startswith("wheel 'fl': r_r: a roller sits on the wheel's rim: ")
    assert main(["show", _write(tmp_path, "swedish", "1")]) == 2  # the description of the same wheel
    assert capsys.readouterr().err.strip().endswith(str(err.value).removeprefix("wheel 'fl': r_r: "))
    ok = Wheel(**kw, r_r=0.05)  # r_r = r: the ball wheel's roller (§3.5.2)
    with pytest.raises(WheelError, match=r"^wheel 'fl': r_r: a roller sits on the wheel's rim"):
        Wheel(**kw, r_r=math.nextafter(0.05, 1.0))  # one ulp above r
    with pytest.raises(WheelError, match=r"^wheel 'fl': r_r: "):
        replace(ok, r=0.04)  # a smaller wheel under the same rollers
    assert replace(ok, r=0.06, r_r=0.0125).r_r == 0.0125
