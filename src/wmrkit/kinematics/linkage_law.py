"""The ideal law of a steering ``linkage`` coupling, ``beta_j = f(beta_i)`` for every wheel j it links to its leader i
(:func:`wmrkit.couplings.linkage_law` names it): the one formula the dynamics hold (:mod:`wmrkit.dynamics.linkages`)
and the kinematics check (:mod:`.linkage_check`: ``ik``, ``fk``).

A description gives no linkage geometry, so the law is the ideal one:

- ``ackermann`` (fixed wheels, their axles on one line, the ``axle``): the linked wheels' axles meet on that line, the
  exact Ackermann law. In the axle's frame (x along the fixed wheels' rolling direction, y along the axle, x_i, y_i
  the steering point of wheel i, psi its heading from the fixed wheels'), ``psi_j = atan2(x_j sin psi_i, x_i cos
  psi_i + (y_i - y_j) sin psi_i)`` (mod pi), so ``f' = x_i x_j / D`` with ``D`` the squared norm of that pair;
  a follower on the axle line (``x_j = 0`` within :data:`AXLE_TOL`) keeps its rest angle, ``f' = 0`` (``D`` is 0
  where the ICR is on it);
- ``parallel``: the linked wheels turn together, ``beta_j - beta_j0 = beta_i - beta_i0`` (a synchro drive's chain:
  one ICR at infinity while they stay parallel).

The leader is the linkage's first wheel (``ackermann``: the first one off the axle line). The ratios are not used.

Table (one row per follower): follower column, leader column, the leader's column in the dynamics' basis (-1 until
set), law (0 parallel, 1 axle), ``x_i``, ``x_j``, ``y_i - y_j``, ``beta_i - psi_i``, the rest angles ``beta_i0``,
``beta_j0``. Law 2 is a ``gear`` between steering joints, ``beta_j - beta_j0 = (k_j / k_i) (beta_i - beta_i0)`` with
the ratios ``k_i``, ``k_j`` in the ``x`` columns: the kinematics set a geared wheel's root with the linkages' code
(:func:`wmrkit.kinematics.gear_check.steer_gears`); the dynamics hold a gear otherwise.
"""

from __future__ import annotations

import math

import numpy as np

from ..couplings import axle_problem, fixed_axle, linkage_law
from ..errors import WmrkitError
from ..wheels import heading_from_beta

#: Width of the table's rows.
COLUMNS = 10
#: A steering angle [rad] (or a rate, relative to the leader's) farther than this from its linkage's law breaks it.
LINKAGE_TOL = 1e-9
#: A steering point [m] closer than this to the fixed wheels' axle line is on it (``ackermann``): a leader is
#: chosen off it; a follower on it keeps its rest angle (its axle is that line, through every ICR on it).
AXLE_TOL = 1e-9


def law(row, beta):
    """``(f, f', f'')`` of the linkage row `row` at the leader's angle `beta` [rad] (compiled as it is by
    :mod:`wmrkit.dynamics._kernels`): the follower's angle, continuous from its rest angle (it turns less than half
    round)."""
    if row[3] == 0.0:
        return row[9] + beta - row[8], 1.0, 0.0
    if row[3] == 2.0:  # a gear between steering joints (the kinematics' root choice only)
        return row[9] + row[5] * (beta - row[8]) / row[4], row[5] / row[4], 0.0
    if row[5] == 0.0:  # a follower on the axle line: f' = 0 / D, and 0 / 0 where the ICR is its steering point
        return row[9], 0.0, 0.0
    xi, xj, dy = row[4], row[5], row[6]
    psi, psi0 = beta - row[7], row[8] - row[7]
    s, c, s0, c0 = math.sin(psi), math.cos(psi), math.sin(psi0), math.cos(psi0)
    u, v, u0, v0 = xj * s, xi * c + dy * s, xj * s0, xi * c0 + dy * s0
    d = u * u + v * v
    slope = xi * xj / d
    curvature = -2.0 * slope * (u * xj * c + v * (dy * c - xi * s)) / d
    return row[9] + math.atan2(u * v0 - v * u0, v * v0 + u * u0), slope, curvature


def linkage_table(robot, names: tuple[str, ...], strict: bool = True) -> np.ndarray:
    """The table of the module docstring for `robot` with steering names `names` (``wheel.steer``: the dynamics'
    velocity names, the kinematics' steering configuration), a row per follower of each linkage with a law
    (:func:`wmrkit.couplings.linkage_law`); ``(0, 10)`` without one. `strict` (the dynamics): a linkage the robot
    cannot hold raises :class:`WmrkitError` naming it. Else (the kinematics, which judge a configuration against
    the law) it is left out, and an ``ackermann`` follower's rest angle is the one the law gives it at its leader's
    rest angle (the described one, mod pi, where they agree)."""
    rows = []
    for c in robot.couplings:
        kind = linkage_law(c, robot.wheels) if c.kind == "linkage" else None
        if kind is None or (not strict and kind == "ackermann" and axle_problem(robot.wheels) is not None):
            continue
        axle = _axle(robot, c) if kind == "ackermann" else None
        wheels = [robot.wheel(j.partition(".")[0]) for j in c.joints]
        frame = [(0.0, 0.0, w.beta) for w in wheels] if axle is None else [_in_axle(axle, w) for w in wheels]
        frame = [(0.0 if abs(x) <= AXLE_TOL else x, y, psi) for x, y, psi in frame]  # on the line: exactly
        lead = next((k for k, (x, _, _) in enumerate(frame) if axle is None or x != 0.0), None)
        if lead is None:
            if not strict:
                continue
            raise WmrkitError(f"robot '{robot.name}': {c.words()}: every linked wheel is on the fixed wheels' "
                              "axle line, so no steering angle sets the ICR; the dynamics cannot hold it")
        xi, yi, psi_i = frame[lead]
        wi = wheels[lead]
        for k, (xj, yj, psi_j) in enumerate(frame):
            if k == lead:
                continue
            wj = wheels[k]
            row = [names.index(f"{wj.name}.steer"), names.index(f"{wi.name}.steer"), -1, 0.0 if axle is None else 1.0,
                   xi, xj, yi - yj, wi.beta - psi_i, wi.beta, wj.beta]
            if axle is not None:
                want = math.atan2(xj * math.sin(psi_i), xi * math.cos(psi_i) + (yi - yj) * math.sin(psi_i))
                off = math.remainder(want - psi_j, math.pi)  # mod pi: a wheel mounted either way round
                if not strict:
                    row[9] += off
                elif abs(off) > LINKAGE_TOL:
                    heads = ", ".join(f"{w.name} {math.degrees(float(heading_from_beta(w.beta, w.delta))):.4g} deg"
                                      for w in (wi, wj))
                    raise WmrkitError(
                        f"robot '{robot.name}': {c.words()}: at the described headings ({heads}) the linked "
                        f"wheels' axles do not meet on the fixed wheels' axle line ({wj.name} would be at "
                        f"{math.degrees(float(heading_from_beta(wj.beta + off, wj.delta))):.4g} deg): "
                        "the dynamics hold a linkage on one ICR; describe headings that agree (docs/dynamics.md)")
            rows.append(row)
    return np.array(rows, dtype=float).reshape(-1, COLUMNS)


def leader_of(row, beta: float) -> float:
    """The leader's angle at which the linkage row `row` sets its follower at `beta` (the law's inverse; a follower
    off the axle line): ``parallel`` by the shift, ``ackermann`` by the same geometry with the two wheels swapped,
    on the branch that gives `beta` (the law's ``psi`` are mod pi)."""
    if row[3] == 0.0:
        return row[8] + beta - row[9]
    xi, xj, dy = row[4], row[5], row[6]
    s0, c0 = math.sin(row[8] - row[7]), math.cos(row[8] - row[7])
    psi_j = beta - row[9] + math.atan2(xj * s0, xi * c0 + dy * s0)  # the follower's psi: its rest one's + turn
    psi_i = math.atan2(xi * math.sin(psi_j), xj * math.cos(psi_j) - dy * math.sin(psi_j))
    lead = row[8] + remainder(psi_i + row[7] - row[8], math.pi)
    return lead if abs(remainder(law(row, lead)[0] - beta, 2 * math.pi)) < math.pi / 2 else lead + math.pi


def remainder(x, y):
    """``math.remainder(x, y)`` for finite `x` and ``y > 0``, exact, written to compile (numba has no
    ``math.remainder``): ``fmod`` by ``2 y`` (exact), then down by ``y`` at most twice (exact, a tie to the even
    quotient), as C libraries reduce."""
    r = abs(np.fmod(x, 2.0 * y))
    if r > 0.5 * y:
        r -= y
        if r >= 0.5 * y:
            r -= y
    return float(r) if math.copysign(1.0, x) > 0 else float(-r)


def _axle(robot, c) -> tuple[np.ndarray, float]:
    """``(point, heading)`` of the fixed wheels' common axle line, on which the ``ackermann`` linkage `c`'s axles
    meet; :class:`WmrkitError` naming it when the wheels give none (:func:`wmrkit.couplings.axle_problem`)."""
    problem = axle_problem(robot.wheels)
    if problem is not None:
        raise WmrkitError(f"robot '{robot.name}': {c.words()}: law ackermann: {problem}; the dynamics cannot "
                          "hold the linkage")
    p0, h0, _ = fixed_axle(robot.wheels)
    return p0, h0


def _in_axle(axle: tuple[np.ndarray, float], w) -> tuple[float, float, float]:
    """``(x, y, psi)`` of wheel `w` in the axle's frame: along the fixed wheels' rolling direction, along the axle,
    its heading from theirs."""
    p0, h0 = axle
    r = np.array(w.position) - p0
    return (float(r[0] * math.cos(h0) + r[1] * math.sin(h0)), float(-r[0] * math.sin(h0) + r[1] * math.cos(h0)),
            float(heading_from_beta(w.beta, w.delta)) - h0)
