"""``wmrkit tyre`` and ``wmrkit simulate``: JSON output, files, plots; user mistakes are one line and exit 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.dynamics.tyres import Tyre


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_tyre_json_is_the_library_value(capsys, tmp_path):
    plot = tmp_path / "tyre.png"
    code, out, err = run(capsys, "tyre", "pacejka", "--load", "8175", "--slip-ratio", "0.1", "--slip-angle",
                         "2.8648 deg", "--param", "shifts=0", "--plot", str(plot), "--json")
    assert code == 0 and err == f"wmrkit: plot written to {plot}\n"
    data = json.loads(out)
    f = Tyre.of("pacejka", {"shifts": 0}).forces_at_slip(8175, 0.1, np.radians(2.8648), 2.0)
    assert data["Fx"] == pytest.approx(float(f.longitudinal)) and data["Fy"] == pytest.approx(float(f.lateral))
    assert data["Fx"] < 0 and data["Fy"] < 0  # the force opposes the slip
    assert plot.stat().st_size > 1000


def test_tyre_friction_coefficients_are_the_forces_over_the_load(capsys):
    code, out, _ = run(capsys, "tyre", "dugoff", "--load", "8000", "--slip-ratio", "0.1", "--json")
    data = json.loads(out)
    assert code == 0 and data["mu_long"] == pytest.approx(-data["Fx"] / 8000) and data["mu_lat"] == 0.0
    assert str(data["mu_lat"]) == "0.0"  # not -0.0
    code, out, _ = run(capsys, "tyre", "linear", "--load", "0", "--slip-ratio", "0.1", "--json")
    data = json.loads(out)
    assert code == 0 and data["Fx"] < 0 and data["mu_long"] is None and data["mu_lat"] is None  # not defined


@pytest.mark.parametrize(("args", "message"), [
    (["--load", "1e300", "--slip-ratio", "0.1"], "--load: at most 1e+07 N"),  # printed Fx = -6.8e299 N, exit 0
    (["--load", "3000", "--speed", "1e300"], "--speed: must be in (0, 1000] m/s, got 1e+300"),
    (["--load", "3000", "--slip-angle", "90deg"], "--slip-angle: must be in (-pi/2, pi/2) rad"),
    (["--load", "3000", "--slip-angle", "-100deg"], "--slip-angle: must be in (-pi/2, pi/2) rad (-90 to 90 deg), got "
                                                    "-1.74533 rad (-100 deg)"),  # "got -1.74533" of -100deg
    (["--load", "3000", "--slip-ratio", "2.5"], "--slip-ratio: must be in (-1, 2], got 2.5")])
def test_tyre_refusals_name_the_option(capsys, args, message):
    """One line naming the option (it was one line naming the three slip inputs together)."""
    code, out, err = run(capsys, "tyre", "pacejka", *args)
    assert code == 2 and out == "" and err.strip().startswith(f"wmrkit: error: {message}")


@pytest.mark.parametrize(("model", "speed", "warned"), [("pacejka", "18", False), ("pacejka", "30", True),
                                                      ("dugoff", "30", False)])
def test_pacejka_beyond_its_fitted_speeds_is_evaluated_with_a_warning(capsys, model, speed, warned):
    """Appendix 7.A1 fits the coefficients to wheel speeds of 1-18 m/s (its peak reaches 0 at 381 m/s, and speeds
    to 1e3 m/s are accepted): beyond 18 m/s the forces come with a warning, on stderr and in the JSON."""
    code, out, err = run(capsys, "tyre", model, "--load", "3000", "--slip-ratio", "0.1", "--speed", speed, "--json")
    assert code == 0 and bool(json.loads(out)["warnings"]) == warned
    assert (err == "") != warned and ("fits its coefficients to wheel speeds up to 18 m/s" in err) == warned


@pytest.mark.parametrize(("tyre", "warned"), [("pacejka", True), ("dugoff", False)])
def test_simulate_warns_when_pacejka_tyres_run_beyond_their_fitted_speeds(capsys, tmp_path, tyre, warned):
    torques = tmp_path / "zero.csv"
    torques.write_text("time,front_left.spin,front_right.spin,rear_left.spin,rear_right.spin\n0,0,0,0,0\n"
                       "0.1,0,0,0,0\n")
    code, out, err = run(capsys, "simulate", "skid-steer-4", "--torques", str(torques), "--initial-twist", "20", "0",
                         "0", "--duration", "0.02", "--tyre", tyre, "--json")
    assert code == 0 and bool(json.loads(out)["warnings"]) == warned and ("pacejka tyre at 2" in err) == warned
    code, out, err = run(capsys, "simulate", "skid-steer-4", "--torques", str(torques), "--initial-twist", "5", "0",
                         "0", "--duration", "0.02", "--tyre", "pacejka", "--json")
    assert code == 0 and json.loads(out)["warnings"] == [] and err == ""


def test_tyre_text(capsys):
    code, out, _ = run(capsys, "tyre", "dugoff", "--load", "8000", "--slip-ratio", "0.01", "--param", "cs=80000")
    assert code == 0 and "Fx (longitudinal) = -808.081 N" in out and "Fy (lateral)      = 0 N" in out


@pytest.mark.parametrize("argv", [
    ("tyre", "dugoff", "--load", "-1"),
    ("tyre", "dugoff", "--load", "100", "--slip-ratio", "-1"),
    ("tyre", "dugoff", "--load", "100", "--slip-angle", "30"),
    ("tyre", "dugoff", "--load", "100", "--param", "cz=1"),
    ("tyre", "dugoff", "--load", "100", "--param", "mu"),
    ("tyre", "magic", "--load", "100"),
    ("tyre", "linear", "--load", "1e-320", "--slip-ratio", "0.1"),  # mu = Fx / Fz overflowed: null, exit 0
    ("simulate", "diff-drive", "--path", "turn"),
    ("simulate", "forklift", "--path", "turn", "--step", "0"),
    ("simulate", "forklift", "--path", "turn", "--duration", "1e9"),
    ("simulate", "forklift", "--torques", "/nonexistent.csv"),
    ("simulate", "forklift", "--path", "loop"),
])
def test_user_mistakes_are_one_line_and_exit_2(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.strip().splitlines()[-1].startswith("wmrkit: error:")
    assert "Traceback" not in err


def test_simulate_path_json_out_and_plot(capsys, tmp_path):
    out_file, plot = tmp_path / "run.csv", tmp_path / "run.png"
    code, out, err = run(capsys, "simulate", "forklift", "--path", "turn", "--out", str(out_file), "--plot",
                         str(plot), "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["final_twist"][2] == pytest.approx(2 / 3, abs=0.05) and data["samples"] == 301
    table = np.loadtxt(out_file, delimiter=",", skiprows=1)
    assert table.shape[0] == 301 and np.allclose(table[-1, 1:4], data["final_pose"])
    assert plot.stat().st_size > 1000


def test_simulate_reports_the_largest_slip_speed(capsys):
    """'largest slip speed' (JSON max_slip_speed) was the largest slip component, below the speed where a tyre slips
    both sideways and along its rolling line (a skid steer's turn: 0.048 m/s printed for 0.059 m/s)."""
    from wmrkit.dynamics.model import DynamicModel
    from wmrkit.dynamics.programs import path_program
    from wmrkit.dynamics.simulate import simulate

    code, out, err = run(capsys, "simulate", "skid-steer-4", "--path", "turn", "--speed", "1", "--json")
    assert code == 0, err
    model = DynamicModel.of(catalog.load("skid-steer-4"))
    sim = simulate(model, *path_program(model, "turn", speed=1.0), step=1e-3, record_step=0.01)
    speed = np.hypot(sim.slip[..., 0], sim.slip[..., 1]).max()
    assert speed > 1.2 * np.abs(sim.slip).max()  # both components matter here
    assert json.loads(out)["max_slip_speed"] == pytest.approx(speed, rel=1e-12)


def test_simulate_reports_the_path_length_under_its_one_name(capsys):
    """The length of the path driven is 'path_length', as in odometry, park and batch odometry ('distance' before):
    on a straight drive it is the distance from the start."""
    code, out, err = run(capsys, "simulate", "skid-steer-4", "--path", "straight", "--duration", "0.5", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert "distance" not in data and data["path_length"] > 0.1
    assert data["path_length"] == pytest.approx(math.hypot(*data["final_pose"][:2]), rel=1e-9)


def test_simulate_out_writes_steering_as_headings(capsys, tmp_path):
    """It wrote the thesis's beta (pi/2 for a forklift rolling straight ahead) as 'steer.steer.position'."""
    torques = tmp_path / "tau.csv"
    torques.write_text("time,left_drive.spin,right_drive.spin\n0,100,100\n2,100,100\n")
    csv_out, json_out = tmp_path / "run.csv", tmp_path / "run.json"
    for out in (csv_out, json_out):
        assert run(capsys, "simulate", "forklift", "--torques", str(torques), "--out", str(out))[0] == 0
    header = csv_out.read_text().splitlines()[0].split(",")
    table = np.loadtxt(csv_out, delimiter=",", skiprows=1)
    assert "steer.steer [rad]" in header  # the heading, as a joint log's steering column
    assert "right_drive.spin [rad]" in header and "steer.steer.rate [rad/s]" in header
    assert np.abs(table[:, header.index("steer.steer [rad]")]).max() < 1e-3  # straight ahead (beta: pi/2)
    data = json.loads(json_out.read_text())
    heading = np.array(data["joint_positions"])[:, data["positions"].index("steer.heading")]
    np.testing.assert_allclose(heading, table[:, header.index("steer.steer [rad]")], atol=1e-8)


@pytest.mark.parametrize(("robot", "path"), [("skid-steer-4", "turn"), ("forklift", "turn")])
def test_simulate_out_is_a_joint_log_that_odometry_reads(capsys, tmp_path, robot, path):
    """simulate --out wrote 'front_left.spin.position' and 'steer.heading' without units: 'wmrkit odometry' on it
    said "missing column 'front_left.spin' (did you mean 'front_left.spin.rate'?)", and following the hint read the
    rates as angles (x = 2.0 m for a run that ended at 16.6 m). The CSV is now a joint log with units in its
    header: odometry reads it as written, and on the slip-free forklift turn ends near the simulated pose."""
    out, traj = tmp_path / "run.csv", tmp_path / "odo.tum"
    assert run(capsys, "simulate", robot, "--path", path, "--out", str(out))[0] == 0
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    code, _, err = run(capsys, "odometry", robot, str(out), "--out", str(traj))
    assert code == 0, err
    end = np.loadtxt(traj)[-1]
    assert end[0] == pytest.approx(table[-1, 0])
    if robot == "forklift":  # little slip: the wheels' odometry is close to the simulated pose
        assert np.hypot(end[1] - table[-1, 1], end[2] - table[-1, 2]) < 0.05 * np.hypot(table[-1, 1], table[-1, 2])


@pytest.mark.parametrize("text, place, message", [
    # a heading of 90 (degrees meant) was read as 90 rad and steered to 2.035 rad (exit 0)
    ("time,right_drive.spin,left_drive.spin,steer.heading\n0,300,300,0.5\n3,300,300,90\n", "3: column "
     "'steer.heading'", "a heading is read in radians, and 90 rad is more than a turn; degrees? 90 deg = 1.5708 rad"),
    # 'right_drive.heading' (a fixed wheel) was refused as "tuple.index(x): x not in tuple"
    ("time,right_drive.spin,right_drive.heading\n0,300,0.1\n1,300,0.1\n", "1: column 'right_drive.heading'",
     "robot 'forklift' has no steered wheel 'right_drive' (a heading column is a steering reference; steered "
     "wheels: steer)"),
], ids=["heading beyond a turn", "heading of a fixed wheel"])
def test_a_bad_heading_column_is_refused_at_its_place(capsys, tmp_path, text, place, message):
    path = tmp_path / "tau.csv"
    path.write_text(text)
    code, out, err = run(capsys, "simulate", "forklift", "--torques", str(path))
    assert code == 2 and out == ""
    assert err.strip() == f"wmrkit: error: {path}:{place}: {message}"


def test_simulate_refuses_speed_without_a_path_program(capsys, tmp_path):
    """--speed sets a --path program's speed; with --torques it was ignored (exit 0), though docs/limits.md said no."""
    path = tmp_path / "tau.csv"
    path.write_text("time,left_drive.spin,right_drive.spin\n0,100,100\n1,100,100\n")
    code, out, err = run(capsys, "simulate", "forklift", "--torques", str(path), "--speed", "3", "--json")
    assert code == 2 and out == ""
    message = "--speed applies to --path (the speed of a built-in program; it would be ignored)"
    assert json.loads(err)["error"] == message


@pytest.mark.parametrize("name", ["run.png", "run.yaml", "run"])
def test_simulate_out_is_csv_or_json(capsys, tmp_path, name):
    """An --out neither .csv nor .json got CSV text under its name (a 'run.png' that no viewer opens), exit 0."""
    out_file = tmp_path / name
    code, out, err = run(capsys, "simulate", "forklift", "--path", "straight", "--out", str(out_file))
    assert code == 2 and out == "" and not out_file.exists()
    assert err.strip() == f"wmrkit: error: --out {out_file}: the samples are written as .csv or .json"


@pytest.mark.parametrize("extra, place, end", [
    (["--duration", "1", "--step", "0.6"], "--duration 1 s is", "1.2"),
    # was '...: the file ends at t = 1 s is not a whole number': no sentence
    (["--step", "0.3"], "{torques}: the file ends at t = 1 s, which is", "0.9"),
])
def test_simulate_refuses_a_duration_that_is_not_whole_steps(capsys, tmp_path, extra, place, end):
    """A fixed-step run takes round(duration / step) steps: '--duration 1 --step 0.6' ran 1.2 s, printing
    '1 s simulated' above a final pose at t = 1.2 s (exit 0)."""
    torques = tmp_path / "tau.csv"
    torques.write_text("time,left_drive.spin,right_drive.spin\n0,100,100\n1,100,100\n")
    code, out, err = run(capsys, "simulate", "forklift", "--torques", str(torques), "--tyre", "linear", *extra)
    assert code == 2 and out == ""
    assert err.strip() == (f"wmrkit: error: {place.format(torques=torques)} not a whole number of --step "
                           f"{extra[-1]} s steps: the run would end at t = {end} s; give a step that divides it")


def test_simulate_out_forces_are_in_the_contact_frame(capsys, tmp_path):
    """docs/dynamics.md: f_long is positive backwards (frame Ē): on a straight run the momentum's change is the
    impulse of -sum(f_long)."""
    torques, out_file = tmp_path / "tau.csv", tmp_path / "run.csv"
    torques.write_text("time,left_drive.spin,right_drive.spin\n0,100,100\n1,100,100\n")
    code, _, err = run(capsys, "simulate", "forklift", "--torques", str(torques), "--tyre", "dugoff", "--method",
                       "adaptive", "--out", str(out_file))
    assert code == 0, err
    header = out_file.read_text().splitlines()[0].split(",")
    table = np.loadtxt(out_file, delimiter=",", skiprows=1)
    column = {name.partition(" [")[0]: table[:, k] for k, name in enumerate(header)}
    wheels = ("right_drive", "left_drive", "steer")
    f_long = sum(column[f"{w}.f_long"] for w in wheels)
    assert np.all(column["right_drive.f_long"][1:] < 0) and np.all(column["vx"][1:] > 0)  # driving forward
    impulse = np.concatenate([[0], np.cumsum(np.diff(column["time"]) * (f_long[1:] + f_long[:-1]) / 2)])
    # from 0.1 s: the first samples, 10 ms apart, miss the forces rising within the first step
    np.testing.assert_allclose(2500 * (column["vx"] - column["vx"][10])[20:], -(impulse - impulse[10])[20:], rtol=1e-3)


def test_simulate_torque_file(capsys, tmp_path):
    path = tmp_path / "tau.csv"
    path.write_text("time,left_drive.spin,right_drive.spin\n0,100,100\n1,100,100\n")
    code, out, err = run(capsys, "simulate", "forklift", "--torques", str(path), "--tyre", "dugoff", "--json")
    assert code == 0, err
    assert json.loads(out)["final_twist"][0] > 0.05  # positive spin torque drives the truck forward


def test_json_errors_about_a_file_give_its_place(capsys, tmp_path):
    """Errors from torque files, references and logs named their file only in the message: the JSON's file, line
    and field were null (a description's were filled in)."""
    from wmrkit.cli.main import main

    torques = tmp_path / "tau.csv"
    torques.write_text("time,right_drive.spin,left_drive.spin,steer.heading\n0,300,300,0.5\n3,300,300,90\n")
    assert main(["simulate", "forklift", "--torques", str(torques), "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(torques), 3, "steer.heading")
    assert data["error"].startswith("a heading is read in radians")
    missing = str(tmp_path / "none.csv")
    assert main(["odometry", "forklift", missing, "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    # field: the argument that gave the file
    assert (data["file"], data["line"], data["field"], data["error"]) == (missing, None, "LOG", "no such file")
    assert main(["ik", "swerve-4", "--twist", "1", "0", "--json"]) == 2  # not about a file: no place
    assert json.loads(capsys.readouterr().err)["file"] is None


def test_a_torque_file_with_a_byte_order_mark_is_read(capsys, tmp_path):
    """A spreadsheet's UTF-8 export starts with a byte-order mark: the file was refused as having no 'time' header
    (joint logs already read it)."""
    path = tmp_path / "tau.csv"
    path.write_bytes(b"\xef\xbb\xbftime,left_drive.spin,right_drive.spin\n0,100,100\n1,100,100\n")
    code, out, err = run(capsys, "simulate", "forklift", "--torques", str(path), "--json")
    assert code == 0, err
    assert json.loads(out)["final_twist"][0] > 0.05


def test_simulate_refuses_to_write_over_its_torque_file_or_description(capsys, tmp_path):
    torques = tmp_path / "torques.csv"
    text = "time,right_drive.spin,left_drive.spin\n0,100,100\n0.1,100,100\n"
    torques.write_text(text)
    code, out, err = run(capsys, "simulate", "forklift", "--torques", str(torques), "--out", str(torques))
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "is also --torques" in err
    assert torques.read_text() == text  # the run wrote its samples over it before
    description = tmp_path / "forklift.yaml"
    catalog.load("forklift").to_file(description)
    text = description.read_text()
    code, out, err = run(capsys, "simulate", str(description), "--path", "straight", "--out", str(description))
    assert code == 2 and out == "" and "is also ROBOT" in err and description.read_text() == text


def test_simulate_refuses_an_initial_twist_that_does_not_roll(capsys, tmp_path):
    """The start rolls without slip: (1, 0, 0.1) for the forklift (origin at the fork tips, axle 1 m behind) left its
    drive wheels slipping sideways at 0.1 m/s from t = 0, silently."""
    torques = tmp_path / "zero.csv"
    torques.write_text("time,right_drive.spin\n0,0\n")
    argv = ["simulate", "forklift", "--torques", str(torques), "--duration", "0.05", "--json", "--initial-twist"]
    code, out, err = run(capsys, *argv, "1", "0", "0.1")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "'left_drive' would slip sideways at 0.1 m/s" in err and "VY = 0.1 m/s" in err
    code, out, err = run(capsys, *argv, "1", "0.1", "0.1")  # the rolling one
    assert code == 0 and json.loads(out)["max_slip_speed"] < 0.01


@pytest.mark.parametrize("extra", [[], ["--feedback", "wls"]])
def test_track_through_the_dynamics_refuses_a_period_of_a_fraction_of_a_step(capsys, extra):
    """The loop advances the dynamics by whole 1 ms steps: a period of 1.5 ms ran 2 ms of dynamics per period of the
    law, so the robot ran ahead of its reference (0.1 m rms along the figure eight in 2 s), silently."""
    code, out, err = run(capsys, "track", "forklift", "--reference", "figure-eight", "--dynamics", "--duration", "2",
                         "--period", "0.0015", *extra)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "whole number of dynamics steps of 0.001 s, got 0.0015" in err


def test_simulate_says_when_its_final_pose_is(capsys):
    """Samples are recorded every 0.01 s: a run of 1.015 s printed the pose at 1.01 s as its final pose, unsaid."""
    argv = ["simulate", "forklift", "--path", "straight", "--duration", "1.015"]
    code, out, _ = run(capsys, *argv, "--json")
    data = json.loads(out)
    assert code == 0 and data["final_time"] == pytest.approx(1.01) and data["duration"] == 1.015
    code, out, _ = run(capsys, *argv)
    assert code == 0 and "final pose (t = 1.01 s): x = " in out


@pytest.mark.parametrize("method", ["semi-implicit", "adaptive"])
def test_a_run_shorter_than_the_record_step_still_records_its_end(capsys, method):
    """The command records every 0.01 s: a run of 4 ms printed '0.004 s simulated', 1 sample, and the start (t = 0,
    the robot at rest) as its final pose and twist. The record step is now at most the duration."""
    argv = ["simulate", "forklift", "--path", "straight", "--duration", "0.004", "--method", method, "--json"]
    code, out, _ = run(capsys, *argv)
    data = json.loads(out)
    assert code == 0 and data["samples"] == 2 and data["final_time"] == pytest.approx(0.004)
    assert data["final_twist"][0] > 0  # the ramp has started


def test_tyre_takes_the_discontinuous_coulomb_law(capsys):
    """docs/dynamics.md: coulomb's `k = inf` is the discontinuous law, and --param follows the descriptions' rules;
    --param k=inf was refused ("cannot read 'inf' as a number")."""
    code, out, err = run(capsys, "tyre", "coulomb", "--load", "3000", "--slip-ratio", "0.1", "--param", "k=inf",
                         "--json")
    assert code == 0, err
    assert json.loads(out)["Fx"] == pytest.approx(-0.8 * 3000)  # mu_long Fz, whatever the slip
    code, _, err = run(capsys, "tyre", "dugoff", "--load", "3000", "--param", "mu=inf")
    assert code == 2 and "--param mu" in err  # only coulomb's k may be infinite


@pytest.mark.parametrize("argv", [
    ("tyre", "pacejka", "--load", "3000", "--slip-ratio", "0.1", "--slip-angle", "0.05"),
    ("simulate", "skid-steer-4", "--path", "turn", "--duration", "0.5"),
])
def test_plots_label_every_axis_and_close_on_a_failed_write(capsys, monkeypatch, tmp_path, argv):
    """The right-hand panels (forces against slip angle, the twist against time) had no y label, their units in
    the legend only; a write that failed left the figure open in the process."""
    import matplotlib.pyplot as plt

    from wmrkit.cli import dynamics as cli_dynamics
    from wmrkit.errors import WmrkitError

    seen = []

    def failing(fig, out):
        seen.append([(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes])
        raise WmrkitError(f"--plot {out}: cannot write (disk full)")

    monkeypatch.setattr(cli_dynamics, "_savefig", failing)
    before = set(plt.get_fignums())
    code, _, err = run(capsys, *argv, "--plot", str(tmp_path / "p.png"))
    assert code == 2 and "disk full" in err
    assert seen and all(x and "[" in y for x, y in seen[0]), seen
    assert set(plt.get_fignums()) == before


def test_an_adaptive_run_states_its_tolerance_not_a_step(capsys):
    """LSODA chooses its own steps: 'wmrkit simulate --method adaptive' printed '(adaptive, step 0.001 s)' and JSON
    "step": 0.001, the default fixed step it never took. It states the tolerance it ran at and the record step."""
    argv = ["simulate", "forklift", "--path", "straight", "--duration", "0.05", "--method", "adaptive"]
    code, out, _ = run(capsys, *argv)
    assert code == 0 and "(adaptive, LSODA, rtol 1e-06, recorded every 0.01 s), 6 samples" in out
    assert "step 0.001" not in out
    code, out, _ = run(capsys, *argv, "--json")
    data = json.loads(out)
    assert code == 0 and data["step"] is None and data["rtol"] == 1e-6
    code, out, _ = run(capsys, *argv[:-2], "--json")  # a fixed step keeps saying it
    data = json.loads(out)
    assert code == 0 and data["step"] == 1e-3 and data["rtol"] is None


def test_step_with_the_adaptive_method_is_refused(capsys):
    """LSODA chooses its own steps: '--method adaptive --step 0.001' ran recording every 0.01 s, and '--step 0.05'
    recorded every 0.05 s, both exit 0, where the help calls --step the integration step."""
    for step in ("0.001", "0.05"):
        code, out, err = run(capsys, "simulate", "forklift", "--path", "straight", "--method", "adaptive", "--step",
                             step)
        assert code == 2 and out == "" and err.count("\n") == 1
        assert err.startswith(f"wmrkit: error: --step {step}: the adaptive method chooses its own steps")


def test_tyre_says_where_a_force_at_zero_slip_comes_from(capsys):
    """`wmrkit tyre pacejka --load 8175` printed Fx = -314 N at zero slip under '(force of the ground on the tyre,
    opposing the slip)': there is no slip; the force is the magic formula's shifts (shifts = 0 removes it)."""
    code, out, _ = run(capsys, "tyre", "pacejka", "--load", "8175")
    assert code == 0 and "Fx (longitudinal) = 0 N" not in out and "shifts add a force at any slip" in out
    code, out, _ = run(capsys, "tyre", "pacejka", "--load", "8175", "--param", "shifts=0")
    assert code == 0 and "Fx (longitudinal) = 0 N" in out and "Fy (lateral)      = 0 N" in out
    assert "shifts" not in out
