"""The place of an error that is not a description's, under ``--json`` (docs/limits.md): the option as ``field``
(and the wheel a ``--steer`` names), the place in a points file, the wheel of a log's joint; and a steering heading
refused at the same size either way it turns."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.description import robot_from_text
from wmrkit.errors import DescriptionError, ShapeError
from wmrkit.wheels import WheelError

CAMERA = Path(__file__).parents[1] / "docs" / "figures" / "vision" / "chufa-camera.yaml"


def _error(argv, capsys) -> dict:
    assert main([*argv, "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    return json.loads(err)


@pytest.mark.parametrize(("steer", "wheel"), [("steer=1e6 turn", "steer"), ("steer=fast", "steer"),
                                              ("right_drive=1", "right_drive"), ("nose=1", "nose")])
def test_a_steer_error_names_the_option_and_the_wheel(steer, wheel, capsys):
    """'"wheel": null, "field": null' though the message named --steer and the wheel."""
    error = _error(["analyze", "forklift", "--steer", steer], capsys)
    assert (error["field"], error["wheel"], error["file"]) == ("--steer", wheel, None)
    assert error["error"].startswith(f"--steer {steer.partition('=')[0]}")  # a wheel it has not: --steer named too


@pytest.mark.parametrize(("argv", "field"), [
    (["sweep", "diff-drive", "--vary", "wheels[0].l=0.1:0.3:3", "--chunk", "0"], "--chunk"),
    (["sweep", "diff-drive", "--vary", "wheels[0].l=0.1:0.3:3", "--top", "-1"], "--top"),
    (["sweep", "diff-drive", "--vary", "wheels[0].l=0.1:0.3:3", "--configs", "0"], "--configs"),
    (["batch", "montecarlo", "diff-drive", "--path", "arc", "-n", "1"], "-n/--runs"),
    (["analyze", "forklift", "--length", "3 deg"], "--length"),
    (["sweep", "diff-drive", "--vary", "wheels[0].l=0.1:0.3:3", "--metric", "nope"], "--metric"),  # argparse's
])
def test_an_option_error_names_the_option_as_its_field(argv, field, capsys):
    error = _error(argv, capsys)
    assert (error["field"], error["wheel"], error["file"], error["line"]) == (field, None, None, None), error


def test_sweep_names_chunk_and_top_as_the_options(capsys):
    """'chunk: expected an integer >= 1, got 0': the keyword of the Python call, not the option the user typed."""
    for option in ("--chunk", "--top"):
        assert main(["sweep", "diff-drive", "--vary", "wheels[0].l=0.1:0.3:3", option, "0"]) == 2
        assert capsys.readouterr().err == f"wmrkit: error: {option}: expected an integer >= 1, got 0\n"
    assert main(["sweep", "diff-drive", "--vary", "wheels[0].l=0.1:0.3:3", "--top", "20000"]) == 2
    assert capsys.readouterr().err.startswith("wmrkit: error: --top: 20000 is more than 10000 best designs")


def test_an_error_in_a_points_file_names_its_place(tmp_path, capsys):
    """'p.json: lines[0]: a point ... lies outside': "field": null."""
    points = tmp_path / "p.json"
    points.write_text('{"lines": [{"n": 0, "points": [[300, -200], [-300, -199]]}]}')
    error = _error(["vision", "locate", "--points", str(points), "--camera", str(CAMERA)], capsys)
    assert (error["file"], error["field"], error["wheel"]) == (str(points), "lines[0]", None)
    assert error["error"].startswith("a point [[300.0, -200.0], [-300.0, -199.0]] lies above the horizon")
    points.write_text('{"lines": [{"n": 2, "points": [[3, -20], [-3, 19]]}]}')
    error = _error(["vision", "locate", "--points", str(points), "--camera", str(CAMERA)], capsys)
    assert (error["field"], error["error"]) == ("lines[0].n", "must be -1, 0 or 1, got 2")


def test_an_error_at_a_joint_of_a_log_names_its_wheel(tmp_path, capsys):
    """'x.csv:3: left.spin: turns 1e+308 rad ...' names the joint of wheel 'left'; a CSV column ('column 'NAME':',
    any name with --column) names no wheel."""
    log = tmp_path / "overflow.csv"
    log.write_text("time,left.spin,right.spin\n0,0,0\n0.01,1e308,-1e308\n0.02,1,1\n")
    error = _error(["odometry", "diff-drive", str(log)], capsys)
    assert (error["file"], error["line"], error["field"], error["wheel"]) == (str(log), 3, "left.spin", "left")
    log.write_text("time,left.spin,right.spin\n0,0,0\n0.1,nan,0.1\n")
    error = _error(["odometry", "diff-drive", str(log)], capsys)
    assert (error["file"], error["line"], error["field"], error["wheel"]) == (str(log), 3, "left.spin", None)


@pytest.mark.parametrize("turns", [1e6, -1e6])
def test_a_heading_of_a_million_turns_is_refused_either_way(turns, capsys):
    """'--steer steer=1e6 turn' was refused, '--steer steer=-1e6turn' taken: beta = heading + 90 deg stayed within
    the limit, and the ICR came out 3.5e9 m away (round-off) with two ill-conditioned warnings."""
    for text in (f"steer={turns:g} turn", f"steer={turns:g}turn"):
        assert main(["analyze", "forklift", "--steer", text]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.startswith(f"wmrkit: error: --steer {text}: wheel 'steer': heading: {turns:.0f} turns "
                                            "is beyond +-999999.75 turns"), err
    forklift = catalog.load("forklift")
    with pytest.raises(WheelError, match=r"heading: .* turns is beyond \+-999999\.75 turns"):
        forklift.with_steering({"steer": 2 * math.pi * turns})
    with pytest.raises(ShapeError, match=r"^heading: steer: .* rad is beyond"):
        forklift.beta_of_heading([[0.0], [2 * math.pi * turns]])
    with pytest.raises(DescriptionError, match=r"^robots/x\.yaml:3: wheels\[0\]\.heading: .* beyond \+-"):
        robot_from_text(f"name: x\nwheels:\n  - {{name: a, type: steerable, position: [0.3, 0.2], heading: "
                        f"{turns:g} turn, r: 0.1}}\n", source="robots/x.yaml")


def test_a_heading_within_the_limit_is_taken_either_way():
    forklift = catalog.load("forklift")
    for turns in (999999.7, -999999.7):
        steered = forklift.with_steering({"steer": 2 * math.pi * turns})
        assert np.isfinite(steered.beta).all()
        assert forklift.beta_of_heading([2 * math.pi * turns]) == pytest.approx(steered.beta, rel=0, abs=0)


@pytest.mark.parametrize("value", ["1e300", "-6283185.307179586"])  # -1e6 turns: its beta is within 1e6 turns
def test_a_logged_heading_beyond_the_limit_names_the_log_row_and_joint(value, tmp_path, capsys):
    """"heading: angles must be finite numbers of at most 1e+06 turns [rad], got 1e+300": no file, line or joint."""
    log = tmp_path / "fk.csv"
    log.write_text(f"time,right_drive.spin,left_drive.spin,steer.steer\n0,0,0,0\n0.1,0.1,0.1,{value}\n")
    error = _error(["odometry", "forklift", str(log)], capsys)
    assert (error["file"], error["line"], error["field"], error["wheel"]) == (str(log), 3, "steer.steer", "steer")
    assert error["error"].startswith(f"heading {float(value):.6g} rad is beyond +-6283183.736 rad")
