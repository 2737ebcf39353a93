"""The loops of :func:`wmrkit.dynamics.linkages.setpoint_knots` and of the set-point checks
(:func:`~wmrkit.dynamics.linkages.first_breach`), over every row of a set-point table at once: plain
Python for a small table, compiled as they are by :mod:`._setpoint_kernel` for a large one (numba loads on first
use). No formula is written here: the law, its inverse and the reduction are :mod:`wmrkit.kinematics.linkage_law`'s.

``plan`` ``(F, 4)`` int, a row per commanded follower of a held linkage (:func:`~.linkages._law_plan`): its index
in the set-points, its linkage table row, the index whose set-point gives its leader's angle, and the table row
through whose inverse it does (:func:`~wmrkit.kinematics.linkage_law.leader_of`), -1: the set-point is the
leader's.
"""

from __future__ import annotations

import math

import numpy as np

from ..kinematics.linkage_law import law, leader_of, remainder

#: Law evaluations (set-points put on the law) from which the compiled loops run.
COMPILED_WORK = 20_000


def project(table, plan, point, out):
    """`out` ``(n_steer,)``: the set-points `point` with each follower of `plan` at the angle its law gives it, the
    turn nearest its value in `point`."""
    for m in range(point.shape[0]):
        out[m] = point[m]
    for q in range(plan.shape[0]):
        j = plan[q, 0]
        out[j] = point[j] + remainder(angle(table, plan, q, point) - point[j], 2.0 * math.pi)


def angle(table, plan, q, point):
    """The angle the law of follower ``plan[q]`` gives it from the set-points `point` ``(n_steer,)``."""
    src, inv = plan[q, 2], plan[q, 3]
    return law(table[plan[q, 1]], point[src] if inv < 0 else leader_of(table[inv], point[src]))[0]


def law_offs(table, plan, beta, at, off):
    """For each row k of the set-points `beta` ``(K, n_steer)`` and follower ``plan[q]``: `at[k, q]` the angle its
    law gives it (:func:`angle`), `off[k, q]` how far its set-point is from it, ``|remainder(beta - at, 2 pi)|``."""
    for k in range(beta.shape[0]):
        for q in range(plan.shape[0]):
            at[k, q] = angle(table, plan, q, beta[k])
            off[k, q] = abs(remainder(beta[k, plan[q, 0]] - at[k, q], 2.0 * math.pi))


def between(table, plan, beta, k, s, point, out):
    """:func:`project` of the set-points interpolated linearly at `s` in [0, 1] from row `k` of `beta` to the next
    (`point`: work space)."""
    for m in range(beta.shape[1]):
        point[m] = (1 - s) * beta[k, m] + s * beta[k + 1, m]
    project(table, plan, point, out)


def continued(table, plan, beta, out):
    """`out` ``(K, n_steer)``: the set-points `beta` moved by whole turns so that each step from a row to the next
    turns the short way: each column not a follower of `plan` (a leader, any directly commanded steering) by its own
    change, the short way round; each follower to the turn its law reaches along the steps from its first row: each
    step's change of the law, from the row to the law at the step's middle (the continued columns' middle) and on to
    the next row, each part the short way round (a heading written wrapped, +179 deg then -179 deg, turns 2 deg, not
    358)."""
    n = beta.shape[1]
    point, follower = np.empty(n), np.zeros(n, dtype=np.bool_)
    for q in range(plan.shape[0]):
        follower[plan[q, 0]] = True
    for k in range(beta.shape[0]):
        for m in range(n):
            out[k, m] = beta[k, m]
    for k in range(beta.shape[0] - 1):
        for m in range(n):
            if not follower[m]:
                out[k + 1, m] = _turned(out[k, m] + remainder(beta[k + 1, m] - beta[k, m], 2.0 * math.pi),
                                        beta[k + 1, m])
            point[m] = 0.5 * (out[k, m] + out[k + 1, m])
        for q in range(plan.shape[0]):
            j = plan[q, 0]
            mid = angle(table, plan, q, point)
            out[k + 1, j] = _turned(out[k, j] + remainder(mid - beta[k, j], 2.0 * math.pi)
                                    + remainder(beta[k + 1, j] - mid, 2.0 * math.pi), beta[k + 1, j])


#: Turns of a gear's reference tried on either side of the one nearest its previous row (:func:`gear_continued`).
GEAR_TRIES = 4


def gear_continued(cols, ratios, rest, tol, beta, out):
    """`out[:, cols]`: the set-points `beta` ``(K, n_steer)`` of one gear's commanded joints (indices `cols`, the first
    its reference; `ratios`, rest angles `rest`: the gear holds ``beta_j - rest_j = ratios_j u``) moved by whole
    turns so that the gear's turn ``u`` steps the short way: at each row the ``u`` nearest the previous row's among
    the reference's turns (its row, plus :data:`GEAR_TRIES` turns either side of the nearest) at which every joint's
    row is on the gear (within `tol`, whole turns aside; the row's own ``u`` always is: the rows were checked), each
    joint then on the turn the gear reaches from its first row. Their linear interpolation stays on the gear."""
    two_pi = 2.0 * math.pi
    k0, c0, r0 = ratios[0], cols[0], rest[0]
    u = (beta[0, c0] - r0) / k0
    offset = np.empty(cols.shape[0])
    for i in range(cols.shape[0]):
        offset[i] = beta[0, cols[i]] - (rest[i] + ratios[i] * u)
        out[0, cols[i]] = beta[0, cols[i]]
    for k in range(1, beta.shape[0]):
        best = (beta[k, c0] - r0) / k0
        centre = round((k0 * u - (beta[k, c0] - r0)) / two_pi)
        for m in range(centre - GEAR_TRIES, centre + GEAR_TRIES + 1):
            cand = (beta[k, c0] - r0 + two_pi * m) / k0
            if abs(cand - u) >= abs(best - u):
                continue
            on = True
            for i in range(1, cols.shape[0]):
                on = on and abs(remainder(rest[i] + ratios[i] * cand - beta[k, cols[i]], two_pi)) <= tol
            if on:
                best = cand
        u = best
        for i in range(cols.shape[0]):
            out[k, cols[i]] = _turned(rest[i] + ratios[i] * u + offset[i], beta[k, cols[i]])


def _turned(reached, row):
    """`row` moved by the whole turns nearest `reached` (the row kept as it is, bit for bit, but for those)."""
    return row + np.round((reached - row) / (2.0 * math.pi)) * 2.0 * math.pi


def chord_errors(table, plan, beta, rows, pieces, off):
    """`off[q]`: the largest distance, over the set-points, between the law at the middle of each of `pieces[q]`
    even pieces of the step from row ``rows[q]`` of `beta` to the next and the mean of the law at its ends."""
    n = beta.shape[1]
    point, a, mid, b = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for q in range(rows.shape[0]):
        k, p = rows[q], pieces[q]
        step = 1.0 / (2 * p)  # the knots and the middles at i step, as np.linspace(0, 1, 2 p + 1)
        between(table, plan, beta, k, 0.0, point, a)
        worst = 0.0
        for i in range(1, p + 1):
            between(table, plan, beta, k, (2 * i - 1) * step, point, mid)
            between(table, plan, beta, k, 1.0 if i == p else (2 * i) * step, point, b)
            for m in range(n):
                worst = max(worst, abs(mid[m] - (a[m] + b[m]) / 2))
            a, b = b, a
        off[q] = worst


def knots(table, plan, t, beta, pieces, at, on):
    """The knots ``(at, on)``: the first row projected, then each step from row k of `t`, `beta` to the next cut
    into `pieces[k]` even pieces, each piece's end projected (:func:`between`)."""
    point = np.empty(beta.shape[1])
    at[0] = t[0]
    project(table, plan, beta[0], on[0])
    o = 1
    for k in range(pieces.shape[0]):
        p = pieces[k]
        step = 1.0 / (2 * p)
        for i in range(1, p + 1):
            s = 1.0 if i == p else (2 * i) * step
            at[o] = t[k + 1] if i == p else t[k] + (t[k + 1] - t[k]) * s
            between(table, plan, beta, k, s, point, on[o])
            o += 1
