"""Whether a twist step of a reference turns a steered wheel (types 3 and 5 with some ``l_oi != 0``, for
:mod:`.feasibility`): a step that only scales the twist (the same ICR) keeps every steered wheel's heading and
steering rate, and breaks no framework (docs/errata.md).
"""

from __future__ import annotations

import math

import numpy as np

from ..robot import Robot
from .jumps import _FLOOR, _jumps, _wrap
from .references import Reference

#: Signals of types 3 and 5 with some l_o != 0 that break Table 8.1 only where a steered wheel turns: its heading
#: (8.10) jumps with a velocity or heading-rate step (False), its steering rate with an acceleration step (True).
#: Where the twist only scales (the same ICR: a speed step or a trapezoidal profile on a line or a circle) every
#: steered wheel keeps its heading and its steering rate, and only spin rates (kinematic) or spin accelerations
#: (dynamic) jump, which each framework allows: the table's 'p_ref C1 / C2' is sufficient, not necessary.
_STEERED = {"velocity": False, "omega": False, "acceleration": True, "omega_rate": True}


#: Floor of a twist step below the usual one (m/s, rad/s) that may still turn a steered wheel: above the rounding of
#: a smooth reference's finite differences.
_SLOW_FLOOR = 1e-9


def _slow_turns(robot: Robot, reference: Reference, point: tuple[float, float] | None, x: np.ndarray,
                jumps: list[tuple[int, int, float]], factor: float) -> list[tuple[int, int, float]]:
    """The steps of the velocity or heading rate `x` under its floor (away from the `jumps` found above it) that turn
    a steered wheel (:func:`_steered_turns`). A steering angle is a state at any speed: a reference reversing its
    curvature at 0.01 m/s (a heading-rate step of 0.007 rad/s on a 3 m radius) turns a swerve robot's wheels by
    0.2 rad in a sample, and a corner at 0.01 m/s by a quarter turn; under the 0.02 floor of those signals both were
    'feasible: yes'. A wheel at rest on either side turns freely (its heading is undefined there)."""
    slow = [j for j in _jumps(x, reference.t, None, _SLOW_FLOOR, factor)
            if not any(j[0] <= b + 2 and a - 2 <= j[1] for a, b, _ in jumps)]
    if not slow:
        return []
    first, last = np.array([j[0] for j in slow]), np.array([j[1] + 1 for j in slow])
    turns = _steered_turns(robot, reference, point, first, last, rate=False)
    return [j for j, turn in zip(slow, turns, strict=True) if turn]


def _steered_turn(robot: Robot, reference: Reference, point: tuple[float, float] | None, before: int, after: int,
                  *, rate: bool) -> bool:
    """:func:`_steered_turns` of one pair of samples."""
    return bool(_steered_turns(robot, reference, point, np.array([before]), np.array([after]), rate=rate)[0])


def _steered_turns(robot: Robot, reference: Reference, point: tuple[float, float] | None, before: np.ndarray,
                   after: np.ndarray, *, rate: bool) -> np.ndarray:
    """Whether some steered wheel's heading (or, with `rate`, its steering rate) differs between samples `before`
    and `after` (arrays of sample indices, one answer each) of `reference`, tracked at `point` (:func:`_wheels`),
    by more than its floor; the heading by more than it turns at the rate of the sample steps on either side (on a
    curve of radius 1 m at 2 m/s it turns by 0.0625 rad a sample at 32 Hz, over the floor, and a speed step there,
    which keeps every wheel's heading, was a 'velocity jump' in the kinematic framework of swerve-4). A wheel at rest
    on either side turns freely there."""
    # a file's rates are central differences of its poses, its accelerations second ones: a step of another signal
    # there spreads over 1 (2) samples on either side (the heading rate of a square's corner was 78 rad/s at the
    # sample before it, whose wheel headings turned: a 'velocity jump' the exact square has not)
    wide = 2 if rate else 1
    before, after = np.maximum(before - wide, 0), np.minimum(after + wide, len(reference.t) - 1)
    (s0, x0), (s1, x1) = (_wheels(robot, reference, point, k, rate=rate) for k in (before, after))
    moving = (s0 > 1e-12) & (s1 > 1e-12)
    if rate:
        change = np.abs(x1 - x0)
    else:
        t, last = reference.t, len(reference.t) - 1
        rates = []
        for a, b in ((np.maximum(before - 1, 0), before), (after, np.minimum(after + 1, last))):
            (sa, xa), (sb, xb) = (_wheels(robot, reference, point, k, rate=False) for k in (a, b))
            with np.errstate(invalid="ignore", divide="ignore"):
                r = _wrap(xb - xa, math.pi) / (t[b] - t[a])[:, None]
            rates.append(np.where((sa > 1e-12) & (sb > 1e-12) & (b > a)[:, None], r, np.nan))
        known = np.isfinite(np.stack(rates))
        smooth = np.nan_to_num(np.stack(rates)).sum(axis=0) / np.maximum(known.sum(axis=0), 1)  # 0: no side known
        change = np.abs(_wrap(x1 - x0 - smooth * (t[after] - t[before])[:, None], math.pi))
    return np.any(moving & (change > _FLOOR["chi_rate" if rate else "chi"]), axis=1)


def _wheels(robot: Robot, reference: Reference, point: tuple[float, float] | None, k: np.ndarray, *,
            rate: bool) -> tuple[np.ndarray, np.ndarray]:
    """The squared speed ``(samples, wheels)`` of each steered wheel's centre at samples `k` of `reference` tracked
    at `point`, and its heading: the direction (modulo half a turn, a 2-quadrant root of (8.9)) of its velocity in
    the robot frame, ``u = R^T v + omega J d``, or with `rate` its rate ``(u x u') / |u|^2`` with
    ``u' = R^T a - omega J R^T v + alpha J d`` (``d`` the wheel from the point)."""
    p = np.zeros(2) if point is None else np.asarray(point, dtype=float)
    d = np.array([w.position for w in robot.wheels if w.type in ("steerable", "double")]) - p
    c, s = np.cos(reference.pose[k, 2])[:, None], np.sin(reference.pose[k, 2])[:, None]
    (vx, vy, w), (ax, ay, al) = reference.velocity[k].T[:, :, None], reference.acceleration[k].T[:, :, None]
    vrx, vry = c * vx + s * vy, -s * vx + c * vy
    ux, uy = vrx - w * d[:, 1], vry + w * d[:, 0]
    speed2 = ux**2 + uy**2
    if not rate:
        return speed2, np.arctan2(uy, ux)
    dux = c * ax + s * ay + w * vry - al * d[:, 1]
    duy = -s * ax + c * ay - w * vrx + al * d[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        return speed2, (ux * duy - uy * dux) / speed2
