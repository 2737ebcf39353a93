"""How a bag's IMU is mounted on the robot: the rotation of its messages' frame (``header.frame_id``) in the robot's
body, from the bag's ``/tf_static`` (``tf2_msgs/msg/TFMessage``, as ``robot_state_publisher`` records it).

The static transforms chained from the IMU's frame up to the root of its static tree (``base_link`` or
``base_footprint``: everything rigidly attached to the body) give the mounting. An IMU turned on the robot (upside
down, on its side) measures the robot's yaw rate about its own axes: without the mounting its ``angular_velocity.z``
is not the robot's yaw rate. A mounting given by the user (``mount=(roll, pitch, yaw)``, ``--imu-mount``) replaces the
bag's; a bag without ``/tf_static`` and no mounting given has its IMU taken as level (:func:`resolve_mounting` says
which, :class:`ImuMounting`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._shapes import as_angles
from ..errors import ShapeError
from .logs import LogError

TF_STATIC = "/tf_static"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
#: :attr:`ImuMounting.source` of an IMU taken as level because the bag has no ``/tf_static`` and none was given.
ASSUMED_LEVEL = f"assumed level (no {TF_STATIC})"
#: A given mounting more than this angle [rad] (0.57 deg) from the bag's ``/tf_static`` one is said to disagree
#: with it: far above a URDF's rounding (1.5708 for pi/2: 4e-6 rad), where the yaw rate starts to take 1 % of
#: the roll or pitch rates.
MOUNT_ATOL = 0.01


@dataclass(frozen=True)
class ImuMounting:
    """How an IMU is mounted on the robot and who said so.

    ``quaternion``: the IMU's frame in the robot's body ``(x, y, z, w)``, None for level (z up). ``source``:
    ``"/tf_static"``, the option that gave it (``"--imu-mount"``, ``"mount="``), or :data:`ASSUMED_LEVEL`.
    ``note``: the line saying a given mounting disagrees with the bag's ``/tf_static`` (by more than
    :data:`MOUNT_ATOL`), else None.
    """

    quaternion: tuple[float, float, float, float] | None
    source: str
    note: str | None = None


def quaternion_rpy(mount: ArrayLike, name: str = "mount") -> np.ndarray:
    """Unit quaternion ``(x, y, z, w)`` of the URDF / REP-103 angles ``(roll, pitch, yaw)`` [rad]: ``Rz(yaw)
    Ry(pitch) Rx(roll)``, the IMU's frame in the robot's. ``(3,) -> (4,)``; angles that are not 3 finite numbers
    are a :class:`ShapeError` naming `name`."""
    rpy = as_angles(mount, 3, name)
    if rpy.shape != (3,):
        raise ShapeError(f"{name}: expected 3 angles (roll, pitch, yaw) [rad], got shape {rpy.shape}")
    half = 0.5 * rpy
    axes = np.zeros((3, 4))
    axes[[0, 1, 2], [0, 1, 2]], axes[:, 3] = np.sin(half), np.cos(half)
    return quaternion_product(axes[2], quaternion_product(axes[1], axes[0]))


def rpy_of_quaternion(q: np.ndarray) -> tuple[float, float, float]:
    """``(roll, pitch, yaw)`` [rad] of the unit quaternion `q` ``(x, y, z, w)``, the inverse of
    :func:`quaternion_rpy` (pitch within +-pi/2)."""
    x, y, z, w = (float(v) for v in q)
    return (math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
            math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x)))),
            math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


def quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a b`` of quaternions ``(x, y, z, w)``. ``(..., 4), (..., 4) -> (..., 4)``."""
    ax, ay, az, aw = np.moveaxis(np.asarray(a, dtype=float), -1, 0)
    bx, by, bz, bw = np.moveaxis(np.asarray(b, dtype=float), -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz], axis=-1)


def yaw_row(q: np.ndarray) -> np.ndarray:
    """The last row of the rotation matrix of the unit quaternion `q` ``(x, y, z, w)``: the body's z axis in the
    rotated frame, so that ``yaw_row(q) @ omega`` is the body's yaw rate of a rate `omega` measured in that frame."""
    x, y, z, w = q
    return np.array([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)])


def static_tree(messages: Iterable, where: str) -> dict[str, tuple[str, np.ndarray]]:
    """``child -> (parent, unit quaternion of the child in the parent)`` of the decoded ``/tf_static`` `messages`
    (`where`: the bag and topic, for errors); frame names without a leading ``/`` (as tf2 reads them)."""
    tree: dict[str, tuple[str, np.ndarray]] = {}
    for msg in messages:
        for tf in msg.transforms:
            r = tf.transform.rotation
            q = np.array([r.x, r.y, r.z, r.w], dtype=float)
            norm = float(np.linalg.norm(q))
            child, parent = tf.child_frame_id.lstrip("/"), tf.header.frame_id.lstrip("/")
            if not (math.isfinite(norm) and norm > 0):
                raise LogError(f"{where}: the transform {parent} -> {child} has rotation {q.tolist()}, no rotation")
            tree[child] = (parent, q / norm)
    return tree


def mounting(tree: dict[str, tuple[str, np.ndarray]], frame: str, where: str) -> np.ndarray | None:
    """The unit quaternion of the IMU's `frame` in the root of its static `tree`, None when it is that root (or the
    tree is empty: the bag says nothing, the IMU is taken as level, z up). A frame the tree does not place is a
    :class:`LogError` naming `where` (file and topic) and the frame."""
    name = frame.lstrip("/")
    parents = {p for p, _ in tree.values()}
    if not tree or (name in parents and name not in tree):
        return None
    if name not in tree:
        placed = ", ".join(sorted(set(tree) | parents)[:16])
        raise LogError(f"{where}: the IMU's frame '{frame}' is not in the bag's {TF_STATIC} (which places {placed}): "
                       "its mounting on the robot is unknown, so its yaw rate is not the robot's")
    q, seen = np.array([0.0, 0.0, 0.0, 1.0]), {name}
    while name in tree:
        name, rotation = tree[name]
        if name in seen:
            raise LogError(f"{where}: the bag's {TF_STATIC} has a loop through frame '{name}'")
        seen.add(name)
        q = quaternion_product(rotation, q)
    return q


def resolve_mounting(tree: dict[str, tuple[str, np.ndarray]], frame: str, where: str, mount: ArrayLike | None,
                     option: str = "mount=") -> ImuMounting:
    """The mounting of the IMU publishing in `frame`: the given `mount` ``(roll, pitch, yaw)`` [rad]
    (:func:`quaternion_rpy`; `option` names it: ``"--imu-mount"``, ``"mount="``), else the static `tree`'s
    (:func:`mounting`, whose errors name `where`), else level (an empty tree, :data:`ASSUMED_LEVEL`). A given one
    overrides the tree's, its :attr:`~ImuMounting.note` saying so when they are more than :data:`MOUNT_ATOL` apart
    (a tree that does not place `frame` says nothing)."""
    if mount is None:
        q = mounting(tree, frame, where)
        return ImuMounting(None if q is None else tuple(q.tolist()), TF_STATIC if tree else ASSUMED_LEVEL)
    given = quaternion_rpy(mount, option.rstrip("="))
    note, known = None, bool(tree)
    try:
        placed = mounting(tree, frame, where)
    except LogError:  # the tree does not place the frame (or loops): it makes no claim to disagree with
        known = False
    if known:
        q = np.array([0.0, 0.0, 0.0, 1.0]) if placed is None else placed
        apart = 2 * math.acos(min(1.0, abs(float(q @ given))))
        if apart > MOUNT_ATOL:
            said = ", ".join(f"{a:.4g}" for a in rpy_of_quaternion(q))
            note = (f"{where}: {option} turns the IMU {apart:.3g} rad ({math.degrees(apart):.3g} deg) from the "
                    f"mounting the bag's {TF_STATIC} gives its frame '{frame}' (roll, pitch, yaw {said} rad): "
                    f"{option} is used")
    return ImuMounting(tuple(given.tolist()), option, note)
