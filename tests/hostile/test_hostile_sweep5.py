"""Sweep 5 of the command-line doors: the newer commands (track, feasibility, calibrate, odometry's estimator options,
simulate, tyre, follow-line) on hostile values. Each case printed a traceback, NaN, an impossible number, hung, or
silently ignored or rewrote what it was given; each now answers with one located line and exit 2 (or, where the
input is valid, the right answer)."""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

import numpy as np
import pytest

from wmrkit.cli.main import COMPILE_NOTICE, DYNAMICS_NOTICE, main
from wmrkit.control.points import ControlError

CAMERA = str(Path(__file__).parents[2] / "docs" / "figures" / "vision" / "follower-camera.yaml")
#: Seconds one refused command may take: a refusal is immediate, and the hangs it replaced ran for over a minute (a wide
#: margin for a loaded machine).
FAST = 30.0
COMPILING = (COMPILE_NOTICE + "\n", DYNAMICS_NOTICE + "\n")  # a first run's notices (the dynamics' its own)

KEEP_COMPILE_NOTICE = True  # refusals are timed: a slow one must show that it compiled (conftest.py)


def _refused(argv: list[str], capsys) -> str:
    start = time.perf_counter()
    code = main(argv)
    elapsed = time.perf_counter() - start
    captured = capsys.readouterr()
    err = captured.err
    for notice in COMPILING:  # a first run after a kernel's source changed compiles it
        err = err.removeprefix(notice)
    assert code == 2, (argv, captured.err, captured.out[-300:])
    assert err.count("\n") == 1 and err.startswith("wmrkit: error: "), (argv, captured.err)
    assert elapsed < FAST or err != captured.err, (argv, elapsed)
    return err


def _write(path: Path, text: str) -> str:
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("option, expected", [
    (["--period", "1e308"], "period: expected a sample period in (0, duration = 2 s]"),  # was OverflowError
    (["--period", "1e-320"], "more than 1000000 samples"),  # was OverflowError
    (["--duration", "1e308"], "more than 1000000 samples"),  # was ValueError: Maximum allowed size exceeded
    (["--dynamics", "--period", "1e308"], "period: expected a sample period"),  # was OverflowError
])
def test_track_refuses_periods_and_durations_it_cannot_sample(option, expected, capsys):
    argv = ["track", "forklift" if "--dynamics" in option else "diff-drive", "--reference", "circle"]
    message = _refused(argv + (["--duration", "2"] if "--duration" not in option else []) + option, capsys)
    assert expected in message


def test_track_ends_a_continuous_run_at_its_duration(capsys):
    # --duration 0.01 (under one 0.05 s output step) raised AttributeError; 0.07 stopped silently at 0.05 s
    for duration in (0.01, 0.07):
        assert main(["track", "diff-drive", "--reference", "circle", "--duration", str(duration), "--json"]) == 0
        t = json.loads(capsys.readouterr().out)["t"]
        assert t[0] == 0.0 and t[-1] == pytest.approx(duration)


def test_track_from_far_away_is_refused_in_bounded_time_not_a_hang(monkeypatch, capsys):
    from wmrkit.control import loop

    # --from 1e4 0 0 ran for minutes (the loop is stiff at 1e4 m/s; now refused up front, below); a start 500 m off
    # commands 500 m/s and is stiff too: the evaluation budget, lowered here to keep the test fast, ends it
    monkeypatch.setattr(loop, "MAX_EVALUATIONS", 2000)
    monkeypatch.setattr(loop, "EVALUATIONS_PER_SECOND", 500)
    assert main(["track", "diff-drive", "--reference", "circle", "--duration", "2"]) == 0  # ~200 evaluations
    capsys.readouterr()
    message = _refused(["track", "diff-drive", "--reference", "circle", "--duration", "2", "--from", "500", "0", "0"],
                       capsys)
    assert "too stiff" in message and "start closer to the reference" in message and "evaluations" in message


#: Seconds an up-front refusal of the continuous loop may take (the reference is built first: ~1 s for a 1 km circle).
UP_FRONT = 10.0


@pytest.mark.parametrize("robot", ["diff-drive", "ackermann"])
def test_track_from_beyond_the_speed_limit_is_refused_up_front(robot, capsys):
    # --from 1e9 1e9 3 integrated for 50 s (diff-drive; 68 s the ackermann) before 'too stiff'
    start = time.perf_counter()
    message = _refused(["track", robot, "--reference", "line", "--from", "1e9", "1e9", "3"], capsys)
    assert time.perf_counter() - start < UP_FRONT
    assert message.startswith("wmrkit: error: initial pose (--from): the controlled point starts 1.414e+09 m")
    assert "beyond 1000 m/s" in message and "within 999.5 m at this gain" in message


def test_track_continuous_loop_too_long_is_refused_up_front(capsys):
    # a 1 km circle at 0.5 m/s (12,566 s) ran for 6 minutes on a loaded machine
    start = time.perf_counter()
    message = _refused(["track", "diff-drive", "--reference", "circle", "--size", "1e3"], capsys)
    assert time.perf_counter() - start < UP_FRONT
    assert "duration 12566.4 s" in message and "at most 2000 s (40000 output samples of 0.05 s" in message


def test_track_limits_keep_runs_that_work():
    # the checks refuse nothing that ran: a start 100 m off (4 s), a robot without fixed wheels far off (no
    # stiffness), a 2000 s continuous run is allowed, and the discrete loop is not concerned
    from wmrkit import catalog
    from wmrkit.control.references import resolve_reference
    from wmrkit.control.track import _check_continuous_work, control_point, track

    line = resolve_reference("line")
    run = track(catalog.load("diff-drive"), line, initial_pose=[100, 0, 0], duration=2)
    assert run.error[0] == pytest.approx(100.2, abs=0.1)
    run = track(catalog.load("omni-3"), line, initial_pose=[500, 500, 3], duration=2)  # 707 m/s: no stiffness
    assert run.error[0] == pytest.approx(707.1, rel=1e-3)
    with pytest.raises(ControlError, match="beyond 1000 m/s: no wheeled robot moves so fast"):  # said "diverged"
        track(catalog.load("omni-3"), line, initial_pose=[1e9, 1e9, 3], duration=2)
    _check_continuous_work(control_point(catalog.load("diff-drive")), line, np.zeros(3), 2000.0, 0.05, 1.0)
    run = track(catalog.load("diff-drive"), line, initial_pose=[1e4, 1e4, 3], period=0.1, duration=2)
    assert run.error[-1] < run.error[0]


@pytest.mark.parametrize("text, expected", [
    ("t,x,y,theta\n0,0,0,0\n1,1,0,0\n2,2,0\n", "ref.csv:4: expected 4 fields, got 3"),  # numpy's message before
    ("t,x,y,theta\n0,0,0,0\n1,1,0,0\n2,2,0,0,5\n", "ref.csv:4: expected 4 fields, got 5"),  # accepted before
    ("t,x,y,theta\n0,0,0,0\n1,1,0,0\n2,2,0,abc\n", "ref.csv:4: column 'theta': cannot read 'abc' as a number"),
    ("t,x,y,theta\n0,0,0,0\n1,1e308,0,0\n2,-1e308,0,0\n", "sample 2: position (1e+308, 0) m is beyond"),  # "feasible"
])
def test_reference_files_are_read_row_by_row(text, expected, tmp_path, capsys):
    path = _write(tmp_path / "ref.csv", text)
    assert expected in _refused(["feasibility", "diff-drive", "--reference", path], capsys)


def test_a_directory_as_reference_is_refused(tmp_path, capsys):
    for command in ("track", "feasibility"):  # IsADirectoryError traceback before
        assert f"{tmp_path}: a folder; a reference is a file" in _refused([command, "diff-drive", "--reference",
                                                                         str(tmp_path)], capsys)


def _skid_log(tmp_path: Path, n: int = 50) -> str:
    rows = "".join(f"{k / 100:.2f},{k / 20:.4f},{k / 16:.4f},{k / 20:.4f},{k / 16:.4f}\n" for k in range(n))
    return _write(tmp_path / "log.csv", "time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n" + rows)


@pytest.mark.parametrize("tum, expected", [
    ("", "no poses in the file"),  # numpy's UserWarning and "8 columns, got 1" before
    ("0 0 0 0 0 0 0 1\n0.1 nan 0 0 0 0 0 1\n0.2 0 0 0 0 0 0 1\n", ":2: column 'tx': value nan is not a finite number"),
    ("0 0 0 0 0 0 0 1\n0.2 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n", "ref.tum:3: time 0.1 s does not increase"),  # silent
    ("0 0 0 0 0 0 0 0\n0.1 0 0 0 0 0 0 0\n0.2 0 0 0 0 0 0 0\n", "ref.tum:1: the quaternion is (almost) zero"),  # silent
    ("0 0 0 0 0 0 0 1\n0.1 1e308 0 0 0 0 0 1\n0.2 0 0 0 0 0 0 1\n", "ref.tum:2: a coordinate beyond"),  # printed inf
])
def test_calibrate_refuses_a_broken_reference_trajectory(tum, expected, tmp_path, capsys):
    ref = _write(tmp_path / "ref.tum", tum)
    message = _refused(["calibrate", "skid-steer-4", _skid_log(tmp_path), "--reference", ref], capsys)
    assert "ref.tum" in message and expected in message


@pytest.mark.parametrize("option, expected", [
    (["--method", "wls", "--mu-default", "1e308,1e-308"], "differ by more than a factor"),  # pose 0, 0, 0 before
    (["--method", "wls", "--mu", "front_left=1e40,1"], "front_left (lateral) (1e+40)"),  # pose 0, 0, 0 before
    (["--method", "wls", "--mu-default", ""], "--mu-default: empty value"),  # ignored before
    (["--method", "wls", "--mu-default", "1,"], "expected two numbers"),
    (["--mu", "front_left=2,1"], "--mu applies to --method wls, not to --method exact"),  # ignored before
    (["--kf-noise", "1", "1", "1"], "--kf-noise applies to --method fk1 or fk2"),  # ignored before
    (["--method", "exact", "--scheme", "euler"], "--scheme applies to --method wls, fk1 or fk2"),  # ignored before
    (["--crowley", "1", "1", "1"], "--crowley applies with --covariance"),  # ignored before
    (["--method", "fk2", "--crowley", "1", "1", "1"], "--crowley applies with --covariance"),  # ignored before
])
def test_odometry_estimator_options_are_used_or_refused(option, expected, tmp_path, capsys):
    assert expected in _refused(["odometry", "skid-steer-4", _skid_log(tmp_path), "--quiet", *option], capsys)


def test_simulate_refuses_duplicate_columns_overflow_and_lift_off(tmp_path, capsys):
    twice = _write(tmp_path / "twice.csv", "time,front_left.spin,front_left.spin\n0,1,2\n0.05,1,2\n")
    assert "twice.csv:1: column 'front_left.spin' given twice" in _refused(
        ["simulate", "skid-steer-4", "--torques", twice], capsys)  # the last column was used silently
    huge = _write(tmp_path / "huge.csv", "time,front_left.spin\n0,1e6\n0.05,1e6\n")
    for method in ("semi-implicit", "adaptive"):  # ZeroDivisionError traceback / a robot standing still
        message = _refused(["simulate", "skid-steer-4", "--torques", huge, "--method", method], capsys)
        assert "diverged" in message or "lifts off the ground" in message
    hard = _write(tmp_path / "hard.csv", "time," + ",".join(f"{w}.spin" for w in (
        "front_left", "front_right", "rear_left", "rear_right")) + "\n0,100,100,100,100\n0.05,100,100,100,100\n")
    # 400 N m lifts the front: the clipped loads carried 10x the weight and the robot did 5.8 g before
    assert "contact 'front_left' lifts off the ground" in _refused(["simulate", "skid-steer-4", "--torques", hard],
                                                                   capsys)
    assert "speed: expected a program speed" in _refused(
        ["simulate", "skid-steer-4", "--path", "straight", "--speed", "1e308"], capsys)  # two warnings and a
    # message about input times before


def test_plots_need_an_extension_instead_of_writing_another_file(tmp_path, capsys):
    base = tmp_path / "figure"  # matplotlib wrote figure.png (or DIR.png for a directory) and exit 0
    for argv in (["tyre", "linear", "--load", "1"], ["feasibility", "diff-drive", "--reference", "circle"],
                 ["track", "diff-drive", "--reference", "circle", "--duration", "0.5"]):
        assert "plot files are .png, .svg, .pdf" in _refused([*argv, "--plot", str(base)], capsys)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("option, expected", [
    (["--param", "c_long=-5"], "--param c_long: must be >= 0"),  # pushed with the slip before
    (["--param", "c_lat=-1", "--slip-angle", "0.1"], "must be >= 0"),
])
def test_tyre_parameters_follow_the_description_rules(option, expected, capsys):
    assert expected in _refused(["tyre", "linear", "--load", "1000", "--slip-ratio", "0.1", *option], capsys)
    assert "mu: must be > 0" in _refused(["tyre", "dugoff", "--load", "1000", "--param", "mu=0"], capsys)
    assert "shifts: must be 0 or 1" in _refused(["tyre", "pacejka", "--load", "1000", "--param", "shifts=0.5"],
                                                capsys)


def test_tyre_overflow_is_one_line_without_warnings(capsys):
    # numpy's two-line RuntimeWarning came before the error ("no finite force"); the speed is now bounded first
    assert "--speed: must be in (0, 1000] m/s" in _refused(["tyre", "pacejka", "--load", "1000", "--slip-ratio",
                                                            "0.1", "--speed", "1e308"], capsys)


@pytest.mark.parametrize("option, expected", [
    (["--noise", "-1", "0"], "noise bounds"),  # numpy ValueError traceback
    (["--noise", "1e308", "0"], "noise bounds"),  # OverflowError traceback
    (["--clutter", "-1"], "clutter must be an integer in [0, 100]"),  # ValueError traceback
    (["--clutter", "1000000000"], "clutter must be an integer in [0, 100]"),  # a hang
    (["--blur", "1e308"], "blur in [0, 50] px"),  # cv2.error traceback
    (["--period", "1e-320"], "more than 10000 periods"),  # OverflowError traceback
    (["--speed", "1e308"], "faster than 1000 m/s"),  # printed final h = nan cm
    (["--line-width", "1e308"], "width must be in [1e-06, 1000] m"),  # RuntimeWarning lines
    (["--start", "1e308", "0"], "start position (--start) (0, 1e+308) m is beyond"),  # RuntimeWarning lines
])
def test_follow_line_options_are_checked(option, expected, capsys):
    argv = ["follow-line", "line-follower", "--camera", CAMERA, "--duration", "1", *option]
    assert expected in _refused(argv, capsys)


def test_a_name_given_twice_is_refused_not_overwritten(capsys):
    # fk used left = 2 and ik the second heading, silently
    assert "--spin left: given twice ('1' and '2')" in _refused(["fk", "diff-drive", "--spin", "left=1", "--spin",
                                                                 "left=2"], capsys)
    assert "--steer front_left: given twice" in _refused(["ik", "swerve-4", "--twist", "1", "0", "0", "--steer",
                                                          "front_left=0.1", "--steer", "front_left=0.2"], capsys)


def test_analyze_resolution_is_bounded(capsys):
    # 1e8 points per turn: numpy's MemoryError traceback (17.8 PiB)
    assert "need 8 to 1440 points per turn" in _refused(["analyze", "swerve-4", "--resolution", "100000000"], capsys)


@pytest.mark.parametrize("option, expected", [
    (["--vary", "wheels[0].alpha=30deg:90deg:1000000000"], "N must be a whole number of points in [1, 1000000]"),
    (["--vary", "wheels[0].l=0.1:0.2:nan"], "got 'nan'"),  # "invalid literal for int() with base 10"
    (["--vary", "wheels[0].alpha=0:720deg:3"], "an angle beyond one turn"),  # "write '12.5664 deg'"
    (["--vary", "wheels[1].alpha=0:1:10000", "--vary", "wheels[0].alpha=0:1:10000"], "the first two --vary axes"),
    (["--vary", "wheels[0].l=0.1:0.3:3", "--vary", "wheels[0].l=0.2:0.4:3"], "move the same field"),  # overwritten
    (["--vary", "wheels[0].l=0.1:0.3:3", "--length", "1e308"], "--length: 1e+308 m is outside"),  # kappa inf
    (["--vary", "wheels[0].l=0.1:0.3:3", "--configs", "100000000"], "--configs must be in [1, 10000]"),
])
def test_sweep_bounds_its_work_and_refuses_overlapping_axes(option, expected, capsys):
    assert expected in _refused(["sweep", "omni-3", "--workers", "0", "--quiet", *option], capsys)


def test_sweep_out_and_plot_paths_are_checked_first(tmp_path, capsys):
    pytest.importorskip("pyarrow")
    argv = ["sweep", "omni-3", "--workers", "0", "--quiet", "--vary", "wheels[0].l=0.1:0.3:3"]
    assert "is a folder" in _refused([*argv, "--out", str(tmp_path)], capsys)  # IsADirectoryError before
    assert "plot files are" in _refused([*argv, "--plot", str(tmp_path / "map")], capsys)  # wrote map.png, exit 0
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("option, expected", [
    (["-n", "1000000000"], "at least 2 runs and at most 1000000"),  # a hang
    (["--noise", "1e308"], "noise must be in [0, 1]"),  # numpy warnings before the error
    (["--slip", "1e308"], "slip in [0, 1] (the standard deviation of a slip ratio)"),  # numpy warnings before
    (["--slip", "1000"], "slip in [0, 1]"),  # a slip ratio's std of 1000: theta -537 rad, exit 0
    (["--rate", "1e308"], "at most 10000000 sample periods"),  # OverflowError traceback
    (["--rate", "1e-320"], "a rate >= 1e-06 Hz"),  # ValueError traceback
])
def test_monte_carlo_options_are_checked(option, expected, capsys):
    argv = ["batch", "montecarlo", "diff-drive", "--path", "square", "-n", "4", "--workers", "0", *option]
    assert expected in _refused(argv, capsys)


def test_odometry_encoder_options_apply_to_counts_only(tmp_path, capsys):
    log = _skid_log(tmp_path)
    for option in (["--gear", "2"], ["--cpr", "100"]):  # ignored silently when no column holds counts
        assert "applies to spin columns of encoder counts" in _refused(["odometry", "skid-steer-4", log, "--quiet",
                                                                        *option], capsys)
    counts = _write(tmp_path / "counts.csv", "time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n"
                    "0,0,0,0,0\n0.1,10,10,10,10\n0.2,20,20,20,20\n")
    # gear 1e308: cpr x gear overflowed and the robot stood still (pose 0, 0, 0)
    assert "counts per wheel revolution: at most" in _refused(
        ["odometry", "skid-steer-4", counts, "--quiet", "--spin", "counts", "--cpr", "100", "--gear", "1e308"], capsys)


def test_odometry_start_pose_and_covariance_overflow(tmp_path, capsys):
    log = _skid_log(tmp_path, 200)
    # --pose 1e308 0 0 printed a 309-digit x
    assert "--pose: a position beyond 1e+09 m" in _refused(["odometry", "skid-steer-4", log, "--quiet", "--pose",
                                                           "1e308", "0", "0"], capsys)
    # numpy's RuntimeWarning (two lines) came before the located error
    assert "the covariance overflows here" in _refused(["odometry", "skid-steer-4", log, "--quiet", "--covariance",
                                                        "--crowley", "1e308", "1", "1"], capsys)


def test_vision_points_outside_the_image_or_given_twice_are_refused(tmp_path, capsys):
    camera = str(Path(CAMERA).with_name("chufa-camera.yaml"))
    far = _write(tmp_path / "far.json", '{"lines": [{"n": 0, "points": [[1e308, 0], [0, 1e308]]}]}')
    # printed h = inf m after numpy's warning
    assert "lies outside the 640 x 480 image" in _refused(["vision", "locate", "--points", far, "--camera", camera],
                                                          capsys)
    twice = _write(tmp_path / "twice.json", '{"lines": [{"n": 0, "points": [[1, 0], [1, 5]]}, '
                                            '{"n": 0, "points": [[2, 0], [2, 5]]}]}')
    # two different lines were averaged as the same one
    assert "line n = 0 given twice" in _refused(["vision", "locate", "--points", twice, "--camera", camera], capsys)


def test_vision_calibrate_out_and_sizes(tmp_path, capsys):
    argv = ["vision", "calibrate", "--x1", "100", "--x2", "60", "--rows", "60", "--half-separation", "3.5cm",
            "--row-distance", "20cm"]
    assert "is a folder" in _refused([*argv, "--out", str(tmp_path)], capsys)  # IsADirectoryError
    # a 1e8 x 1e8 camera was written, and follow-line then tried to render its images
    assert "--size: the image is 100000000 x 480 px, expected 8 to 4096 px a side" in _refused(
        [*argv, "--size", "100000000", "480", "--out", str(tmp_path / "c.yaml")], capsys)
    assert not (tmp_path / "c.yaml").exists()
    # 'cos(tilt) = inf', after numpy's warnings; then a length wmrkit does not handle, named
    assert "--half-separation: half-separation must be at most 1000 m" in _refused(
        [*argv, "--half-separation", "1e308"], capsys)


@pytest.mark.parametrize("old, new, expected", [
    ("com_height: 0.2", "com_height: 1e308", "body.com_height: 1e+308 m: farther than 1000 m"),  # robot stood still
    ("cs: 2000.0", "cs: 1e308", "wheels[0].tyre.cs: must be at most 1e+12"),  # robot stood still
    ("eps: 0.01", "eps: 1e308", "wheels[0].tyre.eps: must be at most 1 m/s"),  # moved 6.6e-311 m
])
def test_description_dynamics_fields_have_an_envelope(old, new, expected, tmp_path, capsys):
    from wmrkit import catalog
    from wmrkit.description import robot_to_dict

    text = json.dumps(robot_to_dict(catalog.load("skid-steer-4")))
    text = text.replace(old.replace(": ", '": ').join(['"', '']), new.replace(": ", '": ').join(['"', '']), 1)
    path = _write(tmp_path / "robot.json", text)
    assert expected in _refused(["simulate", path, "--path", "straight", "--duration", "0.05"], capsys)


def test_track_a_diverging_sampled_loop_is_refused(capsys):
    # gain 1e308 at a 0.1 s period: the poses overflowed and scipy's cKDTree raised ValueError (a traceback)
    assert "the closed loop diverged at t = " in _refused(
        ["track", "diff-drive", "--reference", "circle", "--duration", "2", "--gain", "1e308", "--period", "0.1"],
        capsys)


def test_a_continuous_loop_stops_within_its_computing_time_and_names_a_wheel_held_at_its_range(monkeypatch, capsys):
    # 'track ackermann --reference figure-eight --size 6 --gain 3' (6 m: the car's default before 2799d61) ran 6
    # minutes before 'too stiff': the law asks for turns tighter than the +-40 deg rack allows, and a front wheel
    # held at an end of its range switched ends at every crossing of the heading asked of it past 90 deg (since the
    # hold margin, the run answers in about 11 s). The bound remains: at most MAX_CONTINUOUS_SECONDS of computing
    # (lowered here), and the refusal says where it got and which wheel is held. The loop's clock is a fake one
    # advancing 0.5 s a reading (one reading every 1000 evaluations): on a loaded machine 2 s of real computing
    # stopped it before any wheel was held, and the message had no wheel to name.
    import types

    from wmrkit.control import loop

    readings = iter(range(1, 10**6))
    monkeypatch.setattr(loop, "time", types.SimpleNamespace(monotonic=lambda: 0.5 * next(readings)))
    monkeypatch.setattr(loop, "MAX_CONTINUOUS_SECONDS", 2.0)
    message = _refused(["track", "ackermann", "--reference", "figure-eight", "--size", "6", "--gain", "3"], capsys)
    found = re.search(r"too stiff to integrate over 90.47 s: it reached t = \S+ s after (\d+) evaluations and \d+ s "
                      r"of computing .*wheel 'front_(left|right)' is held at an end of its steer_range", message)
    assert found, message
    # bounded work, not wall time (a loaded machine took over 30 s): the fake clock passes 2 s at the fifth reading,
    # one every 1000 evaluations from the first multiple of 1000 left in the budget
    assert int(found[1]) < 6000, message
