"""The planned path: straight and circular segments between stops, and the poses along them.

World frame of a parking problem (REP-103, x along the road in the direction of the detection pass, y to the
left): origin at the front obstacle's rear corner on the road side; the slot is ``-H <= x <= 0``,
``-J <= y <= 0`` (the curb at ``y = -J``); the front obstacle starts at ``x = 0``, the rear one ends at
``x = -H``. Poses are P_f's ``(x, y, theta)`` [m, m, rad].
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..odometry.integrators import integrate_exact

Pose = tuple[float, float, float]
#: Most samples per segment (:func:`sample_poses`).
MAX_SAMPLES = 200_000


@dataclass(frozen=True, slots=True)
class Segment:
    """One stretch driven without stopping: constant curvature, constant direction (§9.3.3: one speed trapezoid).

    ``phase`` 1 (detection pass), 2 (to the approach point) or 3 (manoeuvres); ``maneuver`` counts the phase-3
    manoeuvres from 1 (0 in phases 1-2); ``direction`` +1 forward, -1 backward; ``curvature`` [1/m] of P_f's path,
    left positive; ``length`` [m] of P_f's path; ``steering`` the equivalent front wheel's heading [rad]
    (0 straight ahead, counter-clockwise positive; inverse of (9.27)).
    """

    phase: int
    maneuver: int
    direction: int
    curvature: float
    length: float
    steering: float
    start: Pose
    end: Pose

    @property
    def twist(self) -> tuple[float, float, float]:
        """Body twist at unit speed ``(vx, vy, omega)`` [m/s, m/s, rad/s] driving this segment."""
        return (float(self.direction), 0.0, self.direction * self.curvature)

    def to_dict(self) -> dict[str, object]:
        """Plain data (the ``path`` entries of ``wmrkit park --json``); SI units."""
        return {"phase": self.phase, "maneuver": self.maneuver,
                "direction": "forward" if self.direction > 0 else "backward",
                "length": self.length, "curvature": self.curvature,
                "radius": None if self.curvature == 0 else 1 / abs(self.curvature),
                "steering": self.steering, "start": list(self.start), "end": list(self.end)}


def arc_end(start: Pose, direction: int, curvature: float, length: float) -> Pose:
    """End pose of a segment, closed form of the constant-twist motion (used while planning)."""
    x, y, th = start
    s = direction * length
    dth = curvature * s
    if abs(dth) < 1e-12:
        return (x + s * math.cos(th), y + s * math.sin(th), th)
    r = 1 / curvature
    return (x + r * (math.sin(th + dth) - math.sin(th)), y - r * (math.cos(th + dth) - math.cos(th)), th + dth)


def sample_poses(segments: tuple[Segment, ...] | list[Segment], step: float = 0.05,
                 cap: int | None = MAX_SAMPLES) -> np.ndarray:
    """P_f's poses along the segments, at most `step` [m] apart, ends included: ``(N, 3)``; at most `cap` per
    segment (then farther apart: 5 cm steps on a segment over 10 km), None for no cap (the exact check, which
    bounds the total before sampling).

    Each segment is integrated from its start pose with the exact SE(2) step of the odometry
    (:func:`wmrkit.odometry.integrators.integrate_exact`), a body twist held constant over each distance.
    """
    chunks = []
    for k, seg in enumerate(segments):
        n = sample_count(seg.length, step, cap)
        s = np.linspace(0.0, seg.length, n + 1)[(1 if k else 0):]
        chunks.append(integrate_exact(np.array(seg.start), np.array(seg.twist), s))
    return np.concatenate(chunks) if chunks else np.zeros((0, 3))


def sample_count(length: float, step: float, cap: int | None = MAX_SAMPLES) -> int:
    """Number of steps :func:`sample_poses` cuts a segment `length` [m] long into: at most `step` [m] each, at most
    `cap` (None: no cap)."""
    n = max(1, math.ceil(length / step))
    return n if cap is None else min(n, cap)


def path_length(segments: tuple[Segment, ...] | list[Segment]) -> float:
    """Total length of P_f's path [m]."""
    return float(sum(seg.length for seg in segments))


def direction_changes(segments: tuple[Segment, ...] | list[Segment]) -> int:
    """Number of cusps (forward <-> backward) along the path."""
    moving = [seg.direction for seg in segments if seg.length > 0]
    return sum(1 for a, b in itertools.pairwise(moving) if a != b)
