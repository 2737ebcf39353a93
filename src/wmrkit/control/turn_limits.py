"""The tightest turns a car-like robot drives within its steering stops, and where a reference turns tighter than a
point of it can (:func:`.feasibility.feasibility` reports it; ``wmrkit track`` and ``wmrkit feasibility`` say it:
Table 8.1 judges a reference's continuity only, and a circle of 1 m was 'feasible: yes' for the catalog car, which
turns on 3.993 m at least).

The check is a necessary condition, from the reference's samples, so it never flags a path within the robot's reach:
a point ``(px, py)`` of a car (robot frame, from its rear axle's midpoint, the car driving along x) moves about the
ICR on the rear axle's line, at curvature ``kappa`` of the rear axle's midpoint, ``|kappa| <= 1/R`` (R:
:func:`min_turning_radius`). Its heading turns by at most ``1/rho`` per metre the point travels (rho:
:func:`point_turning_radius`), and the point's direction of travel is off the heading by
``psi(kappa) = atan2(px kappa, 1 - py kappa)``, which the steering can change (at rest too) within the span of psi
over the stops. So over any length L of its path the point's tangent (modulo half a turn: a car backs up) turns by
at most ``L / rho + span``; on the rear axle (``px = 0``) that is ``L / R``, a bound on the curvature. It is judged
between the breaks Table 8.1 found (a corner is a tangent jump there), the same in the kinematic and dynamic
frameworks (a stop bounds an angle, not its rate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..errors import WmrkitError
from ..robot import Robot

__all__ = ["TurnExcess", "min_turning_radius", "point_turning_radius", "turn_excess"]

#: Tangent turn [rad] beyond the bound that is a violation: the rounding of a file's positions moves the direction of
#: a chord of CHORD by 1e-4 / 0.1 rad at 0.1 mm, and the two ends of a stretch count (a circle 1 % inside the limit
#: of the car's rear axle is flagged after 20 m of it, a lap).
TURN_TOL = 0.05
#: The longest chord [m] the tangent is measured along (shorter for a robot that turns on less than 20 of them): a
#: few cm, long enough that the rounding of the positions hardly turns it, short enough to follow the path.
CHORD = 0.1
#: Samples on either side of a break of Table 8.1 (a corner spreads over a sample or two of finite differences)
#: that no chord spans.
BREAK_SAMPLES = 3


def min_turning_radius(robot: Robot) -> float:
    """The radius [m] of the tightest circle the rear axle's midpoint of a car-like `robot` drives within its
    steering wheels' ``steer_range`` (:func:`wmrkit.parking.problem.curvature_limit`); 0 for any other robot, or
    one whose ranges do not limit it (absent, or half a turn or wider: one root of (8.9) always fits)."""
    from ..parking.problem import curvature_limit

    try:
        return 1.0 / curvature_limit(robot)
    except (WmrkitError, ZeroDivisionError):  # not car-like; or it cannot roll straight ahead
        return 0.0


def _from_rear_axle(robot: Robot, point: ArrayLike) -> tuple[float, float]:
    """`point` ``(x, y)`` [m, robot frame] from the rear axle's midpoint."""
    from ..parking.problem import rear_axle_midpoint

    mx, my = rear_axle_midpoint(robot)
    px, py = (float(c) for c in point)  # type: ignore[union-attr]
    return px - mx, py - my


def point_turning_radius(robot: Robot, point: ArrayLike) -> float:
    """The radius [m] of the tightest circle `point` ``(x, y)`` [m, robot frame] of a car-like `robot` drives
    within its steering stops (0 as :func:`min_turning_radius`): on a circle every point turns about the ICR, on the
    rear axle's line (the car drives along x) at least :func:`min_turning_radius` from the axle's midpoint, so a
    point ``d`` ahead of that midpoint turns on ``hypot(d, R)`` at least (the catalog car's tracked point, 2.809 m
    ahead: 4.882 m)."""
    turning = min_turning_radius(robot)
    if turning <= 0:
        return 0.0
    px, py = _from_rear_axle(robot, point)
    return min(math.hypot(px, py - side * turning) for side in (1.0, -1.0))


@dataclass(frozen=True)
class TurnExcess:
    """A stretch of a reference that turns more than the point can: from ``t`` to ``until`` [s] its tangent turns
    by ``turn`` [rad] over ``length`` [m]; the point turns by at most ``length / radius + span`` there (``radius``:
    :func:`point_turning_radius`, ``span``: what re-steering adds, 0 on the rear axle; ``turning``: the robot's
    minimum turning radius, of its rear axle's midpoint)."""

    t: float
    until: float
    turn: float
    length: float
    radius: float
    span: float
    turning: float

    @property
    def excess(self) -> float:
        """The turn beyond the bound [rad]."""
        return self.turn - self.length / self.radius - self.span


def _resteer_span(robot: Robot, point: ArrayLike, turning: float) -> float | None:
    """The span [rad] of the angle between the heading and the direction of travel of `point` over the steering
    stops (``psi`` above); None where the point lies beside the rear axle as far as the ICR can (no bound)."""
    px, py = _from_rear_axle(robot, point)
    if abs(py) >= turning:
        return None
    return abs(math.atan2(px, turning - py) - math.atan2(-px, turning + py))


def turn_excess(robot: Robot, t: np.ndarray, xy: np.ndarray, point: ArrayLike,
                breaks: ArrayLike = ()) -> TurnExcess | None:
    """The stretch of the path sampled at times `t` ``(n,)`` [s], positions `xy` ``(n, 2)`` [m] of `point` of
    `robot` that turns most beyond what the point can (module docstring), if by more than :data:`TURN_TOL`; None
    for a robot whose steering does not limit its turns. No stretch spans one of the `breaks` [s] (Table 8.1's
    violations: a corner is a tangent jump there, a kink of the path)."""
    turning = min_turning_radius(robot)
    if not turning > 0:
        return None
    radius, span = point_turning_radius(robot, point), _resteer_span(robot, point, turning)
    if span is None or len(t) < 3:
        return None
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])  # the polyline's length
    if not s[-1] > 0:  # a reference at rest: no turn (an empty set of chords raised an IndexError)
        return None
    step = min(CHORD, radius / 20)
    keep = np.unique(np.searchsorted(s, np.arange(0.0, s[-1], step)))
    keep = keep[np.concatenate([[True], np.diff(s[keep]) >= step / 2])]  # chords of step / 2 at least
    if len(keep) < 3:
        return None
    start, end = keep[:-1], keep[1:]  # each chord's samples
    marks = np.unique(np.searchsorted(t, np.asarray(breaks, dtype=float)))
    lo, hi = np.searchsorted(marks, start - BREAK_SAMPLES), np.searchsorted(marks, end + BREAK_SAMPLES, side="right")
    clear = hi == lo  # no break within the chord (or a few samples of it)
    d = xy[end] - xy[start]
    angle = np.arctan2(d[:, 1], d[:, 0])
    mid = 0.5 * (s[start] + s[end])
    best: TurnExcess | None = None
    edges = np.flatnonzero(np.diff(np.concatenate([[False], clear, [False]]).astype(int)))
    for a, b in zip(edges[::2], edges[1::2], strict=True):  # runs of clear chords: the parts between breaks
        if b - a < 2:
            continue
        bend = (np.diff(angle[a:b]) + math.pi / 2) % math.pi - math.pi / 2  # modulo half a turn: a car backs up
        chi = np.concatenate([[0.0], np.cumsum(bend)])
        # the length between chords' midpoints, as an arc (a chord is shorter than the arc it cuts on a circle)
        half = np.abs(bend) / 2
        arc = np.diff(mid[a:b]) * np.where(half > 1e-8, half / np.sin(np.maximum(half, 1e-8)), 1.0)
        along = np.concatenate([[0.0], np.cumsum(arc)])
        for sign in (1.0, -1.0):
            f = sign * chi - along / radius
            k = int(np.argmax(f - np.minimum.accumulate(f)))
            j = int(np.argmin(f[: k + 1]))
            found = TurnExcess(float(t[start[a + j]]), float(t[end[a + k]]), float(sign * (chi[k] - chi[j])),
                               float(along[k] - along[j]), radius, span, turning)
            if best is None or found.excess > best.excess:
                best = found
    return best if best is not None and best.excess > TURN_TOL else None
