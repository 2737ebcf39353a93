"""Whether a reference trajectory can record the run of a joint log, judged in ways slip cannot explain away.

Slip scales a turn (a skid steer turns 1.8 times slower on arcs, 4 times on the spot, than its differential kinematics
says) and turns the path a few degrees off the heading (lateral slip angles), but it does not reverse a turn, stop
one, make one out of nothing, or drive the robot sideways. Three checks, at the reference's poses (``wmrkit
calibrate``, :func:`wmrkit.slip.calibration.calibrate_slip`; thresholds and their reasons in ``docs/slip.md``):

- **turning**: the log's no-slip heading is cut into legs where it turns one way (reversals of less than
  :data:`HYSTERESIS` are kept inside a leg). Over each leg that turns more than :data:`TURN` rad, the reference must
  turn the same way and by at least :data:`MIN_SHARE` of it; and over each leg of the reference's own heading that
  turns more than :data:`TURN`, so must the log.
- **the path's turning**: the direction of travel along chords of about :data:`CHORD` s (modulo pi: forwards or
  backwards), where both move at least :data:`MIN_CHORD` m, must on balance turn the way the no-slip odometry's does
  (a positive least-squares slope of its turns on the odometry's, once those add up to :data:`TURN`): x and y
  swapped mirror the path while the heading column still turns the log's way.
- **direction of travel**: over the same chords, the reference's direction of travel in its own body frame against
  the one the log's no-slip odometry gives (along the heading for a robot that cannot move sideways without
  slipping; whatever the wheels allow for others). The median difference must be below :data:`REFUSE_ANGLE`
  (refused) and should be below :data:`WARN_ANGLE` (a warning).

Only stretches where the reference is sampled at least every :data:`MAX_GAP` s are judged (a run's start and end
poses say nothing of how it turned).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import WmrkitError
from ..odometry.model import wrap_angle

#: A turn [rad] that no noise and no lag can fake: legs turning less are not judged.
TURN = 0.5
#: Reversals of a heading smaller than this [rad] stay inside a leg (encoder steps, a reference's noise).
HYSTERESIS = 0.05
#: Over a judged leg the other side must turn the same way by at least this share of it (a skid steer turning on
#: the spot turns about 0.25 of what its no-slip odometry says; nothing physical comes near 0.1).
MIN_SHARE = 0.1
#: Chords of the path [s] for the direction of travel, judged where both the reference and the log move at least
#: ``MIN_CHORD`` m along them (a reference's noise, a turn on the spot, are not a direction).
CHORD = 0.5
MIN_CHORD = 0.1
#: Reference poses further apart than this [s] are not judged (neither turning nor direction).
MAX_GAP = 2.0
#: Median difference [deg] of the direction of travel: above ``WARN_ANGLE`` suspicious (a skid steer's lateral slip
#: angles reach ~20 deg in tight turns), above ``REFUSE_ANGLE`` refused (not slip: another run, x and y swapped, a
#: heading measured in another frame).
WARN_ANGLE = 25.0
REFUSE_ANGLE = 45.0


def check_reference(t: np.ndarray, ref: np.ndarray, odo: np.ndarray, source: str = "reference") -> list[str]:
    """Refuse (:class:`WmrkitError`) a reference ``(times (M,), poses (M, 3))`` that cannot record the run whose
    no-slip odometry at the same times is `odo` ``(M, 3)`` (heading unwrapped); return warnings of a suspicious one."""
    href = np.unwrap(ref[:, 2])
    dense = np.append(np.diff(t) <= MAX_GAP, False)  # interval k -> k + 1 is judged
    _same_turns(t, odo[:, 2] - odo[0, 2] + href[0], href, dense, ("the log's no-slip odometry", "the reference"),
                source)
    a, b, (course_ref, course_log), judged = _courses(t, ref, odo)
    pairs = judged[:-1] & judged[1:]  # consecutive chords, both judged: how the direction of travel turns
    d_ref, d_log = np.diff(course_ref)[pairs], np.diff(course_log)[pairs]
    if np.abs(d_log).sum() > TURN and (slope := float(d_ref @ d_log / (d_log @ d_log))) <= 0:
        raise WmrkitError(f"{source}: its path turns the other way from the log's (the reference's direction of travel "
                          f"turns {slope:.2g} times the no-slip odometry's, by least squares over {int(pairs.sum())} "
                          f"pairs of {CHORD:g} s chords): a mirror image (x and y swapped?); slip does not reverse a "
                          "turn")
    angle = _direction_difference(ref, odo, href, a, b, judged)
    if angle is None or angle <= WARN_ANGLE:
        return []
    said = (f"{source}: its direction of travel is {angle:.3g} deg (median) off the one the log's wheels allow, in "
            f"the robot's frame")
    if angle > REFUSE_ANGLE:
        raise WmrkitError(f"{said}: more than {REFUSE_ANGLE:g} deg is not slip; the log and the reference do not "
                          "record the same run (x and y swapped? a heading in another frame?)")
    return [f"{said}: more than the {WARN_ANGLE:g} deg of a skid steer's lateral slip; check that the reference's "
            "heading is the robot's"]


def _legs(h: np.ndarray, dense: np.ndarray) -> list[tuple[int, int]]:
    """Index pairs ``(a, b)`` of the legs of `h` over dense stretches: turning points where `h` reverses by more
    than :data:`HYSTERESIS` from its extreme so far."""
    legs, start = [], 0
    for end in [*np.flatnonzero(~dense), len(h) - 1]:  # dense stretches start..end
        a, ext, direction = start, start, 0
        for k in range(start + 1, end + 1):
            d = h[k] - h[ext]
            if direction == 0:
                if abs(d) > HYSTERESIS:
                    direction = 1 if d > 0 else -1
                    ext = k
                continue
            if d * direction > 0:
                ext = k
            elif -d * direction > HYSTERESIS:
                legs.append((a, ext))
                a, direction, ext = ext, -direction, k
        if ext > a:
            legs.append((a, ext))
        start = end + 1
    return legs


def _same_turns(t: np.ndarray, log: np.ndarray, ref: np.ndarray, dense: np.ndarray, labels: tuple[str, str],
                source: str) -> None:
    """Refuse where a leg of one angle (`log`, `ref` at times `t`, over `dense` intervals; `labels` say what turns)
    turns more than :data:`TURN` and the other does not follow it the same way by :data:`MIN_SHARE` of it."""
    for mine, other, (whose, theirs) in ((log, ref, labels), (ref, log, labels[::-1])):
        for a, b in _legs(mine, dense):
            turn, follow = mine[b] - mine[a], other[b] - other[a]
            if abs(turn) > TURN and follow * math.copysign(1.0, turn) < MIN_SHARE * abs(turn):
                raise WmrkitError(
                    f"{source}: from t = {t[a]:.6g} to {t[b]:.6g} s {whose} turns {_rad(turn)} rad and {theirs} "
                    f"{_rad(follow)} rad: slip scales a turn, it does not reverse it, stop it or make one; the log and "
                    "the reference do not record the same run (another run? x and y swapped, a sign flipped?)")


def _rad(angle: float) -> str:
    """`angle` [rad] signed, to 3 digits; round-off of 0 is 0 (a straight log's heading ended at -7.63e-16 rad)."""
    return f"{round(angle, 9) + 0.0:+.3g}"


def _courses(t: np.ndarray, ref: np.ndarray, odo: np.ndarray):
    """Chords ``a -> b`` of about :data:`CHORD` s; the directions of travel along them [rad] of the reference and
    of the odometry (modulo pi: forwards or backwards, unwrapped); and whether a chord is judged (both move at least
    :data:`MIN_CHORD` m, within :data:`MAX_GAP` s)."""
    keep = np.unique(np.append(np.searchsorted(t, np.arange(t[0], t[-1], CHORD)), len(t) - 1))
    a, b = keep[:-1], keep[1:]
    d = [p[b, :2] - p[a, :2] for p in (ref, odo)]
    judged = (np.hypot(*d[0].T) >= MIN_CHORD) & (np.hypot(*d[1].T) >= MIN_CHORD) & (t[b] - t[a] <= MAX_GAP)
    courses = tuple(0.5 * np.unwrap(2.0 * np.arctan2(x[:, 1], x[:, 0])) for x in d)  # forwards or backwards
    return a, b, courses, judged


def _direction_difference(ref: np.ndarray, odo: np.ndarray, href: np.ndarray, a: np.ndarray, b: np.ndarray,
                          judged: np.ndarray) -> float | None:
    """Median [deg] over the judged chords ``a -> b`` of the angle between the reference's and the odometry's
    directions of travel, each in its own body frame at the chord's mid heading; None without a chord to judge."""
    if not judged.any():
        return None
    angles = []
    for poses, heading in ((ref, href), (odo, odo[:, 2])):
        d = poses[b, :2] - poses[a, :2]
        mid = 0.5 * (heading[a] + heading[b])
        c, s = np.cos(mid), np.sin(mid)
        angles.append(np.arctan2(c * d[:, 1] - s * d[:, 0], c * d[:, 0] + s * d[:, 1]))
    off = np.abs(wrap_angle((angles[0] - angles[1])[judged]))
    return float(np.degrees(np.median(off)))
