"""The units rule of the Python API (docs/conventions.md): keywords and arrays take SI numbers; text is read only at
the entry points that take file or command-line values, and there exactly as the CLI reads it."""

from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest

from wmrkit import Robot, ShapeError, catalog, forward_kinematics, parse_quantity, wheel_commands
from wmrkit.batch import parse_vary
from wmrkit.cli.main import main
from wmrkit.kinematics.wheel_ik import forward_kinematics_check, rate_kind
from wmrkit.units import UnitError
from wmrkit.vision.camera import Camera, CameraFileError

DIFF = catalog.load("diff-drive")


@pytest.mark.parametrize("fk", [forward_kinematics, forward_kinematics_check])
@pytest.mark.parametrize(("rates", "said"), [
    ({"left": "120 rpm", "right": 12.0}, r"^rates: left: got the text '120 rpm', but the Python API reads no units: "
                                         r"pass real numbers in rad/s .*parse_quantity\('120 rpm', 'angular rate'\)"),
    ({"left": "12", "right": 12.0}, r"^rates: left: got the text '12'"),  # no longer read (as 12 rad/s)
    ({"vx": "500 mm/s", "left": 1.0}, r"^rates: vx: got the text '500 mm/s'.*in m/s .*'speed'"),
    ({"left": [Fraction(12), "3"], "right": 12.0}, r"^rates: left: got the text '3'"),
])
def test_forward_kinematics_takes_no_text(fk, rates, said):
    """Its rates' text was read with its unit ("its values may come from a file or the command line"): the CLI
    reads its options itself, and the Python API reads numbers."""
    with pytest.raises(ShapeError, match=said):
        fk(DIFF, rates)


def test_text_read_as_the_cli_reads_it_gives_the_cli_s_answer(capsys):
    """``parse_quantity(text, rate_kind(name))``, the advice of the refusal, is what ``wmrkit fk --spin`` reads."""
    assert main(["fk", "diff-drive", "--spin", "left=120rpm", "--spin", "right=3000deg/s", "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    rates = {n: parse_quantity(t, rate_kind(n)) for n, t in (("left", "120rpm"), ("right", "3000deg/s"))}
    assert rates == {"left": 4 * math.pi, "right": math.radians(3000)}
    assert forward_kinematics_check(DIFF, rates).twist.tolist() == cli["twist"]


def test_forward_kinematics_check_takes_one_number_a_rate():
    with pytest.raises(ShapeError, match=r"^rates: left: expected one number .*got shape \(2,\)$"):
        forward_kinematics_check(DIFF, {"left": [1.0, 2.0], "right": 1.0})
    with pytest.raises(ShapeError, match=r"^rates: expected a mapping"):
        forward_kinematics_check(DIFF, [1.0, 2.0])
    assert forward_kinematics_check(DIFF, {"left": np.float32(2.0), "right": np.array([2.0])}).consistent


def test_text_among_the_numbers_of_an_object_array_is_refused():
    """An object array (a Fraction beside text) was converted element by element: '3' read as 3 rad."""
    swerve = catalog.load("swerve-4")
    with pytest.raises(ShapeError, match=r"^beta: got the text '3', but the Python API reads no units"):
        swerve.with_beta([Fraction(1, 10), 0.1, 0.1, "3"])
    with pytest.raises(ShapeError, match=r"^twist_robot: got the text b'1'"):
        wheel_commands(swerve, np.array([Fraction(1), b"1", 0.0], dtype=object))
    assert swerve.with_beta([Fraction(1, 10), 0.1, 0.1, 0.1]).beta[0] == 0.1


CAMERA = {"focal_px": 150, "tilt": "60 deg", "height": "30 cm", "width": 160, "rows": 120}


@pytest.mark.parametrize(("text", "kind"), [("60 deg", "angle"), ("1.0472", "angle"), ("30 cm", "length"),
                                            ("0.3", "length")])
def test_the_documented_doors_read_text_as_the_cli(text, kind):
    """A camera file, a description and a --vary range read a value as the CLI's options read one (a bare number in
    SI): each gives parse_quantity's number."""
    want = parse_quantity(text, kind)
    field = "tilt" if kind == "angle" else "height"
    assert getattr(Camera.from_dict(CAMERA | {field: text}), field) == want
    if kind == "length":  # a wheel's radius
        data = DIFF.to_dict()
        data["wheels"][0]["r"] = text
        assert Robot.from_dict(data).wheels[0].r == want
        assert parse_vary(f"wheels[0].r={text}:{text}:1", DIFF).values[0] == want


@pytest.mark.parametrize("text", ["60", "90"])
def test_a_bare_angle_beyond_a_turn_is_refused_at_the_doors_as_at_the_cli(text, capsys):
    with pytest.raises(UnitError, match="a bare angle is read in radians"):
        parse_quantity(text, "angle")
    with pytest.raises(CameraFileError, match="a bare angle is read in radians"):
        Camera.from_dict(CAMERA | {"tilt": text})
    assert main(["ik", "swerve-4", "--twist", "0.1", "0", "0", "--steer", f"front_left={text}"]) == 2
    assert "a bare angle is read in radians" in capsys.readouterr().err
