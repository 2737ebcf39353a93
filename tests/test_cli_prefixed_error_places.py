"""Under ``--json``, an error whose message names its option after the command's words ('ik: --twist 1e7: ...',
'calibrate: --size: ...'), in parentheses after the name of its value ('follow-line: blur (--blur): ...',
'duration 1e+12 s ...: give a shorter duration (--duration)'), or as argparse names an unknown, ambiguous or missing
one, gives that option as ``field``. Before, each of these had "field": null (docs/limits.md, errors)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from wmrkit.cli.main import main

CAMERA = str(Path(__file__).parents[1] / "docs" / "figures" / "vision" / "chufa-camera.yaml")
CALIBRATE = ["vision", "calibrate", "--rows", "100", "--half-separation", "0.1", "--row-distance", "0.5"]
FOLLOW = ["follow-line", "line-follower", "--camera", CAMERA]


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
    (["track", "diff-drive", "--reference", "circle", "--delay", "2"], "--period"),
    (["park", "ackermann", "--space", "1"], "--space"),  # argparse: unrecognized
    (["tyre", "--slip", "0.1"], "--slip"),  # argparse: ambiguous
    (["calibrate", "diff-drive", "log.csv"], "--reference"),  # argparse: required
])
def test_an_error_naming_its_option_after_the_command_gives_it_as_field(argv, field, capsys):
    assert main([*argv, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    error = json.loads(err)
    assert (error["field"], error["file"], error["line"], error["wheel"]) == (field, None, None, None), error


def test_an_error_naming_two_options_in_parentheses_or_none_first_keeps_field_null(capsys):
    assert main([*CALIBRATE, "--json"]) == 2  # 'calibrate: give either IMAGE or both --x1 and --x2'
    assert json.loads(capsys.readouterr().err)["field"] is None
