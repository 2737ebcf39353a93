"""Sweep 7 of the chapter 7-9 doors (session 30): hostile numbers and texts given to `track`, `simulate`, `park`,
`odometry --method wls`, `vision locate` and `follow-line`. Each case printed a traceback, a Python warning line or an
internal message, or printed a problem's text raw; each now answers with one located line (exit 2) or its answer."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
from refusal import one_line_error

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError


@pytest.mark.parametrize("lookahead", ["1e308", "1e10"])
def test_track_refuses_a_lookahead_beyond_the_coordinates_it_handles(lookahead, capsys):
    # 1e308: OverflowError traceback in pure pursuit's goal test, (1e-3 * aim) ** 2 (exit 1)
    err = one_line_error(["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit",
                           "--lookahead", lookahead], capsys)
    assert "--lookahead: expected a distance in (0, 1e+09] m along the path" in err


def test_pure_pursuit_refuses_the_same_lookahead_from_python():
    from wmrkit.control import builtin_reference
    from wmrkit.control.points import control_point
    from wmrkit.control.trackers import pure_pursuit

    robot = catalog.load("diff-drive")
    with pytest.raises(WmrkitError, match=r"^lookahead: expected a distance in \(0, 1e\+09\] m along the path"):
        pure_pursuit(control_point(robot), builtin_reference("circle", speed=0.5, size=3.0), lookahead=1e308)


def test_a_lookahead_at_the_bound_still_runs(capsys):
    # the largest lookahead accepted: aimed at the path's end, the diff drive follows the circle (its cross-track
    # error is a fraction of a millimetre), as with any lookahead longer than the path
    assert main(["track", "diff-drive", "--reference", "circle", "--controller", "pure-pursuit", "--lookahead",
                 "1e9", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["summary"]["max_cross_track"] < 1e-3


@pytest.mark.parametrize(("argv", "expected"), [
    # was 'time: input times must be at least one, finite and strictly increasing, got [0.0, 1.0, 1.2, inf]' (the
    # program's knots at 2 / 1e-320 = inf s): an internal name, no option
    (["--path", "straight", "--speed", "1e-320"],
     "error: --speed: 9.99989e-321 m/s: program 'straight' would never end"),
    # was '--duration 3.77e+07 s and --step ...': no --duration was given, the program at --speed lasts that long
    (["--path", "figure-eight", "--speed", "1e-6"],
     "--speed 1e-06 m/s: --path figure-eight at this speed lasts 3.77e+07 s; --step 0.001 s: need 0 < step <= "
     "duration and at most 5e+07 steps"),
    (["--path", "straight", "--duration", "1e9"], "--duration 1e+09 s; --step 0.001 s: need 0 < step"),
])
def test_simulate_names_what_makes_a_program_too_long(argv, expected, capsys):
    err = one_line_error(["simulate", "forklift", *argv], capsys)
    assert expected in err


def test_simulate_names_the_torque_file_that_makes_a_run_too_long(tmp_path, capsys):
    # was '--duration 1e+09 s and --step 0.001 s': no --duration was given, the file ends at 1e9 s
    torques = tmp_path / "t.csv"
    torques.write_text("time,right_drive.spin,left_drive.spin\n0,10,10\n1e9,10,10\n")
    err = one_line_error(["simulate", "forklift", "--torques", str(torques)], capsys)
    assert f"{torques}: the file ends at t = 1e+09 s; --step 0.001 s: need 0 < step <= duration" in err


def test_path_program_refuses_a_speed_at_which_it_never_ends():
    from wmrkit.dynamics.model import DynamicModel
    from wmrkit.dynamics.programs import path_program

    model = DynamicModel.of(catalog.load("forklift"))
    with pytest.raises(WmrkitError, match=r"^speed: 9.99989e-321 m/s: program 'turn' would never end"):
        path_program(model, "turn", speed=1e-320)


THESIS_9_1 = Path(__file__).parents[2] / "src" / "wmrkit" / "parking" / "problems" / "thesis-9.1.yaml"


@pytest.mark.parametrize(("name", "expected"), [
    # printed raw: 'problem two' on one line, 'lines<ESC>[31mRED: slot 3.35 x 2 m, ...' in red on the next (exit 0)
    ('"two\\nlines\\e[31mRED"', "p.yaml:4: name: must be printable text on one line, got the character '\\n'"),
    ('"right-to-left \\u202e override"', "p.yaml:4: name: must be printable text on one line, got the character "
                                         "'\\u202e'"),
    ("x" * 5000, "p.yaml:4: name: at most 64 characters, got 5000"),  # printed whole in every answer
])
def test_a_parking_problems_name_follows_the_rules_of_a_robots_name(name, expected, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("p.yaml").write_text(THESIS_9_1.read_text(encoding="utf-8").replace("name: thesis-9.1", f"name: {name}"),
                              encoding="utf-8")
    err = one_line_error(["park", "p.yaml"], capsys)
    assert err.strip() == f"wmrkit: error: {expected}"


def test_a_parking_problems_printable_name_is_kept(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("p.yaml").write_text(THESIS_9_1.read_text(encoding="utf-8").replace("name: thesis-9.1", "name: Plaza Mayor ✓"),
                              encoding="utf-8")
    assert main(["park", "p.yaml", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["problem"] == "Plaza Mayor ✓"


def _skid_log(path: Path) -> Path:
    """A 2 s log of the skid steer driving straight at 1 m/s (wheel angles of radius 0.1 m), 21 samples."""
    rows = [f"{k / 10:g}" + f",{k:g}" * 4 for k in range(21)]
    path.write_text("time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize("mu", ["1e300,1e300", "1e308,1e308"])
def test_wls_friction_coefficients_near_the_largest_float_give_the_answer_without_a_python_warning(mu, tmp_path,
                                                                                                   capsys):
    # printed 'weights.py:88: RuntimeWarning: overflow encountered in scalar multiply' and its source line on
    # stderr before the answer (MAX_RATIO * mu.min() overflowed); only ratios matter, so the answer is that of 1,1
    log = _skid_log(tmp_path / "log.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["odometry", "skid-steer-4", str(log), "--method", "wls", "--mu-default", mu, "--json"]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    assert json.loads(out)["final_pose"] == pytest.approx([2.0, 0.0, 0.0], abs=1e-12)


def test_slip_weights_refuse_a_spread_beyond_max_ratio_even_near_the_largest_float():
    from wmrkit.slip.weights import SlipWeightError, SlipWeights

    robot = catalog.load("skid-steer-4")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert SlipWeights.uniform(1e308, 1e308).row_mu(robot).tolist() == [1e308] * 8
        with pytest.raises(SlipWeightError, match="differ by more than a factor 1e"):
            SlipWeights.uniform(1e295, 1e308).row_mu(robot)  # 1e13 apart


def test_vision_points_far_outside_the_image_are_refused_without_a_python_warning(tmp_path, capsys):
    # printed 'positioning.py:119: RuntimeWarning: overflow encountered in scalar subtract' (the row difference
    # 1e308 - -1e308) before the line refusing the point
    points = tmp_path / "points.json"
    points.write_text('{"lines": [{"n": 0, "points": [[0, 1e308], [0, -1e308]]}]}')
    camera = Path(__file__).parents[2] / "docs" / "figures" / "vision" / "follower-camera.yaml"
    err = one_line_error(["vision", "locate", "--points", str(points), "--camera", str(camera)], capsys)
    assert "lines[0]: a point [[0.0, 1e+308], [0.0, -1e+308]] lies outside the 320 x 240 image" in err


def test_follow_line_refuses_a_line_narrower_than_the_lengths_wmrkit_handles(capsys):
    # 1e-320 m printed 'render.py:79: RuntimeWarning: overflow encountered in divide' and its source line, then
    # 'the camera does not see the line at the start pose'
    camera = Path(__file__).parents[2] / "docs" / "figures" / "vision" / "follower-camera.yaml"
    err = one_line_error(["follow-line", "line-follower", "--camera", str(camera), "--line-width", "1e-320",
                           "--duration", "2"], capsys)
    assert "width must be in [1e-06, 1000] m, got 1e-320" in err


def test_a_body_heavier_than_a_thousand_tonnes_is_refused(tmp_path, capsys):
    # mass 1e300 kg: 'wmrkit simulate' answered with exit 0 and "max_slip_speed": 2e+295 m/s (normal loads of
    # 1e300 N in the compiled model, which the `tyre` command refuses beyond 1e7 N)
    description = catalog.load("forklift").to_dict()
    description["body"]["mass"] = 1e300
    path = tmp_path / "heavy.json"
    path.write_text(json.dumps(description))
    err = one_line_error(["simulate", str(path), "--path", "straight"], capsys)
    assert "body.mass: at most 1e+06 kg (a thousand tonnes" in err


def test_body_refuses_the_same_mass_from_python():
    from wmrkit.dynamics.mass import MAX_MASS, Body, body_problem
    from wmrkit.dynamics.model import GRAVITY
    from wmrkit.dynamics.tyres import MAX_LOAD

    assert MAX_MASS * GRAVITY <= MAX_LOAD  # the whole weight on one tyre stays within what a tyre takes
    assert body_problem(Body(MAX_MASS, 1.0)) == ""
    assert body_problem(Body(2 * MAX_MASS, 1.0)).startswith("body.mass: at most 1e+06 kg")


def test_a_pi_gain_whose_integral_gain_overflows_is_refused_by_its_name(capsys):
    # was 'gain b: expected three finite numbers >= 0, got (inf, inf, inf)': b = a^2 / 4, which no option sets
    err = one_line_error(["track", "diff-drive", "--reference", "circle", "--controller", "pi", "--gain", "1e200"],
                          capsys)
    assert "error: gain: 1e+200 1/s: the PI law's integral gain a^2 / 4 overflows" in err
