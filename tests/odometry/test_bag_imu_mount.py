"""A bag's IMU mounted turned on the robot: its ``frame_id`` placed by the bag's ``/tf_static`` gives the robot's yaw
(rate); a frame that tree does not place is refused, naming the file, topic and frame.

The IMU's readings are made here from the true heading with scipy's rotations (independent of wmrkit's quaternion
code): a gyro reads ``R^T (0, 0, yaw rate)``, an orientation is ``q_world_body q_body_imu``."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from wmrkit import catalog
from wmrkit.cli.main import main
from wmrkit.odometry import simulate
from wmrkit.odometry.bag_imu import read_imu
from wmrkit.odometry.logs import LogError
from wmrkit.odometry.synthetic import TwistProfile

pytest.importorskip("rosbags")

T0 = 1000.0
#: base_footprint -> base_link (a yaw of 0.3 rad, which changes nothing measured) -> imu_link (on its side: x forward,
#: its z along the robot's -y, its y up) as ``(parent, child, rotation)``.
SIDEWAYS = (("base_footprint", "base_link", Rotation.from_euler("z", 0.3)),
            ("base_link", "imu_link", Rotation.from_euler("x", math.pi / 2)))
UPSIDE_DOWN = (("base_link", "imu_link", Rotation.from_euler("x", math.pi)),)
TILTED = (("base_link", "imu_link", Rotation.from_euler("ZYX", [0.7, 0.4, -1.1])),)


@pytest.fixture(scope="module")
def run():
    """A differential drive through turns both ways (12 s; its heading spans about 2.2 rad), no slip."""
    profile = TwistProfile.from_segments([(3.0, 0.4, 0.0, 0.0), (3.0, 0.2, 0.0, 0.6), (6.0, 0.1, 0.0, -0.4)])
    return simulate(catalog.load("diff-drive"), profile, 50.0)


def _write(path, run, kind, mount, *, frame="imu_link", tf=True, frames=None, turned=None):
    """A bag of the `run`'s JointState and an IMU on /imu in `frame` (or `frames`, one per message) turned by `mount`
    (the chain of static transforms, written to /tf_static when `tf`), or by the rotation `turned` when given: its
    orientation or (`kind` "gyro") its rate."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    r_mount = Rotation.identity()
    for _, _, r in mount:
        r_mount = r_mount * r  # the IMU in the chain's root (the body)
    r_mount = r_mount if turned is None else turned
    time = run.log.time
    heading = run.truth[:, 2]
    rate = np.gradient(heading, time)

    def header(t, name):
        sec = math.floor(t)
        return T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](
            sec=sec, nanosec=round((t - sec) * 1e9) % 10**9), frame_id=name)

    vec, quat = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    with Writer(path, version=8) as w:
        if tf:
            conn = w.add_connection("/tf_static", "tf2_msgs/msg/TFMessage", typestore=ts)
            transforms = [T["geometry_msgs/msg/TransformStamped"](
                header=header(T0, parent), child_frame_id=child, transform=T["geometry_msgs/msg/Transform"](
                    translation=vec(x=0.1, y=0.0, z=0.2), rotation=quat(*r.as_quat())))
                for parent, child, r in mount]
            w.write(conn, round(T0 * 1e9), ts.serialize_cdr(T["tf2_msgs/msg/TFMessage"](transforms=transforms),
                                                            "tf2_msgs/msg/TFMessage"))
        conn = w.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        empty = np.zeros(0)
        for t, row in zip(T0 + time, run.log.positions, strict=True):
            msg = T["sensor_msgs/msg/JointState"](header=header(t, ""), name=list(run.log.joints),
                                                  position=row.astype(float), velocity=empty, effort=empty)
            w.write(conn, round(t * 1e9), ts.serialize_cdr(msg, "sensor_msgs/msg/JointState"))
        conn = w.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=ts)
        cov = np.zeros(9)
        for k, t in enumerate(T0 + time):
            if kind == "gyro":
                q, wx, wy, wz = np.zeros(4), *r_mount.inv().apply([0.0, 0.0, rate[k]])
            else:
                q, wx, wy, wz = (Rotation.from_euler("z", heading[k]) * r_mount).as_quat(), 0.0, 0.0, 0.0
            msg = T["sensor_msgs/msg/Imu"](
                header=header(t, frames[k] if frames else frame), orientation=quat(*q),
                orientation_covariance=cov if kind != "gyro" else np.r_[-1.0, np.zeros(8)],
                angular_velocity=vec(x=wx, y=wy, z=wz), angular_velocity_covariance=cov,
                linear_acceleration=vec(x=0.0, y=0.0, z=9.81), linear_acceleration_covariance=cov)
            w.write(conn, round(t * 1e9), ts.serialize_cdr(msg, "sensor_msgs/msg/Imu"))


def _odometry(capsys, bag, *extra):
    code = main(["odometry", "diff-drive", str(bag), "--json", *extra])
    out = capsys.readouterr()
    return code, json.loads(out.out or out.err), out.err


@pytest.mark.parametrize("mount", [SIDEWAYS, UPSIDE_DOWN, TILTED], ids=["sideways", "upside-down", "tilted"])
@pytest.mark.parametrize("kind", ["gyro", "orientation"])
def test_an_imu_placed_by_tf_static_reads_the_robots_heading(tmp_path, run, kind, mount):
    """Before, the IMU's own z was read: on its side its angular_velocity.z is 0 (the IMU 'turned 0 rad'), upside
    down the opposite turn, tilted neither; now the turn is the true heading's (the gyro's within its trapezoids)."""
    bag = tmp_path / "run"
    _write(bag, run, kind, mount)
    t, yaw = read_imu(bag, "/imu")
    heading = run.truth[:, 2]
    np.testing.assert_allclose(t, T0 + run.log.time, atol=1e-9)
    if kind == "gyro":  # integrated from 0; the rate was np.gradient's of the heading
        np.testing.assert_allclose(yaw, heading - heading[0], atol=5e-3)
    else:
        np.testing.assert_allclose(yaw - yaw[0], heading - heading[0], atol=1e-9)
        assert abs(math.remainder(yaw[0] - heading[0], 2 * math.pi)) < 1e-9


def test_a_sideways_imu_placed_by_tf_static_agrees_with_the_odometry(capsys, tmp_path, run):
    """The CLI end to end: before, 'the no-slip odometry's heading contradicts the IMU on /imu: ... the IMU 0 rad ...:
    the wheels slip' on a run without slip; now consistent, no warning."""
    bag = tmp_path / "run"
    _write(bag, run, "gyro", SIDEWAYS)
    code, answer, err = _odometry(capsys, bag)
    assert code == 0 and answer["imu"] == "/imu" and answer["consistent"], err
    assert answer["warnings"] == [] and "warning" not in err


def test_an_imu_frame_the_tree_does_not_place_is_refused(capsys, tmp_path, run):
    """The bag's /tf_static places base_link and imu_link, the IMU publishes in 'imu_top': its mounting is unknown.
    Before, read as if level (exit 0); now named with --imu: one line naming the file, the topic and the frame, exit
    2; found by itself: not checked, a warning saying why."""
    bag = tmp_path / "run"
    _write(bag, run, "gyro", SIDEWAYS, frame="imu_top")
    with pytest.raises(LogError, match=r"run: /imu: the IMU's frame 'imu_top' is not in the bag's /tf_static"):
        read_imu(bag, "/imu")
    code, answer, _ = _odometry(capsys, bag, "--imu", "/imu")
    assert code == 2 and answer["file"] == str(bag) and answer["error"] == (
        "/imu: the IMU's frame 'imu_top' is not in the bag's /tf_static (which places base_footprint, base_link, "
        "imu_link): its mounting on the robot is unknown, so its yaw rate is not the robot's")
    code, answer, err = _odometry(capsys, bag)
    assert code == 0 and answer["imu"] is None
    (line,) = answer["warnings"]
    assert "the IMU's frame 'imu_top' is not in the bag's /tf_static" in line and "not checked" in line
    assert f"wmrkit: warning: {line}" in err


def test_the_tree_root_and_a_bag_without_tf_static_are_level(tmp_path, run):
    """An IMU publishing in the root of the static tree (base_footprint), or in a bag without /tf_static, is read as
    mounted level: its z is the robot's."""
    for name, frame, tf in (("root", "base_footprint", True), ("no-tf", "imu_link", False)):
        bag = tmp_path / name
        _write(bag, run, "gyro", SIDEWAYS, frame=frame, tf=tf, turned=Rotation.identity())
        _, yaw = read_imu(bag, "/imu")
        np.testing.assert_allclose(yaw, run.truth[:, 2] - run.truth[0, 2], atol=5e-3)


def test_an_imu_changing_frame_is_refused(tmp_path, run):
    """One IMU topic whose frame_id changes mid-bag (two mountings): refused, naming the message."""
    frames = ["imu_link"] * len(run.log.time)
    frames[7] = "base_link"
    bag = tmp_path / "run"
    _write(bag, run, "gyro", UPSIDE_DOWN, frames=frames)
    with pytest.raises(LogError, match=r"run: /imu message 7: frame_id 'base_link', not the first message's "
                                       r"'imu_link'"):
        read_imu(bag, "/imu")


def _rpy(rotation: Rotation) -> list[float]:
    """URDF's (roll, pitch, yaw) of a rotation, by scipy: intrinsic ZYX angles reversed."""
    return rotation.as_euler("ZYX")[::-1].tolist()


R_TILTED = TILTED[0][2]


@pytest.mark.parametrize("kind", ["gyro", "orientation"])
def test_mount_reads_a_tilted_imu_of_a_bag_without_tf_static(tmp_path, run, kind):
    """No /tf_static, an IMU tilted on the robot: taken as level its gyro turns 0.42 times the robot (its z only) and
    its orientation's yaw starts 0.7 rad off; with mount=(roll, pitch, yaw) both are the robot's heading."""
    bag = tmp_path / "run"
    _write(bag, run, kind, TILTED, tf=False)
    heading = run.truth[:, 2]
    _, level = read_imu(bag, "/imu")
    _, mounted = read_imu(bag, "/imu", mount=_rpy(R_TILTED))
    if kind == "gyro":
        assert abs((level[-1] - level[0]) - (heading[-1] - heading[0])) > 0.1
        assert np.max(np.abs(level - (heading - heading[0]))) > 0.5
        np.testing.assert_allclose(mounted, heading - heading[0], atol=5e-3)
    else:
        assert abs(level[0] - heading[0] - 0.7) < 1e-9
        np.testing.assert_allclose(mounted, heading, atol=1e-9)


def test_imu_mount_makes_a_tilted_imu_agree_with_the_odometry(capsys, tmp_path, run):
    """The CLI end to end on the bag above (gyro): without --imu-mount "assumed level (no /tf_static)" and the IMU
    contradicts the odometry; with it (degrees read as other angle options) consistent, no warning; the text and
    JSON say where the mounting came from."""
    bag = tmp_path / "run"
    _write(bag, run, "gyro", TILTED, tf=False)
    code, answer, err = _odometry(capsys, bag)
    assert code == 0 and answer["imu"] == "/imu" and answer["imu_mount"] == "assumed level (no /tf_static)"
    assert not answer["consistent"] and "contradicts the IMU on /imu" in answer["warnings"][0]
    roll, pitch, yaw = _rpy(R_TILTED)
    code, answer, err = _odometry(capsys, bag, "--imu-mount", repr(roll), f"{math.degrees(pitch)!r} deg", repr(yaw))
    assert code == 0 and answer["consistent"] and answer["warnings"] == [] and "warning" not in err
    assert answer["imu"] == "/imu" and answer["imu_mount"] == "--imu-mount"
    assert main(["odometry", "diff-drive", str(bag), "--imu-mount", repr(roll), repr(pitch), repr(yaw)]) == 0
    assert capsys.readouterr().out.endswith("heading checked against the IMU on /imu, its mounting from --imu-mount\n")
    assert main(["odometry", "diff-drive", str(bag)]) == 0
    assert capsys.readouterr().out.endswith(
        "heading checked against the IMU on /imu, its mounting assumed level (no /tf_static)\n")


def test_imu_mount_overrides_tf_static_and_says_when_they_disagree(capsys, tmp_path, run):
    """A bag whose /tf_static says the IMU is on its side while it is tilted: --imu-mount wins, a warning says how far
    apart the two are (the angle by scipy); one that agrees with /tf_static (90 deg, 0, 0.3) says nothing; an IMU frame
    /tf_static does not place is read with --imu-mount, not refused."""
    bag = tmp_path / "wrong-tf"
    _write(bag, run, "gyro", SIDEWAYS, turned=R_TILTED)
    code, answer, _ = _odometry(capsys, bag)
    assert code == 0 and answer["imu_mount"] == "/tf_static" and not answer["consistent"]
    code, answer, err = _odometry(capsys, bag, "--imu-mount", *map(repr, _rpy(R_TILTED)))
    assert code == 0 and answer["imu_mount"] == "--imu-mount" and answer["consistent"]
    (line,) = answer["warnings"]
    apart = (Rotation.from_euler("z", 0.3) * Rotation.from_euler("x", math.pi / 2)).inv() * R_TILTED
    assert line.startswith(f"{bag}: /imu: --imu-mount turns the IMU {apart.magnitude():.3g} rad (")
    assert "from the mounting the bag's /tf_static gives its frame 'imu_link' (roll, pitch, yaw 1.571, 0, 0.3 rad): " \
           "--imu-mount is used" in line and f"wmrkit: warning: {line}" in err
    bag = tmp_path / "sideways"
    _write(bag, run, "gyro", SIDEWAYS)
    code, answer, _ = _odometry(capsys, bag, "--imu-mount", "90deg", "0", "0.3")
    assert code == 0 and answer["consistent"] and answer["warnings"] == [] and answer["imu_mount"] == "--imu-mount"
    bag = tmp_path / "unplaced"
    _write(bag, run, "gyro", SIDEWAYS, frame="imu_top", turned=R_TILTED)
    code, answer, _ = _odometry(capsys, bag, "--imu", "/imu", "--imu-mount", *map(repr, _rpy(R_TILTED)))
    assert code == 0 and answer["consistent"] and answer["warnings"] == [] and answer["imu_mount"] == "--imu-mount"


def test_a_bad_imu_mount_is_one_line(capsys, tmp_path, run):
    """Not three finite angles, on a CSV log, on a bag without an Imu topic: one line, exit 2 (JSON under --json);
    in Python a ShapeError naming mount, before the bag is read."""
    from wmrkit.errors import ShapeError
    from wmrkit.odometry.bags import write_joint_states

    bag = tmp_path / "run"
    _write(bag, run, "gyro", TILTED, tf=False)
    code, answer, _ = _odometry(capsys, bag, "--imu-mount", "nan", "0", "0")
    assert code == 2 and answer["error"].startswith("--imu-mount ROLL: cannot read 'nan' as an angle")
    code, answer, _ = _odometry(capsys, bag, "--imu-mount", "0", "1e400", "0")
    assert code == 2 and answer["error"].startswith("--imu-mount PITCH: must be finite")
    assert main(["odometry", "diff-drive", str(bag), "--imu-mount", "0", "0"]) == 2
    assert "argument --imu-mount: expected 3 arguments" in capsys.readouterr().err
    csv = tmp_path / "log.csv"
    csv.write_text("time,left.spin,right.spin\n0,0,0\n1,1,1\n")
    code, answer, _ = _odometry(capsys, csv, "--imu-mount", "0", "0", "0")
    assert code == 2 and answer["error"].startswith("--imu-mount applies to ROS 2 bags")
    plain = tmp_path / "no-imu"
    write_joint_states(plain, run.log)
    code, answer, _ = _odometry(capsys, plain, "--imu-mount", "0", "0", "0")
    assert code == 2 and answer["error"] == f"--imu-mount applies to the IMU the heading is checked against; {plain} " \
                                            "has no Imu topic"
    for mount, said in (((math.nan, 0, 0), r"mount: angles must be finite"), ((0.0, 0.0), r"mount: expected shape"),
                        ("0 0 0", r"mount: got the text"), (np.zeros((2, 3)), r"mount: expected 3 angles")):
        with pytest.raises(ShapeError, match=said):
            read_imu(tmp_path / "no-such-bag", "/imu", mount=mount)
