"""Under ``--json``, an error whose message names its option after the command's words ('ik: --twist 1e7: ...',
'calibrate: --size: ...'), in parentheses after the name of its value ('follow-line: blur (--blur): ...',
'duration 1e+12 s ...: give a shorter duration (--duration)'), or as argparse names an unknown, ambiguous or missing
one, gives that option as ``field``. Before, each of these had "field": null (docs/limits.md, errors).

Session 35: every command's NaN, infinite, negative or huge numeric option refused with exit 2, one line and the
option as field (a library's keyword, 'speed: ...', 'calibration: x1 ...', 'initial twist [...]', was null; '--x1
inf' said '--size' and '--step 10' '--path'); a file's error with no column names the argument that gave it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from wmrkit.cli.main import main

VISION = Path(__file__).parents[1] / "docs" / "figures" / "vision"
CAMERA = str(VISION / "chufa-camera.yaml")
STRIPES = str(VISION / "calibration.png")
LOG = str(Path(__file__).parents[1] / "examples" / "logs" / "mecanum-4.csv")
CALIBRATE = ["vision", "calibrate", "--rows", "100", "--half-separation", "0.1", "--row-distance", "0.5"]
FOLLOW = ["follow-line", "line-follower", "--camera", CAMERA]
POINTS = [*CALIBRATE, "--x1", "200", "--x2", "150"]
SIMULATE = ["simulate", "forklift", "--path", "turn"]
TRACK = ["track", "diff-drive", "--reference", "circle"]


@pytest.mark.parametrize(("argv", "field"), [
    (["ik", "diff-drive", "--twist", "1e7", "0", "0"], "--twist"),
    (["vision", "locate", "--camera", CAMERA, "--points", "p.json", "--lines", "2"], "--lines"),
    ([*CALIBRATE, "--x1", "3"], "--x1"),
    ([*CALIBRATE, "--x1", "200", "--x2", "150", "--size", "3", "3"], "--size"),
    ([*FOLLOW, "--z-p", "1e9"], "--z-p"),
    ([*FOLLOW, "--blur", "1e9"], "--blur"),
    ([*FOLLOW, "--noise", "0.02", "3"], "--noise"),  # 3 rad, meant as 3 deg
    ([*FOLLOW, "--line-width", "100"], "--line-width"),
    (["track", "diff-drive", "--reference", "circle", "--duration", "1e12"], "--duration"),
    (["track", "diff-drive", "--reference", "circle", "--delay", "2"], "--delay"),  # needs --period: --delay's
    (["park", "ackermann", "--space", "1"], "--space"),  # argparse: unrecognized
    (["tyre", "--slip", "0.1"], "--slip"),  # argparse: ambiguous
    (["calibrate", "diff-drive", "log.csv"], "--reference"),  # argparse: required
    # session 35: the simulation's step and duration, the options of its program and start
    ([*SIMULATE, "--step", "10"], "--step"),  # it said --path (the program lasts 3 s)
    ([*SIMULATE, "--step", "1e300"], "--step"),
    ([*SIMULATE, "--duration", "1e300"], "--duration"),
    ([*SIMULATE, "--speed", "1e300"], "--speed"),  # 'speed: expected a program speed ...'
    ([*SIMULATE, "--initial-twist", "1e300", "0", "0"], "--initial-twist"),  # 'initial twist [...]: ...'
    (["tyre", "linear", "--load", "1", "--param", "c_lat=-1"], "--param"),  # 'tyre parameter c_lat: ...'
    (["tyre", "linear", "--load", "1", "--param", "c_lat=1e300"], "--param"),
    (["tyre", "linear", "--load", "1", "--param", "zz=1"], "--param"),  # "tyre model 'linear' has no parameter"
    (["tyre", "nope", "--load", "1"], "MODEL"),
    # the camera's measurements (from --x1/--x2 or an image)
    ([*CALIBRATE, "--x1", "nan", "--x2", "150"], "--x1"),  # 'calibration: x1 must be > 0, got nan'
    ([*CALIBRATE, "--x1", "inf", "--x2", "150"], "--x1"),  # it said --size
    ([*CALIBRATE, "--x1", "200", "--x2", "-1"], "--x2"),
    ([*CALIBRATE, "--x1", "100", "--x2", "150"], "--x1"),  # x1 must exceed x2
    ([*CALIBRATE[:3], "nan", *CALIBRATE[4:], "--x1", "200", "--x2", "150"], "--rows"),
    ([*CALIBRATE[:3], "1e300", *CALIBRATE[4:], "--x1", "200", "--x2", "150"], "--rows"),  # it said --size
    ([*POINTS[:5], "-1", *POINTS[6:]], "--half-separation"),
    ([*POINTS[:5], "1e300", *POINTS[6:]], "--half-separation"),  # a tilt's cosine of 7e300: no option named
    ([*POINTS[:7], "0", *POINTS[8:]], "--row-distance"),
    ([*POINTS[:7], "1e300", *POINTS[8:]], "--row-distance"),
    ([*FOLLOW, "--speed", "1e300"], "--speed"),
    ([*FOLLOW, "--duration", "1e300"], "--duration"),
    ([*FOLLOW, "--period", "1e300"], "--period"),  # longer than the duration (20 s)
    ([*FOLLOW, "--gain", "10"], "--gain"),  # gain x period >= 1 (at the default period)
    ([*FOLLOW, "--period", "4"], "--period"),  # the same at the default gain
    ([*FOLLOW, "--line-width", "-1"], "--line-width"),  # 'scene: width must be in ...'
    ([*FOLLOW, "--start", "1e300", "0"], "--start"),
    # tracking and feasibility
    ([*TRACK, "--speed", "1e300"], "--speed"),  # "reference 'circle' at 1e+300 m/s, size 3 m: ... samples"
    ([*TRACK, "--size", "1e300"], "--size"),
    ([*TRACK, "--from", "1e300", "0", "0"], "--from"),  # 'initial_pose: expected one pose ...'
    ([*TRACK, "--gain", "1e300"], "--gain"),
    ([*TRACK, "--controller", "stanley", "--stanley-gain", "1e300"], "--stanley-gain"),
    ([*TRACK, "--period", "1e300"], "--period"),  # 'period: expected a sample period ...'
    ([*TRACK, "--period", "0.1", "--delay", "-1"], "--delay"),  # 'delay: expected a number of samples >= 0'
    ([*TRACK, "--period", "0.1", "--delay", "1000"], "--delay"),  # 'delay: 1000 samples ... reach past the run'
    (["vision", "locate", "--camera", str(VISION / "thesis-camera.yaml"), str(VISION / "three-lines.png"), "--lines",
      "2", "--spacing", "0.1"], "--spacing"),  # 'spacing: the lines n = -1 and +1 are 0.0175 m apart ...'
    (["feasibility", "diff-drive", "--reference", "circle", "--point", "1e300", "0"], "--point"),
    (["batch", "montecarlo", "diff-drive", "--path", "arc", "--rate", "inf", "--workers", "0"], "--rate"),
    (["batch", "montecarlo", "diff-drive", "--path", "nope", "--workers", "0"], "--path"),  # 'unknown path'
    (["feasibility", "diff-drive", "--reference", "nope"], "--reference"),  # 'no built-in reference'
    (["fk", "diff-drive", "--spin", "nope=1"], "--spin"),  # "robot 'diff-drive' has no joint rate 'nope'"
    (["odometry", "mecanum-4", LOG, "--sensed", "nope.spin"], "--sensed"),  # "robot ... has no wheel 'nope'"
    (["odometry", "mecanum-4", LOG, "--sensed", "front_left.steer"], "--sensed"),  # has no joint 'steer'
    (["batch", "montecarlo", "diff-drive", "--path", "arc", "--rate", "1e300", "--workers", "0"], "--rate"),
])
def test_an_error_naming_its_option_after_the_command_gives_it_as_field(argv, field, capsys):
    assert main([*argv, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    error = json.loads(err)
    assert (error["field"], error["file"], error["line"], error["wheel"]) == (field, None, None, None), error


@pytest.mark.parametrize(("argv", "field", "wheel"), [
    (["odometry", "mecanum-4", LOG, "--weight", "front_left=-1"], "--weight", "front_left"),
    (["odometry", "mecanum-4", LOG, "--weight", "front_left=0"], "--weight", "front_left"),
    (["odometry", "mecanum-4", LOG, "--weight", "front_left=1e300"], "--weight", "front_left"),  # 1e300 x the others
])
def test_an_option_naming_a_wheel_gives_the_wheel(argv, field, wheel, capsys):
    assert main([*argv, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    error = json.loads(err)
    assert (error["field"], error["wheel"], error["file"]) == (field, wheel, None), error


@pytest.mark.parametrize(("argv", "field", "file"), [
    (["simulate", "forklift", "--torques", "nope.csv"], "--torques", "nope.csv"),  # cannot read the file
    (["vision", "calibrate", "nope.png", *CALIBRATE[2:]], "IMAGE", "nope.png"),  # no such image file
    ([*CALIBRATE, CAMERA], "IMAGE", CAMERA),  # not an image OpenCV can read
    (["vision", "calibrate", STRIPES, "--rows", "0", *CALIBRATE[4:]], "--rows", STRIPES),  # within the image's
    (["vision", "calibrate", STRIPES, "--rows", "1e6", *CALIBRATE[4:]], "--rows", STRIPES),  # 'nan': refused
    # before the image is read (tests/cli/test_option_units.py)
    (["vision", "calibrate", STRIPES, *CALIBRATE[2:5], "-1", *CALIBRATE[6:]], "--half-separation", STRIPES),
    (["vision", "calibrate", STRIPES, *CALIBRATE[2:7], "0", *CALIBRATE[8:]], "--row-distance", STRIPES),
    (["vision", "calibrate", str(VISION / "three-lines.png"), *CALIBRATE[2:]], "IMAGE",
     str(VISION / "three-lines.png")),  # more than two stripes: what the image shows
    (["vision", "locate", "--camera", "nocam.yaml", "--points", "p.json"], "--camera", "nocam.yaml"),
])
def test_an_error_of_a_file_gives_the_argument_that_named_it_or_the_option_it_names(argv, field, file, capsys):
    """"file" was filled and "field" null: the argument that named the file is the field, or the option the
    message names after the file (the image's rows +-A, its ground lengths)."""
    assert main([*argv, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    error = json.loads(err)
    assert (error["field"], error["file"], error["wheel"]) == (field, file, None), error


def test_an_error_asking_for_one_of_two_arguments_names_the_missing_one(capsys):
    """'calibrate: give either IMAGE or both --x1 and --x2' had "field": null (tests/cli/test_error_fields.py has
    the other cases)."""
    assert main([*CALIBRATE, "--json"]) == 2
    assert json.loads(capsys.readouterr().err)["field"] == "IMAGE"
