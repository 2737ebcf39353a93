"""What users use today, on the same robots and references: pure pursuit and Stanley (beyond the thesis).

Both steer a point of the robot onto the reference *path* (they do not correct timing), at the path's speed where
that point is on it (:meth:`PathIndex.speed`: the reference's speed where it passes the point's projection, as
path followers take it from the path, not from a clock), slowing to stop at the path's end
(:meth:`PathIndex.approach`):

- **pure pursuit** (Coulter 1992): the axle point ``A`` (the foot of the fixed axle, the origin without fixed wheels)
  drives on the arc through a goal point ``lookahead`` metres further along the path, held at the path's end once
  that is nearer (as MATLAB's ``controllerPurePursuit`` and Nav2's Regulated Pure Pursuit do: the arc through the
  end reaches it), and on the end's tangent once the end is no longer ahead of ``A``, or within its aim radius
  (``AIM_FRACTION`` of ``L_d``)
  (a robot beside it, or at it, does not circle it): curvature ``kappa = 2 y_g / L_d^2``; a goal behind ``A``
  (``x_g <= 0``) turns it round on the circle of diameter ``L_d`` (``kappa = +-2 / L_d``, towards the goal's side,
  left when straight behind); ``L_d`` defaults to the wheelbase of a robot with steered wheels, else to
  ``MIN_LOOKAHEAD_TIME`` at the reference's top speed (:func:`default_lookahead`);
- **Stanley** (Thrun et al. 2006; Hoffmann et al. 2007): a front point ``F`` at ``wheelbase`` ahead of ``A``;
  steering ``delta = psi_e - atan(k e / (v_F + eps))`` with the heading error ``psi_e``, the signed cross-track
  error ``e`` of ``F`` (positive left) and ``F``'s speed ``v_F`` (the path's: the front axle's, as in Hoffmann's
  law, whose cross-track error then obeys ``e' = -v_F sin(atan(k e / v_F))``); ``A`` drives at
  ``v_F cos(delta)``, turning at ``v_F sin(delta) / wheelbase``; ``eps`` is ``EPS_FRACTION`` of the reference's
  top speed.

Every length of the followers is relative (the same robot and reference scaled by any factor, speeds with them and
times kept, give the same run scaled): to the follower's own length ``L`` (:attr:`PathFollower.length`: pure
pursuit's lookahead, Stanley's stopping length), or to the reference's top speed times a time.

Both limit the curvature to the robot's tightest turn (:func:`max_curvature`: a car's steering stops).
The resulting unicycle twist ``(v, omega)`` at ``A`` along the robot's rolling direction is moved to the origin
(rigid body) and goes through the same per-wheel IK as the thesis's controller. A robot whose steering couplings
leave it one steering turn ``u`` (:mod:`.coupled_point`) is steered on that turn instead (:mod:`.coupled_arcs`):
pure pursuit's arc is the circle ``A`` drives about the ICR of ``n(u)``, through the goal; Stanley's ``psi + delta``
the direction of ``F``'s velocity, within the coupling's arc (its steering limit, not ``max_steer``); a synchro
drive, which turns no way but its wheels, takes the path's direction as its heading. Their twists ``s n(u)`` are
admissible. Neither has a time law: each stops
once its point has passed the path's end (pure pursuit: and the end is no longer ahead of it, or it is at the end;
:class:`PathFollower`), and a default run of :func:`.track.track` lasts
until then, or at most :func:`follower_duration` (:class:`ArrivalWarning` when it ends away from the end).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..limits import MAX_COORDINATE
from ..robot import Robot
from .coupled_arcs import arc_twist, front_steering, rotates, within
from .loop import TwistController
from .points import ControlError, ControlPoint, robot_reach
from .references import Reference

__all__ = ["AIM_FRACTION", "ARRIVAL_FRACTION", "MAX_LOOKAHEAD", "ArrivalWarning", "PathFollower", "PathIndex",
           "arrived", "check_lookahead", "default_lookahead", "default_wheelbase", "follower_duration", "max_curvature",
           "min_length", "pure_pursuit", "stanley", "steers", "top_speed"]

#: Pure pursuit's default lookahead for a robot without steered wheels, and the shortest stopping length of Stanley,
#: as a time [s] at the reference's top speed (Nav2's Regulated Pure Pursuit's ``lookahead_time``): 1 m at 0.5 m/s
#: (:func:`default_lookahead`).
MIN_LOOKAHEAD_TIME = 2.0
#: Stanley's ``eps`` (the speed added to the front point's in ``atan(k e / (v_F + eps))``) as a fraction of the
#: reference's top speed: 1e-3 m/s at 0.5 m/s.
EPS_FRACTION = 2e-3
#: The slowest a follower drives along its path, as a fraction of the reference's top speed (where the reference is
#: at rest, or crawls: a start from rest would never leave it).
MIN_SPEED_FRACTION = 0.1
#: A follower slows to stop at the path's end over its own length ``L`` (pure pursuit's lookahead; Stanley's
#: wheelbase, at least ``MIN_LOOKAHEAD_TIME`` at the reference's top speed): its
#: speed is scaled by ``sqrt(d / L)`` within ``d < L`` of the end along the path (a constant deceleration, as a
#: driver brakes), at least by ``APPROACH_FLOOR`` (it creeps over the last ``APPROACH_FLOOR**2 L``, and arrives).
APPROACH_FLOOR = 0.005
#: A follower's default run: the reference's duration and up to this fraction of it more, at least ``EXTRA_MIN`` s
#: (:func:`follower_duration`); it ends once the tracked point has passed the path's end.
EXTRA_FRACTION, EXTRA_MIN = 0.5, 10.0
#: A follower that ends farther than this fraction of its length ``L`` (:attr:`PathFollower.length`) from the path's
#: end did not arrive (:class:`ArrivalWarning`): 0.1 m at ``L`` = 1 m.
ARRIVAL_FRACTION = 0.1
#: Pure pursuit has reached the path's end within its aim radius, this fraction of its lookahead ``L`` (1 mm at
#: ``L`` = 1 m; its run stops there: :meth:`PathIndex.done`); it aims at
#: the end until then (or until the end is no longer ahead), and drives on along the end's tangent after: aiming at a
#: point ``r`` away turns at up to ``2 / r``, and a robot at rest just short of the end (the slip of the dynamics)
#: was steered round at the stops and tipped over.
AIM_FRACTION = 1e-3
#: The longest lookahead [m]: the largest coordinate of a reference (``limits.MAX_COORDINATE``); any lookahead longer
#: than the path aims at its end alike (a lookahead of 1e308 m overflowed the goal test, a traceback).
MAX_LOOKAHEAD = MAX_COORDINATE


class ArrivalWarning(UserWarning):
    """A path follower's default run ended with its tracked point away from the path's end."""


def follower_duration(duration: float) -> float:
    """The longest default run [s] of a path follower on a reference of `duration` [s]."""
    return duration + max(EXTRA_MIN, EXTRA_FRACTION * duration)


class PathIndex:
    """The reference's path as a polyline with arc length, and nearest-point queries near a time."""

    def __init__(self, reference: Reference, window: float = 5.0) -> None:
        self.ref = reference
        self.xy = np.ascontiguousarray(reference.pose[:, :2])
        seg = np.hypot(*np.diff(self.xy, axis=0).T)
        self.s = np.concatenate([[0.0], np.cumsum(seg)])
        self.half = 0.5 * seg
        self._t = np.array(reference.t, dtype=float)  # writable: the compiled search's signature
        self._search: Callable[..., tuple[int, float]] | None = None
        self._last: tuple[tuple[float, ...], tuple[float, float, float]] = ((math.nan,), (0.0, 0.0, 0.0))
        self.window = window
        # a round-off guard [m] of distances between its points (ties at a corner): above the coordinates' rounding
        # (1e-16 of them) at any size, far below any length the followers use (1e-9 of a 1 mm path)
        self.tie = 1e-12 * max(1.0, float(np.abs(self.xy).max()))
        speed = np.hypot(*reference.velocity[:, :2].T)
        self.top_speed = float(speed.max())
        moving = speed > 1e-9 * self.top_speed  # at rest: a relative round-off guard
        self._s_moving, self._v_moving = self.s[moving], speed[moving]
        self.min_speed = MIN_SPEED_FRACTION * self.top_speed
        self.at_rest = float(self.s[-1]) <= self.tie  # a path of zero length: its start is its end

    def speed(self, s: float) -> float:
        """The reference's speed [m/s] where it passes arc length `s` [m] (interpolated between its moving samples),
        at least ``MIN_SPEED_FRACTION`` of its top speed; 0 for a reference that never moves."""
        if not len(self._v_moving):
            return 0.0
        return max(float(np.interp(s, self._s_moving, self._v_moving)), self.min_speed)

    def approach(self, s: float, length: float, to_end: float = 0.0) -> float:
        """The factor in [``APPROACH_FLOOR``, 1] of the speed at arc length `s` [m] that stops a follower of
        `length` [m] at the path's end (see ``APPROACH_FLOOR``), `to_end` [m] from it at least (a point beside the
        end that drives on to it: its projection is on the end)."""
        left = max(float(self.s[-1]) - s, to_end, 0.0)
        return 1.0 if left >= length else max(math.sqrt(left / length), APPROACH_FLOOR)

    def _segment(self, point: np.ndarray, t: float) -> tuple[int, float]:
        """The segment ``j`` of the path nearest to `point` near time `t` and its foot's fraction ``u``: among the
        segments within ``window`` s of `t`, and beyond either end of that window as long as the path stays within
        twice the window's nearest sample's distance of `point` (a robot ahead of or behind the reference's time:
        the path it is near may leave the window through a corner; that nearer part of the path is found, not the
        far side of the corner inside the window). Ties between adjacent segments (a corner): the segment ahead.
        One compiled pass (:func:`._path_kernel.nearest_segment`): a few µs a call."""
        if self._search is None:  # imported at the first query: numba
            from ._path_kernel import nearest_segment

            self._search = nearest_segment
        return self._search(self.xy, self.half, self._t, float(point[0]), float(point[1]), float(t),
                               float(self.window), self.tie)

    def done(self, point: np.ndarray, s: float, heading: float | None = None, previous: np.ndarray | None = None,
             steps: int = 0, aim: float = 0.0) -> bool:
        """Whether `point`, projected at arc length `s` [m] (:meth:`project`), has passed the path's end: it projects
        on the end, past it along the last segment (a closed path's start, on its end, has not); given the `heading`
        [rad] of a point that steers for the end (pure pursuit), also the end is no longer ahead of it (one that
        crossed the end's line beside it, on an arc to it, drives on to it), unless it has arrived: it is within
        `aim` [m] (its aim radius) of the end, whatever its heading, or its step from `previous` (its position a
        sample before) passed the end within ``steps`` times that step, at least `aim` (:func:`arrived`). A path of
        zero length (a reference at rest) is driven at once: there is nothing to follow."""
        if self.at_rest:
            return True
        a, b = self.xy[-2], self.xy[-1]
        if heading is not None and previous is not None:  # its last step passed the end: arrived
            reach = max(aim, steps * float(np.hypot(*(point - previous))))
            if s >= self.s[-1] - reach - aim and arrived(previous, point, b, reach):
                return True
        if s < self.s[-1]:
            return False
        if heading is not None and float(np.hypot(*(point - b))) < aim:  # at the end: arrived
            return True
        if not (float((point - b) @ (b - a)) >= 0 and float(np.hypot(*(point - b))) > 1e3 * self.tie):
            return False
        return heading is None or float((b - point) @ np.array([math.cos(heading), math.sin(heading)])) <= 0

    def project(self, point: np.ndarray, t: float) -> tuple[float, float, float]:
        """Continuous projection of `point` on the path near time `t` (:meth:`_segment`): ``(s [m], chi [rad],
        e [m], signed, left positive)``, the foot's arc length, its segment's direction and the signed distance.
        The last query's answer is kept: a loop's record asks it again of the same point (its stop rule)."""
        key = (float(point[0]), float(point[1]), float(t))
        if key == self._last[0]:
            return self._last[1]
        j, u = self._segment(point, t)
        x0, y0 = self.xy[j]
        dx, dy = self.xy[j + 1, 0] - x0, self.xy[j + 1, 1] - y0
        length = math.hypot(dx, dy)
        chi = math.atan2(dy, dx) if length > 0 else self.tangent(j)
        e = (key[0] - (x0 + u * dx)) * -math.sin(chi) + (key[1] - (y0 + u * dy)) * math.cos(chi)
        out = (float(self.s[j] + u * length), chi, float(e))
        self._last = (key, out)
        return out

    def point_at(self, s: float) -> np.ndarray:
        """Path point at arc length `s` [m] (clamped to the start; beyond the end, on the end's tangent: pure
        pursuit's goal once the end is behind the robot, which circled it on ever tighter turns, ``2 / L_d``)."""
        beyond = s - self.s[-1]
        if beyond > 0:
            chi = self.tangent(len(self.xy) - 1)
            return self.xy[-1] + beyond * np.array([math.cos(chi), math.sin(chi)])
        return np.array([np.interp(s, self.s, self.xy[:, 0]), np.interp(s, self.s, self.xy[:, 1])])

    def tangent(self, i: int) -> float:
        """Path direction [rad] at sample `i` (from the reference velocity, or the chord)."""
        v = self.ref.velocity[i, :2]
        if np.hypot(*v) > 1e-9 * self.top_speed:
            return math.atan2(v[1], v[0])
        j = min(i + 1, len(self.xy) - 1)
        k = max(j - 1, 0)
        return math.atan2(*(self.xy[j] - self.xy[k])[::-1])

    def cross_track(self, points: np.ndarray) -> np.ndarray:
        """Distance [m] from each of `points` ``(n, 2)`` to the path polyline (the segments either side of the
        nearest sample). ``-> (n,)``."""
        from scipy.spatial import cKDTree

        near = cKDTree(self.xy).query(points)[1]
        best = np.full(len(points), np.inf)
        for shift in (-1, 0):
            j = np.clip(near + shift, 0, len(self.xy) - 2)
            a, b = self.xy[j], self.xy[j + 1]
            d = b - a
            n2 = np.maximum(np.sum(d * d, axis=1), 1e-300)
            u = np.clip(np.sum((points - a) * d, axis=1) / n2, 0.0, 1.0)
            best = np.minimum(best, np.hypot(*(points - a - u[:, None] * d).T))
        return best


def arrived(q: np.ndarray, p: np.ndarray, end: np.ndarray, reach: float) -> bool:
    """Whether a point that moved from `q` to `p` in a sample passed `end` within `reach` [m] (the step's nearest
    point to it is between them). A sampled loop moves ``v T`` between its decisions and sees its pose ``delay``
    samples late: it passes the end between two samples, off it by up to about ``(1 + delay) v T``, and a test of
    `p` alone against the aim radius is met only by luck (:meth:`PathFollower.stop_rule`)."""
    d = p - q
    n2 = float(d @ d)
    u = float((end - q) @ d) / n2 if n2 > 0 else 1.0
    return 0 < u < 1 and float(np.hypot(*(q + u * d - end))) < reach


def default_wheelbase(cp: ControlPoint) -> float:
    """Distance [m] from the axle point to the steered wheels (type 4), else to the control point, else (a robot
    whose point is its axle point: an omnidirectional one) the robot's size (:func:`.points.robot_reach`): at its
    scale (a fixed 0.5 m made Stanley on a mecanum-4 scaled by 1e-3 look 1,300 of its sizes ahead)."""
    a = cp.axle_point
    steered = [w.position for w in cp.robot.wheels if w.type in ("steerable", "double")]
    ahead = np.array([math.cos(cp.forward), math.sin(cp.forward)])
    if cp.reduced and steered:
        return float(max(abs((np.asarray(p) - a) @ ahead) for p in steered))
    d, size = float(np.hypot(*(cp.point - a))), robot_reach(cp.robot)
    return d if d > 1e-9 * size else size  # a round-off guard relative to the robot's size


def top_speed(reference: Reference) -> float:
    """The reference's top speed [m/s] along its path (0 for one at rest)."""
    return float(np.hypot(*reference.velocity[:, :2].T).max())


def min_length(speed: float) -> float:
    """``MIN_LOOKAHEAD_TIME`` at a reference's top `speed` [m/s], in metres: pure pursuit's default lookahead for a
    robot without steered wheels, and Stanley's shortest stopping length."""
    return MIN_LOOKAHEAD_TIME * speed


def steers(cp: ControlPoint) -> bool:
    """Whether the robot of `cp` steers with steered wheels (a reduced robot with type-4 or double wheels)."""
    return cp.reduced and any(w.type in ("steerable", "double") for w in cp.robot.wheels)


def default_lookahead(cp: ControlPoint, speed: float) -> float:
    """Pure pursuit's default lookahead [m] on a reference of top `speed` [m/s]: the wheelbase
    (:func:`default_wheelbase`) of a robot that steers with steered wheels (a shorter lookahead oscillates once the
    loop is sampled at speed: the car's figure-eight at 5 m/s, period 0.1 s and one sample late, 138 mm RMS
    cross-track at 1 m against 15 mm at its 2.7 m wheelbase; a longer one cuts its turns: 807 mm at 2 s at that
    speed, 11.8 m); for any other robot :func:`min_length`, 2 s at the top speed (1 m at 0.5 m/s); the wheelbase
    where that is 0 (a reference at rest: its run stops at once)."""
    wheelbase = default_wheelbase(cp)
    ahead = wheelbase if steers(cp) and wheelbase > 0 else min_length(speed)
    return ahead if ahead > 0 else wheelbase


def max_curvature(robot: Robot) -> float:
    """The largest curvature [1/m] the axle point of car-like `robot` drives within its wheels' ``steer_range``
    (:func:`wmrkit.parking.problem.curvature_limit`, a hair inside it: the wheels then stay within their ranges);
    inf for any other robot, or one whose ranges do not limit it."""
    from ..errors import WmrkitError
    from ..parking.problem import curvature_limit

    try:
        limit = curvature_limit(robot)
    except WmrkitError:  # not car-like
        return math.inf
    return limit * (1 - 1e-9) if limit > 0 else math.inf


def _axle_state(cp: ControlPoint, pose: np.ndarray) -> tuple[np.ndarray, float]:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    a = cp.axle_point
    return np.array([pose[0] + c * a[0] - s * a[1], pose[1] + s * a[0] + c * a[1]]), pose[2] + cp.forward


def _rotate(angle: float, x: float, y: float = 0.0) -> np.ndarray:
    """``(x, y)`` turned by `angle` [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * x - s * y, s * x + c * y])


def _twist_at_origin(cp: ControlPoint, v: float, omega: float) -> np.ndarray:
    """Body twist of the origin for speed `v` of the axle point along the rolling direction and rate `omega`."""
    ax, ay = cp.axle_point
    vx, vy = v * math.cos(cp.forward), v * math.sin(cp.forward)
    return np.array([vx + omega * ay, vy - omega * ax, omega])


class PathFollower:
    """A geometric tracker: the :data:`TwistController` `law`, and the path it follows with its `tracked` point
    (``pose -> (2,)`` world [m]), to tell when that point has driven it to the end (:meth:`finished`); `heading`
    (``pose -> rad``): that point's direction of travel, for a law that steers for the end (:meth:`PathIndex.done`);
    `axle` (``pose -> (A, psi)``): the axle point and its heading, the tracked point being `offset` [m] ahead of it,
    ``A`` turning at most at curvature `tightest` [1/m] (why it missed the end: :mod:`.follower_run`); `length` [m]:
    its own length ``L`` (pure pursuit's lookahead, Stanley's stopping length), which its tolerances are relative
    to: ``aim`` = ``AIM_FRACTION L`` (its aim radius), ``arrival_tol`` = ``ARRIVAL_FRACTION L``."""

    def __init__(self, path: PathIndex, tracked: Callable[[np.ndarray], np.ndarray], law: TwistController,
                 heading: Callable[[np.ndarray], float] | None = None, tightest: float = math.inf,
                 axle: Callable[[np.ndarray], tuple[np.ndarray, float]] | None = None, offset: float = 0.0,
                 length: float = 1.0) -> None:
        self.path, self.tracked, self.law, self.heading, self.tightest = path, tracked, law, heading, tightest
        self.axle, self.offset, self.length = axle, offset, length
        self.aim, self.arrival_tol = AIM_FRACTION * length, ARRIVAL_FRACTION * length

    def __call__(self, t: float, pose: np.ndarray, integral: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.law(t, pose, integral)

    def finished(self, t: float, pose: np.ndarray, previous: np.ndarray | None = None, steps: int = 0) -> bool:
        """Whether the tracked point has passed the path's end at `t` (the law then commands rest, for ever);
        `previous`: the pose a sample before, `steps`: a sampled loop's (:meth:`PathIndex.done`)."""
        p = self.tracked(pose)
        q = None if previous is None else self.tracked(previous)
        heading = None if self.heading is None else self.heading(pose)
        return self.path.done(p, self.path.project(p, t)[0], heading, q, steps, self.aim)

    def stop_rule(self, delay: int | None = None) -> Callable[[float, np.ndarray], bool]:
        """:meth:`finished` on a run's successive samples ``(t, pose)``, each with the one before, for a continuous
        loop (`delay` None) or a sampled one measuring its pose `delay` periods late: a loop's `until`. Its point
        has arrived once its last step passed the end within ``(1 + delay)`` times that step (at least its aim
        radius): what the loop resolves (:func:`arrived`). A sample no later than the last starts a run."""
        last: list = [math.inf, None]
        steps = 0 if delay is None else 1 + delay

        def until(t: float, pose: np.ndarray) -> bool:
            previous = last[1] if t > last[0] else None
            last[:] = [t, np.array(pose, dtype=float)]
            return self.finished(t, pose, previous, steps)

        return until

    def end_distance(self, pose: np.ndarray) -> float:
        """Distance [m] of the tracked point from the path's end."""
        return float(np.hypot(*(self.tracked(pose) - self.path.xy[-1])))


def check_lookahead(lookahead: float, what: str = "lookahead") -> None:
    """Raise :class:`ControlError` naming `what` unless `lookahead` [m] is in ``(0, MAX_LOOKAHEAD]``."""
    if not 0 < lookahead <= MAX_LOOKAHEAD:  # NaN included
        raise ControlError(f"{what}: expected a distance in (0, {MAX_LOOKAHEAD:g}] m along the path, got {lookahead}")


def pure_pursuit(cp: ControlPoint, reference: Reference, lookahead: float | None = None,
                 curvature: float = math.inf) -> PathFollower:
    """Pure-pursuit controller (see module doc); `lookahead` [m], > 0 (default :func:`default_lookahead`); the
    commanded curvature is limited to ``+-curvature`` [1/m] (the robot's tightest turn, :func:`max_curvature`)."""
    if lookahead is None:
        lookahead = default_lookahead(cp, top_speed(reference))
    check_lookahead(lookahead)
    path, aim = PathIndex(reference), AIM_FRACTION * lookahead
    coupled = cp.coupled
    level = coupled is not None and not rotates(coupled)  # a synchro drive: it heads along the path

    def control(t: float, pose: np.ndarray, integral: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a, psi = _axle_state(cp, pose)
        s_near, chi, _ = path.project(a, t)
        if level:
            psi = chi
        if path.done(a, s_near, psi, aim=aim):  # the path is driven: stop
            return np.zeros(3), np.zeros(3)
        c, s = math.cos(psi), math.sin(psi)
        ahead, end = s_near + lookahead, float(path.s[-1])
        d = path.point_at(min(ahead, end)) - a  # the goal: held at the path's end (the arc through it reaches it)
        x_g, y_g = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        if ahead > end and (x_g <= 0 or x_g * x_g + y_g * y_g < aim * aim):  # the end passed, or reached:
            d = path.point_at(ahead) - a  # on along the end's tangent
            x_g, y_g = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        dist2 = x_g * x_g + y_g * y_g
        at_goal, ahead_of = dist2 <= (1e-3 * aim) ** 2, x_g > 0 or level  # (1e-6 of the lookahead: round-off)
        if at_goal:
            kappa = 0.0
        elif x_g > 0:
            kappa = 2.0 * y_g / dist2
        else:  # goal behind (the path runs against the robot): 2 y_g / L^2 ~ 0 drove straight away; turn round
            kappa = math.copysign(2.0 / math.sqrt(dist2), y_g)
        kappa = min(max(kappa, -curvature), curvature)
        to_end = float(np.hypot(*(path.xy[-1] - a)))  # beside the end, on the arc to it: its projection is the end
        v = path.speed(s_near) * path.approach(s_near, lookahead, to_end)  # the path's speed where it is on it
        if coupled is None:
            return _twist_at_origin(cp, v, v * kappa), np.zeros(3)
        turn = psi - pose[2]  # the heading's direction in the robot frame (forward; a synchro drive's: the path's)
        goal = cp.axle_point + _rotate(turn, x_g, y_g)
        return arc_twist(coupled, cp.axle_point, goal if ahead_of and not at_goal else None, v, kappa), np.zeros(3)

    return PathFollower(path, lambda pose: _axle_state(cp, pose)[0], control, lambda pose: _axle_state(cp, pose)[1],
                        curvature, lambda pose: _axle_state(cp, pose), length=lookahead)


def stanley(cp: ControlPoint, reference: Reference, gain: float = 1.0, wheelbase: float | None = None,
            max_steer: float = 1.2) -> PathFollower:
    """Stanley controller (see module doc); cross-track `gain` [1/s], steering limited to ``+-max_steer`` [rad] (a
    robot with coupled steering: to its coupling's arc, a synchro drive to ``+-max_steer`` off the path)."""
    length = default_wheelbase(cp) if wheelbase is None else wheelbase
    if not 0 <= gain < math.inf:
        raise ControlError(f"stanley gain: expected a cross-track gain >= 0 (1/s), got {gain}")
    if not 0 < length < math.inf:
        raise ControlError(f"wheelbase: expected a distance > 0 m, got {length}")
    if not 0 < max_steer < math.pi / 2:
        raise ControlError(f"max_steer: expected a steering limit in (0, 90) deg [rad], got {max_steer}")
    path = PathIndex(reference)
    stopping, eps = max(length, min_length(path.top_speed)), EPS_FRACTION * path.top_speed

    def front(pose: np.ndarray) -> np.ndarray:
        a, psi = _axle_state(cp, pose)
        return a + length * np.array([math.cos(psi), math.sin(psi)])

    coupled = None if cp.coupled is None else front_steering(cp.coupled, cp.axle_point + _rotate(cp.forward, length))
    level = coupled is not None and not rotates(coupled)  # a synchro drive: it heads along the path

    def control(t: float, pose: np.ndarray, integral: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        psi = _axle_state(cp, pose)[1]
        f = front(pose)
        s_front, chi, e = path.project(f, t)
        if path.done(f, s_front):  # the path is driven: stop
            return np.zeros(3), np.zeros(3)
        v_front = path.speed(s_front) * path.approach(s_front, stopping)  # the front point's (Hoffmann et al. 2007)
        psi = chi if level else psi
        psi_e = math.remainder(chi - psi, 2 * math.pi)
        delta = psi_e - math.atan2(gain * e, v_front + eps)
        if coupled is not None and not level:  # F's velocity along psi + delta: within the coupling's arc
            return coupled.twist(_rotate(within(coupled, psi + delta - pose[2]), v_front)), np.zeros(3)
        delta = min(max(delta, -max_steer), max_steer)
        if coupled is not None:  # a synchro drive's F: along the path's direction psi + delta
            return coupled.twist(_rotate(psi + delta - pose[2], v_front)), np.zeros(3)
        v = v_front * math.cos(delta)  # the axle point's: the front one's along the heading
        return _twist_at_origin(cp, v, v_front * math.sin(delta) / length), np.zeros(3)

    return PathFollower(path, front, control, tightest=math.tan(max_steer) / length,
                        axle=lambda pose: _axle_state(cp, pose), offset=length, length=stopping)
