"""The reduced control point of a robot whose steering couplings leave it one steering degree of freedom.

Two steered units turned by one ``gear`` (or a ``linkage``) and no fixed wheel: classified by their generic ranks
as type 5 (δm = 1, δs = 2), but the coupling leaves one turn ``u`` of the leader's heading (``h = h0 + u``, the
followers set by the ratios or the law, :mod:`.linked_ranges`), so the robot is a type (1, 1) without fixed wheels:
maneuverability 2, as the car. The thesis merges coupled orientable wheels into one equivalent wheel (§5.2, digest
ch5-6 2.3) and controls types 2 and 4 by the ``(x, y)`` of a point off the axle, the heading as zero dynamics
(§8.4-8.5, Table 8.1); it has no closed form for a coupling whose ICR curve is not a line. Here, at turn ``u`` the
admissible twists are the null space ``n(u)`` of the wheels' constraint lines (6.18) at the coupled headings
(one-dimensional: the ICR fixed by ``u``), so the velocity of a body point ``P`` is ``s g(u)``, ``g = M_P n``
(rigid body, speed ``s``), and the law's wanted velocity of ``P`` gives ``(s, u)``: ``u`` where ``g(u)`` points
along it (Newton on the angle, from the branch's table), then ``s``. The commanded twist ``s n(u)`` is admissible by
construction: every wheel's lateral constraint holds at the coupled headings.

``u`` is sought on one branch: the interval around straight driving (``n`` a translation, ``u0``) where the
direction of ``P``'s velocity turns monotonically with ``u`` (it folds beyond: 1:2 units at ``P`` ahead turn it
by -0.6 a radian of ``u`` at ``u0`` and fold at ``u = -0.84`` and ``1.20`` rad, where it has turned +99 and
-103 deg). A direction within the branch's arc is driven forward, else backward if its opposite is within, else the
branch's nearer end is held (the coupling's stop). Near straight driving the ICRs lie on a line, the virtual axle
(the limit of the ICR as ``u -> u0``); the default ``P`` is ahead of it by the robot's size, as the car's point
ahead of its rear axle: the heading's zero dynamics are then stable driving forward (the error of the heading decays
at ``speed / distance``), and the map is well conditioned there (``d angle / du = distance / wheelbase``).
"""


from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .._shapes import readonly
from ..analysis.lines import constraint_lines
from ..robot import Robot
from . import coupled_solve
from .coupled_solve import SAMPLES
from .linked_ranges import LinkedRanges
from .points import ControlError, _point_map, robot_reach
from .steering import steer_ranges

__all__ = ["CoupledSteering", "coupled_steering"]

#: Relative size below which a singular value is a null direction (the admissible twists are one-dimensional).
RANK_TOL = 1e-9


@dataclass(frozen=True, eq=False)
class CoupledSteering:
    """One steering degree of freedom: the turn ``u`` [rad] of the leader's heading (``robot.steer_names[leader]``)
    from its rest, the followers set by their couplings. ``point (2,)`` [m]: the controlled point; ``forward`` [rad]:
    the direction of straight driving (towards +x); ``axle_point (2,)``: the point's foot on the virtual axle (the
    point itself when no turn rotates the robot). ``turns (n,)`` [rad] and ``angles (n,)`` [rad, robot frame,
    increasing]: the branch's table of the angle of ``P``'s velocity, ``sign`` that of ``d angle / du``; ``u0`` the
    turn of straight driving. Read-only arrays; ``arrays`` the robot's for :mod:`.coupled_solve` (the formulas,
    shared with the compiled tick)."""

    robot: Robot
    leader: int
    point: np.ndarray
    forward: float
    axle_point: np.ndarray
    turns: np.ndarray
    angles: np.ndarray
    sign: float
    u0: float
    _links: LinkedRanges
    _lines: np.ndarray  # (n_lines, 3): the constraint lines at u = 0
    _pivots: np.ndarray  # (n_lines, 2): the steering pivot of each line's wheel
    _ratios: np.ndarray  # (n_lines,): its heading's turn per turn of the leader
    _null: np.ndarray  # (SAMPLES, 3): n oriented continuously from forward driving

    @property
    def arrays(self) -> tuple[np.ndarray, ...]:
        """``(lines, pivots, ratios, null, turns, angles)`` of :mod:`.coupled_solve`."""
        return self._lines, self._pivots, self._ratios, self._null, self.turns, self.angles

    def headings(self, u: float) -> np.ndarray:
        """The steered wheels' headings ``(n_steer,)`` [rad] at turn `u`."""
        return _headings(self.robot, self._links, self.leader, u)

    def lines(self, u: float) -> np.ndarray:
        """The constraint lines (6.18) at turn `u` ``(n_lines, 3)``: ``line . twist = 0`` for admissible twists."""
        out = np.empty((len(self._lines), 3))
        coupled_solve.rotated_lines(u, self._lines, self._pivots, self._ratios, out, np.empty_like(out))
        return out

    def twist_direction(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        """The unit admissible twist ``n(u)`` ``(3,)`` (oriented continuously from forward driving) and ``dn/du``
        ``(3,)`` (:func:`.coupled_solve.direction`: each line turned about its wheel's pivot at its ratio)."""
        d = coupled_solve.direction(float(u), self._lines, self._pivots, self._ratios, self._null)
        return np.array(d[:3]), np.array(d[3:])

    def point_velocity(self, speed: float, u: float) -> tuple[np.ndarray, np.ndarray]:
        """The velocity ``s g(u)`` ``(2,)`` [m/s, robot frame] of the control point at `speed` ``s`` and turn `u`,
        and its Jacobian ``(2, 2)`` in ``(s, u)``."""
        n, dn = self.twist_direction(u)
        g = _at_point(self.point, n)
        return speed * g, np.column_stack([g, speed * _at_point(self.point, dn)])

    def solve(self, velocity: np.ndarray) -> tuple[float, float, np.ndarray]:
        """``(s, u, n(u))`` giving the control point `velocity` ``(2,)`` [m/s, robot frame]: forward when its
        direction is within the branch's arc, else backward when the opposite one is, else at the branch's nearer end
        (least squares in ``s`` there); at rest ``(0, u0, n(u0))`` (:func:`.coupled_solve.solve`)."""
        s, u, *n = coupled_solve.solve(float(velocity[0]), float(velocity[1]), *self._scalars, *self.arrays)
        return s, u, np.array(n)

    def twist(self, velocity: np.ndarray) -> np.ndarray:
        """The admissible body twist ``s n(u)`` ``(3,)`` giving the control point `velocity` ``(2,)`` [m/s, robot
        frame] (:meth:`solve`)."""
        s, _, n = self.solve(velocity)
        return s * n

    @property
    def _scalars(self) -> tuple[float, float, float, float]:
        return float(self.point[0]), float(self.point[1]), float(self.sign), float(self.u0)


def _headings(robot: Robot, links: LinkedRanges, leader: int, u: float) -> np.ndarray:
    h = _rest(robot).copy()
    h[leader] += u
    links.follow(h)
    return h


@functools.lru_cache(maxsize=64)
def _rest(robot: Robot) -> np.ndarray:
    """The described headings (read-only; ``robot.heading`` converts them at each call)."""
    return readonly(np.array(robot.heading, dtype=float))


def _at_point(p: np.ndarray, twist: np.ndarray) -> np.ndarray:
    """Velocity ``(..., 2)`` of the body point `p` under `twist` ``(..., 3)`` (rigid body: ``points._point_map``)."""
    return np.asarray(twist) @ _point_map(p).T


def coupled_steering(robot: Robot, point: np.ndarray | None) -> CoupledSteering | None:
    """The one steering degree of freedom of `robot` controlled at `point` ``(2,)`` [m] (default: ahead of the
    virtual axle by the robot's size, or the origin when no turn rotates the robot), or None unless the robot has
    no fixed wheel, its constraint lines are all of steered wheels held with one leader by gears or linkages, and
    they leave one-dimensional twists at the rest turn (None too when the default point's velocity cannot be
    assigned near straight driving). Raises :class:`ControlError` for a given point on the virtual axle (its velocity
    cannot be assigned there)."""
    if any(w.type == "fixed" for w in robot.wheels):
        return None
    links = LinkedRanges.of(robot, steer_ranges(robot))
    if links is None or len(links.leaders) != 1:
        return None
    leader = int(links.leaders[0])
    group = {robot.steer_names[leader], *(robot.steer_names[f] for f in links.followers.tolist())}
    cl = constraint_lines(robot)
    if not cl.wheels or any(w not in group for w in cl.wheels):
        return None
    ratio = np.ones(len(robot.steer_names))  # each steered wheel's heading turn per turn of the leader
    for link in links.links:
        if link.ratio is None:  # a law that is not a turn in proportion (an Ackermann linkage: with fixed wheels)
            return None
        ratio[link.follower] = link.ratio
    grid = np.linspace(-math.pi, math.pi, SAMPLES, endpoint=False)
    heads = np.array([_headings(robot, links, leader, float(u)) for u in grid])
    lines = cl.lines(robot.steering(heading=heads))
    padded = np.concatenate([lines, np.zeros((SAMPLES, max(0, 3 - lines.shape[1]), 3))], axis=1)  # two lines: rank 2
    _, sv, vt = np.linalg.svd(padded)
    one = (sv[:, -1] <= RANK_TOL * sv[:, 0]) & (sv[:, -2] > RANK_TOL * sv[:, 0])  # a one-dimensional null space
    mid = SAMPLES // 2  # u = 0
    if not one[mid]:
        return None
    null = vt[:, -1].copy()
    for order in (range(mid + 1, SAMPLES), range(mid - 1, -1, -1)):  # oriented continuously from u = 0
        prev = mid
        for k in order:
            if null[k] @ null[prev] < 0:
                null[k] *= -1
            prev = k
    u0, forward = _straight(grid, null, mid)
    t = np.array([math.cos(forward), math.sin(forward)])
    k0 = int(np.argmin(np.abs(grid - u0)))
    if null[k0, :2] @ t < 0:
        null *= -1
    pivots = np.array([robot.wheel(w).position for w in cl.wheels], dtype=float)
    ratios = ratio[[robot.steer_names.index(w) for w in cl.wheels]]
    rest = cl.lines(robot.steering(heading=_headings(robot, links, leader, 0.0)))  # u = 0
    arrays = (readonly(rest), readonly(pivots), readonly(ratios), readonly(null))
    cs = CoupledSteering(robot, leader, np.zeros(2), forward, np.zeros(2), np.zeros(0), np.zeros(0), 1.0, u0, links,
                         *arrays)
    n0, dn0 = cs.twist_direction(u0)
    axle = None if abs(dn0[2]) <= RANK_TOL else (dn0[0] * n0[1] - dn0[1] * n0[0]) / (dn0[2] * math.hypot(*n0[:2]))
    if point is not None:
        p = np.asarray(point, dtype=float)
    elif axle is None:
        p = np.zeros(2)
    else:
        p = (axle + robot_reach(robot)) * t
    foot = p if axle is None else p - t * (p @ t - axle)
    g0, dg0 = _at_point(p, n0), _at_point(p, dn0)
    slope = float(g0[0] * dg0[1] - g0[1] * dg0[0]) / max(float(g0 @ g0), 1e-300)  # d angle / du at u0
    if not (float(np.hypot(*g0)) > RANK_TOL and abs(slope) > RANK_TOL):
        if point is None:  # no point of its own well placed (no first-order virtual axle): the full pose, as before
            return None
        raise ControlError(f"control point ({p[0]:g}, {p[1]:g}) m of robot '{robot.name}' lies on the virtual axle of "
                           "its coupled steering: its velocity cannot be assigned near straight driving (choose a "
                           "point ahead of it)")
    turns, angles, sign = _branch(grid, null, one, p, k0, math.copysign(1.0, slope))
    return CoupledSteering(robot, leader, readonly(p), forward, readonly(foot), readonly(turns), readonly(angles),
                           sign, u0, links, *arrays)


def _straight(grid: np.ndarray, null: np.ndarray, mid: int) -> tuple[float, float]:
    """The turn nearest 0 at which the admissible twist translates (``omega`` changes sign, refined linearly), and
    the direction of that translation towards +x [rad]; u = 0's direction when every turn translates."""
    w = null[:, 2]
    u0, k = 0.0, mid
    if abs(w[mid]) > RANK_TOL:
        cross = np.flatnonzero(np.sign(w[:-1]) != np.sign(w[1:]))
        if len(cross):
            k = int(cross[np.argmin(np.abs(grid[cross]))])
            u0 = float(grid[k] - w[k] * (grid[k + 1] - grid[k]) / (w[k + 1] - w[k]))
    forward = math.atan2(null[k, 1], null[k, 0])
    if math.cos(forward) < -1e-9 or (abs(math.cos(forward)) <= 1e-9 and math.sin(forward) < 0):
        forward = math.remainder(forward + math.pi, 2 * math.pi)  # ahead = towards +x, as points.control_point
    return u0, forward


def _branch(grid: np.ndarray, null: np.ndarray, one: np.ndarray, p: np.ndarray, k0: int,
            sign: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The branch's table: the turns around straight driving (sample `k0`) where the angle of `p`'s velocity turns
    monotonically with the `sign` it has there, the null space is one-dimensional and `p` moves; sorted by
    increasing angle, with that sign. Steering ranges do not cut it: a turn beyond them is held at their end by the
    loop's keeper and reported, as the car's (:mod:`.linked_ranges`)."""
    g = _at_point(p, null)
    speed = np.hypot(g[:, 0], g[:, 1])
    angle = np.unwrap(np.arctan2(g[:, 1], g[:, 0]))
    step = np.diff(angle)
    ok = one & (speed > RANK_TOL)
    lo = hi = k0
    while lo > 0 and ok[lo - 1] and step[lo - 1] * sign > 0:
        lo -= 1
    while hi < len(grid) - 1 and ok[hi + 1] and step[hi] * sign > 0:
        hi += 1
    turns, angles = grid[lo:hi + 1], angle[lo:hi + 1]
    return (turns, angles, sign) if sign > 0 else (turns[::-1].copy(), angles[::-1].copy(), sign)
