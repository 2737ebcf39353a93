"""Every refused command line names the argument at fault as the JSON error's ``field`` (docs/limits.md): argparse's
missing positionals and one-of groups, an unknown robot, a robot a command cannot drive, a value the message quotes
(``--param``, ``--column``), an option named anywhere in the message, and the CLI's own one-of-two refusals. Each
row had ``"field": null`` (or named the wrong option) before session 36; in-process and cheap (no run starts)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from wmrkit.cli.main import main

ROOT = Path(__file__).parents[2]
LOG = str(ROOT / "examples" / "logs" / "mecanum-4.csv")
CAMERA = str(ROOT / "docs" / "figures" / "vision" / "chufa-camera.yaml")
CALIBRATE = ["batch", "calibrate", "mecanum-4", LOG, "--closed", "--workers", "0"]
STRIPES = ["vision", "calibrate", "--rows", "100", "--half-separation", "0.1", "--row-distance", "1"]

CASES = [
    # argparse: a missing positional, the first of several, the command, a subcommand, a one-of group
    (["odometry", "diff-drive"], "LOG", "the following arguments are required: LOG"),
    (["odometry"], "ROBOT", "required: ROBOT, LOG"),
    ([], "COMMAND", "required: COMMAND"),
    (["batch"], "SUBCOMMAND", "required: SUBCOMMAND"),
    (["slip-study"], "STUDY", "required: STUDY"),
    (["slip-study", "nope"], "STUDY", "invalid choice: 'nope'"),
    (["simulate", "forklift"], "--torques", "one of the arguments --torques --path is required"),
    (["vision", "locate", "--camera", CAMERA], "IMAGE", "one of the arguments IMAGE --points is required"),
    # words argparse does not know: the first of them, an option or a stray word
    (["analyze", "forklift", "abc", "def"], "abc", "unrecognized arguments: abc def"),
    (["park", "thesis-9.2", "--space", "1"], "--space", "unrecognized arguments: --space 1"),
    # a robot: no such catalog name, or one the command cannot drive
    (["show", "nope"], "ROBOT", "no robot 'nope' in the catalog"),
    (["track", "nope", "--reference", "circle"], "ROBOT", "no robot 'nope' in the catalog"),
    (["follow-line", "diff-drive", "--camera", CAMERA], "ROBOT", "robot 'diff-drive': its origin"),
    # batch calibrate --param: its names, checked before the logs are read
    ([*CALIBRATE, "--param", "nope.r"], "--param", "--param 'nope.r': robot 'mecanum-4' has no wheel 'nope'"),
    ([*CALIBRATE, "--param", "front_left.r,nope.r"], "--param", "--param 'nope.r': robot"),
    ([*CALIBRATE, "--param", "front_left.nope"], "--param", "--param 'front_left.nope': a swedish wheel has no"),
    ([*CALIBRATE, "--param", ","], "--param", "--param ',': names no WHEEL.FIELD"),
    ([*CALIBRATE, "--param", "front_left.r", "--param", "front_left.r"], "--param", "--param 'front_left.r': given"),
    (["batch", "calibrate", "mecanum-4", LOG, "--reference", "nope", "--workers", "0"], "--reference",
     "--reference nope: no such folder"),
    (["batch", "calibrate", "mecanum-4", LOG, "--reference", LOG, "--workers", "0"], "--reference", "not a folder"),
    ([*CALIBRATE, "--slip"], "LOG", "LOG: slip weights with an interval (--slip) need at least two logs, got 1"),
    # an option the message names, or the two-of-one refusals of the command itself
    (["track", "diff-drive", "--reference", "circle", "--delay", "2"], "--delay",
     "--delay: a measurement delay in samples needs a sample period (--period)"),
    (["sweep", "diff-drive", "--vary", "wheels[0].l=0:1:3", "--vary", "wheels[0].l=0:1:3", "--workers", "0"], "--vary",
     "two --vary axes move the same field"),
    (["follow-line", "line-follower", "--camera", CAMERA, "--period", "10", "--duration", "1"], "--duration",
     "duration (--duration) 1 s is shorter than one period (--period, 10 s)"),
    (["batch", "montecarlo", "diff-drive", "--workers", "0"], "LOG", "give a LOG or --path NAME"),
    (["batch", "montecarlo", "diff-drive", LOG, "--path", "arc", "--workers", "0"], "--path", "give a LOG or --path"),
    (STRIPES, "IMAGE", "give either IMAGE or both --x1 and --x2"),
    ([*STRIPES, "--x2", "10", str(ROOT / "docs" / "figures" / "vision" / "calibration.png")], "--x2",
     "give either IMAGE or both"),
]


@pytest.mark.parametrize(("argv", "field", "message"), CASES, ids=[" ".join(c[0][:3]) + f" [{c[1]}]" for c in CASES])
def test_the_json_error_names_the_argument_at_fault(argv, field, message, capsys):
    assert main([*argv, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    error = json.loads(err)
    assert error["field"] == field, error
    assert message in error["error"], error


def test_a_column_given_for_no_joint_names_column_not_the_log(capsys):
    """'LOG: a column is given for 'nope.spin', no joint': the file is the log, the field the --column that named it
    (was LOG)."""
    assert main(["odometry", "mecanum-4", LOG, "--column", "nope.spin=x", "--json"]) == 2
    error = json.loads(capsys.readouterr().err)
    assert (error["file"], error["field"]) == (LOG, "--column"), error


def test_the_text_error_of_a_delay_without_a_period_names_the_option(capsys):
    """'wmrkit: error: delay: ...': the library's keyword, not the option typed."""
    assert main(["track", "diff-drive", "--reference", "circle", "--delay", "2"]) == 2
    assert capsys.readouterr().err == ("wmrkit: error: --delay: a measurement delay in samples needs a sample period "
                                       "(--period)\n")
