"""A ROS 2 bag's ``sensor_msgs/msg/Imu`` topic read as the robot's yaw, for the heading check of ``wmrkit odometry``
(:mod:`.diagnostics`): the orientation's yaw, or the gyro's yaw rate integrated, turned into the robot's body by the
IMU's mounting (:mod:`.imu_mount`: given as ``mount=(roll, pitch, yaw)``, else the bag's ``/tf_static``, else level).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator

import numpy as np
from numpy.typing import ArrayLike

from ..limits import MAX_SPEED, MAX_TABLE_SIZE
from .bags import IMU, _messages, _open, _typestore, bag_message_count
from .imu_mount import (
    TF_MESSAGE,
    TF_STATIC,
    ImuMounting,
    quaternion_product,
    quaternion_rpy,
    resolve_mounting,
    static_tree,
    yaw_row,
)
from .logs import LogError
from .trajectories import yaw_of_quaternion

#: Most ``Imu`` messages read for the heading check (:func:`read_imu`): their time and yaw are held whole, 16 bytes
#: each, at most what wmrkit reads whole into memory (``limits.MAX_TABLE_SIZE``): 2.9 h at 400 Hz.
MAX_IMU_MESSAGES = MAX_TABLE_SIZE // 16
#: ``Imu`` messages per chunk of :func:`read_imu_yaw` (by default) and :func:`read_imu`.
IMU_CHUNK = 1 << 14


def read_imu_yaw(path: str | os.PathLike[str], topic: str, *, mount: ArrayLike | None = None,
                 chunk_size: int = IMU_CHUNK) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """``(time [s], yaw [rad])`` chunks of the ``Imu`` messages on `topic`, the yaw continuous (unwrapped).

    The yaw is the orientation's (REP-103 / REP-145: about z, counter-clockwise, ZYX Euler angles); when the first
    message has none (``orientation_covariance[0] == -1``, REP-145, or an all-zero quaternion) it is
    ``angular_velocity.z`` [rad/s, at most :data:`~wmrkit.limits.MAX_SPEED`] integrated by trapezoids from 0. Time
    as JointState's (the header stamp, else the receive time), strictly increasing. A :class:`LogError` names the
    message of a bad stamp or value. The IMU's mounting (:func:`~.imu_mount.resolve_mounting`): `mount` ``(roll,
    pitch, yaw)`` [rad] (URDF / REP-103, ``Rz Ry Rx``: the IMU's frame in the robot's; 3 finite angles, else a
    :class:`~wmrkit.errors.ShapeError`) when given, overriding the bag's ``/tf_static``; else the ``/tf_static``
    that places its ``frame_id`` (one it does not place is a :class:`LogError`, the mounting unknown); else, a bag
    without ``/tf_static``, level (z up).
    """
    yield from _imu_chunks(path, topic, mount, "mount=", chunk_size, [])


def _imu_chunks(path: str | os.PathLike[str], topic: str, mount: ArrayLike | None, option: str, chunk_size: int,
                said: list[ImuMounting]) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """:func:`read_imu_yaw`, appending the IMU's mounting to `said` at its first message (`option` names `mount`)."""
    if mount is not None:
        quaternion_rpy(mount, option.rstrip("="))  # refused before the bag is opened (at the first chunk asked)
    source = os.fspath(path)
    where = f"{source}: {topic}"
    reader, ts = _open(source), _typestore()
    try:
        conns = [c for c in reader.connections if c.topic == topic and c.msgtype == IMU]
        if not conns:  # (no connections would read every topic's messages)
            raise LogError(f"{where}: no {IMU} topic of that name")
        tf = [c for c in reader.connections if c.topic == TF_STATIC and c.msgtype == TF_MESSAGE]
        where_tf = f"{source}: {TF_STATIC}"
        tree = static_tree((m for _, m in _messages(reader, tf, where_tf, TF_MESSAGE, ts)), where_tf) if tf else {}
        gyro, last, times, values, q_body_imu, row = None, None, [], [], None, None
        for index, (stamp_ns, msg) in enumerate(_messages(reader, conns, where, IMU, ts)):
            o, frame = msg.orientation, msg.header.frame_id
            q = (o.x, o.y, o.z, o.w)
            if gyro is None:
                gyro = msg.orientation_covariance[0] == -1 or not any(q)
                said.append(resolve_mounting(tree, frame, where, mount, option))
                first_frame, turned = frame, said[-1].quaternion
                q_body_imu = None if turned is None else np.array(turned)
                row = None if q_body_imu is None else yaw_row(q_body_imu)
            elif frame != first_frame:
                raise LogError(f"{where} message {index}: frame_id '{frame}', not the first message's "
                               f"'{first_frame}' (one IMU has one mounting)")
            w = msg.angular_velocity
            rate, what = (w.z, "angular_velocity.z") if row is None else \
                (float(row @ (w.x, w.y, w.z)), f"the yaw rate (angular_velocity turned from '{frame}')")
            if gyro and not abs(rate) <= MAX_SPEED:  # NaN included
                raise LogError(f"{where} message {index}: {what} is {rate:g} rad/s, not "
                               f"a finite rate within the {MAX_SPEED:g} rad/s of any wheeled robot (docs/limits.md)")
            if not gyro and not (all(map(math.isfinite, q)) and any(q)):
                raise LogError(f"{where} message {index}: orientation {list(q)} is no rotation")
            stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
            t = stamp if stamp > 0 else 1e-9 * stamp_ns
            if t <= (times[-1] if times else last[0] if last else -math.inf):
                raise LogError(f"{where} message {index}: time {t!r} s does not follow the previous message's")
            times.append(t)
            values.append(rate if gyro else q)
            if len(times) == chunk_size:
                last = yield from _yaw_chunk(np.array(times), _readings(values, gyro, q_body_imu), gyro, last)
                times, values = [], []
        if times:
            yield from _yaw_chunk(np.array(times), _readings(values, gyro, q_body_imu), gyro, last)
        elif last is None:
            raise LogError(f"{where}: no message")
    finally:
        reader.close()


def read_imu(path: str | os.PathLike[str], topic: str, *,
             mount: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The whole ``(time [s], yaw [rad])`` of :func:`read_imu_yaw` (`mount` as there); more than
    :data:`MAX_IMU_MESSAGES` messages (by the bag's count, then as read) are a :class:`LogError`."""
    time, yaw, _ = read_imu_mounted(path, topic, mount=mount)
    return time, yaw


def read_imu_mounted(path: str | os.PathLike[str], topic: str, *, mount: ArrayLike | None = None,
                     option: str = "mount=") -> tuple[np.ndarray, np.ndarray, ImuMounting]:
    """:func:`read_imu`, and the IMU's mounting and where it came from (:class:`~.imu_mount.ImuMounting`; `option`
    names `mount` there: ``"--imu-mount"`` for the CLI)."""
    where, most = f"{os.fspath(path)}: {topic}", MAX_IMU_MESSAGES

    def too_many(count: int) -> LogError:
        return LogError(f"{where}: {count} messages, more than the {most} the IMU check holds in memory "
                        f"({MAX_TABLE_SIZE} bytes, docs/limits.md)")

    if mount is not None:
        quaternion_rpy(mount, option.rstrip("="))  # refused before the bag is opened
    if (count := bag_message_count(path, topic)) > most:
        raise too_many(count)
    said: list[ImuMounting] = []
    times, yaws, count, chunks = [], [], 0, _imu_chunks(path, topic, mount, option, IMU_CHUNK, said)
    try:
        for t, yaw in chunks:
            count += len(t)
            if count > most:  # the bag's count was wrong
                raise too_many(count)
            times.append(t)
            yaws.append(yaw)
    finally:
        chunks.close()  # the bag's reader closed now
    return np.concatenate(times), np.concatenate(yaws), said[0]


def _readings(values: list, gyro: bool, mount: np.ndarray | None) -> np.ndarray:
    """The readings of a chunk of :func:`read_imu_yaw`: its rates, or the yaws of its quaternions, the body's
    (``q_world_imu conj(mount)``) for an IMU turned by `mount` (one vectorised call per chunk: per message it took
    40 us, as long as decoding the message)."""
    if gyro:
        return np.array(values)
    q = np.array(values)
    return yaw_of_quaternion(q if mount is None else quaternion_product(q, mount * (-1.0, -1.0, -1.0, 1.0)))


def _yaw_chunk(t: np.ndarray, v: np.ndarray, gyro: bool, last: tuple[float, float, float] | None):
    """Yield one ``(time, yaw)`` chunk of :func:`read_imu_yaw` from its readings `v` (yaw or yaw rate), continuing
    the `last` ``(time, yaw, reading)``; return the chunk's own."""
    if gyro:
        tt, r = (t, v) if last is None else (np.concatenate([[last[0]], t]), np.concatenate([[last[2]], v]))
        yaw = np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(tt)) + (0.0 if last is None else last[1])
        yaw = np.concatenate([[0.0], yaw]) if last is None else yaw
    else:
        yaw = np.unwrap(v) if last is None else np.unwrap(np.concatenate([[last[1]], v]))[1:]
    yield t, yaw
    return float(t[-1]), float(yaw[-1]), float(v[-1])

