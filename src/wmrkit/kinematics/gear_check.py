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
each wheel's line by (8.9) on its own, and the gear the root on it: :func:`steer_roots` puts every moving wheel of the
gear on the root the gear sets from its reference wheel, the one whose steering axis moves fastest (its angle the
best defined), with the linkages' code (:func:`.linkage_check._roots_at`, the gear a row of law 2,
:func:`.linkage_law.law`): from the reference's root ``b``, or ``b + pi`` where only that one sets every wheel on its
line, or fits their steering ranges and ``b`` does not. :func:`steer_breach` judges the headings so set: ``u`` from the
reference's heading (-1 to 2 whole turns on), a wheel the gear sets off its heading by ``e`` (mod 360 deg: a wheel half
a turn off would roll against its spin) breaks the gear when ``|e| > LINKAGE_TOL`` and its axis speed times
``sin(min(|e|, 90 deg))`` (the side speed it would slip at, set by the gear) exceeds ``slip_tol``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..couplings import GEAR_EXACT_RTOL, GearBreach, gear_breaches
from ..robot import Robot
from ..wheels import Wheel, heading_from_beta
from .linkage_check import Breach, _roots_at, _speeds
from .linkage_check import _plan as _link_plan
from .linkage_law import COLUMNS, LINKAGE_TOL, remainder

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
    `x`, `y` the steering axes [m] ``(n_steer,)``; `rows` each entry as a row of a linkage table
    (:mod:`.linkage_law`, law 2) from its gear's first joint, ``(n_entries, 10)``, for the root choice
    (:func:`steer_roots`), and `turns` its candidate half turns with each entry the reference, ``(n_entries, 6)``
    (:func:`candidate_turns`, :data:`NO_TURN` after the last). Read-only arrays."""

    table: GearTable
    rest: np.ndarray
    x: np.ndarray
    y: np.ndarray
    rows: np.ndarray
    turns: np.ndarray


@functools.lru_cache(maxsize=64)
def steer_gears(robot: Robot) -> SteerGears:
    """The :class:`SteerGears` of `robot` (kept per robot, a frozen value)."""
    table = gear_table(robot, tuple(f"{n}.steer" for n in robot.steer_names))
    xy = np.array([robot.wheel(n).position for n in robot.steer_names], dtype=float).reshape(-1, 2)
    rest = np.array(robot.beta, dtype=float).reshape(-1)
    rows = np.zeros((len(table.joint), COLUMNS))
    turns = np.full((len(table.joint), len(HALF_TURNS)), NO_TURN, dtype=np.int64)
    for g in range(len(table.coupling)):
        first, last = int(table.start[g]), int(table.start[g + 1])
        lead = table.joint[first]
        for t in range(first, last):
            rows[t] = (table.joint[t], lead, -1, 2.0, table.ratio[first], table.ratio[t], 0.0, 0.0, rest[lead],
                       rest[table.joint[t]])
            kept = candidate_turns(table.ratio[first:last] / table.ratio[t])
            turns[t, :len(kept)] = kept
    arrays = (rest, xy[:, 0].copy(), xy[:, 1].copy(), rows, turns)
    for a in arrays:
        a.flags.writeable = False
    return SteerGears(table, *arrays)


def gear_reference(joint, first, last, x, y, vx, vy, w):
    """The entry of the gear of entries `first:last` whose steering axis moves fastest under the twist ``(vx, vy,
    w)`` (the first of them), -1 if none moves (written to compile)."""
    ref, top = -1, 0.0
    for t in range(first, last):
        s = math.hypot(vx - w * y[joint[t]], vy + w * x[joint[t]])
        if s > top:
            ref, top = t, s
    return ref


def steer_roots(joint, ratio, first, last, rest, x, y, vx, vy, w, rows, turns, beta, speed, slip_tol, tol, free, lo,
                width, offset, turn):
    """``turn[k]`` for each wheel k of the gear of entries `first:last` whose root ``ik`` chose (``free[k]``): whether
    its angle ``beta[k]`` is the root of (8.9) the gear does not set (module docstring; axis speeds `speed`, steering
    ranges `lo`, `width`, `offset` as :func:`.linkage_check._roots_at` takes them; `rows`, `turns` the gear's in
    :class:`SteerGears`); none where no turn of the gear sets every wheel on its line (:func:`_gear_turn`). Written
    to compile."""
    ref = gear_reference(joint, first, last, x, y, vx, vy, w)
    if ref < 0:
        return
    k, step = joint[ref], math.pi / ratio[ref]  # step: the gear's turn that turns the reference half round
    u = remainder(beta[k] - rest[k], 2.0 * math.pi) / ratio[ref]
    m = _gear_turn(joint, ratio, first, last, rest, beta, speed, free, u, step, turns[ref], slip_tol, tol)
    if m == NO_TURN:
        return
    u += m * step
    ranged = False  # a free wheel with a steering range: the reference turned half round may be wanted
    for t in range(first, last):
        ranged = ranged or (free[joint[t]] and width[joint[t]] < 2.0 * math.pi)
    other = ranged and _turned(joint, ratio, first, last, rest, beta, speed, free, u + step, slip_tol, tol) >= 0
    lead = joint[first]
    _roots_at(rows, first + 1, last, lead, beta, rest[lead] + ratio[first] * u, ratio[first] * step if other else 0.0,
              free, lo, width, offset, turn)


#: The reference's half turns ``m`` that :func:`steer_roots` may give its gear (``u + m pi / ratio_ref``), in order:
#: on its root, a whole turn on or back (which moves the wheels geared to it by other than whole turns), then turned.
HALF_TURNS = (0, 2, -2, 1, -1, 3)
#: :func:`_gear_turn`'s answer when no candidate holds the gear; ``SteerGears.turns`` after its last candidate.
NO_TURN = 99


def candidate_turns(ratios: np.ndarray) -> list[int]:
    """The half turns of :data:`HALF_TURNS` worth trying for a gear whose wheels turn `ratios` ``(n,)`` [rad per rad]
    of its reference's turn: those that set them at headings no earlier one sets (mod 2 pi), and an odd one (the
    reference turned) only where no even one sets them on the same lines (mod pi: it holds the gear where that one
    does, and loses to it). Ratios 1 or 2 of the reference leave one, ``[0]``; 1/2 leaves ``[0, 2, 1, -1]``."""
    def same(a: list[float], b: list[float], period: float) -> bool:
        return all(abs(math.remainder(p - q, period)) <= 1e-9 for p, q in zip(a, b, strict=True))

    kept: list[tuple[int, list[float]]] = []
    for m in HALF_TURNS:
        shift = [m * math.pi * float(r) for r in ratios]
        if not any(same(shift, s, 2.0 * math.pi) or (m % 2 and not n % 2 and same(shift, s, math.pi))
                   for n, s in kept):
            kept.append((m, shift))
    return [m for m, _ in kept]


def _gear_turn(joint, ratio, first, last, rest, beta, speed, free, u, step, turns, slip_tol, tol):
    """Of the reference's half turns `turns` (:func:`candidate_turns`, `u` the gear's turn with it on its root, `step`
    its turn for half a turn of it), the one that holds the gear with the reference on its root if any can, then
    with the fewest wheels off the roots ``ik`` chose (each the one closest to its current angle, so the set-point
    stays continuous); :data:`NO_TURN` if none holds (written to compile)."""
    best, score = NO_TURN, -1
    for m in turns:
        if m == NO_TURN:
            break
        turned = _turned(joint, ratio, first, last, rest, beta, speed, free, u + m * step, slip_tol, tol)
        here = turned + (m % 2) * (last - first + 1)
        if turned >= 0 and (score < 0 or here < score):
            best, score = m, here
            if score == 0:  # every wheel on the root ik chose: nothing nearer
                break
    return best


def _turned(joint, ratio, first, last, rest, beta, speed, free, u, slip_tol, tol):
    """How many free wheels of the gear of entries `first:last` its turn `u` sets half a turn from their angles
    `beta`, or -1 if it sets one off its line (mod pi, beyond :func:`steer_breach`'s floor: `tol` [rad], its side
    speed at axis speed `speed` over `slip_tol` [m/s]). Written to compile."""
    turned = 0
    for t in range(first, last):
        j = joint[t]
        off = remainder(beta[j] - rest[j] - ratio[t] * u, 2.0 * math.pi)
        line = min(abs(off), math.pi - abs(off))  # abs(remainder(off, pi)), exactly
        if line > tol and speed[j] * abs(math.sin(off)) > slip_tol:
            return -1
        if free[j] and abs(off) > 0.5 * math.pi:
            turned += 1
    return turned


def steer_breach(joint, ratio, first, last, rest, x, y, vx, vy, w, beta, slip_tol, tol):
    """The first steering angle that the gear of entries `first:last` (``joint``, ``ratio``) breaks at angles `beta`
    ``(n_steer,)`` under the twist ``(vx, vy, w)`` (module docstring): ``(entry, angle the gear sets it at, reference
    entry, side speed [m/s])``, entry -1 for none (written to compile: :mod:`._gear_kernel` and the ``realtime`` ik
    call it compiled)."""
    ref = gear_reference(joint, first, last, x, y, vx, vy, w)
    if ref < 0:
        return -1, 0.0, first, 0.0
    turn = remainder(beta[joint[ref]] - rest[joint[ref]], 2.0 * math.pi)
    found, want, slip = -1, 0.0, 0.0
    for m in (0, 1, -1, 2):  # u from the reference's heading, then a turn further (ik's gear roots, wrapped)
        u = (turn + 2.0 * m * math.pi) / ratio[ref]
        hit = -1
        for t in range(first, last):
            k = joint[t]
            off = remainder(beta[k] - rest[k] - ratio[t] * u, 2.0 * math.pi)
            if t == ref or abs(off) <= tol:
                continue
            side = math.hypot(vx - w * y[k], vy + w * x[k]) * math.sin(min(abs(off), 0.5 * math.pi))
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


def _steer_turns(joint, ratio, start, rest, x, y, rows, turns, twist, beta, speed, slip_tol, tol, free, lo, width,
                 offset, out):
    """:func:`steer_roots` of every gear over rows ``(N, 3)`` of `twist` and ``(N, n_steer)`` of `beta`, `speed`,
    `free`: `out` ``(N, n_steer)`` (all False on entry) True at each wheel to turn onto its other root (written to
    compile: :mod:`._gear_kernel`)."""
    for i in range(beta.shape[0]):
        for g in range(start.shape[0] - 1):
            steer_roots(joint, ratio, start[g], start[g + 1], rest, x, y, twist[i, 0], twist[i, 1], twist[i, 2], rows,
                        turns, beta[i], speed[i], slip_tol, tol, free[i], lo, width, offset, out[i])


#: Twists from which a batch of steering gears is judged by the compiled kernel (:mod:`._gear_kernel`).
COMPILED_BATCH = 64


def steer_gear_turns(robot: Robot, twist: np.ndarray, beta: np.ndarray, free: np.ndarray,
                     slip_tol: float) -> np.ndarray | None:
    """``(..., n_steer)`` bool: the geared wheels whose root of (8.9) ``ik`` chose (`free` ``(..., n_steer)``:
    moving, steered by the twist) and whose angle in its steering `beta` ``(..., n_steer)`` for `twist` ``(..., 3)``
    is the root their gear does not set (:func:`steer_roots`); None for a robot without a steering gear. ``ik`` turns
    them half round, spin reversed. A batch of at least :data:`COMPILED_BATCH` twists is set compiled."""
    sg = steer_gears(robot)
    if not sg.table.coupling:
        return None
    n, links = len(sg.rest), _link_plan(robot)
    batch = np.broadcast_shapes(twist.shape[:-1], beta.shape[:-1], free.shape[:-1])
    rows = np.ascontiguousarray(np.broadcast_to(twist, (*batch, 3)).reshape(-1, 3), dtype=float)
    flat_beta = np.broadcast_to(beta, (*batch, n)).reshape(-1, n)
    speed = np.broadcast_to(_speeds(sg, twist), (*batch, n)).reshape(-1, n)
    flat_free = np.broadcast_to(free, (*batch, n)).reshape(-1, n)
    out = np.zeros(flat_beta.shape, dtype=bool)
    kernel, t = _steer_turns, sg.table
    if len(rows) >= COMPILED_BATCH:
        from ._gear_kernel import turns as kernel
    kernel(t.joint, t.ratio, t.start, sg.rest, sg.x, sg.y, sg.rows, sg.turns, rows, flat_beta, speed, float(slip_tol),
          LINKAGE_TOL, flat_free, links.lo, links.width, links.offset, out)
    return out.reshape(*batch, n)


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
    ``robot.couplings``) sets at `want` (mod 2 pi) with its `reference` wheel at `ref_beta`;
    `slip` [m/s] the side speed the wheel would roll at, so set (a linkage's :class:`.linkage_check.Breach`, worded
    for a gear)."""

    def describe(self, robot: Robot) -> str:
        """``"<gear> (ratios ...) sets <wheel> at heading ... deg with <reference> at ... deg, not ... deg (... deg
        off; ... m/s)"``, the gear in the description's terms (:meth:`wmrkit.couplings.Coupling.words`)."""
        c, names = robot.couplings[self.coupling], robot.steer_names
        head = [math.degrees(float(heading_from_beta(b, robot.wheel(names[k]).delta)))
                for k, b in ((self.column, self.want), (self.reference, self.ref_beta), (self.column, self.beta))]
        ratios = ", ".join(f"{k:g}" for k in c.ratios)
        return (f"{c.words()} (ratios {ratios}) sets {names[self.column]} at "
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
