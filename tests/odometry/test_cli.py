"""``wmrkit odometry``, run in-process: outputs, options, and exit code 2 with one line for bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import WmrkitError
from wmrkit.kinematics.wheel_ik import wheel_commands
from wmrkit.odometry.encoders import IncrementalEncoder, catalog_encoders
from wmrkit.odometry.logs import write_csv
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.odometry.trajectories import read_trajectory_csv, read_tum


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_json_prints_the_final_pose(capsys, diff_csv, diff_run):
    out = _json(capsys, ["odometry", "diff-drive", diff_csv, "--json"])
    np.testing.assert_allclose(out["final_pose"], diff_run.truth[-1], atol=1e-9)
    assert out["samples"] == len(diff_run.log) and out["method"] == "exact"


@pytest.mark.parametrize("method", ["exact", "rk2", "euler", "paper002"])
def test_methods_rank_as_expected(capsys, diff_csv, diff_run, method):
    out = _json(capsys, ["odometry", "diff-drive", diff_csv, "--json", "--method", method])
    err = np.hypot(*(np.array(out["final_pose"][:2]) - diff_run.truth[-1, :2]))
    assert err < {"exact": 1e-9, "rk2": 1e-4, "euler": 0.05, "paper002": 0.05}[method]


def test_text_summary_and_start_pose(capsys, diff_csv):
    assert main(["odometry", "diff-drive", diff_csv, "--pose", "1", "2", "90 deg", "--covariance"]) == 0
    text = capsys.readouterr().out
    assert "robot diff-drive, method exact" in text and "final std:" in text
    out = _json(capsys, ["odometry", "diff-drive", diff_csv, "--json", "--pose", "1 m", "200 mm", "0.5"])
    base = _json(capsys, ["odometry", "diff-drive", diff_csv, "--json"])
    x, y, th = base["final_pose"]
    c, s = math.cos(0.5), math.sin(0.5)
    np.testing.assert_allclose(out["final_pose"], [1 + c * x - s * y, 0.2 + s * x + c * y, th + 0.5], atol=1e-12)


def test_outputs_csv_tum_bag_and_plot(capsys, tmp_path, diff_csv, diff_run):
    assert main(["odometry", "diff-drive", diff_csv, "--out", str(tmp_path / "t.csv"), "--covariance",
                 "--plot", str(tmp_path / "p.png"), "--quiet"]) == 0
    traj = read_trajectory_csv(tmp_path / "t.csv")
    np.testing.assert_allclose(traj.poses, diff_run.truth, atol=1e-9)
    assert traj.covariance is not None and (tmp_path / "p.png").stat().st_size > 1000
    assert main(["odometry", "diff-drive", diff_csv, "--out", str(tmp_path / "t.tum")]) == 0
    t, poses = read_tum(tmp_path / "t.tum")
    np.testing.assert_allclose(poses[:, :2], diff_run.truth[:, :2], atol=1e-9)
    pytest.importorskip("rosbags")
    assert main(["odometry", "diff-drive", diff_csv, "--out", str(tmp_path / "t_bag")]) == 0
    from wmrkit.odometry.bags import read_odometry

    np.testing.assert_allclose(read_odometry(tmp_path / "t_bag").poses, diff_run.truth, atol=1e-9)
    assert main(["odometry", "diff-drive", diff_csv, "--out", str(tmp_path / "t.dat"), "--format", "tum"]) == 0
    assert len(read_tum(tmp_path / "t.dat")[0]) == len(t)
    capsys.readouterr()


def test_forklift_counts_log_uses_the_catalog_encoders(capsys, tmp_path):
    robot = catalog.load("forklift")
    profile = TwistProfile.from_segments([(4.0, 1.0, 0.2, 0.2), (1.0, 0, 0, 0), (4.0, 1.0, 0.0, 0.0)])
    enc = catalog_encoders("forklift")
    run = simulate(robot, profile, 20.0, encoders=enc)
    path = tmp_path / "fork.csv"
    write_csv(path, ("stamp", "enc_r", "enc_l", "steer_raw"),
              np.column_stack([run.log.time, *(run.counts[j] for j in run.log.joints)]), fmt="%.10g")
    out = _json(capsys, ["odometry", "forklift", str(path), "--json", "--spin", "counts", "--steer", "counts",
                         "--time-column", "stamp", "--column", "right_drive.spin=enc_r",
                         "--column", "left_drive.spin=enc_l", "--column", "steer.steer=steer_raw"])
    # what the library gives on the decoded angles (counts relative to the first sample)
    log = run.log
    log = type(log)(log.time, log.joints, log.positions - np.array([*log.positions[0, :2], 0.0]))
    np.testing.assert_allclose(out["final_pose"], odometry(robot, log).final_pose, atol=1e-9)
    # 8 m driven; steering quantised to 1.4 deg makes the least-squares blend turn a little: within 2 %
    assert np.hypot(*(np.array(out["final_pose"][:2]) - run.truth[-1, :2])) < 0.16
    # the same with explicit settings: --cpr and --steer-resolution
    out2 = _json(capsys, ["odometry", "forklift", str(path), "--json", "--spin", "counts", "--steer", "counts",
                          "--time-column", "stamp", "--cpr", "8290", "--steer-resolution", "1.4118 deg",
                          "--column", "right_drive.spin=enc_r", "--column", "left_drive.spin=enc_l",
                          "--column", "steer.steer=steer_raw"])
    assert out2["final_pose"] == out["final_pose"]  # one rule: every steering encoder reads 0 straight ahead
    out3 = _json(capsys, ["odometry", "forklift", str(path), "--json", "--spin", "counts", "--steer", "counts",
                          "--time-column", "stamp", "--weight", "steer=0.01", "--column", "right_drive.spin=enc_r",
                          "--column", "left_drive.spin=enc_l", "--column", "steer.steer=steer_raw"])
    err3 = np.hypot(*(np.array(out3["final_pose"][:2]) - run.truth[-1, :2]))
    assert err3 < 0.2 * np.hypot(*(np.array(out["final_pose"][:2]) - run.truth[-1, :2]))  # trusting the steering less
    # --gear with the catalog's counts per revolution: 2 encoder turns per wheel turn halve every spin angle (it was
    # ignored without --cpr: the same pose, exit 0)
    columns = ["--column", "right_drive.spin=enc_r", "--column", "left_drive.spin=enc_l", "--column",
               "steer.steer=steer_raw"]
    geared = [_json(capsys, ["odometry", "forklift", str(path), "--json", "--spin", "counts", "--steer", "counts",
                             "--time-column", "stamp", *columns, *gear]) for gear in (["--gear", "2"],
                                                                                      ["--cpr", "8290", "--gear", "2"])]
    assert geared[0] == geared[1] and geared[0]["path_length"] == pytest.approx(out["path_length"] / 2, rel=1e-9)


def test_wrapping_counter_and_sensed_subset(capsys, tmp_path, diff_run):
    enc = IncrementalEncoder(1024, bits=12)
    counts = [enc.wrap(enc.quantize(diff_run.log.positions[:, k])) for k in range(2)]
    path = tmp_path / "c.csv"
    write_csv(path, ("time", "left.spin", "right.spin"), np.column_stack([diff_run.log.time, *counts]), fmt="%.10g")
    out = _json(capsys, ["odometry", "diff-drive", str(path), "--json", "--spin", "counts", "--cpr", "1024",
                         "--counter-bits", "12"])
    assert np.hypot(*(np.array(out["final_pose"][:2]) - diff_run.truth[-1, :2])) < 0.01


@pytest.mark.parametrize("width", ["u64", "s64"])
def test_a_64_bit_counter_header_is_read(capsys, tmp_path, width):
    path = tmp_path / "c.csv"  # the header's widths are 8 to 64 bits; 64 was refused without the file or column
    path.write_text(f"time,left.spin [counts:{width}],right.spin [counts:{width}]\n0,0,0\n1,1000,1000\n")
    out = _json(capsys, ["odometry", "diff-drive", str(path), "--json", "--cpr", "1000"])
    assert out["final_pose"] == pytest.approx([2 * math.pi * 0.075, 0.0, 0.0], abs=1e-12)


def test_an_angle_in_a_steering_counts_column_is_refused(capsys, tmp_path):
    path = tmp_path / "f.csv"  # degrees written to the forklift's counts column were read as 1.4118-deg counts
    path.write_text("time,right_drive.spin [counts],left_drive.spin [counts],steer.steer [counts]\n"
                    "0,0,0,-25.17\n1,1000,1000,-25.17\n")
    assert main(["odometry", "forklift", str(path)]) == 2
    assert "column 'steer.steer [counts]': counts must be whole numbers, got -25.17" in capsys.readouterr().err


def test_gyro_heading(capsys, tmp_path, diff_run):
    gyro = np.gradient(diff_run.truth[:, 2], diff_run.log.time)
    path = tmp_path / "g.csv"
    write_csv(path, ("time", "left.spin", "right.spin", "gz"),
              np.column_stack([diff_run.log.time, diff_run.log.positions, gyro]))
    out = _json(capsys, ["odometry", "diff-drive", str(path), "--json", "--gyro-column", "gz"])
    assert out["final_pose"][2] == pytest.approx(diff_run.truth[-1, 2], abs=0.01)


@pytest.mark.parametrize(("column", "values", "agrees"), [
    ("gz", lambda w: w, True), ("yaw", lambda y: y, True),
    ("gz", np.degrees, False),  # a gyro in deg/s read as rad/s: theta 57 times the truth, "consistent": true
    ("yaw", lambda y: -y, False),  # a clockwise (NED) yaw: the mirror path
    ("gz", lambda w: 1.3 * w, True),
    ("gz", lambda w: w / 3, True),  # a skid steer's wheels turn up to 2-3 times the robot: not a contradiction
    ("yaw", lambda y: y / 3, True),
])
def test_an_external_heading_that_contradicts_the_wheels_warns(capsys, tmp_path, diff_run, column, values, agrees):
    truth = diff_run.truth[:, 2]
    data = values(np.gradient(truth, diff_run.log.time) if column == "gz" else truth)
    path = tmp_path / "h.csv"
    write_csv(path, ("time", "left.spin", "right.spin", column), np.column_stack([diff_run.log.time,
                                                                                  diff_run.log.positions, data]))
    option = "--gyro-column" if column == "gz" else "--heading-column"
    assert main(["odometry", "diff-drive", str(path), "--json", option, column]) == 0
    out = capsys.readouterr()
    assert json.loads(out.out)["consistent"] is agrees
    assert ("external heading (column '" + column + "')" in out.err) is not agrees, out.err


@pytest.mark.parametrize(("setup", "args", "message"), [
    ("nan", [], r"x\.csv:4: column 'right\.spin': value nan is not a finite number \(field 3\)"),
    ("repeat", [], r"x\.csv:4: time 0\.05 s repeats the previous sample \(a zero time step\)"),
    ("ok", ["--time-column", "stamp"], r"missing column 'stamp'"),
    ("wheels", [], r"column 'front\.spin' names no wheel of the robot"),
    ("ok", ["--spin", "counts"], r"joint 'left\.spin' of robot 'diff-drive': no encoder data"),
    ("ok", ["--pose", "0", "0", "abc"], r"--pose: cannot read 'abc' as an angle"),
    ("ok", ["--sensed", "left.spin"], r"do not determine its motion"),
    ("ok", ["--max-gap", "0.01"], r"x\.csv:3: time step of 0\.05 s exceeds max_gap"),
    ("ok", ["--out", "/nonexistent/dir/t.csv"], r"--out /nonexistent/dir/t.csv: no such folder '/nonexistent/dir'"),
    ("ok", ["--plot", "p.gif"], r"plot files are \.png, \.svg, \.pdf"),
    ("ok", ["--chunk-size", "0"], r"--chunk-size must be in \[1, 4194304\] samples"),
    ("ok", ["--weight", "left=-1"], r"weight of wheel 'left' must be a finite number > 0"),
    ("missing", [], r"no such file"),
    # one encoder read for two wheels, a joint misspelt: were read as a straight line / ignored
    ("ok", ["--column", "right.spin=left.spin"], r"x\.csv:1: column 'left\.spin' is read for both left\.spin and "
                                                  r"right\.spin"),
    ("ok", ["--column", "left.spin=time"], r"x\.csv:1: column 'time' is read for both time and left\.spin"),
    ("ok", ["--heading-column", "right.spin"], r"column 'right\.spin' is read for both right\.spin and heading"),
    ("ok", ["--column", "lfet.spin=left.spin"], r"a column is given for 'lfet\.spin', no joint of the robot"),
    # a steering resolution for a log without steering counts was ignored; encoder settings named their fields
    ("ok", ["--steer-resolution", "1.4118 deg"], r"--steer-resolution applies to steer columns of encoder counts"),
    ("ok", ["--spin", "counts", "--cpr", "0"], r"--cpr must be a finite number > 0, got 0"),
    ("ok", ["--spin", "counts", "--cpr", "100", "--gear", "-2"], r"--gear must be a finite number > 0, got -2"),
    ("ok", ["--spin", "counts", "--cpr", "100", "--counter-bits", "65"], r"--counter-bits must be between 2 and 64"),
    ("ok", ["--max-gap", "-1"], r"--max-gap must be > 0 s, got -1"),
    # bag options on a CSV log were ignored (CSV options on a bag were refused)
    ("ok", ["--joint-name", "wheel_l=left.spin"], r"--joint-name applies to ROS 2 bags; LOG .*x\.csv is read as a CSV"),
    ("ok", ["--topic", "/wheels"], r"--topic applies to ROS 2 bags"),
    # steering options on a robot that reads no steering were ignored (exit 0): a log of another robot?
    ("ok", ["--steer", "degrees"], r"--steer applies to steering columns; robot 'diff-drive' reads none \(sensed: "
                                   r"left\.spin, right\.spin\)"),
    ("ok", ["--steer-convention", "beta"], r"--steer-convention applies to steering columns"),
])
def test_bad_input_exits_2_with_one_line(capsys, tmp_path, setup, args, message):
    path = tmp_path / "x.csv"
    rows = {"ok": ["0,0,0", "0.05,1,1", "0.1,2,2"], "nan": ["0,0,0", "0.05,1,1", "0.1,2,nan"],
            "repeat": ["0,0,0", "0.05,1,1", "0.05,2,2"], "wheels": ["0,0,0,0"], "missing": None}[setup]
    header = "time,left.spin,right.spin" + (",front.spin" if setup == "wheels" else "")
    if rows is not None:
        path.write_text(header + "\n" + "\n".join(rows) + "\n")
    assert main(["odometry", "diff-drive", str(path), *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wmrkit: error: ") and err.count("\n") == 1
    assert __import__("re").search(message, err), err


def test_a_field_that_is_no_number_is_located_by_its_column_under_json(capsys, tmp_path):
    """An empty or non-numeric cell was named "field 3", so --json gave "field": null; the column is named now."""
    path = tmp_path / "x.csv"
    path.write_text("time,left.spin,right.spin [rad]\n0,0,0\n0.05,1,\n")
    assert main(["odometry", "diff-drive", str(path), "--json"]) == 2
    err = json.loads(capsys.readouterr().err)
    assert (err["file"], err["line"], err["field"]) == (str(path), 3, "right.spin [rad]")
    assert err["error"] == "cannot read '' as a number (field 3)"


def test_usage_errors_exit_2(capsys, diff_csv):
    assert main(["odometry", "diff-drive", diff_csv, "--method", "rk4"]) == 2  # usage errors: exit 2, no traceback
    assert "argument --method: invalid choice: 'rk4'" in capsys.readouterr().err
    assert main(["odometry", "no-such-robot", diff_csv]) == 2
    assert "no robot 'no-such-robot'" in capsys.readouterr().err


def _forklift_log(tmp_path, *, steer_scale: float = 1.0, header=lambda j: j):
    robot = catalog.load("forklift")
    joints = ("right_drive.spin", "left_drive.spin", "steer.steer")
    run = simulate(robot, TwistProfile.from_segments([(6.0, 1.0, 0.0, 0.15)]).about((-1.0, 0.0)), 50.0)
    headings = run.log.heading_positions(robot)  # what a log file holds: steering as headings
    cols = [headings[:, run.log.joints.index(j)] * (steer_scale if j.endswith(".steer") else 1.0) for j in joints]
    path = tmp_path / "forklift.csv"
    write_csv(path, ("time", *map(header, joints)), np.column_stack([run.log.time, *cols]))
    return path


def test_units_in_the_header_need_no_options_and_contradicting_options_are_refused(capsys, tmp_path):
    """Issue 8: a log says what its columns hold; the README's odometry line runs as written on the example's log."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    subprocess.run([sys.executable, str(root / "examples" / "odometry_forklift_log.py"), str(tmp_path)], check=True,
                   capture_output=True)
    log = str(tmp_path / "forklift_counts.csv")
    assert main(["odometry", "forklift", log, "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert main(["odometry", "forklift", log, "--spin", "counts", "--steer", "counts", "--counter-bits", "16",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["final_pose"] == plain["final_pose"] and plain["consistent"] is True
    assert 20 < plain["path_length"] < 30  # the example's 24 m drive, not 85.9 km of counts read as radians
    assert main(["odometry", "forklift", log, "--spin", "angle"]) == 2
    assert "the header says --spin counts, the option says angle" in capsys.readouterr().err


def test_degrees_written_as_radians_warn_and_say_inconsistent(capsys, tmp_path):
    good = _forklift_log(tmp_path)
    assert main(["odometry", "forklift", str(good), "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["consistent"] is True and err == ""
    bad = _forklift_log(tmp_path, steer_scale=180 / math.pi)  # the steering column in degrees, read as radians
    assert main(["odometry", "forklift", str(bad), "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["consistent"] is False
    assert err.startswith("wmrkit: warning: the sensed joints contradict each other") and err.count("\n") == 1
    # the wheels named with their RMS slip, largest first (which one is largest depends on the wrong angle read)
    listed = __import__("re").search(r"slip per wheel: ([^)]*)\)", err).group(1).split(", ")
    slips = [float(item.split()[1]) for item in listed]
    assert sorted(item.split()[0] for item in listed) == ["left_drive", "right_drive", "steer"]
    assert slips == sorted(slips, reverse=True) and slips[0] > 0


@pytest.mark.parametrize("weight", ["steer=1e16", "steer=1e-7"])
def test_weights_too_far_apart_are_refused(capsys, tmp_path, weight):
    """At a ratio of 1e16 the forklift's drive-wheel rows fell below the rank tolerance: a pose of 4e-31 m, exit 0."""
    from wmrkit.odometry.model import odometry_model

    profile = TwistProfile.from_segments([(4.0, 1.0, 0.2, 0.2), (1.0, 0, 0, 0), (4.0, 1.0, 0.0, 0.0)])
    run = simulate(catalog.load("forklift"), profile, 50.0)
    path = tmp_path / "fork.csv"
    write_csv(path, ("time", *run.log.joints), np.column_stack([run.log.time, run.log.positions]))
    assert main(["odometry", "forklift", str(path), "--weight", weight]) == 2
    assert "differ by more than a factor 1e+06" in capsys.readouterr().err
    close = odometry_model(catalog.load("forklift"), weights={"steer": 1e6})  # at the limit: still the motion
    assert np.hypot(*odometry(close, run.log).final_pose[:2]) == pytest.approx(np.hypot(*run.truth[-1, :2]),
                                                                               abs=1e-6)


def test_a_byte_order_mark_is_not_part_of_the_first_column(capsys, diff_csv, tmp_path):
    """Spreadsheet exports start with a UTF-8 byte-order mark: the log was refused ('no time column')."""
    bom = tmp_path / "bom.csv"
    with open(diff_csv, encoding="utf-8") as f:
        bom.write_text("\ufeff" + f.read(), encoding="utf-8")
    plain = _json(capsys, ["odometry", "diff-drive", diff_csv, "--json"])
    marked = _json(capsys, ["odometry", "diff-drive", str(bom), "--json"])
    assert marked["final_pose"] == plain["final_pose"] and marked["samples"] == plain["samples"]


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="needs named pipes")
def test_a_named_pipe_is_refused_not_waited_on(tmp_path):
    """A FIFO given as the log: the reader waited for a writer forever (run in a child, with a time limit)."""
    import os
    import subprocess
    import sys

    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    out = subprocess.run([sys.executable, "-m", "wmrkit", "odometry", "diff-drive", str(fifo), "--json"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 2 and out.stdout == ""
    error = json.loads(out.stderr)  # one line, the file named
    assert error["file"].endswith("pipe.csv") and error["error"].startswith("not a regular file")


@pytest.mark.parametrize("alias", ["same", "dot", "link"])
@pytest.mark.parametrize("fmt", ["csv", "tum"])
def test_an_output_that_is_the_log_is_refused_and_the_log_kept(capsys, diff_csv, tmp_path, monkeypatch, alias, fmt):
    """``--out log.csv`` opened the log for writing before reading it: the log was emptied (then 'empty file')."""
    import os
    from pathlib import Path

    log = Path(diff_csv)
    before = log.read_bytes()
    monkeypatch.chdir(log.parent)
    if alias == "link":
        os.symlink(log.name, "link.csv")
    given = {"same": str(log), "dot": f"./{log.name}", "link": "link.csv"}[alias]
    assert main(["odometry", "diff-drive", str(log), "--out", given, "--format", fmt]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out " in err and "is also LOG (the output would replace it)" in err, err
    assert log.read_bytes() == before


@pytest.mark.parametrize(("header", "args"), [
    ("time [s],left.spin,right.spin,latency [ms]", []),  # the time was read in ms: every step 1000 times shorter
    ("time,left.spin,right.spin,battery [V]", []),  # refused: 'unknown unit V (time units ...)'
    ("time,left.spin,right.spin,imu.yaw [deg]", []),  # refused: 'unknown unit deg (for a spin joint ...)'
    ("time,enc_l [rad],enc_r [rad]", ["--column", "left.spin=enc_l", "--column", "right.spin=enc_r"]),  # refused
])
def test_units_of_columns_that_are_not_the_logs_do_not_change_the_reading(capsys, tmp_path, header, args):
    plain = tmp_path / "plain.csv"
    rows = "0,0,0{x}\n0.5,1,2{x}\n1,2,4{x}\n"
    plain.write_text("time,left.spin,right.spin\n" + rows.format(x=""))
    path = tmp_path / "units.csv"
    path.write_text(header + "\n" + rows.format(x=",5" if header.count(",") == 3 else ""))
    want = _json(capsys, ["odometry", "diff-drive", str(plain), "--json"])
    got = _json(capsys, ["odometry", "diff-drive", str(path), "--json", *args])
    assert (got["final_pose"], got["max_dt"]) == (want["final_pose"], want["max_dt"])


def test_a_heading_column_with_its_unit(capsys, tmp_path):
    """``--heading-column yaw`` on a header ``yaw [rad]`` was refused ('time units'); a unit other than rad and deg
    is refused, named."""
    path = tmp_path / "yaw.csv"
    path.write_text("time,left.spin,right.spin,yaw [rad]\n0,0,0,0\n1,1,1,0.5\n")
    out = _json(capsys, ["odometry", "diff-drive", str(path), "--json", "--heading-column", "yaw"])
    assert out["final_pose"][2] == 0.5
    path.write_text("time,left.spin,right.spin,yaw [grad]\n0,0,0,0\n1,1,1,0.5\n")
    assert main(["odometry", "diff-drive", str(path), "--heading-column", "yaw"]) == 2
    assert "column 'yaw': unknown unit 'grad' (for a heading column: rad, deg)" in capsys.readouterr().err


@pytest.mark.parametrize(("header", "option", "values"), [
    ("yaw [deg]", "--heading-column", lambda t: np.degrees(0.5 * t)),   # WPILib's gyro angle, in degrees
    ("gz [deg/s]", "--gyro-column", lambda t: np.full_like(t, np.degrees(0.5))),
    ("yaw [rad]", "--heading-column", lambda t: 0.5 * t),
    ("gz [rad/s]", "--gyro-column", lambda t: np.full_like(t, 0.5)),
])
def test_a_heading_or_gyro_column_in_degrees_is_read_as_its_header_says(capsys, tmp_path, header, option, values):
    """A gyro logged in degrees (WPILib's ``getAngle()``, deg/s rates) was refused ('a heading column is read in
    rad') with no way to read it but converting the file; the header's ``[deg]`` / ``[deg/s]`` now reads it. Swerve
    modules driving the body twist (1 m/s at 30 deg, 0.5 rad/s), the gyro agreeing: the pose is the arc of speed
    1 m/s at the world angle 0.5 t + 30 deg, integrated here by its closed form."""
    c = np.radians(30)
    swerve, t = catalog.load("swerve-4"), np.linspace(0.0, 2.0, 201)
    commands = wheel_commands(swerve, [np.cos(c), np.sin(c), 0.5])  # constant headings and spins
    joints = [f"{w}.spin,{w}.steer [deg]" for w in swerve.wheel_names]
    rows = [f"{a:.6f}," + ",".join(f"{s * a:.12f},{np.degrees(h):.12f}" for s, h in
                                   zip(commands.spin, commands.heading, strict=True)) + f",{v:.12f}"
            for a, v in zip(t, values(t), strict=True)]
    path = tmp_path / "gyro.csv"
    path.write_text(f"time,{','.join(joints)},{header}\n" + "\n".join(rows) + "\n")
    out = _json(capsys, ["odometry", "swerve-4", str(path), "--json", option, header.split()[0]])
    want = [(np.sin(1 + c) - np.sin(c)) / 0.5, (np.cos(c) - np.cos(1 + c)) / 0.5, 1.0]  # x = int cos(0.5 t + c)
    np.testing.assert_allclose(out["final_pose"], want, atol=1e-8)
    assert out["consistent"] is True


def test_an_output_that_is_the_plot_is_refused(capsys, diff_csv, tmp_path):
    """``--out p.png --format csv --plot p.png``: the plot replaced the trajectory and the run reported success."""
    same = str(tmp_path / "p.png")
    assert main(["odometry", "diff-drive", diff_csv, "--out", same, "--format", "csv", "--plot", same]) == 2
    assert "is also --plot (the output would replace it)" in capsys.readouterr().err
    assert not (tmp_path / "p.png").exists()


def test_json_error_about_a_log_row_names_its_joint(capsys, tmp_path):
    """limits.md: an error about a log gives its column as `field`; a row's value error ('x.csv:3: left.spin: value
    nan ...') left it null."""
    log = tmp_path / "nan.csv"
    log.write_text("time,left.spin,right.spin\n0,0,0\n0.1,nan,1\n")
    assert main(["odometry", "diff-drive", str(log), "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(log), 3, "left.spin"), data
    assert data["error"].startswith("value nan is not a finite number")


def test_a_heading_column_in_degrees_without_its_unit_is_refused(capsys, tmp_path):
    """A yaw logged in degrees under a bare name was read as radians (theta 213 rad where the wheels said 3.75,
    exit 0): beyond one turn, a bare heading is refused as probably degrees (the rule of descriptions); an
    unwrapped heading in rad beyond a turn passes when its header writes the unit."""
    rows = "".join(f"{k},{k},{k},{6.0 * k}\n" for k in range(4))  # 0, 6, 12, 18: degrees
    path = tmp_path / "yaw.csv"
    path.write_text("time,left.spin,right.spin,yaw\n" + rows)
    assert main(["odometry", "diff-drive", str(path), "--json", "--heading-column", "yaw"]) == 2
    got = json.loads(capsys.readouterr().err)
    assert (got["file"], got["line"], got["field"]) == (str(path), 4, "yaw"), got
    assert got["error"].startswith("12 is beyond one turn as radians, probably degrees")
    path.write_text("time,left.spin,right.spin,yaw [rad]\n" + rows)
    assert _json(capsys, ["odometry", "diff-drive", str(path), "--json", "--heading-column", "yaw"])["final_pose"][2] \
        == pytest.approx(math.remainder(18, 2 * math.pi), abs=1e-12)  # the pose's heading is wrapped


def test_a_plot_file_wmrkit_cannot_draw_names_the_option(capsys, diff_csv, tmp_path):
    """'p.txt: cannot draw to ...' named no option (other commands say '--plot p.txt: ...'); checked before the run."""
    assert main(["odometry", "diff-drive", diff_csv, "--plot", str(tmp_path / "p.txt")]) == 2
    assert capsys.readouterr().err == (f"wmrkit: error: --plot {tmp_path / 'p.txt'}: cannot draw to '.txt' (plot "
                                       "files are .png, .svg, .pdf)\n")


def test_json_error_about_a_missing_column_names_it(capsys, tmp_path):
    """'x.csv:1: missing column 'right.spin' (columns: ...)' gave "field": null in --json."""
    log = tmp_path / "one.csv"
    log.write_text("time,left.spin\n0,0\n1,1\n")
    assert main(["odometry", "diff-drive", str(log), "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(log), 1, "right.spin"), data
    assert data["error"].startswith("missing column 'right.spin'")


@pytest.mark.parametrize(("header", "option"), [("left.spin [counts:u16],right.spin [counts:u16]", "--cpr"),
                                                ("left.spin,right.spin", "--cpr")])
def test_counts_without_encoder_data_name_the_file_column_and_option(capsys, tmp_path, header, option):
    """A counts log of a robot without catalog encoders said "joint 'left.spin' of robot 'diff-drive': no encoder
    data; give the counts per revolution": no file, no column (--json "file": null, "field": null), no option."""
    log = tmp_path / "c.csv"
    log.write_text(f"time,{header}\n0,0,0\n1,10,10\n")
    extra = [] if "counts" in header else ["--spin", "counts"]
    assert main(["odometry", "diff-drive", str(log), "--json", *extra]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(log), 1, "left.spin"), data
    assert option in data["error"]


def test_a_start_pose_too_far_names_the_option(capsys, tmp_path):
    """'--pose 1e10 0 0' was refused as 'pose0: ...', the Python argument's name, not the option's."""
    log = tmp_path / "d.csv"
    log.write_text("time,left.spin,right.spin\n0,0,0\n1,1,1.2\n")
    assert main(["odometry", "diff-drive", str(log), "--pose", "1e10", "0", "0"]) == 2
    assert capsys.readouterr().err.startswith("wmrkit: error: --pose: a position beyond 1e+09 m, got [10000000000.0")


@pytest.mark.parametrize("unit", ["m", "m/s"])
def test_spin_columns_of_wheel_travel_in_metres_are_divided_by_the_radius(capsys, tmp_path, unit):
    """WPILib's swerve odometry takes module positions in metres (SwerveModulePosition.distanceMeters): such a log,
    'front_left.spin [m]', was refused ('unknown unit 'm''). The header's m (m/s) now reads the wheel's travel
    (speed), divided by its radius. The modules drive the body twist (1 m/s at 30 deg, 0.5 rad/s): the pose is the
    closed-form arc, as the same log in rad gives."""
    from wmrkit.odometry.logs import LogFormat, load_csv

    c = np.radians(30)
    swerve, t = catalog.load("swerve-4"), np.linspace(0.0, 2.0, 201)
    commands = wheel_commands(swerve, [np.cos(c), np.sin(c), 0.5])
    speed = commands.spin * 0.0508  # m/s along each module's heading
    joints = [f"{w}.spin [{unit}],{w}.steer [deg]" for w in swerve.wheel_names]
    rows = [f"{a:.6f}," + ",".join(f"{v * a if unit == 'm' else v:.12f},{np.degrees(h):.12f}"
                                   for v, h in zip(speed, commands.heading, strict=True)) for a in t]
    path = tmp_path / "modules.csv"
    path.write_text(f"time,{','.join(joints)}\n" + "\n".join(rows) + "\n")
    out = _json(capsys, ["odometry", "swerve-4", str(path), "--json"])
    want = [(np.sin(1 + c) - np.sin(c)) / 0.5, (np.cos(c) - np.cos(1 + c)) / 0.5, 1.0]
    np.testing.assert_allclose(out["final_pose"], want, atol=1e-8)
    assert out["consistent"] is True and out["path_length"] == pytest.approx(2.0, rel=1e-9)
    with pytest.raises(WmrkitError, match=r"spin columns in m or m/s .* need the robot's wheel radii: pass robot="):
        load_csv(path, ["front_left.spin"], LogFormat(spin="distance" if unit == "m" else "speed"))


@pytest.mark.parametrize(("unit", "per_rad", "rate"), [
    ("deg", 180 / np.pi, False), ("deg/s", 180 / np.pi, True), ("rev", 0.5 / np.pi, False),
    ("rev/s", 0.5 / np.pi, True), ("turn", 0.5 / np.pi, False), ("rpm", 30 / np.pi, True),
])
def test_spin_columns_in_degrees_or_turns_are_converted(capsys, tmp_path, unit, per_rad, rate):
    """A wheel angle logged in degrees or turns ('left.spin [deg]', an encoder's 'rev', a motor's 'rpm') was refused
    ("unknown unit 'deg' (for a spin joint: rad, ...)"), while the same header's steering in [deg] was read; the
    user had to rewrite the file. The header's unit now converts the column into radians (rad/s), in the CLI and
    in Python through header_format. A differential drive driving the arc (0.4 m/s, 0.5 rad/s) for 2 s: the pose
    is the closed-form arc, as the same log in rad gives; a header mixing deg and rad is refused."""
    from wmrkit.odometry.header import header_format
    from wmrkit.odometry.logs import load_csv

    diff, t = catalog.load("diff-drive"), np.linspace(0.0, 2.0, 201)
    spins = wheel_commands(diff, [0.4, 0.0, 0.5]).spin[:2]  # rad/s, left then right (then the castor)
    rows = [f"{a:.6f}," + ",".join(f"{(w if rate else w * a) * per_rad:.12f}" for w in spins) for a in t]
    path = tmp_path / "spin.csv"
    path.write_text(f"time,left.spin [{unit}],right.spin [{unit}]\n" + "\n".join(rows) + "\n")
    out = _json(capsys, ["odometry", "diff-drive", str(path), "--json"])
    np.testing.assert_allclose(out["final_pose"], [np.sin(1.0) / 0.5 * 0.4, (1 - np.cos(1.0)) / 0.5 * 0.4, 1.0],
                               atol=1e-8)
    log = load_csv(path, ["left.spin", "right.spin"], header_format(path, "diff-drive", ["left.spin", "right.spin"]),
                   robot=diff)
    np.testing.assert_allclose(log.positions[-1], spins * 2.0, rtol=1e-9)
    path.write_text(f"time,left.spin [{unit}],right.spin [rad{'/s' if rate else ''}]\n0,0,0\n")
    assert main(["odometry", "diff-drive", str(path)]) == 2
    assert "the spin columns mix units" in capsys.readouterr().err


def test_a_header_with_quoted_column_names_reads_as_without_quotes(capsys, tmp_path):
    """A spreadsheet's export quotes its header ('"time [s]","left.spin [deg]"'): it was refused with 'missing
    column 'time' (columns: '"time [s]", ...')', the quotes read as part of the names. The header line is read as
    CSV (quotes removed, a quoted delimiter kept in its name), in the CLI and load_csv, with its units."""
    from wmrkit.odometry.header import header_format
    from wmrkit.odometry.logs import load_csv

    rows = "0,0,0,5\n0.5,57.3,114.6,5\n1,114.6,229.2,5\n"
    plain, quoted = tmp_path / "plain.csv", tmp_path / "quoted.csv"
    plain.write_text("time [s],left.spin [deg],right.spin [deg],volts\n" + rows)
    quoted.write_text('"time [s]", "left.spin [deg]","right.spin [deg]","battery, volts"\n' + rows)
    want = _json(capsys, ["odometry", "diff-drive", str(plain), "--json"])
    assert _json(capsys, ["odometry", "diff-drive", str(quoted), "--json"])["final_pose"] == want["final_pose"]
    joints = ["left.spin", "right.spin"]
    log = load_csv(quoted, joints, header_format(quoted, "diff-drive", joints), robot=catalog.load("diff-drive"))
    np.testing.assert_allclose(log.positions[-1], np.radians([114.6, 229.2]), rtol=1e-12)


GEARED = """name: geared
wheels:
  - {name: left, type: fixed, position: [0, 0.2], heading: 0, r: 0.1, actuated: [spin], sensed: [spin]}
  - {name: right, type: fixed, position: [0, -0.2], heading: 0, r: 0.1, sensed: [spin]}
couplings:
  - {kind: gear, joints: [left.spin, right.spin], ratios: [1, RATIO]}
"""


@pytest.mark.parametrize(("ratio", "right", "agrees"), [
    (1, 2.0, False),  # the gear turns both spins together; the log turns the right one twice as fast
    (2, 2.0, True),  # the gear's ratio 2: as logged
    (-1, -1.0, True),  # a gear reversing the right wheel (the robot turns on the spot)
    (-1, 1.0, False),  # ... logged turning the same way
    (1, 1.03, True),  # 3 % apart: backlash, encoder noise
])
def test_a_log_that_breaks_a_gear_coupling_warns_and_says_inconsistent(capsys, tmp_path, ratio, right, agrees):
    """A description's gear says its joints turn together (q_j = ratio_j * u); a log whose geared spins did not
    (right = 2 x left on a 1:1 gear: another robot's log, or a wrong description) was integrated as a turn, exit 0,
    "consistent": true, slip indicator 0 (two sensed spins determine a differential drive's twist: nothing else
    compared them). Now a warning names the coupling and how far apart its joints turn, and "consistent" is false."""
    robot = tmp_path / "geared.yaml"
    robot.write_text(GEARED.replace("RATIO", str(ratio)))
    log = tmp_path / "g.csv"
    log.write_text("time,left.spin,right.spin\n" + "".join(f"{t},{t},{t * right}\n" for t in range(5)))
    assert main(["odometry", str(robot), str(log), "--json"]) == 0
    out = capsys.readouterr()
    assert json.loads(out.out)["consistent"] is agrees
    if agrees:
        assert out.err == ""
    else:
        assert out.err.count("\n") == 1 and out.err.startswith(
            f"wmrkit: warning: the joints of the gear of wheels 'left' and 'right' (ratios 1, {ratio:g}) do not turn "
            "together")


@pytest.mark.parametrize("name", ["traj.json", "t.TUM.bak", "odom.bag2"])
def test_an_out_with_an_unknown_suffix_is_refused_not_written_as_a_bag(diff_csv, tmp_path, capsys, name):
    """'--out traj.json' wrote a ROS 2 bag, a folder named traj.json, exit 0. Now refused naming --out and the file;
    --format bag (or a name without a suffix) writes the bag."""
    out = tmp_path / name
    assert main(["odometry", "diff-drive", diff_csv, "--out", str(out), "--json"]) == 2
    error = json.loads(capsys.readouterr().err)
    assert (error["field"], error["file"]) == ("--out", str(out)) and not out.exists()
    assert "no trajectory format has the suffix" in error["error"]
    assert main(["odometry", "diff-drive", diff_csv, "--out", str(out), "--format", "bag"]) == 0
    assert (out / "metadata.yaml").exists()
