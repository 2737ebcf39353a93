"""ROS 2 bags: a JointState bag made from a synthetic run (at test time), read back; Odometry bags written."""

from __future__ import annotations

import numpy as np
import pytest

from wmrkit import catalog
from wmrkit.odometry.bags import (
    JOINT_STATE,
    OdometryBagWriter,
    bag_message_count,
    read_joint_states,
    read_odometry,
    write_joint_states,
)
from wmrkit.odometry.covariance import CrowleyNoise
from wmrkit.odometry.files import odometry_file
from wmrkit.odometry.logs import JointLog, LogError, concatenate
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.synthetic import TwistProfile, simulate

pytest.importorskip("rosbags")

ROS_NAMES = {"front_left.spin": "fl_wheel_joint", "front_right.spin": "fr_wheel_joint",
             "rear_left.spin": "rl_wheel_joint", "rear_right.spin": "rr_wheel_joint"}


@pytest.fixture(scope="module")
def mecanum_bag(tmp_path_factory):
    """The example bag: a Mecanum robot strafing and turning, JointState with ROS-style joint names."""
    robot = catalog.load("mecanum-4")
    profile = TwistProfile.from_segments([(2.0, 0.3, 0.2, 0.0), (2.0, 0.0, -0.3, 0.4), (1.0, 0.2, 0.0, -0.5)])
    run = simulate(robot, profile, 25.0)
    path = tmp_path_factory.mktemp("bags") / "mecanum_joint_states"
    write_joint_states(path, run.log, names=ROS_NAMES)
    return robot, run, path


def test_joint_state_bag_reads_back_the_log(mecanum_bag):
    _, run, path = mecanum_bag
    assert bag_message_count(path, "/joint_states") == len(run.log)
    back = {v: k for k, v in ROS_NAMES.items()}
    joints = run.log.joints[::-1]  # any order the model asks for
    log = concatenate(list(read_joint_states(path, joints, names=back, chunk_size=17)))
    np.testing.assert_allclose(log.time, run.log.time, atol=1e-9)
    np.testing.assert_array_equal(log.positions, run.log.positions[:, ::-1])


def test_odometry_from_the_bag_equals_odometry_from_memory(mecanum_bag, tmp_path):
    robot, run, path = mecanum_bag
    out = tmp_path / "odom"
    summary = odometry_file(robot, path, joint_names={v: k for k, v in ROS_NAMES.items()}, out=out,
                            noise=CrowleyNoise())
    ref = odometry(robot, run.log, noise=CrowleyNoise())
    np.testing.assert_allclose(summary.final_pose, ref.final_pose, atol=1e-12)
    np.testing.assert_allclose(summary.final_pose, run.truth[-1], atol=1e-9)
    written = read_odometry(out)
    np.testing.assert_allclose(written.poses, ref.poses, atol=1e-12)
    np.testing.assert_allclose(written.covariance, ref.covariance, atol=1e-15)
    np.testing.assert_allclose(written.time, ref.time, atol=1e-9)


def test_odometry_bag_twist_is_the_body_velocity(tmp_path):
    t = np.arange(5) * 0.5
    poses = np.column_stack([np.cos(t), np.sin(t), t + np.pi / 2])  # unit circle at 1 rad/s: body twist (1, 0, 1)
    from wmrkit.odometry.trajectories import Trajectory

    with OdometryBagWriter(tmp_path / "o") as w:
        w.write(Trajectory(t[:2], poses[:2], np.zeros(2)))
        w.write(Trajectory(t[2:], poses[2:], np.zeros(3)))
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(tmp_path / "o") as reader:
        msgs = [ts.deserialize_cdr(d, c.msgtype) for c, _, d in reader.messages()]
    assert msgs[0].twist.twist.linear.x == 0.0
    for m in msgs[1:]:  # the finite difference read in the frame at the start of each 0.5 s chord had vy = 0.245 m/s
        assert m.twist.twist.linear.x == pytest.approx(1.0, abs=1e-12)
        assert m.twist.twist.linear.y == pytest.approx(0.0, abs=1e-12)
        assert m.twist.twist.angular.z == pytest.approx(1.0, abs=1e-12)
        assert m.header.frame_id == "odom" and m.child_frame_id == "base_link"


def test_bad_bags(mecanum_bag, tmp_path):
    _, run, path = mecanum_bag
    with pytest.raises(LogError, match=r"no topic '/js' \(topics: /joint_states\)"):
        list(read_joint_states(path, run.log.joints, topic="/js"))
    with pytest.raises(LogError, match="no JointState message on '/joint_states' names the joints"):
        list(read_joint_states(path, run.log.joints))  # ROS names not mapped
    with pytest.raises(LogError, match="no such bag"):
        list(read_joint_states(tmp_path / "missing", run.log.joints))
    partial = tmp_path / "partial"
    log = JointLog(run.log.time[:3], run.log.joints[:3], run.log.positions[:3, :3])
    write_joint_states(partial, log)
    with pytest.raises(LogError, match=r"/joint_states message 0: no position for rear_right\.spin"):
        list(read_joint_states(partial, run.log.joints))
    with pytest.raises(LogError, match="already exists"):
        write_joint_states(partial, log)


def test_a_bag_of_unmapped_ros_names_is_refused_with_the_names_it_holds(mecanum_bag, capsys):
    """A ROS 2 user's bag (fl_wheel_joint, ...) read without --joint-name said only that no message names
    front_left.spin, ...: not which names the bag holds, nor how to map them."""
    from wmrkit.cli.main import main

    _, run, path = mecanum_bag
    ros = ", ".join(ROS_NAMES[j] for j in run.log.joints)
    with pytest.raises(LogError, match=f"; its messages name {ros}: map them onto the robot's joints with "
                                       r"--joint-name ROS=WHEEL\.spin \(names= in Python\)"):
        list(read_joint_states(path, run.log.joints))
    assert main(["odometry", "mecanum-4", str(path)]) == 2
    assert "its messages name fl_wheel_joint" in capsys.readouterr().err


@pytest.mark.parametrize("start", [3e9, -1.0, 1e300])
def test_times_a_ros_stamp_cannot_hold_are_refused_by_name(tmp_path, start):
    """A log's time beyond 2^31 s (a ms log read as s, an epoch in ms) raised struct.error from rosbags' int32
    seconds, 1e300 s an OverflowError: tracebacks. Negative stamps were written (ROS 2 refuses them)."""
    from wmrkit.cli.main import main
    from wmrkit.odometry.trajectories import Trajectory

    path = tmp_path / "log.csv"
    path.write_text(f"time,left.spin,right.spin\n{start!r},0,0\n{start * (1 + 1e-9) + 1!r},1,1\n")
    assert main(["odometry", "diff-drive", str(path), "--out", str(tmp_path / "odom")]) == 2
    with pytest.raises(LogError, match=r"is no ROS 2 time stamp \(0 to 2\^31 s"):
        with OdometryBagWriter(tmp_path / "o") as w:
            w.write(Trajectory(np.array([start]), np.zeros((1, 3)), np.zeros(1)))
    with pytest.raises(LogError, match=r"js: time .* is no ROS 2 time stamp"):
        write_joint_states(tmp_path / "js", JointLog(np.array([start]), ("left.spin",), np.zeros((1, 1))))


@pytest.mark.parametrize("name", ["odom", "odom.csv", "odom.tum"])
def test_a_run_that_fails_leaves_no_partial_output(tmp_path, name):
    """A log broken half way (NaN at row 60) is refused, and the trajectory file or bag begun is removed: a partial
    output (the bag's metadata, a CSV header) would read as the run's result."""
    log = tmp_path / "log.csv"
    rows = [f"{0.01 * i},{0.1 * i if i != 60 else 'nan'},{0.1 * i}" for i in range(100)]
    log.write_text("time,left.spin,right.spin\n" + "\n".join(rows) + "\n")
    out = tmp_path / name
    with pytest.raises(LogError, match=r"log\.csv:62: column 'left\.spin': value nan"):
        odometry_file(catalog.load("diff-drive"), log, out=out, chunk_size=16)  # chunks before row 60 written
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["log.csv"]


def test_header_stamps_going_backwards_are_named_as_such(tmp_path):
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    state, header, stamp = (ts.types[t] for t in (JOINT_STATE, "std_msgs/msg/Header", "builtin_interfaces/msg/Time"))
    with Writer(tmp_path / "js", version=8) as w:  # received in order, stamped 1 s, 2 s, 1.5 s
        conn = w.add_connection("/joint_states", JOINT_STATE, typestore=ts)
        for k, (sec, nsec) in enumerate([(1, 0), (2, 0), (1, 500_000_000)]):
            msg = state(header=header(stamp=stamp(sec=sec, nanosec=nsec), frame_id=""),
                        name=["left.spin", "right.spin"], position=np.full(2, float(k)),
                        velocity=np.zeros(0), effort=np.zeros(0))
            w.write(conn, (k + 1) * 10**9, ts.serialize_cdr(msg, JOINT_STATE))
    for chunk_size in (1, 10):  # was: "turns 1 rad in -0.5 s (-2 rad/s > 10000 rad/s): an implausible jump"
        with pytest.raises(LogError, match=r"sample 2: time 1.5 s goes backwards"):
            list(read_joint_states(tmp_path / "js", ("left.spin", "right.spin"), chunk_size=chunk_size))


@pytest.mark.parametrize(("time", "left", "message"), [
    ([0.0, 1.0, 1.0], [0.0, 1.0, 2.0], r"sample 2: time 1.0 s repeats the previous sample"),  # was: "in 0 s"
    ([0.0, 1.0, 2.0], [0.0, np.nan, 2.0], r"sample 1: left.spin: value nan is not a finite number"),
])
def test_bad_stamps_and_positions_of_a_bag_are_named_as_such(tmp_path, time, left, message):
    path = tmp_path / "js"
    write_joint_states(path, JointLog(np.array(time), ("left.spin", "right.spin"),
                                      np.column_stack([left, [0.0, 1.0, 2.0]])))
    for chunk_size in (1, 10):
        with pytest.raises(LogError, match=message):
            list(read_joint_states(path, ("left.spin", "right.spin"), chunk_size=chunk_size))


def test_a_joint_named_twice_in_a_message_is_refused(tmp_path):
    path = tmp_path / "js"  # the last of the two positions was used silently
    write_joint_states(path, JointLog(np.array([0.0, 1.0]), ("left.spin", "right.spin"), np.array([[0, 0], [1, 2.0]])),
                       names={"right.spin": "left.spin"})
    with pytest.raises(LogError, match=r"message 0: left.spin is named twice \(left.spin, left.spin\)"):
        list(read_joint_states(path, ("left.spin", "right.spin")))
    with pytest.raises(LogError, match=r"message 0: right.spin is named twice \(wheel_l, wheel_r\)"):
        write_joint_states(tmp_path / "js2", JointLog(np.array([0.0, 1.0]), ("left.spin", "right.spin"),
                                                      np.array([[0, 0], [1, 2.0]])),
                           names={"left.spin": "wheel_l", "right.spin": "wheel_r"})
        list(read_joint_states(tmp_path / "js2", ("left.spin", "right.spin"),
                               names={"wheel_l": "right.spin", "wheel_r": "right.spin"}))


def test_a_ros_name_mapped_to_no_joint_of_the_robot_is_refused(mecanum_bag):
    robot, run, path = mecanum_bag  # a misspelt target was ignored silently
    names = {v: k for k, v in ROS_NAMES.items()} | {"x_joint": "front_lfet.spin"}
    with pytest.raises(LogError, match=r"ROS joint 'x_joint' is mapped to 'front_lfet\.spin', no joint of the "
                                         r"robot \(did you mean 'front_left\.spin'\?\)"):
        list(read_joint_states(path, run.log.joints, robot=robot, names=names))
