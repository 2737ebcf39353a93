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
from .linkage_law import LINKAGE_TOL, law, leader_of, linkage_table


class LinkageAngleWarning(UserWarning):
    """Given steering angles break a ``linkage`` coupling's law (:func:`given_breaches`): the linkage cannot set
    them, so the twist ``fk`` finds from them is not the robot's."""


@dataclass(frozen=True, eq=False)
class _Plan:
    """A robot's held linkages: per linkage its position in ``robot.couplings``, its columns (the leader's first),
    its table rows (as lists) and the ``(column, row)`` of the wheels its leader's angle can be found from (the leader,
    row None; a follower whose law turns it)."""

    groups: tuple[tuple[int, list[int], list[list[float]], list[tuple[int, list[float] | None]]], ...]
    x: np.ndarray  # (n_steer,) steering axes [m]
    y: np.ndarray


@functools.lru_cache(maxsize=64)
def _plan(robot: Robot) -> _Plan:
    names = tuple(f"{n}.steer" for n in robot.steer_names)
    table = linkage_table(robot, names, strict=False)
    groups = []
    for lead in dict.fromkeys(int(r[1]) for r in table):
        index = next(i for i, c in enumerate(robot.couplings) if c.kind == "linkage" and names[lead] in c.joints)
        rows = table[table[:, 1] == lead].tolist()
        able = [(lead, None), *((int(r[0]), r) for r in rows if r[3] == 0.0 or r[5] != 0.0)]
        groups.append((index, [lead, *(int(r[0]) for r in rows)], rows, able))
    xy = np.array([robot.wheel(n).position for n in robot.steer_names], dtype=float).reshape(-1, 2)
    return _Plan(tuple(groups), xy[:, 0], xy[:, 1])


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
        """``"<linkage> (law ...) sets <wheel> at heading ... deg with <reference> at ... deg, not ... deg"``."""
        from ..couplings import linkage_law

        c = robot.couplings[self.coupling]
        names = robot.steer_names
        head = [math.degrees(float(heading_from_beta(b, robot.wheel(names[k]).delta)))
                for k, b in ((self.column, self.want), (self.reference, self.ref_beta), (self.column, self.beta))]
        return (f"{c.channel_name} (law {linkage_law(c, robot.wheels)}) sets {names[self.column]} at heading "
                f"{head[0]:.6g} deg with {names[self.reference]} at {head[1]:.6g} deg, not {head[2]:.6g} deg")


def _judge(plan: _Plan, beta: list[float], speed: list[float] | None, slip_tol: float, tol: float) -> list[Breach]:
    """The breaches of steering angles `beta` ``(n_steer,)``: with axis speeds `speed` (ik) mod pi on the slip
    floor, the reference the fastest; without (fk) mod 2 pi within `tol`, the reference the leader."""
    out = []
    for index, members, rows, able in plan.groups:
        lead = members[0]
        ref, ref_row = lead, None
        if speed is not None:
            if max(speed[k] for k in members) == 0.0:
                continue
            ref, ref_row = max(able, key=lambda a: speed[a[0]])  # the first of the fastest: the leader on a tie
        b = beta[lead] if ref_row is None else leader_of(ref_row, beta[ref])
        wants = [b, *(law(r, b)[0] for r in rows)]
        for k, want in zip(members, wants, strict=True):
            off = math.remainder(beta[k] - want, math.pi if speed is not None else 2 * math.pi)
            slip = 0.0 if speed is None else speed[k] * abs(math.sin(off))
            if abs(off) > tol and (speed is None or slip > slip_tol):
                out.append(Breach(index, k, float(beta[k]), float(beta[k] - off), ref, float(beta[ref]), slip))
                break
    return out


def _speeds(plan: _Plan, twist: np.ndarray) -> np.ndarray:
    """The speeds [m/s] of the steering axes ``(..., n_steer)`` under `twist` ``(..., 3)``."""
    vx, vy, w = twist[..., 0:1], twist[..., 1:2], twist[..., 2:3]
    return np.hypot(vx - w * plan.y, vy + w * plan.x)


def ik_breaches(robot: Robot, twist: np.ndarray, beta: np.ndarray, slip_tol: float) -> list[Breach]:
    """The linkages (one breach each, the first wheel off) that ``ik``'s steering `beta` ``(n_steer,)`` for one
    `twist` ``(3,)`` breaks (module docstring)."""
    plan = _plan(robot)
    if not plan.groups:
        return []
    speed = _speeds(plan, np.asarray(twist, dtype=float)).tolist()
    return _judge(plan, np.asarray(beta, dtype=float).tolist(), speed, slip_tol, LINKAGE_TOL)


def linkage_holds(robot: Robot, twist: np.ndarray, beta: np.ndarray, slip_tol: float) -> np.ndarray:
    """``(..., n_couplings)`` bool: False at a linkage the steering `beta` ``(..., n_steer)`` that ``ik`` gives for
    `twist` ``(..., 3)`` breaks (:func:`ik_breaches`); True for the other couplings."""
    plan = _plan(robot)
    batch = np.broadcast_shapes(twist.shape[:-1], beta.shape[:-1])
    out = np.ones((*batch, len(robot.couplings)), dtype=bool)
    if not plan.groups:
        return out
    speed = np.broadcast_to(_speeds(plan, twist), (*batch, len(plan.x))).reshape(-1, len(plan.x)).tolist()
    flat_beta = np.broadcast_to(beta, (*batch, len(plan.x))).reshape(-1, len(plan.x)).tolist()
    flat = out.reshape(-1, len(robot.couplings))
    for i, (b_i, s_i) in enumerate(zip(flat_beta, speed, strict=True)):
        for b in _judge(plan, b_i, s_i, slip_tol, LINKAGE_TOL):
            flat[i, b.coupling] = False
    return out


def given_breaches(robot: Robot, beta: np.ndarray, rtol: float) -> list[Breach]:
    """The linkages that given steering angles `beta` ``(n_steer,)`` (``fk``'s) break, one breach each: a follower
    off the law at its leader's angle by more than ``asin(rtol)`` (mod 2 pi; module docstring)."""
    plan = _plan(robot)
    tol = math.asin(min(rtol, 1.0))
    return _judge(plan, np.asarray(beta, dtype=float).tolist(), None, 0.0, tol) if plan.groups else []
