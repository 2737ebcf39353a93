"""Steering at the log doors: CSV and bag files hold headings (0 = rolling straight ahead, as ROS 2 and WPILib),
JointLog holds the thesis's β, and every reader and writer converts with the robot's wheels (one conversion)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.errors import ShapeError
from wmrkit.odometry.encoders import AbsoluteEncoder, IncrementalEncoder, catalog_encoders
from wmrkit.odometry.files import odometry_file
from wmrkit.odometry.logs import JointLog, LogError, LogFormat, load_csv, write_csv, write_log
from wmrkit.odometry.model import odometry_model
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.steering import SteeringError
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.wheels import wrap_angle

SWERVE = catalog.load("swerve-4")


def _json(capsys, argv):
    assert main(argv) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def _castor_with_delta():
    """thesis-diff-castor with its sensed castor's axle turned by δ = 0.3 rad from the arm (heading != β - 90°)."""
    robot = catalog.load("thesis-diff-castor")
    return replace(robot, wheels=tuple(replace(w, delta=0.3) if w.name == "c3" else w for w in robot.wheels))


def _same_angles(a, b, atol=1e-12):
    np.testing.assert_allclose(wrap_angle(np.asarray(a) - np.asarray(b)), 0.0, atol=atol)


ROUND_TRIPS = {  # robot, profile: every kind of sensed steering (steerable pairs, four modules, a castor with δ)
    "forklift": (catalog.load("forklift"), TwistProfile.from_segments([(3.0, 1.0, 0.0, 0.2)]).about((-1.0, 0.0))),
    "swerve-4": (SWERVE, TwistProfile.from_segments([(1.5, 0.4, 0.3, 0.5)])),
    "ackermann": (catalog.load("ackermann"), TwistProfile.from_segments([(2.0, 2.0, 0.0, 0.2)])),
    "castor-delta": (_castor_with_delta(), TwistProfile.from_segments([(2.0, 0.0, 0.3, 0.4)])),
    # a castor whose heading turns past 180 deg: the file keeps counting (a continuous joint), no 2 pi jump
    "castor-turning": (catalog.load("thesis-diff-castor"), TwistProfile.from_segments([(6.0, 0.0, 0.3, -0.8)])),
}


@pytest.mark.parametrize("name", ROUND_TRIPS)
def test_csv_written_with_headings_reads_back(tmp_path, name):
    robot, profile = ROUND_TRIPS[name]
    run = simulate(robot, profile, 20.0)
    path = tmp_path / "log.csv"
    write_log(path, run.log, robot)
    header = path.read_text().splitlines()[0].split(",")
    assert header == ["time", *run.log.joints]
    written = np.loadtxt(path, delimiter=",", skiprows=1)
    steer = [k for k, j in enumerate(run.log.joints) if j.endswith(".steer")]
    for k in steer:  # the file holds each wheel's rolling direction: that of the robot steered to the logged β
        wheel = run.log.joints[k].partition(".")[0]
        for row in (0, len(run.log) - 1):
            steered = robot.with_beta_angles({wheel: run.log.positions[row, k]}).wheel(wheel)
            _same_angles(written[row, 1 + k], steered.heading)
    if name == "castor-turning":
        column = written[:, 1 + run.log.joints.index("c3.steer")]
        assert column.min() < -math.pi and np.abs(np.diff(column)).max() < 0.5
    back = load_csv(path, run.log.joints, robot=robot)
    _same_angles(back.positions, run.log.positions)
    np.testing.assert_allclose(odometry(robot, back).poses, odometry(robot, run.log).poses, atol=1e-12)
    if not name.startswith("castor"):  # a sensed castor turns continuously: its midpoint angle is second order
        np.testing.assert_allclose(odometry(robot, back).poses, run.truth, atol=1e-9)


def test_degrees_and_counts_read_as_headings(capsys, tmp_path):
    """A swerve robot driving straight, then diagonally at 45 deg: its modules' steering encoders read 0, then
    45 deg; the same run logged in radians, in degrees and as counts gives one trajectory."""
    profile = TwistProfile.from_segments([(1.0, 0.5, 0.0, 0.0), (0.5, 0.0, 0.0, 0.0), (1.0, 0.3, 0.3, 0.0)])
    res = 2 * math.pi / 4096
    enc = {j: (AbsoluteEncoder(res) if j.endswith(".steer") else IncrementalEncoder(4096, bits=16))
           for j in SWERVE.sensed}
    run = simulate(SWERVE, profile, 20.0, encoders=enc)
    joints = run.log.joints
    steer = [j for j in joints if j.endswith(".steer")]
    straight, diagonal = run.log.time < 0.99, run.log.time > 1.6
    for j in steer:  # independent of the code: straight ahead is 0, the 45 deg diagonal 512 counts of 4096
        assert np.all(run.counts[j][straight] == 0) and np.all(run.counts[j][diagonal] == 512)
    headings = run.log.heading_positions(SWERVE)
    rad, deg, counts = (tmp_path / f"{n}.csv" for n in ("rad", "deg", "counts"))
    write_csv(rad, ("time", *(f"{j} [rad]" for j in joints)), np.column_stack([run.log.time, headings]))
    degrees = np.where([j.endswith(".steer") for j in joints], np.degrees(headings), headings)
    write_csv(deg, ("time", *(f"{j} [{'deg' if j.endswith('.steer') else 'rad'}]" for j in joints)),
              np.column_stack([run.log.time, degrees]))
    write_csv(counts, ("time", *(f"{j} [counts{'' if j.endswith('.steer') else ':u16'}]" for j in joints)),
              np.column_stack([run.log.time, *(run.counts[j] for j in joints)]), fmt="%.10g")
    ref = odometry(SWERVE, run.log).final_pose
    for path in (rad, deg):
        np.testing.assert_allclose(_json(capsys, ["odometry", "swerve-4", str(path), "--json"])["final_pose"], ref,
                                   atol=1e-9)
    out = _json(capsys, ["odometry", "swerve-4", str(counts), "--json", "--cpr", "4096",
                         "--steer-resolution", f"{360 / 4096} deg"])
    np.testing.assert_allclose(out["final_pose"], ref, atol=1e-9)  # spins relative to the first sample: same motion
    back = load_csv(deg, joints, LogFormat(steer="degrees", columns=tuple((j, f"{j} [{u}]") for j, u in zip(
        joints, ["deg" if j.endswith(".steer") else "rad" for j in joints], strict=True))), robot=SWERVE)
    _same_angles(back.positions, run.log.positions)


@settings(max_examples=100, deadline=None)
@given(heading=st.floats(-math.pi, math.pi), speed=st.floats(0.1, 2.0))
def test_swerve_modules_at_one_heading_drive_the_robot_along_it(heading, speed):
    """ROS-style joint data (steering 0 = straight ahead): four modules held at heading h, wheels rolling at
    `speed`, move the robot along h without turning (closed form), whatever h."""
    t = np.linspace(0.0, 2.0, 11)
    model = odometry_model(SWERVE)
    r = SWERVE.wheel("front_left").r
    cols = [np.full_like(t, heading) if j.endswith(".steer") else speed * t / r for j in model.joints]
    log = JointLog.from_headings(SWERVE, t, model.joints, np.column_stack(cols))
    pose = odometry(model, log).final_pose
    np.testing.assert_allclose(pose, [2 * speed * math.cos(heading), 2 * speed * math.sin(heading), 0.0],
                               atol=1e-9)
    back, given = log.heading_positions(SWERVE), np.column_stack(cols)
    steer = np.array([j.endswith(".steer") for j in model.joints])
    _same_angles(back[:, steer], given[:, steer])  # a heading of -pi comes back as pi: headings are in (-pi, pi]
    assert np.all((back[:, steer] > -math.pi) & (back[:, steer] <= math.pi))
    np.testing.assert_allclose(back[:, ~steer], given[:, ~steer], atol=1e-12)


def test_ackermann_log_with_textbook_steering_angles_drives_the_circle(capsys, tmp_path):
    """A car log as ros2_control writes it: front steering joints at the Ackermann angles atan(L / (R -+ w/2))
    (0 = straight), wheels rolling at their distance to the centre of the turn: the rear-axle midpoint drives the
    circle of radius R (closed form) from the file, through the CLI."""
    robot = catalog.load("ackermann")
    length, half, r = 2.7, 0.775, robot.wheel("rear_left").r
    radius, turn = 10.0, 1.0
    t = np.linspace(0.0, 5.0, 51)
    angle = turn * t / t[-1]
    columns = {"rear_left.spin": (radius - half) * angle / r, "rear_right.spin": (radius + half) * angle / r,
               "front_left.spin": math.hypot(length, radius - half) * angle / r,
               "front_right.spin": math.hypot(length, radius + half) * angle / r,
               "front_left.steer": np.full_like(t, math.atan(length / (radius - half))),
               "front_right.steer": np.full_like(t, math.atan(length / (radius + half)))}
    path = tmp_path / "car.csv"
    write_csv(path, ("time", *columns), np.column_stack([t, *columns.values()]))
    out = _json(capsys, ["odometry", "ackermann", str(path), "--json"])
    circle = [radius * math.sin(turn), radius * (1 - math.cos(turn)), turn]
    np.testing.assert_allclose(out["final_pose"], circle, atol=1e-9)
    assert out["consistent"] is True and out["max_slip"] < 1e-9
    legacy = _json(capsys, ["odometry", "ackermann", str(path), "--json", "--steer-convention", "beta"])
    assert legacy["consistent"] is False  # the same numbers read as the thesis's β: contradicting sensors


def test_bag_holds_headings_and_reads_back(tmp_path):
    from wmrkit.odometry.bags import read_joint_states, write_joint_states

    rosbags = pytest.importorskip("rosbags.rosbag2")
    from rosbags.typesys import Stores, get_typestore

    profile = TwistProfile.from_segments([(1.0, 0.5, 0.0, 0.0), (0.5, 0.0, 0.0, 0.0), (1.0, 0.3, 0.3, 0.0)])
    run = simulate(SWERVE, profile, 20.0)
    names = {j: j.replace(".", "_") + "_joint" for j in run.log.joints}
    path = tmp_path / "swerve_bag"
    write_joint_states(path, run.log, robot=SWERVE, names=names)
    ts = get_typestore(Stores.ROS2_HUMBLE)
    with rosbags.Reader(path) as reader:
        msgs = [ts.deserialize_cdr(d, c.msgtype) for c, _, d in reader.messages()]
    steer = [k for k, n in enumerate(msgs[0].name) if n.endswith("_steer_joint")]
    assert len(steer) == 4
    first, last = msgs[5].position[steer], msgs[-1].position[steer]  # driving straight, then diagonally
    np.testing.assert_allclose(first, 0.0, atol=1e-12)
    np.testing.assert_allclose(last, math.pi / 4, atol=1e-12)
    back = {v: k for k, v in names.items()}
    log = next(iter(read_joint_states(path, run.log.joints, robot=SWERVE, names=back)))
    _same_angles(log.positions, run.log.positions)
    summary = odometry_file(SWERVE, path, joint_names=back)
    np.testing.assert_allclose(summary.final_pose, odometry(SWERVE, run.log).final_pose, atol=1e-12)
    np.testing.assert_allclose(summary.final_pose, run.truth[-1], atol=1e-3)  # a steering change while stopped


def test_legacy_beta_logs_stay_readable(capsys, tmp_path):
    """Files written in the thesis's β by older wmrkit versions: ``[deg:beta]``/``[rad:beta]`` in the header, or
    ``--steer-convention beta``, read them as they are; a header and an option that disagree are refused."""
    robot, profile = ROUND_TRIPS["forklift"]
    run = simulate(robot, profile, 20.0)
    joints = run.log.joints
    is_steer = np.array([j.endswith(".steer") for j in joints])
    write_log(tmp_path / "new.csv", run.log, robot)
    ref = _json(capsys, ["odometry", "forklift", str(tmp_path / "new.csv"), "--json"])["final_pose"]
    np.testing.assert_allclose(ref, run.truth[-1], atol=1e-9)
    beta_deg = np.where(is_steer, np.degrees(run.log.positions), run.log.positions)
    cases = {"deg": (beta_deg, "deg:beta", []), "rad": (run.log.positions, "rad:beta", []),
             "plain": (run.log.positions, None, ["--steer-convention", "beta"])}
    for name, (values, unit, options) in cases.items():
        path = tmp_path / f"{name}.csv"
        header = [j if unit is None or not j.endswith(".steer") else f"{j} [{unit}]" for j in joints]
        write_csv(path, ("time", *header), np.column_stack([run.log.time, values]))
        out = _json(capsys, ["odometry", "forklift", str(path), "--json", *options])
        np.testing.assert_allclose(out["final_pose"], ref, atol=1e-9)
    legacy = tmp_path / "plain.csv"  # β read as headings: 90 deg off, the sensors contradict each other
    assert _json(capsys, ["odometry", "forklift", str(legacy), "--json"])["consistent"] is False
    fmt = LogFormat(steer="degrees", steer_convention="beta", columns=(("steer.steer", "steer.steer [deg:beta]"),))
    _same_angles(load_csv(tmp_path / "deg.csv", joints, fmt).positions, run.log.positions)  # β needs no robot
    assert main(["odometry", "forklift", str(tmp_path / "deg.csv"), "--steer-convention", "heading"]) == 2
    assert "the header says --steer-convention beta, the option says heading" in capsys.readouterr().err


def test_forklift_counts_decode_as_before():
    """Folding the forklift's encoder offset into the general rule changes nothing: its counts give exactly the
    β of the former catalog encoder (offset pi/2), and straight ahead reads 0."""
    robot = catalog.load("forklift")
    enc = catalog_encoders("forklift")
    assert enc["steer.steer"].offset == 0.0
    profile = TwistProfile.from_segments([(2.0, 1.0, 0.0, 0.0), (3.0, 1.0, 0.0, 0.3)]).about((-1.0, 0.0))
    run = simulate(robot, profile, 20.0, encoders=enc)
    counts = run.counts["steer.steer"]
    assert np.all(counts[run.log.time < 1.99] == 0) and np.any(counts != 0)
    former = AbsoluteEncoder(enc["steer.steer"].resolution, offset=math.pi / 2)
    np.testing.assert_array_equal(run.log.positions[:, 2], former.angle(counts))


def test_heading_doors_need_the_robot(tmp_path):
    from wmrkit.odometry.bags import read_joint_states, write_joint_states

    robot, profile = ROUND_TRIPS["forklift"]
    run = simulate(robot, profile, 10.0)
    path = tmp_path / "f.csv"
    write_log(path, run.log, robot)
    with pytest.raises(SteeringError, match=r"f\.csv: steering joints \(steer\.steer\) are headings .* pass robot="):
        load_csv(path, run.log.joints)
    with pytest.raises(SteeringError, match="pass robot="):
        write_log(tmp_path / "g.csv", run.log)
    with pytest.raises(SteeringError, match="robot 'diff-drive' has no steering wheel of that name"):
        JointLog.from_headings(catalog.load("diff-drive"), run.log.time, ("left.steer",), run.log.positions[:, :1])
    pytest.importorskip("rosbags")
    with pytest.raises(SteeringError, match="pass robot="):
        write_joint_states(tmp_path / "b", run.log)
    write_joint_states(tmp_path / "b", run.log, robot=robot)
    with pytest.raises(SteeringError, match="pass robot="):
        list(read_joint_states(tmp_path / "b", run.log.joints))


def test_the_pages_example_of_ros_data_runs():
    """docs/odometry.md: joint data with headings enters through JointLog.from_headings."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "odometry.md").read_text()
    block = next(b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if "from_headings" in b)
    scope: dict = {}
    exec(compile(block, "docs/odometry.md", "exec"), scope)  # our own documentation
    np.testing.assert_allclose(scope["pose"], [math.cos(0.5), math.sin(0.5), 0.0], atol=1e-12)


def test_headings_beyond_the_described_steer_range_are_refused(capsys, tmp_path):
    """A forklift described with its +-90 deg steering range: a log whose steering column holds degrees, read as
    radians, is refused at its line with a hint; the same log read with ``--steer degrees`` runs. Headings up to
    3 deg past the stops pass (encoder offset); wheels without a range are not checked."""
    from wmrkit.control.forklift import with_steer_range

    plain = catalog.load("forklift")
    ranged = with_steer_range(plain, "steer", -math.pi / 2, math.pi / 2)
    description = tmp_path / "forklift.yaml"
    ranged.to_file(description)
    joints = ("right_drive.spin", "left_drive.spin", "steer.steer")
    t = np.arange(5) * 0.1
    spins = np.column_stack([t * 4, t * 4])
    log = tmp_path / "deg.csv"
    write_csv(log, ("time", *joints), np.column_stack([t, spins, [0, 10, 20, 30, 30]]))  # degrees
    assert main(["odometry", str(description), str(log)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"{log}:3: steer.steer: heading 10 rad (572.958 deg) outside the wheel's steer_range "
                        "[-90, 90] deg; degrees read as radians? (CSV logs: --steer degrees)")
    assert "\n" not in err
    ok = _json(capsys, ["odometry", str(description), str(log), "--steer", "degrees", "--json"])
    assert ok["final_pose"] == pytest.approx(_json(capsys, ["odometry", "forklift", str(log), "--steer", "degrees",
                                                      "--json"])["final_pose"])
    assert main(["odometry", "forklift", str(log)]) == 0  # no range described: not checked
    capsys.readouterr()
    past = np.radians([[92.9], [-92.9]])
    JointLog.from_headings(ranged, t[:2], joints[2:], past)  # within 3 deg of the stops
    with pytest.raises(SteeringError, match=r"^<log>: sample 1: steer\.steer: heading -1\.6249 rad \(-93\.1 deg\) "
                       r"outside the wheel's steer_range \[-90, 90\] deg$"):
        JointLog.from_headings(ranged, t[:2], joints[2:], np.radians([[92.9], [-93.1]]))


def test_the_car_template_refuses_its_steering_logged_in_degrees(capsys, tmp_path):
    """The catalog's car (``ackermann``) describes its +-40 deg steering range, so a log of its steering in degrees,
    read as radians, is refused at its line with the hint, and runs with ``--steer degrees``."""
    car = catalog.load("ackermann")
    assert {w.name: w.steer_range for w in car.wheels if w.type == "steerable"} == {
        "front_left": pytest.approx((-math.radians(40), math.radians(40))),
        "front_right": pytest.approx((-math.radians(40), math.radians(40)))}
    joints = odometry_model(car).joints
    t = np.arange(4) * 0.1
    columns = {j: (t * 3 if j.endswith(".spin") else np.array([0.0, 5.0, 10.0, 10.0])) for j in joints}
    log = tmp_path / "car.csv"
    write_csv(log, ("time", *joints), np.column_stack([t, *columns.values()]))
    assert main(["odometry", "ackermann", str(log)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("degrees read as radians? (CSV logs: --steer degrees)") and f"{log}:3: front_" in err
    assert main(["odometry", "ackermann", str(log), "--steer", "degrees"]) == 0


@pytest.mark.parametrize(("joints", "positions", "error", "message"), [
    # a 1-D or 3-D array raised numpy's IndexError / broadcast ValueError from the conversion
    (("front_left.spin", "front_left.steer"), np.zeros(3), LogError, r"expected time \(N,\) and positions \(N, 2\), "
                                                                       r"got \(3,\) and \(3,\)"),
    (("front_left.spin", "front_left.steer"), np.zeros((3, 2, 1)), LogError, r"positions \(N, 2\), got .* \(3, 2, 1\)"),
    # a lone string was read as one joint per letter ("positions (N, 16)")
    ("front_left.steer", np.zeros((3, 1)), LogError, r"joints: expected a sequence of joint names, got the string "
                                                      r"'front_left\.steer'"),
    (("front_left.spin", "front_left.steer"), [["0", "0"]] * 3, ShapeError, r"positions: got the text '0'"),
])
def test_joint_data_of_the_wrong_shape_or_kind_is_refused_by_name(joints, positions, error, message):
    with pytest.raises(error, match=message):
        JointLog.from_headings(SWERVE, np.arange(3.0), joints, positions)


def test_a_joint_log_holds_float_arrays_and_refuses_a_lone_joint_name():
    log = JointLog(np.arange(3), ("left.spin",), np.arange(3)[:, None])  # integers: converted
    assert log.time.dtype == float and log.positions.dtype == float
    with pytest.raises(LogError, match=r"got the string 'left\.spin'"):
        JointLog(np.arange(3.0), "left.spin", np.zeros((3, 1)))
