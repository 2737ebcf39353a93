"""The one check of a command's joint rates against its ``gear`` couplings (``q_j = ratio_j u``).

``wheel_commands``' ``in_gear`` (``wmrkit ik``, the simulator's programs and ``--initial-twist``) calls
:func:`gears_hold`; the compiled ``realtime`` ik and the generated C and Python (``kinematics --codegen``) print its
formula with the tables of :func:`gear_table`. A gear holds when, ``u = k.q / k.k`` its least-squares turn and
``e_j = |q_j - ratio_j u|`` each joint's departure [rad/s], either every ``e_j <= GEAR_RTOL max |q|`` (round-off of
the rates, relative to the command's largest) or every ``e_j lever_j <= slip_tol``: the speed [m/s] the departure
moves the joint's contact at (:func:`contact_lever`) within the slip check's absolute floor, so that a twist of
1e-320 rad/s is judged as one of 1e-320 m/s (both roll) and the floor scales with the robot.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..couplings import GEAR_EXACT_RTOL, GearBreach, gear_breaches
from ..robot import Robot
from ..wheels import Wheel

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
