"""A bag's IMU (``sensor_msgs/msg/Imu``) checks the odometry's heading: ``wmrkit odometry ROBOT BAG [--imu TOPIC]``.

The bags are written here: JointState from a run, Imu from that run's true heading (the orientation, or its rate in
``angular_velocity.z`` with ``orientation_covariance[0] = -1``), the IMU's stamps a few ms off the joint states'."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.odometry import simulate
from wmrkit.odometry.synthetic import TwistProfile

pytest.importorskip("rosbags")

#: A skid steer described as a differential drive (its front wheels' track and radius): two spins, no redundancy, so
#: the slip indicator cannot see the wheels slip sideways in a turn.
SKID_AS_DIFF = """name: skid-as-diff
wheels:
  - {name: left, type: fixed, position: [0, 0.25], heading: 0, r: 0.1, actuated: [spin], sensed: [spin]}
  - {name: right, type: fixed, position: [0, -0.25], heading: 0, r: 0.1, actuated: [spin], sensed: [spin]}
"""
T0 = 1000.0  # the bags' clock at the run's start [s]
PATTERN = re.compile(r"over the run the no-slip odometry turned (\S+) rad and the IMU (\S+) rad(?:; from (\S+) s to "
                     r"(\S+) s into the run the no-slip odometry turned (\S+) rad and the IMU (\S+) rad)?")


def _write(path, time, joints, positions, imus):
    """A bag of JointState (`joints` at `time` [s]) and Imu topics: `imus` maps a topic to ``(time, yaw, rate)``,
    one of yaw [rad] (the orientation) or rate [rad/s] (angular_velocity.z, no orientation) None."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types

    def header(t, frame):
        sec = math.floor(t)
        return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](
            sec=sec, nanosec=round((t - sec) * 1e9) % 10**9), frame_id=frame)

    with Writer(path, version=8) as w:
        conn = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        empty = np.zeros(0)
        for t, row in zip(T0 + time, positions, strict=True):
            msg = T["sensor_msgs/msg/JointState"](header=header(t, ""), name=list(joints), position=row.astype(float),
                                                  velocity=empty, effort=empty)
            w.write(conn, round(t * 1e9), ts.serialize_cdr(msg, "sensor_msgs/msg/JointState"))
        for topic, (times, yaw, rate) in imus.items():
            conn = w.add_connection(topic, "sensor_msgs/msg/Imu", typestore=ts)
            vec, cov = T["geometry_msgs/msg/Vector3"], np.zeros(9)
            for k, t in enumerate(T0 + times):
                half = 0.5 * yaw[k] if yaw is not None else None
                q = (0.0, 0.0, 0.0, 0.0) if half is None else (0.0, 0.0, math.sin(half), math.cos(half))
                msg = T["sensor_msgs/msg/Imu"](
                    header=header(t, "imu_link"), orientation=T["geometry_msgs/msg/Quaternion"](*q),
                    orientation_covariance=cov if yaw is not None else np.r_[-1.0, np.zeros(8)],
                    angular_velocity=vec(x=0.0, y=0.0, z=0.0 if rate is None else float(rate[k])),
                    angular_velocity_covariance=cov, linear_acceleration=vec(x=0.0, y=0.0, z=9.81),
                    linear_acceleration_covariance=cov)
                w.write(conn, round(t * 1e9), ts.serialize_cdr(msg, "sensor_msgs/msg/Imu"))


def _imu(time, heading, kind, *, bias=0.0, noise=0.0, seed=0):
    """``(time, yaw, rate)`` of an IMU reading `heading` (at `time`) 7 ms late at the same rate: its orientation
    (`kind` "orientation") or its rate plus a `bias` [rad/s] and white `noise` [rad/s] ("gyro")."""
    t = time[1:] + 0.007  # its first message after the joint states' first, its last after their last
    yaw = np.interp(t, time, heading)
    if kind == "orientation":
        return t, yaw, None
    rate = np.gradient(yaw, t) + bias + np.random.default_rng(seed).normal(0.0, noise, len(t))
    return t, None, rate


def _run(capsys, robot, bag, *extra) -> tuple[int, dict, str]:
    code = main(["odometry", str(robot), str(bag), "--json", *extra])
    out = capsys.readouterr()
    return code, json.loads(out.out or out.err), out.err


@pytest.fixture(scope="module")
def skid_turn():
    """A skid steer (the quasi-static slip model, its tyres) driving 2 s, turning on the spot 4 s, driving 2 s: its
    wheels' no-slip rates of 1.25 rad/s (5 rad), the robot turns 1.25 rad."""
    from wmrkit.slip.skid import segment_run

    log, truth = segment_run(catalog.load("skid-steer-4"), ((2.0, 1.0, 0.0), (4.0, 0.0, 1.25), (2.0, 1.0, 0.0)), 50.0,
                             source="quasi-static")
    return log, truth


@pytest.mark.parametrize("kind", ["orientation", "gyro"])
def test_a_skid_steer_turn_that_slips_is_flagged_with_both_turns(capsys, tmp_path, skid_turn, kind):
    """Before, the bag passed: "consistent": true, no warning, the odometry turning 4 times what the robot did. Now
    one warning gives the wheels' turn (the run's own final theta) and the IMU's (the slip model's true turn)."""
    log, truth = skid_turn
    robot = tmp_path / "skid.yaml"
    robot.write_text(SKID_AS_DIFF)
    k = [log.joints.index("front_left.spin"), log.joints.index("front_right.spin")]
    bag = tmp_path / "run"
    _write(bag, log.time, ("left.spin", "right.spin"), log.positions[:, k],
           {"/imu/data": _imu(log.time, truth[:, 2], kind)})
    code, answer, err = _run(capsys, robot, bag)
    assert code == 0 and answer["imu"] == "/imu/data" and not answer["consistent"]
    assert "wmrkit: note: heading checked against the IMU on /imu/data" in err
    (line,) = answer["warnings"]
    assert line.startswith("the no-slip odometry's heading contradicts the IMU on /imu/data")
    m = PATTERN.search(line)
    assert float(m[1]) == pytest.approx(answer["final_pose"][2], rel=1e-3)
    turned = log.positions[-1, k] - log.positions[0, k]  # the differential drive's r (right - left) / track
    assert float(m[1]) == pytest.approx(0.1 * (turned[1] - turned[0]) / 0.5, rel=1e-3)
    # the IMU's first message is 7 ms after the run's start, at rest: the truth's turn
    assert float(m[2]) == pytest.approx(truth[-1, 2] - truth[0, 2], rel=1e-3 if kind == "orientation" else 2e-2)
    assert float(m[2]) == pytest.approx(1.25, rel=2e-2)


def test_a_turn_undone_is_caught_by_a_window(capsys, tmp_path):
    """Turning left then back right, both 60 % more than the robot turned: over the run both turn 0 rad; over the
    window of the right turn the odometry turns -1.6 rad and the IMU -1.0 rad."""
    robot = catalog.load("diff-drive")
    profile = TwistProfile.from_segments([(2.0, 0.3, 0.0, 0.0), (2.0, 0.3, 0.0, 0.5), (4.0, 0.3, 0.0, 0.0),
                                          (2.0, 0.3, 0.0, -0.5), (2.0, 0.3, 0.0, 0.0)])
    run = simulate(robot, profile, 20.0)
    # the wheels' heading 1.6 times the truth's: the right wheel's travel past the left's scaled up
    left, right = (run.log.positions[:, run.log.joints.index(j)] for j in ("left.spin", "right.spin"))
    mid = 0.5 * (left + right)
    positions = np.column_stack([mid - 1.6 * (right - mid), mid + 1.6 * (right - mid)])
    bag = tmp_path / "run"
    _write(bag, run.log.time, ("left.spin", "right.spin"), positions,
           {"/imu": _imu(run.log.time, run.truth[:, 2], "orientation")})
    code, answer, _ = _run(capsys, "diff-drive", bag)
    assert code == 0 and not answer["consistent"]
    (line,) = answer["warnings"]
    m = PATTERN.search(line)
    assert abs(float(m[1])) < 1e-3 and abs(float(m[2])) < 1e-3  # the run: no net turn
    assert m[3] is not None  # the window
    assert (float(m[5]), float(m[6])) == (pytest.approx(-1.6, rel=1e-3), pytest.approx(-1.0, rel=1e-3))


@pytest.mark.parametrize(("kind", "bias", "noise"), [("orientation", 0.0, 0.0), ("gyro", 0.0, 0.0),
                                                    ("gyro", 0.002, 0.01)])
def test_a_clean_run_is_not_flagged(capsys, tmp_path, kind, bias, noise):
    """A differential drive that rolls (squares' worth of turns both ways, 30 s), its IMU agreeing, or drifting
    0.002 rad/s (0.11 deg/s) with 0.01 rad/s of noise: no warning."""
    robot = catalog.load("diff-drive")
    profile = TwistProfile.from_segments([(3.0, 0.4, 0.0, 0.0), (3.0, 0.2, 0.0, 0.6), (3.0, 0.4, 0.0, 0.0),
                                          (6.0, 0.1, 0.0, -0.5), (15.0, 0.3, 0.0, 0.1)])
    run = simulate(robot, profile, 20.0)
    bag = tmp_path / "run"
    _write(bag, run.log.time, run.log.joints, run.log.positions,
           {"/imu": _imu(run.log.time, run.truth[:, 2], kind, bias=bias, noise=noise)})
    code, answer, err = _run(capsys, "diff-drive", bag)
    assert code == 0 and answer["imu"] == "/imu" and answer["warnings"] == [] and answer["consistent"]
    assert "wmrkit: warning" not in err


def test_a_run_without_turning_is_not_flagged_by_a_drifting_gyro(capsys, tmp_path):
    """Driving straight 60 s while the gyro reads 0.004 rad/s (its yaw drifts 0.24 rad): no warning."""
    robot = catalog.load("diff-drive")
    run = simulate(robot, TwistProfile.from_segments([(60.0, 0.5, 0.0, 0.0)]), 10.0)
    bag = tmp_path / "run"
    _write(bag, run.log.time, run.log.joints, run.log.positions,
           {"/imu": _imu(run.log.time, run.truth[:, 2], "gyro", bias=0.004)})
    _, answer, _ = _run(capsys, "diff-drive", bag)
    assert answer["warnings"] == [] and answer["consistent"]


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    robot = catalog.load("diff-drive")
    return simulate(robot, TwistProfile.from_segments([(2.0, 0.5, 0.0, 0.2)]), 10.0)


def test_imu_topics_choice_and_refusals(capsys, tmp_path, short_run):
    """Two Imu topics: none is checked (a warning says so: it was a note, not in the JSON's warnings); --imu chooses
    one; --imu naming no Imu topic, or on a CSV log, is one error line (exit 2)."""
    run = short_run
    imu = _imu(run.log.time, run.truth[:, 2], "orientation")
    bag = tmp_path / "two"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu/a": imu, "/imu/b": imu})
    code, answer, err = _run(capsys, "diff-drive", bag)
    assert code == 0 and answer["imu"] is None
    line = ("heading not checked against an IMU: the bag has 2 sensor_msgs/msg/Imu topics (/imu/a, /imu/b); choose "
            "one with --imu TOPIC")
    assert answer["warnings"] == [line] and f"wmrkit: warning: {line}" in err
    code, answer, err = _run(capsys, "diff-drive", bag, "--imu", "/imu/b")
    assert code == 0 and answer["imu"] == "/imu/b" and answer["warnings"] == [] and "note" not in err
    for topic, what in (("/imu/c", "is not in the bag"),
                        ("/joint_states", "carries sensor_msgs/msg/JointState, not sensor_msgs/msg/Imu")):
        code, answer, err = _run(capsys, "diff-drive", bag, "--imu", topic)
        assert code == 2 and answer["error"] == (f"--imu topic '{topic}' {what} (sensor_msgs/msg/Imu topics: /imu/a, "
                                                 "/imu/b)") and answer["file"] == str(bag)
    csv = tmp_path / "log.csv"
    csv.write_text("time,left.spin,right.spin\n0,0,0\n1,1,1\n")
    code, answer, _ = _run(capsys, "diff-drive", csv, "--imu", "/imu")
    assert code == 2 and answer["error"].startswith("--imu applies to ROS 2 bags")


def test_an_imu_on_another_clock(capsys, tmp_path, short_run):
    """The IMU's stamps 500 s after the joint states': found by itself, the IMU is not checked (a warning, exit 0);
    named by --imu, that is an error (exit 2)."""
    run = short_run
    t, yaw, _ = _imu(run.log.time, run.truth[:, 2], "orientation")
    bag = tmp_path / "clock"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t + 500.0, yaw, None)})
    code, answer, _ = _run(capsys, "diff-drive", bag)
    assert code == 0 and answer["consistent"] and answer["imu"] is None
    (line,) = answer["warnings"]
    assert "the IMU's stamps (1500.107 to 1502.007 s) miss the joint states' (1000 to 1002 s): another clock?" in line
    assert line.endswith("(the odometry is not checked against it)")
    code, answer, _ = _run(capsys, "diff-drive", bag, "--imu", "/imu")
    assert code == 2 and "another clock?" in answer["error"]


def test_read_imu_yaw_unwraps_integrates_and_chunks(tmp_path):
    """The orientation's yaw past pi read continuous; the gyro's constant rate integrated exactly (trapezoids); the
    same values in chunks of 7 as in one."""
    from wmrkit.odometry.bag_imu import read_imu_yaw

    t = np.linspace(0.0, 4.0, 41)
    yaw = 1.5 * t  # 6 rad: past pi, wrapped by the quaternion
    bag = tmp_path / "imu"
    _write(bag, t, ("left.spin",), np.zeros((41, 1)),
           {"/o": (t, yaw, None), "/g": (t, None, np.full(41, -0.3))})
    for topic, expected in (("/o", yaw), ("/g", -0.3 * t)):
        whole = list(read_imu_yaw(bag, topic))
        chunks = list(read_imu_yaw(bag, topic, chunk_size=7))
        assert len(whole) == 1 and len(chunks) == 6
        np.testing.assert_allclose(whole[0][0], T0 + t, atol=1e-9)
        np.testing.assert_allclose(whole[0][1], expected, atol=1e-9)
        np.testing.assert_allclose(np.concatenate([c[1] for c in chunks]), expected, atol=1e-9)


@pytest.fixture(scope="module")
def skid4_bag(tmp_path_factory, skid_turn):
    """The slipping skid turn of all four wheels (``skid-steer-4``), its IMU the true heading (1.25 rad) on /imu and
    the no-slip model's (its lateral rows halve the wheels' 5 rad: 2.5 rad) on /noslip."""
    from wmrkit.odometry import odometry

    log, truth = skid_turn
    noslip = odometry(catalog.load("skid-steer-4"), log).poses[:, 2]
    bag = tmp_path_factory.mktemp("skid4") / "run"
    _write(bag, log.time, log.joints, log.positions, {"/imu": _imu(log.time, truth[:, 2], "orientation"),
                                                      "/noslip": _imu(log.time, noslip, "orientation")})
    return bag, truth[-1, 2] - truth[0, 2], noslip[-1] - noslip[0]


def test_the_imu_judges_the_wls_trajectory_that_agrees(capsys, skid4_bag):
    """--method wls with lateral rows weighted 3 times the rolling rows: its heading is the longitudinal rows' 5 rad x
    1/(1+3) = 1.25 rad, the true turn. Before, the IMU was compared with the no-slip model's 2.5 rad and the run was
    told "the odometry's heading contradicts the IMU"; now only the slip indicator's warning (the wheels do slip)."""
    bag, true_turn, noslip_turn = skid4_bag
    assert (true_turn, noslip_turn) == (pytest.approx(1.25, rel=2e-2), pytest.approx(2.5, rel=2e-2))
    code, answer, err = _run(capsys, "skid-steer-4", bag, "--imu", "/imu", "--method", "wls", "--mu-default", "3,1")
    assert code == 0 and answer["final_pose"][2] == pytest.approx(true_turn, rel=2e-2)
    (line,) = answer["warnings"]
    assert line.startswith("the sensed joints contradict each other") and "IMU" not in err


@pytest.mark.parametrize(("options", "label"), [(("--method", "wls", "--mu-default", "3,1"), "wls"),
                                                (("--weight", "front_left=0.001", "--weight", "front_right=0.001"),
                                                 "weighted no-slip (--weight)")])
def test_the_imu_judges_the_trajectory_that_disagrees_naming_it(capsys, skid4_bag, options, label):
    """The IMU on /noslip agrees with the no-slip model (2.5 rad); the wls run (1.25 rad) and a run weighting the
    front wheels 1/1000 (the rear wheels' rolling rows alone fix the turn: their 5 rad, the lateral rows absorbed by
    v_y) do not. Before, no warning (the no-slip heading was judged); now the warning names the odometry judged and
    gives its own turn, the run's final theta."""
    bag, _, noslip_turn = skid4_bag
    code, answer, _ = _run(capsys, "skid-steer-4", bag, "--imu", "/noslip", *options)
    assert code == 0 and not answer["consistent"]
    line = answer["warnings"][-1]
    assert line.startswith(f"the {label} odometry's heading contradicts the IMU on /noslip: over the run the "
                           f"{label} odometry turned ")
    m = re.search(r"over the run the .* odometry turned (\S+) rad and the IMU (\S+) rad", line)
    assert float(m[1]) == pytest.approx(answer["final_pose"][2], rel=1e-3)
    assert float(m[1]) == pytest.approx(1.25 if label == "wls" else 5.0, rel=3e-2)
    assert float(m[2]) == pytest.approx(noslip_turn, rel=1e-3)


def test_the_joint_states_are_read_once(capsys, tmp_path, monkeypatch):
    """The check samples the run's output as it is produced: every JointState message is decoded once (before, the
    bag's joint states were read again after the run: twice)."""
    from wmrkit.odometry import bag_imu, bags

    robot = catalog.load("diff-drive")
    run = simulate(robot, TwistProfile.from_segments([(12.0, 0.4, 0.0, 0.3)]), 20.0)
    bag = tmp_path / "run"
    _write(bag, run.log.time, run.log.joints, run.log.positions,
           {"/imu": _imu(run.log.time, run.truth[:, 2], "orientation")})
    decoded: dict[str, int] = {}
    original = bags._messages

    def counting(reader, conns, source, msgtype, typestore):
        for item in original(reader, conns, source, msgtype, typestore):
            decoded[msgtype] = decoded.get(msgtype, 0) + 1
            yield item

    monkeypatch.setattr(bags, "_messages", counting)
    monkeypatch.setattr(bag_imu, "_messages", counting)
    code, answer, _ = _run(capsys, "diff-drive", bag, "--chunk-size", "50")
    assert code == 0 and answer["imu"] == "/imu" and answer["consistent"] and answer["samples"] == len(run.log)
    assert decoded == {"sensor_msgs/msg/JointState": len(run.log), "sensor_msgs/msg/Imu": len(run.log) - 1}


def _bad_imu_bag(tmp_path, run):
    """A bag whose IMU's 10th message has a NaN orientation."""
    t, yaw, _ = _imu(run.log.time, run.truth[:, 2], "orientation")
    yaw = yaw.copy()
    yaw[10] = np.nan
    bag = tmp_path / "bad"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t, yaw, None)})
    return bag


@pytest.mark.parametrize("out", ["traj.csv", "traj.tum", "odom_bag"])
def test_a_named_bad_imu_leaves_no_output(capsys, tmp_path, short_run, out):
    """Before, the run wrote --out, then the IMU failed to read: exit 2 and the trajectory left behind. Now the IMU is
    read before the run: exit 2, one line naming its message, no output; found by itself it is a warning and the
    run's output is written."""
    bag, path = _bad_imu_bag(tmp_path, short_run), tmp_path / out
    code, answer, _ = _run(capsys, "diff-drive", bag, "--imu", "/imu", "--out", str(path))
    assert code == 2 and answer["error"].startswith("/imu message 10: orientation [") and answer["file"] == str(bag)
    assert not path.exists()
    code, answer, _ = _run(capsys, "diff-drive", bag, "--out", str(path))
    assert code == 0 and answer["imu"] is None and path.exists()
    (line,) = answer["warnings"]
    assert "/imu message 10: orientation [" in line and line.endswith("(the odometry is not checked against it)")


def test_a_named_imu_on_another_clock_leaves_no_output(capsys, tmp_path, short_run):
    """The clock is the run's (known at its end): a named IMU missing it fails the run, whose output is removed."""
    run = short_run
    t, yaw, _ = _imu(run.log.time, run.truth[:, 2], "orientation")
    bag, path = tmp_path / "clock", tmp_path / "traj.csv"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t + 500.0, yaw, None)})
    code, answer, _ = _run(capsys, "diff-drive", bag, "--imu", "/imu", "--out", str(path))
    assert code == 2 and "another clock?" in answer["error"] and not path.exists()


def test_an_imu_too_long_to_hold_is_refused(tmp_path, short_run, monkeypatch):
    """The IMU's (time, yaw) are held whole: beyond bag_imu.MAX_IMU_MESSAGES (16 bytes each, limits.MAX_TABLE_SIZE
    in all) one error line, before the messages are read."""
    from wmrkit.odometry import bag_imu
    from wmrkit.odometry.logs import LogError

    assert bag_imu.MAX_IMU_MESSAGES * 16 == bag_imu.MAX_TABLE_SIZE
    run = short_run
    bag = tmp_path / "long"
    _write(bag, run.log.time, run.log.joints, run.log.positions,
           {"/imu": _imu(run.log.time, run.truth[:, 2], "orientation")})
    assert len(bag_imu.read_imu(bag, "/imu")[0]) == len(run.log) - 1
    monkeypatch.setattr(bag_imu, "MAX_IMU_MESSAGES", len(run.log) - 2)
    with pytest.raises(LogError, match=rf"/imu: {len(run.log) - 1} messages, more than the {len(run.log) - 2} "):
        bag_imu.read_imu(bag, "/imu")


def test_read_imu_yaw_converts_a_chunk_of_quaternions_at_once(tmp_path, monkeypatch):
    """The orientations' yaws are computed once per chunk (before, once per message: 41 calls for 41 messages), the
    values those of the quaternions' yaw one by one."""
    from wmrkit.odometry import bag_imu
    from wmrkit.odometry.trajectories import yaw_of_quaternion

    t = np.linspace(0.0, 4.0, 41)
    yaw = np.sin(t) * 3.0
    bag = tmp_path / "imu"
    _write(bag, t, ("left.spin",), np.zeros((41, 1)), {"/o": (t, yaw, None)})
    calls = []
    monkeypatch.setattr(bag_imu, "yaw_of_quaternion", lambda q: calls.append(np.shape(q)) or yaw_of_quaternion(q))
    chunks = list(bag_imu.read_imu_yaw(bag, "/o", chunk_size=16))
    assert calls == [(16, 4), (16, 4), (9, 4)]
    np.testing.assert_allclose(np.concatenate([c[1] for c in chunks]), yaw, atol=1e-12)


def test_samples_far_apart_in_time_keep_the_check_small():
    """Two joint-state samples 2**31 s apart (and an IMU as long) once made the check sample 4e8 window ends (3.4 GB;
    1e8 s here, 2e7 before): it samples at most diagnostics.MAX_IMU_WINDOWS of them, its windows longer."""
    from wmrkit.odometry import diagnostics
    from wmrkit.odometry.trajectories import Trajectory

    span = 1e8
    imu_time = np.linspace(0.0, span, 5)
    check = diagnostics.ImuCheck("b", "/imu", imu_time, 3.0 * imu_time / span, "no-slip", named=True)
    check(Trajectory(np.array([0.0]), np.zeros((1, 3)), np.zeros(1)))
    check(Trajectory(np.array([span]), np.array([[0.0, 0.0, 1.0]]), np.zeros(1)))
    held = sum(len(t) for t in check._times)
    assert held <= diagnostics.MAX_IMU_WINDOWS + 3
    check.judge()
    assert check.checked and check.line is None  # 2 rad apart in 3 years: within the gyro's drift


#: The ends of the lines of diagnostics.IMU_FRAME_SCALES and of the odometry's (the generic line).
OPPOSITE = "is the IMU mounted upside down, or its frame not REP-103 (z down, NED)?"
DEG_S = "the IMU's yaw turns 57.3 times the odometry's: does the IMU publish deg/s?"
SLIP = "the wheels slip (a skid steer turning?), or the description's track or wheel radii are wrong"


@pytest.fixture(scope="module")
def turning_run():
    """A differential drive rolling through turns both ways (30 s; its heading spans about 3.4 rad), no slip."""
    profile = TwistProfile.from_segments([(3.0, 0.4, 0.0, 0.0), (3.0, 0.2, 0.0, 0.6), (3.0, 0.4, 0.0, 0.0),
                                          (6.0, 0.1, 0.0, -0.5), (15.0, 0.3, 0.0, 0.1)])
    return simulate(catalog.load("diff-drive"), profile, 20.0)


@pytest.mark.parametrize(("kind", "scale", "said"), [("gyro", -1.0, OPPOSITE), ("orientation", -1.0, OPPOSITE),
                                                     ("gyro", 180 / math.pi, DEG_S),
                                                     ("gyro", -180 / math.pi, "does the IMU publish deg/s")])
def test_an_imu_upside_down_or_in_deg_s_is_said_to_be_so(capsys, tmp_path, turning_run, kind, scale, said):
    """The odometry is right (the run's own joints, no slip); the IMU reads the true heading times -1 (a gyro upside
    down, an orientation in a NED frame), 57.3 (a gyro in deg/s) or both. Before, the line blamed the wheels ("the
    wheels slip ..., or the description's track or wheel radii are wrong"); now it says what the IMU looks like, and
    the turns it gives are the truth's and the truth's times the scale."""
    run = turning_run
    t, yaw, rate = _imu(run.log.time, run.truth[:, 2], kind)
    yaw, rate = (None, scale * rate) if kind == "gyro" else (scale * yaw, None)
    bag = tmp_path / "run"
    _write(bag, run.log.time, run.log.joints, run.log.positions, {"/imu": (t, yaw, rate)})
    code, answer, err = _run(capsys, "diff-drive", bag)
    assert code == 0 and answer["imu"] == "/imu" and not answer["consistent"]
    (line,) = answer["warnings"]
    assert said in line and SLIP not in line and f"wmrkit: warning: {line}" in err
    m = PATTERN.search(line)
    true = run.truth[-1, 2] - run.truth[0, 2]
    assert float(m[1]) == pytest.approx(true, rel=1e-3)
    assert float(m[2]) == pytest.approx(scale * true, rel=2e-2)


@pytest.mark.parametrize(("scale", "turn", "said"), [(-1.0, 1.0, OPPOSITE), (-0.95, 3.0, OPPOSITE), (-0.85, 3.0, SLIP),
                                                     (-1.0, 0.5, OPPOSITE), (-1.0, 0.4, SLIP),
                                                     (0.97 * 180 / math.pi, 1.0, DEG_S), (30.0, 1.0, SLIP),
                                                     (0.5, 1.0, SLIP)])
def test_the_imu_frame_is_said_within_the_check_tolerance_and_past_a_least_turn(scale, turn, said):
    """The heading turns `turn` rad in 5 s and back over 20 s; the IMU reads `scale` times it. The IMU's frame or
    units are said when its turns over the scale agree with the heading's by the check's rule (0.05 rad + 0.005 rad/s
    x 10 s + 10 % of the turn: over 3 rad, -0.95 does and -0.85 does not; 0.97 x 57.3 does; 30 and 0.5 fit no scale)
    and the odometry turns 0.5 rad somewhere (diagnostics.IMU_FRAME_MIN_TURN: 0.4 rad does not)."""
    from wmrkit.odometry.diagnostics import IMU_FRAME_MIN_TURN, imu_warning

    assert IMU_FRAME_MIN_TURN == 0.5
    grid = np.arange(0.0, 20.01, 5.0)
    heading = turn * np.array([0.0, 1.0, 1.0, 0.0, 0.0])
    line = imu_warning(grid, heading, scale * heading, "/imu")
    assert line is not None and said in line and (said == SLIP) == line.endswith(SLIP)
