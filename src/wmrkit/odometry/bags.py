"""ROS 2 bags (via ``rosbags``): read ``sensor_msgs/msg/JointState`` as joint logs, find a bag's
``sensor_msgs/msg/Imu`` topic (read as a yaw by :mod:`.bag_imu`), write ``nav_msgs/msg/Odometry``.

JointState ``position`` entries are read as cumulative wheel angles and steering **headings** [rad] (as
ros2_control's joint state broadcaster publishes them: a steering joint reads 0 when its wheel rolls straight
ahead), converted to the thesis's β of :class:`~.logs.JointLog` with the robot's wheels (:mod:`.steering`); the
writer converts back. Joint names are the robot's ``WHEEL.spin`` / ``WHEEL.steer`` unless
``names`` maps ROS names onto them. Messages naming none of the needed joints (other publishers on the topic)
are skipped; a message naming some but not all, or one of them twice, is an error. Time is the header stamp (the
bag's receive time when the stamp is zero), strictly increasing.

``rosbags`` is the optional extra ``bags``, imported on first use. A bag that cannot be read (no metadata, an
unknown version, a file that is no SQLite or MCAP store, metadata larger than :data:`MAX_METADATA` or using
YAML anchors, a message that does not decode) is refused with one :class:`LogError` line naming the file.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WmrkitError
from ._text import did_you_mean
from .integrators import sinc
from .logs import MAX_RATE, JointLog, LogError, check_jumps, check_time, joint_names
from .pipeline import check_finite
from .steering import check_robot, check_steer_range, convert_steering

if TYPE_CHECKING:
    from ..robot import Robot
from .trajectories import Trajectory, quaternion_z, yaw_of_quaternion

JOINT_STATE = "sensor_msgs/msg/JointState"
IMU = "sensor_msgs/msg/Imu"
#: How many of the names a bag's messages give an error quotes when none names the robot's joints.
MAX_SEEN_NAMES = 16
ODOMETRY = "nav_msgs/msg/Odometry"


#: First time [s] past what a ROS 2 stamp holds (``builtin_interfaces/msg/Time``: int32 seconds, never negative).
MAX_STAMP = 2.0 ** 31

#: Largest ``metadata.yaml`` read [bytes]; ``ros2 bag`` writes a few kilobytes.
MAX_METADATA = 1 << 20

_YAML_ALIAS = re.compile(r"(?:^|[\s\[{,:-])[&*][^\s,\]}]")


def _rosbags(module: str):
    """The ``rosbags`` submodule `module`, or a :class:`WmrkitError` naming the extra to install."""
    import importlib

    try:
        return importlib.import_module(f"rosbags.{module}")
    except ImportError:
        raise WmrkitError("reading and writing ROS 2 bags needs the 'bags' extra: pip install 'wmrkit[bags]'"
                          ) from None


def _open(path: str | os.PathLike[str]):
    """An open ``rosbags`` reader of the bag at `path`, or one :class:`LogError` line naming the file."""
    reader_cls = _rosbags("rosbag2").Reader
    source = os.fspath(path)
    p = Path(source)
    if not p.exists():
        raise LogError(f"{source}: no such bag")
    meta = p / "metadata.yaml" if p.is_dir() else None
    if meta is not None:
        if not meta.is_file():
            raise LogError(f"{source}: not a ROS 2 bag: the directory has no metadata.yaml")
        if meta.stat().st_size > MAX_METADATA:
            raise LogError(f"{meta}: {meta.stat().st_size} bytes of metadata (more than {MAX_METADATA}): not "
                           "written by ros2 bag")
        try:
            text = meta.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as err:
            raise LogError(f"{meta}: cannot read the bag's metadata ({err.__class__.__name__})") from None
        if _YAML_ALIAS.search(text):
            raise LogError(f"{meta}: YAML anchors or aliases in the bag's metadata (ros2 bag writes none; a YAML "
                           "bomb?)")
    try:
        reader = reader_cls(source)
        reader.open()
    except Exception as err:  # rosbags raises its own and sqlite/mcap errors for unreadable bags
        raise LogError(f"{source}: cannot read as a ROS 2 bag ({err.__class__.__name__}: {err})") from None
    return reader


def _messages(reader, conns, source: str, msgtype: str, typestore) -> Iterator[tuple[int, object]]:
    """``(receive time [ns], message)`` of `conns`; a message or store that does not decode is a LogError."""
    it = iter(reader.messages(connections=conns))
    index = 0
    while True:
        try:
            item = next(it, None)
            if item is None:
                return
            _, stamp_ns, data = item
            msg = typestore.deserialize_cdr(data, msgtype)
        except Exception as err:  # corrupt store or message: rosbags, sqlite3, struct, index errors
            raise LogError(f"{source}: message {index}: cannot decode ({err.__class__.__name__}: {err})") from None
        yield stamp_ns, msg
        index += 1


def _typestore():
    _rosbags("rosbag2")
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def _check_stamps(path: str, time: np.ndarray) -> None:
    """Refuse times [s] a ROS 2 stamp cannot hold (outside [0, :data:`MAX_STAMP`)), naming the bag `path`."""
    bad = np.flatnonzero(~((time >= 0) & (time < MAX_STAMP)))
    if bad.size:
        raise LogError(f"{path}: time {float(time[bad[0]])!r} s is no ROS 2 time stamp (0 to 2^31 s, "
                       "builtin_interfaces/Time's int32 seconds): is the log's time unit right (--time-unit)?")


def _stamp(t: float):
    ts = _typestore()
    sec = int(np.floor(t))
    return ts.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=round((t - sec) * 1e9) % 1_000_000_000)


def bag_message_count(path: str | os.PathLike[str], topic: str) -> int:
    """Number of messages on `topic` in the bag at `path` (for progress bars)."""
    reader = _open(path)
    try:
        count = sum(c.msgcount for c in reader.connections if c.topic == topic)
    except Exception as err:  # counts of broken metadata
        raise LogError(f"{os.fspath(path)}: unreadable message counts ({err.__class__.__name__})") from None
    finally:
        reader.close()
    return int(count) if isinstance(count, int) else 0


def read_joint_states(path: str | os.PathLike[str], joints: Sequence[str], *, robot: Robot | None = None,
                      topic: str = "/joint_states", names: Mapping[str, str] | None = None,
                      chunk_size: int = 1 << 14, progress: Callable[[int], object] | None = None,
                      max_rate: float | None = MAX_RATE) -> Iterator[JointLog]:
    """Joint logs from the ``JointState`` messages on `topic`, in chunks (bounded memory).

    `robot`: the robot logged, whose wheels convert the steering headings to β (required when `joints` has
    steering joints). `names` maps ROS joint names to the robot's joint names. `progress` is called with the
    number of messages read. Raises :class:`LogError` for a missing bag or topic and for messages lacking some
    joints, and for spin joints turning faster than `max_rate` [rad/s] between two messages
    (:func:`.logs.check_jumps`).
    """
    source, rename = os.fspath(path), dict(names or {})
    joints = joint_names(joints, source)
    check_robot(joints, robot, source)
    wheels = [w.name for w in robot.wheels] if robot is not None else []
    for ros, joint in rename.items():  # a misspelt joint's name would be ignored
        wheel, _, kind = joint.rpartition(".")
        if joint not in joints and (kind not in ("spin", "steer") or (wheels and wheel not in wheels)):
            raise LogError(f"{source}: ROS joint '{ros}' is mapped to '{joint}', no joint of the robot"
                           f"{did_you_mean(joint, wheels)} (joints WHEEL.spin, WHEEL.steer"
                           f"{'; wheels: ' + ', '.join(wheels) if wheels else ''})")
    reader = _open(source)
    ts = _typestore()
    try:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            topics = sorted({c.topic for c in reader.connections})
            raise LogError(f"{source}: no topic '{topic}' (topics: {', '.join(topics) or 'none'})")
        if any(c.msgtype != JOINT_STATE for c in conns):
            raise LogError(f"{source}: topic '{topic}' carries {conns[0].msgtype}, not {JOINT_STATE}")
        times, rows, index, first = [], [], 0, 0
        last: tuple[float, np.ndarray] | None = None
        seen: dict[str, None] = {}  # names of skipped messages, for the error when none names the joints
        for stamp_ns, msg in _messages(reader, conns, f"{source}: {topic}", JOINT_STATE, ts):
            got = {rename.get(n, n): k for k, n in enumerate(msg.name)}
            have = [j for j in joints if j in got]
            if len(got) < len(msg.name):  # a joint named twice: which position is it?
                named = [rename.get(n, n) for n in msg.name]
                twice = [j for j in have if named.count(j) > 1]
                if twice:
                    raise LogError(f"{source}: {topic} message {index}: {twice[0]} is named twice "
                                   f"({', '.join(n for n in msg.name if rename.get(n, n) == twice[0])})")
            if progress is not None:
                progress(1)
            if not have:
                if len(seen) < MAX_SEEN_NAMES:
                    seen.update(dict.fromkeys(msg.name[:MAX_SEEN_NAMES]))
                continue
            if len(have) != len(joints):
                missing = [j for j in joints if j not in got]
                raise LogError(f"{source}: {topic} message {index}: no position for {', '.join(missing)}")
            if len(msg.position) != len(msg.name):
                raise LogError(f"{source}: {topic} message {index}: {len(msg.name)} names but "
                               f"{len(msg.position)} positions")
            stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
            times.append(stamp if stamp > 0 else 1e-9 * stamp_ns)
            rows.append([msg.position[got[j]] for j in joints])
            index += 1
            if len(times) == chunk_size:
                last = yield from _chunk(times, joints, rows, f"{source}: {topic}", first, last, max_rate, robot)
                first, times, rows = index, [], []
        if times:
            yield from _chunk(times, joints, rows, f"{source}: {topic}", first, last, max_rate, robot)
        if index == 0:
            names_seen = list(seen)[:MAX_SEEN_NAMES]
            raise LogError(f"{source}: no JointState message on '{topic}' names the joints {', '.join(joints)}"
                           + (f"; its messages name {', '.join(names_seen)}: map them onto the robot's joints with "
                              f"--joint-name ROS=WHEEL.spin (names= in Python)" if names_seen else ""))
    finally:
        reader.close()


def _chunk(times: list[float], joints: Sequence[str], rows: list, source: str, first: int,
           last: tuple[float, np.ndarray] | None, max_rate: float | None, robot: Robot | None):
    """Yield one chunk (checked for jumps against the `last` sample before it, steering converted to β); return
    its own last sample (as read)."""
    raw = np.array(rows, dtype=float).reshape(len(times), len(joints))
    log = JointLog(np.array(times), tuple(joints), raw, None, source, None, first)
    t = log.time if last is None else np.concatenate([[last[0]], log.time])
    check_finite(log)  # named as such, not as a jump of nan rad
    check_time(log, log.time, None if last is None else last[0], None)  # a repeated stamp, not a jump in 0 s
    check_jumps(log, raw, None if last is None else last[1], t, max_rate)
    check_steer_range(robot, joints, raw, log.where)
    yield JointLog(log.time, log.joints, convert_steering(robot, joints, raw, to="beta", source=source), None,
                   source, None, first)
    return float(log.time[-1]), raw[-1].copy()


def write_joint_states(path: str | os.PathLike[str], log: JointLog, *, robot: Robot | None = None,
                       topic: str = "/joint_states", names: Mapping[str, str] | None = None) -> None:
    """Write `log` as ``JointState`` messages (one per sample) to a new bag; `names` maps joints to ROS names.
    Steering positions are written as headings, converted with `robot` (required when the log steers)."""
    ts = _typestore()
    rename = dict(names or {})
    _check_stamps(os.fspath(path), log.time)
    positions = log.heading_positions(robot)
    header_t, state_t = ts.types["std_msgs/msg/Header"], ts.types[JOINT_STATE]
    with _writer(path) as writer:
        conn = writer.add_connection(topic, JOINT_STATE, typestore=ts)
        names_out = [rename.get(j, j) for j in log.joints]
        empty = np.zeros(0)
        for t, row in zip(log.time.tolist(), positions, strict=True):
            msg = state_t(header=header_t(stamp=_stamp(t), frame_id=""), name=names_out,
                          position=np.asarray(row, dtype=np.float64), velocity=empty, effort=empty)
            writer.write(conn, round(t * 1e9), ts.serialize_cdr(msg, JOINT_STATE))


class OdometryBagWriter:
    """Writes trajectory chunks as ``nav_msgs/msg/Odometry`` to a new bag (context manager).

    Times must lie in [0, :data:`MAX_STAMP`) s (a ROS 2 stamp), else :class:`LogError`.
    Pose covariance: the ``(x, y, theta)`` covariance at rows/columns 0, 1, 5 of the 6x6 ROS matrix (z, roll,
    pitch left 0: planar motion). Twist: the constant body twist ``(vx, vy, omega)`` that moves the robot from the
    pose before to each pose in its interval (the SE(2) logarithm of the step; 0 at the first).
    """

    def __init__(self, path: str | os.PathLike[str], *, topic: str = "/odom", frame_id: str = "odom",
                 child_frame_id: str = "base_link") -> None:
        self._ts = _typestore()
        self.path = os.fspath(path)
        self._ctx = _writer(path)
        self._writer = self._ctx.__enter__()
        self._conn = self._writer.add_connection(topic, ODOMETRY, typestore=self._ts)
        self.frame_id, self.child_frame_id = frame_id, child_frame_id
        self._last: tuple[float, np.ndarray] | None = None

    def write(self, chunk: Trajectory) -> None:
        """Append one Odometry message per pose of `chunk`."""
        t = self._ts.types
        _check_stamps(self.path, chunk.time)
        prev_t = chunk.time[:1] if self._last is None else np.array([self._last[0]])
        prev_p = chunk.poses[:1] if self._last is None else self._last[1][None]
        times, poses = np.concatenate([prev_t, chunk.time]), np.vstack([prev_p, chunk.poses])
        dt = np.diff(times)
        d = np.diff(poses, axis=0)
        # the SE(2) logarithm of the step (the exact scheme's chord form): the chord is Rot(theta + dtheta / 2)
        # (vx, vy) dt sinc(dtheta / 2)
        half = 0.5 * d[:, 2]
        c, s, k = np.cos(poses[:-1, 2] + half), np.sin(poses[:-1, 2] + half), 1.0 / sinc(half)
        body = np.column_stack([k * (c * d[:, 0] + s * d[:, 1]), k * (-s * d[:, 0] + c * d[:, 1]), d[:, 2]])
        twist = np.divide(body, dt[:, None], out=np.zeros_like(body), where=dt[:, None] > 0)
        quats = quaternion_z(chunk.poses[:, 2])
        zero6 = np.zeros(36)
        for k in range(len(chunk)):
            cov = np.zeros(36)
            if chunk.covariance is not None:
                cov.reshape(6, 6)[np.ix_([0, 1, 5], [0, 1, 5])] = chunk.covariance[k]
            x, y, _th = chunk.poses[k]
            pose = t["geometry_msgs/msg/Pose"](
                position=t["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=0.0),
                orientation=t["geometry_msgs/msg/Quaternion"](*(float(v) for v in quats[k])))
            tw = t["geometry_msgs/msg/Twist"](
                linear=t["geometry_msgs/msg/Vector3"](x=float(twist[k, 0]), y=float(twist[k, 1]), z=0.0),
                angular=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=float(twist[k, 2])))
            msg = t[ODOMETRY](
                header=t["std_msgs/msg/Header"](stamp=_stamp(float(chunk.time[k])), frame_id=self.frame_id),
                child_frame_id=self.child_frame_id,
                pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=cov),
                twist=t["geometry_msgs/msg/TwistWithCovariance"](twist=tw, covariance=zero6))
            self._writer.write(self._conn, round(float(chunk.time[k]) * 1e9),
                               self._ts.serialize_cdr(msg, ODOMETRY))
        self._last = (float(chunk.time[-1]), chunk.poses[-1].copy())

    def close(self) -> None:
        """Finish the bag (writes its metadata)."""
        self._ctx.__exit__(None, None, None)

    def __enter__(self) -> OdometryBagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_odometry(path: str | os.PathLike[str], *, topic: str = "/odom") -> Trajectory:
    """Odometry messages of a bag as a :class:`Trajectory` (poses, and the (x, y, theta) covariance)."""
    ts = _typestore()
    times, poses, covs = [], [], []
    reader = _open(path)
    try:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            raise LogError(f"{os.fspath(path)}: no topic '{topic}'")
        for _, m in _messages(reader, conns, f"{os.fspath(path)}: {topic}", ODOMETRY, ts):
            q = m.pose.pose.orientation
            times.append(m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec)
            poses.append([m.pose.pose.position.x, m.pose.pose.position.y,
                          float(yaw_of_quaternion(np.array([q.x, q.y, q.z, q.w])))])
            covs.append(m.pose.covariance.reshape(6, 6)[np.ix_([0, 1, 5], [0, 1, 5])])
    finally:
        reader.close()
    p = np.array(poses).reshape(-1, 3)
    p[:, 2] = np.unwrap(p[:, 2])
    return Trajectory(np.array(times), p, np.zeros(len(times)), np.array(covs).reshape(-1, 3, 3))


def imu_topic(path: str | os.PathLike[str], topic: str | None = None) -> tuple[str | None, str | None]:
    """The ``Imu`` topic of the bag at `path` to check its odometry with, and a note to say: `topic` itself (a
    :class:`LogError` when the bag has no ``Imu`` topic of that name), else the bag's only ``Imu`` topic (noted), else
    None (noted when it has several)."""
    source, reader = os.fspath(path), _open(path)
    try:
        types = {c.topic: c.msgtype for c in reader.connections}
    finally:
        reader.close()
    imus = sorted(t for t, m in types.items() if m == IMU)
    if topic is not None:
        if types.get(topic) != IMU:
            what = f"carries {types[topic]}, not {IMU}" if topic in types else "is not in the bag"
            raise LogError(f"{source}: --imu topic '{topic}' {what} ({IMU} topics: {', '.join(imus) or 'none'})")
        return topic, None
    if len(imus) == 1:
        return imus[0], (f"heading checked against the IMU on {imus[0]}, the bag's one {IMU} topic (--imu TOPIC "
                         "chooses it)")
    return None, (f"heading not checked against an IMU: the bag has {len(imus)} {IMU} topics ({', '.join(imus)}); "
                  "choose one with --imu TOPIC") if imus else None


def _writer(path: str | os.PathLike[str]):
    Writer = _rosbags("rosbag2").Writer

    if Path(path).exists():
        raise LogError(f"{os.fspath(path)}: already exists (a bag is a new directory)")
    return Writer(path, version=8)
