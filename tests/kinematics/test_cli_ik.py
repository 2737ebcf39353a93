"""``wmrkit ik`` and ``wmrkit fk``: JSON shape, human tables, warnings on stderr, user mistakes exit 2."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_ik_json_has_the_documented_shape(capsys):
    code, out, err = run(capsys, "ik", "swerve-4", "--twist", "1", "0.5", "0.2", "--json")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert set(data) == {"robot", "wheels", "slip", "out_of_range", "out_of_gear", "out_of_steer_gear",
                         "out_of_linkage", "feasible", "warnings"}
    assert data["robot"] == "swerve-4"
    assert data["feasible"] is True and data["warnings"] == []
    assert data["out_of_range"] == []
    robot = catalog.load("swerve-4")
    assert list(data["wheels"]) == list(robot.wheel_names)
    for name, (x, y) in zip(robot.wheel_names, (w.position for w in robot.wheels), strict=True):
        entry = data["wheels"][name]
        assert set(entry) == {"heading", "spin", "steer_rate"} and entry["steer_rate"] is None
        ux, uy = 1 - 0.2 * y, 0.5 + 0.2 * x  # steering axis velocity; its direction is the heading (WPILib's angle)
        assert entry["heading"] == pytest.approx(math.atan2(uy, ux), abs=1e-12)
        assert entry["spin"] == pytest.approx(math.hypot(ux, uy) / 0.0508, rel=1e-12)


def test_ik_json_of_other_wheel_types_adds_their_joints(capsys):
    code, out, _ = run(capsys, "ik", "mecanum-4", "--twist", "0.3", "0.2", "0.1", "--json")
    data = json.loads(out)
    assert code == 0 and all(set(e) == {"spin", "steer_rate", "roller"} for e in data["wheels"].values())


def test_ik_warns_about_an_infeasible_twist(capsys):
    code, out, err = run(capsys, "ik", "diff-drive", "--twist", "1", "0.2", "0.5")
    assert code == 1  # an answer that is no (docs/limits.md, Exit codes)
    assert err.startswith("wmrkit: warning: twist not feasible for robot 'diff-drive'") and err.count("\n") == 1
    assert "feasible: NO" in out and "left" in out and "caster" in out
    code, out, err = run(capsys, "ik", "diff-drive", "--twist", "1", "0", "0.5", "--json")
    assert err == "" and json.loads(out)["feasible"] is True


def test_ik_steer_accepts_degrees_and_radians(capsys):
    _, deg, _ = run(capsys, "ik", "forklift", "--twist", "-1", "0", "0", "--steer", "steer=170deg", "--json")
    _, rad, _ = run(capsys, "ik", "forklift", "--twist", "-1", "0", "0", "--steer", f"steer={math.radians(170)}",
                    "--json")
    assert json.loads(deg) == json.loads(rad)
    entry = json.loads(deg)["wheels"]["steer"]  # reversing with the wheel turned round: it rolls forward, backwards
    assert abs(entry["heading"]) == pytest.approx(math.pi) and entry["spin"] == pytest.approx(1 / 0.23)


def test_ik_heading_in_the_text_table(capsys):
    """The issue's case: a swerve module whose heading is 32.957 deg is printed as 32.957, not 122.957."""
    code, out, _ = run(capsys, "ik", "swerve-4", "--twist", "1", "0.5", "0.3")
    x, y = catalog.load("swerve-4").wheels[0].position
    want = math.degrees(math.atan2(0.5 + 0.3 * x, 1 - 0.3 * y))
    row = next(line for line in out.splitlines() if line.startswith("front_left"))
    assert code == 0 and "heading [deg]" in out and float(row.split()[2]) == pytest.approx(want, abs=1e-4)


def test_fk_json_and_text(capsys):
    code, out, err = run(capsys, "fk", "diff-drive", "--spin", "left=10", "--spin", "right.spin=12", "--json")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert set(data) == {"robot", "twist", "determined", "residual", "consistent", "slipping", "warnings"}
    assert data["robot"] == "diff-drive"
    assert data["consistent"] is True and data["warnings"] == []
    assert data["determined"] is True
    r, half_track = 0.075, 0.20
    np.testing.assert_allclose(data["twist"], [r * 11, 0.0, r * 2 / (2 * half_track)], atol=1e-12)
    assert data["residual"] < 1e-12
    code, out, err = run(capsys, "fk", "swerve-4", "--spin", "front_left=3", "--steer", "front_left=100deg")
    assert code == 0 and "twist (robot frame)" in out and "residual" in out  # 8 rows, 6 unknowns
    assert "contradict" in err  # one module turned to 100 deg, the others straight: no common ICR, they slip
    code, out, err = run(capsys, "fk", "diff-drive", "--spin", "left=3")
    assert code == 0 and "do not determine the twist" in err and err.count("\n") == 1
    # under --json the output says so too (it had only the text warning: a program read a minimum-norm twist)
    code, out, err = run(capsys, "fk", "diff-drive", "--spin", "left=3", "--json")
    assert code == 0 and json.loads(out)["determined"] is False and "do not determine the twist" in err


def test_ik_text_names_each_reason_once(capsys):
    """Both front wheels of the car out of their steer_range: 'NO (a wheel cannot steer there; a wheel cannot steer
    there)' repeated the reason per wheel (the warnings on stderr name the wheels)."""
    code, out, err = run(capsys, "ik", "ackermann", "--twist", "1", "0", "1")
    assert code == 1 and out.splitlines()[-1] == "feasible: NO (a wheel cannot steer there)"
    assert "wheel 'front_left'" in err and "wheel 'front_right'" in err


@pytest.mark.parametrize(("argv", "message"), [
    (["ik", "diff-drive", "--twist", "1", "0", "0", "--steer", "left=1"], "wheel 'left' of robot 'diff-drive' does"),
    (["ik", "swerve-4", "--twist", "1", "0", "0", "--steer", "front_left=fast"], "--steer front_left: cannot read"),
    (["ik", "swerve-4", "--twist", "1", "0", "0", "--steer", "front_left"], "--steer: expected NAME=VALUE"),
    (["ik", "no-such-robot", "--twist", "1", "0", "0"], "no robot 'no-such-robot'"),
    (["fk", "diff-drive", "--spin", "lft=1"], "no joint rate 'lft' (valid: left, right"),
    (["fk", "diff-drive", "--spin", "left=nan"], "--spin left: cannot read 'nan'"),
    (["fk", "diff-drive"], "--spin: give at least one joint rate of robot 'diff-drive' as NAME=RATE, e.g. --spin "
                           "left=10 (names: left.spin, right.spin, caster.steer, caster.spin)"),
])
def test_user_mistakes_exit_2_with_one_line(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.startswith("wmrkit: error: ") and message in err and err.count("\n") == 1


def test_bad_twist_is_one_line_naming_its_component(capsys):
    assert main(["ik", "swerve-4", "--twist", "1", "0", "inf"]) == 2
    err = capsys.readouterr().err
    assert err == "wmrkit: error: ik: --twist OMEGA: cannot read 'inf' as an angular rate (write e.g. '0.5' or " \
                  "'30 deg/s' or '60 rpm')\n"
    assert main(["ik", "swerve-4", "--twist", "1", "0", "inf", "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert "--twist OMEGA" in data["error"] and data["file"] is None
    assert set(data) == {"error", "file", "wheel", "field", "line"}  # every error has the five keys ("line" lacked)


def test_fk_textbook_ackermann_angles_are_consistent(capsys):
    """The issue's car: rear spins and the textbook Ackermann steering angles, as headings, agree (small residual)."""
    argv = ["fk", "ackermann", "--spin", "rear_left=14.4", "--spin", "rear_right=15.9",
            "--steer", "front_left=9.66deg", "--steer", "front_right=8.79deg", "--json"]
    code, out, err = run(capsys, *argv)
    data = json.loads(out)
    assert code == 0 and err == "" and data["consistent"] is True and data["residual"] < 0.05
    r, wheelbase, half_track = 0.33, 2.70, 0.775
    assert data["twist"][0] == pytest.approx(r * (14.4 + 15.9) / 2, rel=2e-3)  # the rear axle's mean speed
    turn_radius = np.mean([wheelbase / math.tan(math.radians(9.66)) + half_track,  # the ICR of the steering
                           wheelbase / math.tan(math.radians(8.79)) - half_track])
    assert data["twist"][2] == pytest.approx(data["twist"][0] / turn_radius, rel=2e-2)


def test_fk_contradicting_rates_warn_and_say_so_in_json(capsys):
    """The same rates with the steering given in the thesis's axle angles (heading + 90 deg) contradict."""
    argv = ["fk", "ackermann", "--spin", "rear_left=14.4", "--spin", "rear_right=15.9",
            "--steer", "front_left=99.66deg", "--steer", "front_right=98.79deg"]
    code, out, err = run(capsys, *argv, "--json")
    data = json.loads(out)
    assert code == 0 and data["consistent"] is False and set(data["slipping"]) >= {"front_left", "front_right"}
    lines = err.splitlines()  # the headings also break the linkage (at 99.66 deg it sets front_right at 68.0 deg)
    assert len(lines) == 2 and lines[0].startswith("wmrkit: warning: the headings break a steering linkage")
    assert lines[1].startswith("wmrkit: warning: the rates contradict each other")
    code, out, err = run(capsys, *argv)
    assert "INCONSISTENT" in out and "front_left" in err


@pytest.mark.parametrize("argv", [
    ["ik", "swerve-4", "--twist", "1e308", "1e308", "1e308"],
    ["ik", "mecanum-4", "--twist", "2e6", "0", "0"],
    ["fk", "forklift", "--spin", "right_drive=1e308", "--spin", "left_drive=-1e308"],
])
def test_rates_beyond_any_robot_are_refused_not_printed_as_inf(capsys, argv):
    """Issue 9: finite input whose result overflows gets one line and exit 2, never inf in the output (ik's --twist
    printed argparse's usage line first: a value out of range is not a mistake of syntax)."""
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "" and "beyond 1e+06" in err and "inf" not in err.replace("infeasible", "")
    assert err.count("\n") == 1 and err.startswith("wmrkit: error: ")


def test_ik_outside_a_steer_range_is_not_feasible(capsys):
    """The car's front wheels steer within +-40 deg: a turn that needs 46.5 deg was printed 'feasible: yes'."""
    from wmrkit.kinematics.wheel_ik import wheel_commands

    robot = catalog.load("ackermann")
    code, out, err = run(capsys, "ik", "ackermann", "--twist", "1", "0", "0.3", "--json")
    data = json.loads(out)
    assert code == 1 and data["feasible"] is False and data["out_of_range"] == ["front_left"]
    assert math.degrees(data["wheels"]["front_left"]["heading"]) == pytest.approx(46.5433, abs=1e-4)
    assert "wheel 'front_left' would steer to heading 46.5433 deg, outside its steer_range [-40, 40] deg" in err
    code, out, err = run(capsys, "ik", "ackermann", "--twist", "1", "0", "0.3")
    assert "feasible: NO (a wheel cannot steer there)" in out and "slips" not in err
    batch = wheel_commands(robot, [[1, 0, 0.1], [1, 0, 0.3], [1, 0.5, 0.1]])
    assert batch.feasible.tolist() == [True, False, False]  # the last: a fixed wheel slips
    assert batch.in_range[:, robot.wheel_names.index("front_left")].tolist() == [True, False, True]


def test_ik_takes_the_other_root_when_only_it_is_within_the_steer_range(tmp_path, capsys):
    """Modules limited to +-90 deg at heading 80 deg, asked to roll towards 100 deg: the closest root (100 deg) is
    outside the range but the other (-80 deg, spinning backwards) is inside. It was 'feasible: NO (a wheel cannot
    steer there)' for a twist the robot can follow."""
    from wmrkit import Robot
    from wmrkit.kinematics.wheel_ik import wheel_commands

    wheels = "\n".join(f"  - {{name: {n}, type: steerable, position: [{x}, {y}], heading: 80 deg, r: 0.05, "
                       f"steer_range: [-90 deg, 90 deg]}}" for n, x, y in (("a", 0.3, 0.3), ("b", -0.3, -0.3)))
    path = tmp_path / "limited.yaml"
    path.write_text(f"name: limited\nwheels:\n{wheels}\n")
    twist = [math.cos(math.radians(100)), math.sin(math.radians(100)), 0.0]
    code, out, err = run(capsys, "ik", str(path), "--twist", *map(str, twist), "--json")
    data = json.loads(out)
    assert code == 0 and data["feasible"] is True and data["out_of_range"] == [] and err == ""
    for entry in data["wheels"].values():
        assert math.degrees(entry["heading"]) == pytest.approx(-80.0) and entry["spin"] == pytest.approx(-20.0)
    robot = Robot.from_file(path)
    c = wheel_commands(robot, [twist, [-t for t in twist], [0.0, 1.0, 0.0]], heading=[[80.0 * math.pi / 180] * 2] * 3)
    assert c.feasible.tolist() == [True, True, True]
    np.testing.assert_allclose(np.degrees(c.heading[:, 0]), [-80.0, -80.0, 90.0], atol=1e-9)
    np.testing.assert_allclose(c.spin[:, 0], [-20.0, 20.0, 20.0], atol=1e-9)
    assert np.abs(robot.slip_velocity(c.velocity([twist, [-t for t in twist], [0.0, 1.0, 0.0]]), c.beta)).max() < 1e-12


def test_text_prints_rounding_noise_as_zero(capsys):
    """The tables printed 0 for rounding noise but the twist line and the 'other rates' column did not:
    'vy = 1.92296e-16 m/s' for a differential drive and 'roller -1.77636e-14' for a Mecanum wheel driving
    straight. Below 1e-12 (m/s, rad/s) every printed number is 0, as in the tables; JSON keeps the raw floats."""
    code, out, _ = run(capsys, "fk", "diff-drive", "--spin", "left=10", "--spin", "right=12")
    assert code == 0 and "vy = 0 m/s" in out and "e-1" not in out.splitlines()[0]
    code, out, _ = run(capsys, "ik", "mecanum-4", "--twist", "1", "0", "0")
    assert code == 0 and out.count("roller 0\n") == 4 and "e-1" not in out


def test_ik_and_show_tables_keep_long_wheel_names_apart_from_their_type(capsys, tmp_path):
    # ROS 2 names its joints 'front_left_wheel_joint': a name of 14 characters or more ran into the type column
    # ('front_left_wheel_jointswedish'), in ik's and show's tables alike
    path = tmp_path / "ros.yaml"
    names = ("front_left_wheel_joint", "front_right_wheel_joint", "rear_right_wheel_joint", "rl")
    places = ((0.2, 0.15), (0.2, -0.15), (-0.2, -0.15), (-0.2, 0.15))
    wheels = ", ".join(f"{{name: {n}, type: mecanum, position: [{x}, {y}], r: 0.05, actuated: spin}}"
                       for n, (x, y) in zip(names, places, strict=True))
    path.write_text(f"name: ros-mecanum\nwheels: [{wheels}]\n")
    for argv in (("ik", str(path), "--twist", "0.3", "0.2", "0.5"), ("show", str(path))):
        code, out, _ = run(capsys, *argv)
        rows = [line.split() for line in out.splitlines() if line.split() and line.split()[0] in names]
        assert code == 0 and [r[0] for r in rows] == list(names) and {r[1] for r in rows} == {"mecanum"}
        header = next(line for line in out.splitlines() if line.split()[:2] == ["wheel", "type"])
        for line in out.splitlines():  # the columns line up: each row's type starts under the header's
            if line.split() and line.split()[0] in names:
                assert line.index(" mecanum") + 1 == header.index("type")


def test_every_number_column_of_the_ik_table_names_its_unit(capsys):
    """'steer rate' was the one column of numbers without its unit (rad/s), beside 'spin [rad/s]' and 'slip [m/s]'."""
    assert main(["ik", "diff-drive", "--twist", "1", "0.2", "0.5"]) == 1  # not feasible: an answer that is no
    header = capsys.readouterr().out.splitlines()[0]
    columns = re.split(r"\s{2,}", header.strip())
    assert columns[:2] == ["wheel", "type"] and all(re.search(r"\[[^]]+\]$", c) for c in columns[2:]), columns


def test_ik_twist_takes_speed_and_angular_rate_units(capsys):
    """'--twist "1.8 km/h" 0 "30 deg/s"' is the twist (0.5, 0, pi/6) in SI: it was refused ("accepted: none")."""
    code, out, _ = run(capsys, "ik", "swerve-4", "--twist", "1.8 km/h", "250 mm/s", "30 deg/s", "--json")
    assert code == 0
    robot = catalog.load("swerve-4")
    for name, (x, y) in zip(robot.wheel_names, (w.position for w in robot.wheels), strict=True):
        ux, uy = 0.5 - math.pi / 6 * y, 0.25 + math.pi / 6 * x
        assert json.loads(out)["wheels"][name]["spin"] == pytest.approx(math.hypot(ux, uy) / 0.0508, rel=1e-12)


@pytest.mark.parametrize(("twist", "message"), [
    (("0.5 rad", "0", "0"), "--twist VX: '0.5 rad' is an angle, expected a speed"),
    (("0", "0", "10 mm/s"), "--twist OMEGA: '10 mm/s' is a speed, expected an angular rate"),
    (("0", "1e10 mm/s", "0"), "--twist VY 1e10 mm/s: beyond"),
])
def test_ik_twist_units_of_the_wrong_kind_or_too_fast_are_refused_by_component(capsys, twist, message):
    code, out, err = run(capsys, "ik", "swerve-4", "--twist", *twist)
    assert code == 2 and out == "" and message in err and len(err.strip().splitlines()) == 1


def test_fk_spin_takes_rpm_and_its_twist_speeds_take_speed_units(capsys):
    """120 rpm on both wheels of the diff drive (r = 0.075 m, read from the catalog) is vx = 4 pi r; a gyro's
    '0 deg/s' and vx in cm/s agree with it."""
    r = catalog.load("diff-drive").wheels[0].r
    code, out, _ = run(capsys, "fk", "diff-drive", "--spin", "left=120 rpm", "--spin", "right=2 rev/s",
                       "--spin", f"vx={400 * math.pi * r} cm/s", "--spin", "omega=0 deg/s", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["twist"] == pytest.approx([4 * math.pi * r, 0, 0], abs=1e-12) and data["residual"] < 1e-12
    code, _, err = run(capsys, "fk", "diff-drive", "--spin", "left=1 m")
    assert code == 2 and "--spin left: '1 m' is a length, expected an angular rate" in err
