"""The one check of a command's joint rates against its ``gear`` couplings (``q_j = ratio_j u``).

``wheel_commands``' ``in_gear`` (``wmrkit ik``, the simulator's programs and ``--initial-twist``) calls
:func:`gears_hold`; the compiled ``realtime`` ik and the generated C and Python (``kinematics --codegen``) print its
formula with the tables of :func:`gear_table`. A gear holds when, ``u = k.q / k.k`` its least-squares turn and
``e_j = |q_j - ratio_j u|`` each joint's departure [rad/s], either every ``e_j <= GEAR_RTOL max |q|`` (round-off of
the rates, relative to the command's largest) or every ``e_j lever_j <= slip_tol``: the speed [m/s] the departure
moves the joint's contact at (:func:`contact_lever`) within the slip check's absolute floor, so that a twist of
1e-320 rad/s is judged as one of 1e-320 m/s (both roll) and the floor scales with the robot.

A gear between steering joints (two double wheels' steering turned 1:2) turns their angles too, ``beta_j - beta_j0 =
ratio_j u`` from the described ones (the dynamics' rule, :func:`wmrkit.dynamics.linkages.gear_breach`), while ik sets
each wheel's angle by (8.9) on its own: :func:`steer_breach` judges those angles as the linkage check judges a
linkage's (:mod:`.linkage_check`). ``u`` is found from the gear's wheel whose steering axis moves fastest (its angle
the best defined), from either of its roots (``b``, ``b + pi``); a wheel the gear then sets off its own angle by ``e``
(mod pi: it rolls either way) breaks the gear when ``|e| > LINKAGE_TOL`` and its axis speed times ``|sin e|`` (the
side speed it would slip at, set by the gear) exceeds ``slip_tol``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..couplings import GEAR_EXACT_RTOL, GearBreach, gear_breaches
from ..robot import Robot
from ..wheels import Wheel, heading_from_beta
from .linkage_check import Breach
from .linkage_law import LINKAGE_TOL, remainder

#: A gear's rates are in its ratios when each departs from them by at most this fraction of the command's largest
#: joint rate (round-off of the rates (8.12)-(8.28) is ~1e-16 of it).
GEAR_RTOL = 1e-9


def contact_lever(wheel: Wheel, joint: str) -> float:
    """The length [m] turning `joint`'s rate [rad/s] into the speed of the wheel's contact: a spin's (``spin``,
    ``spin1``, ``spin2``) wheel radius, a roller's radius (``r_r``; a ball's or orthogonal wheel's ``r``), a steering
    rate's distance from the steering axis to the contacts, ``hypot(d, b)`` (a castor's offset, a double wheel's
    half spacing)."""
    if joint == "steer":
        return math.hypot(wheel.d, wheel.b)
    if joint == "roller" and "r_r" in wheel.kind.required:
        return abs(wheel.r_r)
    return abs(wheel.r)


@dataclass(frozen=True, eq=False)
class GearTable:
    """A robot's ``gear`` couplings, flattened for a loop: gear ``g``'s joints are entries ``start[g]:start[g+1]``
    of ``joint`` (their positions in the checked rates), ``ratio`` and ``lever`` [m] (:func:`contact_lever`);
    ``coupling`` their positions in ``robot.couplings``. Read-only arrays."""

    coupling: tuple[int, ...]
    joint: np.ndarray
    ratio: np.ndarray
    lever: np.ndarray
    start: np.ndarray


@functools.lru_cache(maxsize=64)
def gear_table(robot: Robot, names: tuple[str, ...]) -> GearTable:
    """The :class:`GearTable` of `robot`'s gears over rates named `names` (``wheel.joint``): each gear's joints among
    them (all, for ik's rates; ``fk``'s given rates may name some: a gear with fewer than two is left out, nothing
    to judge). Kept per robot (a frozen value)."""
    gears = [(i, [(j, k) for j, k in zip(c.joints, c.ratios, strict=True) if j in names])
             for i, c in enumerate(robot.couplings) if c.kind == "gear"]
    gears = [(i, read) for i, read in gears if len(read) >= 2]
    joints = [j for _, read in gears for j, _ in read]
    arrays = (np.array([names.index(j) for j in joints], dtype=np.int64),
              np.array([k for _, read in gears for _, k in read], dtype=float),
              np.array([contact_lever(robot.wheel(j.partition(".")[0]), j.partition(".")[2]) for j in joints],
                       dtype=float),
              np.cumsum([0] + [len(read) for _, read in gears]).astype(np.int64))
    for a in arrays:
        a.flags.writeable = False
    return GearTable(tuple(i for i, _ in gears), *arrays)


def gears_hold(table: GearTable, q: np.ndarray, slip_tol: float, rtol: float = GEAR_RTOL) -> np.ndarray:
    """Whether each gear of `table` turns the rates `q` ``(..., n)`` in its ratios (the module's rule, with the
    slip check's floor `slip_tol` [m/s]): ``(..., n_gears)`` bool; False where a rate of the gear is NaN. The sums
    run joint by joint in the table's order, as the compiled and generated loops run them. `rtol` 0 judges by the
    floor alone (``fk``'s given rates, judged relatively by :func:`wmrkit.couplings.gear_breaches`)."""
    scale = rtol * np.abs(q).max(axis=-1, initial=0.0)
    out = []
    for g in range(len(table.coupling)):
        span = range(int(table.start[g]), int(table.start[g + 1]))
        kq = kk = 0.0
        for t in span:
            kq = kq + table.ratio[t] * q[..., table.joint[t]]
            kk = kk + table.ratio[t] * table.ratio[t]
        relative = absolute = True
        for t in span:
            e = np.abs(q[..., table.joint[t]] - table.ratio[t] * (kq / kk))
            relative = relative & (e <= scale)
            absolute = absolute & (e * table.lever[t] <= slip_tol)
        out.append(relative | absolute)
    return np.stack(out, axis=-1) if out else np.zeros((*q.shape[:-1], 0), dtype=bool)


def given_gear_breaches(robot: Robot, names: tuple[str, ...], q: np.ndarray, slip_tol: float) -> list[GearBreach]:
    """The gears whose given rates `q` (one row, of the joints `names`) break their ratios beyond round-off
    (:func:`wmrkit.couplings.gear_breaches` at :data:`~wmrkit.couplings.GEAR_EXACT_RTOL`), unless each joint's
    departure moves its contact within the slip floor `slip_tol` [m/s] (:func:`gears_hold` with no relative part):
    1e-320 rad/s on one wheel of a 1:1 axle and 0 on the other roll alike, as ik judges them (``fk``'s given rates,
    the extended solutions' assigned rows, a simulator state)."""
    table = gear_table(robot, names)
    held = gears_hold(table, np.asarray(q, dtype=float), slip_tol, rtol=0.0)
    within = {id(robot.couplings[i]) for i, h in zip(table.coupling, held, strict=True) if h}
    return [b for b in gear_breaches(robot.couplings, names, q, GEAR_EXACT_RTOL) if id(b.coupling) not in within]


@dataclass(frozen=True, eq=False)
class SteerGears:
    """A robot's gears between steering joints, flat for a loop: `table` their :class:`GearTable` over the steering
    angles (``joint`` a column of ``robot.steer_names``), `rest` the described angles (thesis, ``(n_steer,)`` [rad]),
    `x`, `y` the steering axes [m] ``(n_steer,)``. Read-only arrays."""

    table: GearTable
    rest: np.ndarray
    x: np.ndarray
    y: np.ndarray


@functools.lru_cache(maxsize=64)
def steer_gears(robot: Robot) -> SteerGears:
    """The :class:`SteerGears` of `robot` (kept per robot, a frozen value)."""
    table = gear_table(robot, tuple(f"{n}.steer" for n in robot.steer_names))
    xy = np.array([robot.wheel(n).position for n in robot.steer_names], dtype=float).reshape(-1, 2)
    arrays = (np.array(robot.beta, dtype=float).reshape(-1), xy[:, 0].copy(), xy[:, 1].copy())
    for a in arrays:
        a.flags.writeable = False
    return SteerGears(table, *arrays)


def steer_breach(joint, ratio, first, last, rest, x, y, vx, vy, w, beta, slip_tol, tol):
    """The first steering angle that the gear of entries `first:last` (``joint``, ``ratio``) breaks at angles `beta`
    ``(n_steer,)`` under the twist ``(vx, vy, w)`` (module docstring): ``(entry, angle the gear sets it at, on its
    branch, reference entry, side speed [m/s])``, entry -1 for none (written to compile: :mod:`._gear_kernel` and the
    ``realtime`` ik call it compiled)."""
    ref, top = -1, 0.0
    for t in range(first, last):
        s = math.hypot(vx - w * y[joint[t]], vy + w * x[joint[t]])
        if s > top:
            ref, top = t, s
    if ref < 0:
        return -1, 0.0, first, 0.0
    turn = remainder(beta[joint[ref]] - rest[joint[ref]], 2.0 * math.pi)
    found, want, slip = -1, 0.0, 0.0
    for m in range(2):  # the reference's root b, then b + pi
        u = (turn + m * math.pi) / ratio[ref]
        hit = -1
        for t in range(first, last):
            k = joint[t]
            off = remainder(beta[k] - rest[k] - ratio[t] * u, math.pi)
            if t == ref or abs(off) <= tol:
                continue
            side = math.hypot(vx - w * y[k], vy + w * x[k]) * abs(math.sin(off))
            if side > slip_tol:
                hit = t
                if m == 0:
                    found, want, slip = t, beta[k] - off, side
                break
        if hit < 0:
            return -1, 0.0, ref, 0.0
    return found, want, ref, slip


def _steer_holds(joint, ratio, start, rest, x, y, twist, beta, slip_tol, tol, out):
    """:func:`steer_breach` over rows ``(N, 3)`` of `twist` and ``(N, n_steer)`` of `beta`: `out` ``(N, n_gears)``
    (all True on entry) False at each gear broken (written to compile: :mod:`._gear_kernel`)."""
    for i in range(beta.shape[0]):
        for g in range(start.shape[0] - 1):
            if steer_breach(joint, ratio, start[g], start[g + 1], rest, x, y, twist[i, 0], twist[i, 1], twist[i, 2],
                            beta[i], slip_tol, tol)[0] >= 0:
                out[i, g] = False


#: Twists from which a batch of steering gears is judged by the compiled kernel (:mod:`._gear_kernel`).
COMPILED_BATCH = 64


def steer_gears_hold(robot: Robot, twist: np.ndarray, beta: np.ndarray, slip_tol: float) -> np.ndarray:
    """``(..., n_couplings)`` bool: False at a gear between steering joints that the angles `beta` ``(...,
    n_steer)`` ``ik`` gives for `twist` ``(..., 3)`` break (:func:`steer_breach`); True for the other couplings.
    A batch of at least :data:`COMPILED_BATCH` twists is judged compiled."""
    sg = steer_gears(robot)
    batch = np.broadcast_shapes(twist.shape[:-1], beta.shape[:-1])
    out = np.ones((*batch, len(robot.couplings)), dtype=bool)
    if not sg.table.coupling:
        return out
    n = len(sg.rest)
    rows = np.ascontiguousarray(np.broadcast_to(twist, (*batch, 3)).reshape(-1, 3), dtype=float)
    angles = np.ascontiguousarray(np.broadcast_to(beta, (*batch, n)).reshape(-1, n), dtype=float)
    held = np.ones((len(rows), len(sg.table.coupling)), dtype=bool)
    holds = _steer_holds
    if len(rows) >= COMPILED_BATCH:
        from ._gear_kernel import holds
    t = sg.table
    holds(t.joint, t.ratio, t.start, sg.rest, sg.x, sg.y, rows, angles, float(slip_tol), LINKAGE_TOL, held)
    out[..., list(t.coupling)] = held.reshape(*batch, -1)
    return out


class SteerBreach(Breach):
    """A wheel (steering `column`) at angle `beta` [rad] that the gear at `coupling` (its position in
    ``robot.couplings``) sets at `want` (on the wheel's branch, mod pi) with its `reference` wheel at `ref_beta`;
    `slip` [m/s] the side speed the wheel would roll at, so set (a linkage's :class:`.linkage_check.Breach`, worded
    for a gear)."""

    def describe(self, robot: Robot) -> str:
        """``"<gear> (ratios ...) sets <wheel> at heading ... deg with <reference> at ... deg, not ... deg (... deg
        off; ... m/s)"``."""
        c, names = robot.couplings[self.coupling], robot.steer_names
        head = [math.degrees(float(heading_from_beta(b, robot.wheel(names[k]).delta)))
                for k, b in ((self.column, self.want), (self.reference, self.ref_beta), (self.column, self.beta))]
        return (f"{c.channel_name} (ratios {', '.join(f'{k:g}' for k in c.ratios)}) sets {names[self.column]} at "
                f"heading {head[0]:.6g} deg with {names[self.reference]} at {head[1]:.6g} deg, not {head[2]:.6g} deg, "
                f"which the twist needs ({math.degrees(abs(self.want - self.beta)):.3g} deg off; set by the gear, the "
                f"wheel would slip sideways at {self.slip:.3g} m/s)")


def steer_breaches(robot: Robot, twist: np.ndarray, beta: np.ndarray, slip_tol: float) -> list[SteerBreach]:
    """The gears between steering joints that ``ik``'s angles `beta` ``(n_steer,)`` for one `twist` ``(3,)`` break,
    one :class:`SteerBreach` each (the first wheel off)."""
    sg, out = steer_gears(robot), []
    t, (vx, vy, w), beta = sg.table, np.asarray(twist, dtype=float).tolist(), np.asarray(beta, dtype=float)
    for g, c in enumerate(t.coupling):
        e, want, ref, slip = steer_breach(t.joint, t.ratio, int(t.start[g]), int(t.start[g + 1]), sg.rest, sg.x, sg.y,
                                          vx, vy, w, beta, slip_tol, LINKAGE_TOL)
        if e >= 0:
            k, r = int(t.joint[e]), int(t.joint[ref])
            out.append(SteerBreach(c, k, float(beta[k]), float(want), r, float(beta[r]), float(slip)))
    return out
