"""How a bag's IMU is mounted on the robot: the rotation of its messages' frame (``header.frame_id``) in the robot's
body, from the bag's ``/tf_static`` (``tf2_msgs/msg/TFMessage``, as ``robot_state_publisher`` records it).

The static transforms chained from the IMU's frame up to the root of its static tree (``base_link`` or
``base_footprint``: everything rigidly attached to the body) give the mounting. An IMU turned on the robot (upside
down, on its side) measures the robot's yaw rate about its own axes: without the mounting its ``angular_velocity.z``
is not the robot's yaw rate.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from .logs import LogError

TF_STATIC = "/tf_static"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"


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
