"""Steering angles judged against the ``linkage`` couplings' ideal law (:mod:`.linkage_law`, the law the dynamics
hold): ``ik``'s (:func:`linkage_holds`, :func:`ik_breaches`) and ``fk``'s given ones (:func:`given_breaches`).

``ik`` (``wheel_commands``' ``in_linkage``): each wheel's angle (8.9) is its own; a held linkage sets them all from
one, so a twist whose angles break its law is not feasible (a synchro drive, one ``parallel`` linkage of all its
wheels, asked to turn). The linkage's angles are found from its wheel whose steering axis moves fastest (its angle
the best defined; a wheel at the ICR may take any), the leader's angle from it by the law's inverse; a wheel whose
angle is off the law by ``e`` (mod pi: a wheel rolls either way, the spin reversed) at an axis speed ``s`` breaks it
when ``|e| > LINKAGE_TOL`` (round-off) and ``s |sin e| > slip_tol``: set by the linkage, it would slip sideways at
more than the slip check's floor (the gear check's rule, :mod:`.gear_check`). An Ackermann linkage (fixed wheels)
holds for every twist the fixed wheels roll with: the ICR is on their axle line.

``fk``: given (sensed) angles are a configuration: a follower off the law at its leader's angle (mod 2 pi) by more
than ``asin(rtol)`` breaks the linkage, which could not set it, and the twist from it is not the robot's
(:class:`LinkageAngleWarning`): ``rtol`` is ``fk``'s slip tolerance (2 % of the fastest speed), and a wheel set that far
off would slip sideways at that fraction of its speed (1.15 deg: sensed or rounded headings pass).
Linkages with no law to hold (:func:`wmrkit.couplings.linkage_law`), or that the robot cannot hold (no axle line, every
wheel on it) are not judged.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..robot import Robot
from ..wheels import heading_from_beta
from .linkage_law import LINKAGE_TOL, law, leader_of, linkage_table, remainder

#: Twists from which a batch is judged by the compiled kernel (:mod:`._linkage_kernel`), below by its Python
#: source: numba takes a moment to import, a few twists do not.
COMPILED_BATCH = 64


class LinkageAngleWarning(UserWarning):
    """Given steering angles break a ``linkage`` coupling's law (:func:`given_breaches`): the linkage cannot set
    them, so the twist ``fk`` finds from them is not the robot's."""


@dataclass(frozen=True, eq=False)
class _Plan:
    """A robot's held linkages, flat for a loop (read-only arrays): the follower rows of :func:`linkage_table`,
    linkage ``g``'s rows ``start[g]:start[g + 1]``, its leader's column ``lead[g]`` and its position in
    ``robot.couplings`` ``coupling[g]``; the steering axes ``x``, ``y`` [m], the ``steer_range`` as its start ``lo``
    and ``width`` [rad] (0 and inf without one) and ``offset`` = ``delta - pi/2`` (heading = beta + offset), each
    ``(n_steer,)``."""

    table: np.ndarray
    start: np.ndarray
    lead: np.ndarray
    coupling: np.ndarray
    x: np.ndarray
    y: np.ndarray
    lo: np.ndarray
    width: np.ndarray
    offset: np.ndarray


@functools.lru_cache(maxsize=64)
def _plan(robot: Robot) -> _Plan:
    names = tuple(f"{n}.steer" for n in robot.steer_names)
    table = linkage_table(robot, names, strict=False)
    leads = list(dict.fromkeys(int(r[1]) for r in table))
    coupling = [next(i for i, c in enumerate(robot.couplings) if c.kind == "linkage" and names[k] in c.joints)
                for k in leads]
    rows = [table[table[:, 1] == k] for k in leads]
    wheels = [robot.wheel(n) for n in robot.steer_names]
    xy = np.array([w.position for w in wheels], dtype=float).reshape(-1, 2)
    ranges = np.array([w.steer_range or (0.0, math.inf) for w in wheels], dtype=float).reshape(-1, 2)
    arrays = (np.concatenate([table[:0], *rows]), np.cumsum([0, *map(len, rows)]).astype(np.int64),
              np.array(leads, dtype=np.int64), np.array(coupling, dtype=np.int64), xy[:, 0].copy(), xy[:, 1].copy(),
              ranges[:, 0].copy(), ranges[:, 1] - ranges[:, 0],
              np.array([w.delta - 0.5 * math.pi for w in wheels], dtype=float))
    for a in arrays:
        a.flags.writeable = False
    return _Plan(*arrays)


def _reference(table, first, last, lead, beta, speed):
    """``ik``'s reference of the linkage of rows `first:last` of `table` (leader column `lead`) at steering angles
    `beta` and axis speeds `speed` ``(n_steer,)``: the first of its fastest wheels the leader's angle can be found
    from (the leader, a follower whose law turns it), and the leader's angle it gives, ``(column, angle)``; column -1
    when none of its axes moves (written to compile: :mod:`._linkage_kernel`)."""
    top = speed[lead]
    for r in range(first, last):
        top = max(top, speed[int(table[r, 0])])
    if top == 0.0:
        return -1, 0.0
    ref, ref_row = lead, -1
    for r in range(first, last):
        k = int(table[r, 0])
        if (table[r, 3] == 0.0 or table[r, 5] != 0.0) and speed[k] > speed[ref]:
            ref, ref_row = k, r
    return ref, (beta[lead] if ref_row < 0 else leader_of(table[ref_row], beta[ref]))


def _breach(table, first, last, lead, beta, speed, by_speed, slip_tol, tol):
    """The first wheel that the linkage of rows `first:last` of `table` (leader column `lead`) breaks at steering
    angles `beta` ``(n_steer,)``: ``(column, want, reference column, slip)``, column -1 for none (written to compile:
    :mod:`._linkage_kernel`). `by_speed` (ik): axis speeds `speed`, mod pi on the slip floor, the reference
    :func:`_reference`'s; else (fk) mod 2 pi within `tol`, the reference the leader."""
    ref, b = lead, beta[lead]
    if by_speed:
        ref, b = _reference(table, first, last, lead, beta, speed)
        if ref < 0:
            return -1, 0.0, lead, 0.0
    return _breach_at(table, first, last, lead, beta, speed, by_speed, slip_tol, tol, ref, b)


def _breach_at(table, first, last, lead, beta, speed, by_speed, slip_tol, tol, ref, b):
    """:func:`_breach` from the reference column `ref` and the leader's angle `b` it gives (found once by a caller
    that also sets the roots, :func:`_roots_at`)."""
    period = math.pi if by_speed else 2.0 * math.pi
    for r in range(first - 1, last):  # the leader, then its followers
        k = lead if r < first else int(table[r, 0])
        off = remainder(beta[k] - (b if r < first else law(table[r], b)[0]), period)
        slip = speed[k] * abs(math.sin(off)) if by_speed else 0.0
        if abs(off) > tol and (slip > slip_tol or not by_speed):
            return k, beta[k] - off, ref, slip
    return -1, 0.0, ref, 0.0


def _roots(table, first, last, lead, beta, speed, free, lo, width, offset, turn):
    """The wheels of the linkage of rows `first:last` of `table` (leader column `lead`) that ``ik``'s steering angles
    `beta` ``(n_steer,)`` put on a root of (8.9) the linkage does not set, from :func:`_reference` (axis speeds
    `speed`), as :func:`_breach` judges them: :func:`_roots_at` (written to compile: :mod:`._linkage_kernel`)."""
    ref, b = _reference(table, first, last, lead, beta, speed)
    if ref >= 0:
        _roots_at(table, first, last, lead, beta, b, math.pi, free, lo, width, offset, turn)


def _roots_at(table, first, last, lead, beta, b, half, free, lo, width, offset, turn):
    """``turn[k]`` for each wheel k of the linkage that ik chose the root of (``free[k]``: moving, steered by the
    twist): whether its angle ``beta[k]`` is more than 90 deg from the angle the law sets it at from the leader's
    angle `b`; from ``b + half`` (the leader's angle with the reference wheel turned half round: pi for a linkage,
    every such wheel turned with it; a gear's ratio of the two, :func:`.gear_check.steer_roots`) when that puts all
    of them within their steering ranges (``heading = beta + offset`` at most ``width`` counter-clockwise from
    ``lo``) and `b` does not. ``turn`` is left as it is elsewhere."""
    if not _set_roots(table, first, last, lead, beta, b, free, lo, width, offset, turn, True):
        if half != 0.0 and _set_roots(table, first, last, lead, beta, b + half, free, lo, width, offset, turn, False):
            _set_roots(table, first, last, lead, beta, b + half, free, lo, width, offset, turn, True)


def _set_roots(table, first, last, lead, beta, b, free, lo, width, offset, turn, write):
    """Whether every free wheel of the linkage fits its steering range on the root the law sets from the leader's
    angle `b`, those roots written to ``turn`` (True: the other one) if `write`."""
    fits = True
    for r in range(first - 1, last):  # the leader, then its followers
        k = lead if r < first else int(table[r, 0])
        if free[k]:
            other = math.cos(beta[k] - (b if r < first else law(table[r], b)[0])) < 0.0
            fits = fits and in_range_at(beta[k] + offset[k] + (math.pi if other else 0.0), lo[k], width[k])
            if write:
                turn[k] = other
    return fits


def in_range_at(h, lo, width):
    """Whether heading `h` [rad] is within `width` counter-clockwise of `lo` (:func:`wmrkit.wheels.heading_in_range`'s
    operations, tolerance 1e-12; ``width`` inf: no range, answered without the reduction, as any width of a whole
    turn; written to compile, the ``realtime`` ik's too)."""
    return width >= 2.0 * math.pi or (h - lo + 1e-12) % (2.0 * math.pi) - 1e-12 <= width + 1e-12


def _holds(table, start, lead, coupling, beta, speed, slip_tol, tol, out):
    """:func:`linkage_holds` over rows ``(N, n_steer)`` of `beta` and `speed`: `out` ``(N, n_couplings)`` (all True
    on entry) False at each linkage broken (written to compile: :mod:`._linkage_kernel`)."""
    for i in range(beta.shape[0]):
        for g in range(lead.shape[0]):
            if _breach(table, start[g], start[g + 1], lead[g], beta[i], speed[i], True, slip_tol, tol)[0] >= 0:
                out[i, coupling[g]] = False


def _turns(table, start, lead, beta, speed, free, lo, width, offset, out):
    """:func:`_roots` of every linkage over rows ``(N, n_steer)`` of `beta`, `speed` and `free`: `out` ``(N,
    n_steer)`` (all False on entry) True at each wheel to turn onto its other root (written to compile:
    :mod:`._linkage_kernel`)."""
    for i in range(beta.shape[0]):
        for g in range(lead.shape[0]):
            _roots(table, start[g], start[g + 1], lead[g], beta[i], speed[i], free[i], lo, width, offset, out[i])


@dataclass(frozen=True)
class Breach:
    """A wheel (`column` of the steering) whose angle `beta` [rad] is off its linkage's law, which sets it at `want`
    (on the wheel's branch, mod pi for ``ik``) with the linkage's `reference` wheel at `ref_beta`; `coupling` the
    linkage's position in ``robot.couplings``; `slip` [m/s] the side speed it would roll at (ik; 0 for fk)."""

    coupling: int
    column: int
    beta: float
    want: float
    reference: int
    ref_beta: float
    slip: float = 0.0

    def describe(self, robot: Robot) -> str:
        """``"<linkage> (law ...) sets <wheel> at heading ... deg with <reference> at ... deg, not ... deg"``, the
        linkage in the description's terms (:meth:`wmrkit.couplings.Coupling.words`; the JSON keeps its channel)."""
        from ..couplings import linkage_law

        c = robot.couplings[self.coupling]
        names = robot.steer_names
        head = [math.degrees(float(heading_from_beta(b, robot.wheel(names[k]).delta)))
                for k, b in ((self.column, self.want), (self.reference, self.ref_beta), (self.column, self.beta))]
        return (f"{c.words()} (law {linkage_law(c, robot.wheels)}) sets {names[self.column]} at heading "
                f"{head[0]:.6g} deg with {names[self.reference]} at {head[1]:.6g} deg, not {head[2]:.6g} deg")


def _judge(plan: _Plan, beta: np.ndarray, speed: np.ndarray | None, slip_tol: float, tol: float) -> list[Breach]:
    """The breaches of steering angles `beta` ``(n_steer,)`` (:func:`_breach`; `speed` None: fk's)."""
    out = []
    for g in range(len(plan.lead)):
        k, want, ref, slip = _breach(plan.table, int(plan.start[g]), int(plan.start[g + 1]), int(plan.lead[g]), beta,
                                     beta if speed is None else speed, speed is not None, slip_tol, tol)
        if k >= 0:
            out.append(Breach(int(plan.coupling[g]), k, float(beta[k]), float(want), ref, float(beta[ref]),
                              float(slip)))
    return out


def _speeds(plan: _Plan, twist: np.ndarray) -> np.ndarray:
    """The speeds [m/s] of the steering axes ``(..., n_steer)`` under `twist` ``(..., 3)``."""
    vx, vy, w = twist[..., 0:1], twist[..., 1:2], twist[..., 2:3]
    return np.hypot(vx - w * plan.y, vy + w * plan.x)


def ik_breaches(robot: Robot, twist: np.ndarray, beta: np.ndarray, slip_tol: float) -> list[Breach]:
    """The linkages (one breach each, the first wheel off) that ``ik``'s steering `beta` ``(n_steer,)`` for one
    `twist` ``(3,)`` breaks (module docstring)."""
    plan = _plan(robot)
    if not len(plan.lead):
        return []
    speed = _speeds(plan, np.asarray(twist, dtype=float))
    return _judge(plan, np.asarray(beta, dtype=float), speed, slip_tol, LINKAGE_TOL)


def linkage_holds(robot: Robot, twist: np.ndarray, beta: np.ndarray, slip_tol: float) -> np.ndarray:
    """``(..., n_couplings)`` bool: False at a linkage the steering `beta` ``(..., n_steer)`` that ``ik`` gives for
    `twist` ``(..., 3)`` breaks (:func:`ik_breaches`); True for the other couplings. A batch of at least
    :data:`COMPILED_BATCH` twists is judged by the compiled :func:`_holds` (numba loads on first use)."""
    plan = _plan(robot)
    batch = np.broadcast_shapes(twist.shape[:-1], beta.shape[:-1])
    out = np.ones((*batch, len(robot.couplings)), dtype=bool)
    if not len(plan.lead):
        return out
    n = len(plan.x)
    speed = np.broadcast_to(_speeds(plan, twist), (*batch, n)).reshape(-1, n)
    flat_beta = np.broadcast_to(beta, (*batch, n)).reshape(-1, n)
    holds = _holds
    if len(speed) >= COMPILED_BATCH:
        from ._linkage_kernel import holds
    holds(plan.table, plan.start, plan.lead, plan.coupling, flat_beta, speed, float(slip_tol), LINKAGE_TOL,
          out.reshape(-1, len(robot.couplings)))
    return out


def linkage_turns(robot: Robot, twist: np.ndarray, beta: np.ndarray, free: np.ndarray) -> np.ndarray | None:
    """``(..., n_steer)`` bool: the linked wheels whose root of (8.9) ``ik`` chose (`free` ``(..., n_steer)``: moving,
    steered by the twist) and whose angle in its steering `beta` ``(..., n_steer)`` for `twist` ``(..., 3)`` is the
    root their linkage does not set (:func:`_roots`: from the linkage's reference wheel, the one
    :func:`linkage_holds` judges from, or all turned half round with it where only that fits their steering ranges);
    None for a robot without a held linkage. ``ik`` turns them half round, spin reversed. A batch of at least
    :data:`COMPILED_BATCH` twists is judged by the compiled :func:`_turns`."""
    plan = _plan(robot)
    if not len(plan.lead):
        return None
    n = len(plan.x)
    batch = np.broadcast_shapes(twist.shape[:-1], beta.shape[:-1], free.shape[:-1])
    speed = np.broadcast_to(_speeds(plan, twist), (*batch, n)).reshape(-1, n)
    flat_beta = np.broadcast_to(beta, (*batch, n)).reshape(-1, n)
    flat_free = np.broadcast_to(free, (*batch, n)).reshape(-1, n)
    out = np.zeros(flat_beta.shape, dtype=bool)
    turns = _turns
    if len(speed) >= COMPILED_BATCH:
        from ._linkage_kernel import turns
    turns(plan.table, plan.start, plan.lead, flat_beta, speed, flat_free, plan.lo, plan.width, plan.offset, out)
    return out.reshape(*batch, n)


def given_breaches(robot: Robot, beta: np.ndarray, rtol: float) -> list[Breach]:
    """The linkages that given steering angles `beta` ``(n_steer,)`` (``fk``'s) break, one breach each: a follower
    off the law at its leader's angle by more than ``asin(rtol)`` (mod 2 pi; module docstring)."""
    plan = _plan(robot)
    tol = math.asin(min(rtol, 1.0))
    return _judge(plan, np.asarray(beta, dtype=float), None, 0.0, tol) if len(plan.lead) else []
