"""Session 31's sweep of one-line answers: what the dynamics lacks in a description, a torque beyond any motor, the
IMU check of `odometry`, the gear check of a tiny `--initial-twist`, `batch calibrate --level` and an overflowing
log: each refused or said in one line naming its file, wheel (row) and field (column or option)."""

from __future__ import annotations

import json

import pytest
from refusal import one_line_error

from wmrkit.cli.main import main

# 1. What the dynamics needs of a description (a body, inertias, a stance) is named at its file, line and field.

AXLE = """\
name: axle
body:
  mass: 50
  inertia: 2.0
  com: [{com}, 0]
wheels:
  - {{name: left, type: fixed, position: [0, 0.25], beta: 90 deg, r: 0.10, actuated: [spin]{left}}}
  - {{name: right, type: fixed, position: [0, -0.25], beta: 90 deg, r: 0.10, actuated: [spin], inertia: {{spin: 0.01}}}}
  - {{name: caster, type: {kind}, position: [-0.4, 0], r: 0.05, {caster}}}
"""
SPIN = ", inertia: {spin: 0.01}"
CASTOR = "d: 0.05, inertia: {spin: 0.001, steer: 0.001}"
ROLLERS = "heading: 0, gamma: 45 deg, r_r: 0.01, inertia: {spin: 0.001}"  # no 'roller'


def _line(text: str, word: str) -> int:
    """The 1-based line of `text` where `word` first appears: where the file says it, independently of wmrkit."""
    return next(i for i, line in enumerate(text.splitlines(), start=1) if word in line)


@pytest.mark.parametrize(("left", "kind", "caster", "com", "wheel", "field", "word"), [
    ("", "castor", CASTOR, 0, "left", "inertia.spin", "name: left"),  # no inertia at all
    (", inertia: {spin: 0}", "castor", CASTOR, 0, "left", "inertia.spin", "name: left"),
    (SPIN, "castor", "d: 0.05, inertia: {spin: 0.001}", 0, "caster", "inertia.steer", "name: caster"),
    (SPIN, "swedish", ROLLERS, 0, "caster", "inertia.roller", "name: caster"),
    (SPIN, "castor", CASTOR, 1.0, None, "body.com", "com:"),  # ahead of the axle: the castor would lift
])
def test_what_the_dynamics_lacks_is_named_at_its_file_line_wheel_and_field(
        left, kind, caster, com, wheel, field, word, tmp_path, capsys):
    # 'robot 'axle': wheel 'left' needs 'inertia.spin' > 0 for the dynamics' named neither the file nor the line
    text = AXLE.format(left=left, kind=kind, caster=caster, com=com)
    robot, torques = tmp_path / "axle.yaml", tmp_path / "t.csv"
    robot.write_text(text)
    torques.write_text("time,left.spin,right.spin\n0,1,1\n1,1,1\n")
    where = f"{robot}:{_line(text, word)}: " + (f"wheels[{['left', 'right', 'caster'].index(wheel)}].{field}: "
                                                if wheel else f"{field}: ")
    for argv in (["simulate", str(robot), "--torques", str(torques)],
                 ["track", str(robot), "--reference", "line", "--dynamics"]):
        assert one_line_error(argv, capsys).startswith(f"wmrkit: error: {where}")
        assert main([*argv, "--json"]) == 2
        out, err = capsys.readouterr()
        assert out == ""
        data = json.loads(err)
        assert (data["file"], data["line"], data["wheel"], data["field"]) == (
            str(robot), _line(text, word), wheel, field)


def test_contacts_on_one_line_and_a_missing_body_name_the_file(tmp_path, capsys):
    text = AXLE.format(left=SPIN, kind="castor", caster=CASTOR, com=0)
    robot = tmp_path / "two.yaml"
    robot.write_text(text.rsplit("  - {name: caster", 1)[0])  # the two wheels of one axle
    err = one_line_error(["simulate", str(robot), "--path", "straight"], capsys)
    assert err.startswith(f"wmrkit: error: {robot}:{_line(text, 'wheels:')}: wheels: the contacts of its wheels "
                          "(left, right) lie on one line")
    err = one_line_error(["simulate", "diff-drive", "--path", "straight"], capsys)
    assert err.startswith("wmrkit: error: catalog:diff-drive: body: the robot has no mass properties")


# 2. A torque beyond any motor (limits.MAX_TORQUE) is refused at its file, line and column, not "diverged".

@pytest.mark.parametrize("value", ["1e308", "-1e308", "1.0000001e10", "-2e10"])
def test_a_torque_beyond_the_limit_is_refused_at_its_row_and_column(value, tmp_path, capsys):
    # 1e308 N m printed "the simulation diverged before t = 2 s; use a smaller --step", naming no file nor column
    from wmrkit.limits import MAX_TORQUE

    assert abs(float(value)) > MAX_TORQUE
    torques = tmp_path / "t.csv"
    torques.write_text(f"time,front_left.spin,front_right.spin\n0,1,1\n1,1,{value}\n2,1,1\n")
    err = one_line_error(["simulate", "skid-steer-4", "--torques", str(torques)], capsys)
    assert err.startswith(f"wmrkit: error: {torques}:3: column 'front_right.spin': {float(value):.8g} N m is beyond "
                          "the largest torque wmrkit applies, 1e+10 N m")
    assert main(["simulate", "skid-steer-4", "--torques", str(torques), "--json"]) == 2
    data = json.loads(capsys.readouterr().err)
    assert (data["file"], data["line"], data["field"]) == (str(torques), 3, "front_right.spin")


def test_the_limit_itself_is_a_torque_and_python_inputs_are_bound_alike():
    from wmrkit import catalog
    from wmrkit.dynamics.model import DynamicModel
    from wmrkit.dynamics.simulate import Inputs
    from wmrkit.errors import WmrkitError
    from wmrkit.limits import MAX_TORQUE

    model = DynamicModel.of(catalog.load("skid-steer-4"))
    at = Inputs.torques_only(model, [0.0], {"front_left.spin": [MAX_TORQUE]})  # accepted (its run lifts off)
    assert at.torques.max() == MAX_TORQUE
    with pytest.raises(WmrkitError, match=r"torques: expected torques within 1e\+10 N m .*got -30000000000\.0"):
        Inputs.torques_only(model, [0.0], {"front_left.spin": [-3e10]})


# 3. The IMU check of `odometry` says one thing: checked (a note), or not checked (a warning saying why).

@pytest.fixture(scope="module")
def imu_run():
    pytest.importorskip("rosbags")
    from wmrkit import catalog
    from wmrkit.odometry import simulate
    from wmrkit.odometry.synthetic import TwistProfile

    return simulate(catalog.load("diff-drive"), TwistProfile.from_segments([(2.0, 0.5, 0.0, 0.2)]), 10.0)


def _imu_bag(tmp_path, run, pick, shift=0.0):
    """A bag of `run`'s joint states and one Imu topic, /imu, reading its heading at the messages `pick` selects."""
    from test_bag_imu import _imu, _write

    t, yaw, _ = _imu(run.log.time, run.truth[:, 2], "orientation")
    bag = tmp_path / "run"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t[pick] + shift, yaw[pick], None)})
    return bag


def _odometry(bag, capsys, *extra) -> tuple[dict, str]:
    assert main(["odometry", "diff-drive", str(bag), "--json", *extra]) == 0
    out, err = capsys.readouterr()
    return json.loads(out), err


@pytest.mark.parametrize(("pick", "shift", "why"), [
    (slice(5, 6), 0.0, "1 IMU message (at 1000.607 s): too few to measure a turn"),
    (slice(5, 6), 0.0, None),  # the same bag, --imu naming the topic: an error
    (slice(None), 100.0, "the IMU's stamps (1100.107 to 1102.007 s) miss the joint states' (1000 to 1002 s)"),
])
def test_an_imu_that_checks_nothing_is_said_not_checked_once(pick, shift, why, imu_run, tmp_path, capsys):
    # a one-message IMU answered "consistent": true, "imu": "/imu" and the note "heading checked against the IMU",
    # having compared no turn; stamps missing the run's printed that note, then "... not checked against it"
    bag = _imu_bag(tmp_path, imu_run, pick, shift)
    if why is None:
        err = one_line_error(["odometry", "diff-drive", str(bag), "--imu", "/imu"], capsys)
        assert err == f"wmrkit: error: {bag}: /imu: 1 IMU message (at 1000.607 s): too few to measure a turn\n"
        return
    answer, err = _odometry(bag, capsys)
    line = f"{bag}: /imu: {why}"
    assert answer["imu"] is None
    (said,) = answer["warnings"]
    assert said.startswith(line) and said.endswith("(the odometry is not checked against it)")
    assert "checked against the IMU" not in err  # no note saying the opposite
    assert err.count("wmrkit: ") == 1 and err.startswith(f"wmrkit: warning: {line}")


def test_an_imu_of_two_messages_checks_the_stretch_between_them(imu_run, tmp_path, capsys):
    answer, err = _odometry(_imu_bag(tmp_path, imu_run, slice(5, 7)), capsys)
    assert answer["imu"] == "/imu" and answer["warnings"] == [] and answer["consistent"]
    assert err.startswith("wmrkit: note: heading checked against the IMU on /imu")


# 4. A gear's check has the slip check's absolute floor (SLIP_TOL [m/s] at the contacts), at any robot scale.

def _geared_cart(scale: float) -> str:
    """A cart on a solid axle (a 1:1 gear: both spins equal) and a castor, every length times `scale`."""
    m = min(scale, 1.0) ** 3  # a body of the same density (at most the 1e6 kg wmrkit takes: 20 kg)
    return f"""name: geared-axle
body: {{mass: {20 * m!r}, inertia: {0.5 * m * scale ** 2!r}, com: [{-0.05 * scale!r}, 0], com_height: {0.1 * scale!r}}}
wheels:
  - {{name: left, type: fixed, position: [0, {0.2 * scale!r}], heading: 0, r: {0.075 * scale!r}, actuated: [spin],
     inertia: {{spin: {0.01 * m * scale ** 2!r}}}}}
  - {{name: right, type: fixed, position: [0, {-0.2 * scale!r}], heading: 0, r: {0.075 * scale!r},
     inertia: {{spin: {0.01 * m * scale ** 2!r}}}}}
  - {{name: caster, type: castor, position: [{-0.25 * scale!r}, 0], heading: 0, d: {0.04 * scale!r},
     r: {0.025 * scale!r}, inertia: {{spin: {0.001 * m * scale ** 2!r}, steer: {0.001 * m * scale ** 2!r}}}}}
couplings:
  - {{kind: gear, joints: [left.spin, right.spin], ratios: [1, 1]}}
"""


@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e3])
@pytest.mark.parametrize("factor", [1e-300, 0.9, 1.1])
def test_the_gear_check_and_the_slip_check_share_their_absolute_floor(scale, factor):
    # '--initial-twist 0 0 1e-320' was refused by the gear check (relative to the rates, all ~1e-320), while
    # '0 1e-320 0' passed the slip check (SLIP_TOL = 1e-6 m/s, absolute)
    from wmrkit import Robot
    from wmrkit.dynamics.model import DynamicModel
    from wmrkit.dynamics.programs import SLIP_TOL, twist_program
    from wmrkit.errors import WmrkitError

    model = DynamicModel.of(Robot.from_dict(__import__("yaml").safe_load(_geared_cart(scale))))
    # a turn at omega spins the two wheels of the axle apart: the gear holds them equal, so each contact slips
    # along by omega * (half track) from the gear's common turn; a lateral speed vy slips both sideways by vy
    turn, side = factor * SLIP_TOL / (0.2 * scale), factor * SLIP_TOL
    for twist, what in (([0.0, 0.0, turn], "out of its ratios"), ([0.0, side, 0.0], "would slip sideways")):
        if factor < 1:
            twist_program(model, [0.0], [twist])  # within the floor: rolls
        else:
            with pytest.raises(WmrkitError, match=what):
                twist_program(model, [0.0], [twist])


@pytest.mark.parametrize("twist", [["0", "0", "1e-320"], ["0", "1e-320", "0"]])
def test_a_tiny_initial_twist_starts_alike_whichever_speed_it_holds(twist, tmp_path, capsys):
    robot = tmp_path / "cart.yaml"
    robot.write_text(_geared_cart(1.0))
    assert main(["simulate", str(robot), "--path", "straight", "--duration", "0.01", "--initial-twist", *twist]) == 0
    assert "0.01 s simulated" in capsys.readouterr().out


@pytest.mark.parametrize("vy", ["1.1e-6", "-1.1e-6"])
def test_the_initial_twist_refusal_says_vy_0_not_minus_0(vy, tmp_path, capsys):
    # a side speed of the cart (axle at the origin: it rolls at VY = 0 whatever VX and OMEGA) printed "VY = -0 m/s"
    robot = tmp_path / "cart.yaml"
    robot.write_text(_geared_cart(1.0))
    assert main(["simulate", str(robot), "--path", "straight", "--initial-twist", "0", vy, "0"]) == 2
    err = capsys.readouterr().err
    assert "it rolls at VY = 0 m/s)" in err and "VY = -0" not in err


# 5. `batch calibrate --level` within (0.5, 0.9999], named; the level printed as given.

@pytest.fixture(scope="module")
def closed_runs(tmp_path_factory):
    from batch_params import write_log

    from wmrkit import catalog
    from wmrkit.odometry.synthetic import simulate, square_path

    d = tmp_path_factory.mktemp("closed")
    for i in range(3):
        write_log(d / f"run{i}.csv", simulate(catalog.load("diff-drive"), square_path(1.0 + 0.2 * i), 10.0,
                                              spin_noise_per_rad=1e-5, seed=i))
    return d


@pytest.mark.parametrize("level", ["1e-320", "0", "0.5", "1", "0.99999", "2", "-0.95"])  # 'nan': no number, the
# reader's refusal (tests/cli/test_option_units.py)
def test_a_confidence_level_outside_its_range_is_refused_naming_the_option(level, closed_runs, capsys):
    # 1e-320 printed "0% intervals" (exit 0), intervals of no width
    err = one_line_error(["batch", "calibrate", "diff-drive", str(closed_runs / "*.csv"), "--closed", "--workers",
                          "0", "--level", level], capsys)
    assert err.startswith("wmrkit: error: --level must be in (0.5, 0.9999] (a confidence level: 0.95 for 95 % "
                          f"intervals), got {float(level)!r}")


@pytest.mark.parametrize(("level", "shown"), [("0.9999", "99.99%"), ("0.95", "95%"), ("0.500001", "50.0001%")])
def test_the_level_is_printed_as_given(level, shown, closed_runs, capsys):
    # 0.9999 printed "100% intervals" (':.0%')
    assert main(["batch", "calibrate", "diff-drive", str(closed_runs / "*.csv"), "--closed", "--workers", "0",
                 "--level", level]) == 0
    assert f"; {shown} intervals (jacobian)" in capsys.readouterr().out


# 5b. A log whose spin step or rate overflows says so at its sample, never "inf rad/s".

@pytest.mark.parametrize(("rows", "line", "said"), [
    ("0,0,0\n0.01,1e308,0\n", 3, "turns 1e+308 rad in 0.01 s, a rate that overflows (at most 10000 rad/s)"),
    ("0,0,0\n1e-300,1e10,0\n", 3, "turns 1e+10 rad in 1e-300 s, a rate that overflows (at most 10000 rad/s)"),
    ("0,1e308,0\n0.01,-1e308,0\n", 3, "from 1e+308 rad to -1e+308 rad, a step that overflows (values too large to "
                                      "subtract)"),
    ("0,0,0\n0.01,0.5,0\n0.02,300.5,0\n", 4, "turns 300 rad in 0.01 s (3e+04 rad/s > 10000 rad/s)"),  # finite
])
def test_an_overflowing_spin_is_named_at_its_sample(rows, line, said, tmp_path, capsys):
    # "turns 1e+308 rad in 0.01 s (inf rad/s > 10000 rad/s)", and "turns inf rad in 0.01 s (inf rad/s > ...)"
    log = tmp_path / "log.csv"
    log.write_text("time,left.spin,right.spin\n" + rows)
    err = one_line_error(["odometry", "diff-drive", str(log)], capsys)
    assert err.startswith(f"wmrkit: error: {log}:{line}: left.spin: {said}: an implausible jump")
    assert "inf" not in err.replace("(encoder glitch", "")
