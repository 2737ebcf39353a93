"""The twist of a coupled-steering robot (:mod:`.coupled_point`) on arrays and scalars: one implementation, run as
plain Python by :class:`~.coupled_point.CoupledSteering` and compiled as it is by :mod:`._coupled_kernel` (the
single-call tick, :func:`.tick.control_tick`).

The robot enters as arrays: ``lines (m, 3)`` its constraint lines (6.18) at the turn ``u = 0``, ``pivots (m, 2)``
the steering pivot of each line's wheel and ``ratios (m,)`` that wheel's heading turn per turn of the leader (a
gear's ratio, 1 on a parallel linkage): at turn ``u`` each line is turned by ``ratio u`` about its pivot (a line of a
steered wheel is fixed in its steering frame). ``null (SAMPLES, 3)``: the admissible twist over the grid of turns
``-pi + 2 pi k / SAMPLES``, oriented continuously from forward driving (the sign of ``n``). The branch: ``turns``,
``angles`` (increasing), ``sign``, ``u0`` and the control point ``(px, py)``.
"""

from __future__ import annotations

import math

import numpy as np

from ..kinematics.linkage_law import remainder

__all__ = ["direction", "rotated_lines", "solve"]

TWO_PI = 2.0 * math.pi
#: Samples of the leader's turn over a whole turn: the branch and Newton's first guess.
SAMPLES = 1440
#: Newton iterations at most (2 to 4 from the table's guess; bisection where a step leaves the bracket).
NEWTON_STEPS = 40
#: The angle of P's velocity is solved to this [rad].
ANGLE_TOL = 1e-12


def rotated_lines(u, lines, pivots, ratios, out, turned):
    """Write the lines at turn `u` into `out` ``(m, 3)`` and their derivative per turn into `turned` ``(m, 3)``
    (each line turned about its wheel's pivot at its ratio)."""
    for i in range(lines.shape[0]):
        r = ratios[i]
        c, s = math.cos(r * u), math.sin(r * u)
        x0, y0 = lines[i, 0], lines[i, 1]
        x, y = c * x0 - s * y0, s * x0 + c * y0
        px, py = pivots[i, 0], pivots[i, 1]
        out[i, 0], out[i, 1], out[i, 2] = x, y, lines[i, 2] + px * (y - y0) - py * (x - x0)
        turned[i, 0], turned[i, 1], turned[i, 2] = -y * r, x * r, (px * x + py * y) * r


def direction(u, lines, pivots, ratios, null):
    """The unit admissible twist ``n(u)`` (oriented as the nearest sample of `null`) and ``dn/du``, six scalars.

    The lines meet at the ICR (6.20): ``n`` is the cross product of the two lines farthest from parallel (the
    null vector of the lines' matrix, of rank 2), normalised; ``dn/du`` its derivative (``A dn = -A' n``, ``dn``
    normal to ``n``: the ``-A^+ A' n`` of the matrix's pseudo-inverse)."""
    m = lines.shape[0]
    a, turned = np.empty((m, 3)), np.empty((m, 3))
    rotated_lines(u, lines, pivots, ratios, a, turned)
    best, bi, bj = -1.0, 0, 0
    for i in range(m):
        for j in range(i + 1, m):
            c0 = a[i, 1] * a[j, 2] - a[i, 2] * a[j, 1]
            c1 = a[i, 2] * a[j, 0] - a[i, 0] * a[j, 2]
            c2 = a[i, 0] * a[j, 1] - a[i, 1] * a[j, 0]
            size = c0 * c0 + c1 * c1 + c2 * c2
            if size > best:
                best, bi, bj = size, i, j
    k = math.floor((u + math.pi) * (null.shape[0] / TWO_PI) + 0.5) % null.shape[0]
    if not best > 0.0:  # the lines coincide (not on a branch): the table's sample, not moving
        return null[k, 0], null[k, 1], null[k, 2], 0.0, 0.0, 0.0
    i, j = bi, bj
    norm = math.sqrt(best)
    n0 = (a[i, 1] * a[j, 2] - a[i, 2] * a[j, 1]) / norm
    n1 = (a[i, 2] * a[j, 0] - a[i, 0] * a[j, 2]) / norm
    n2 = (a[i, 0] * a[j, 1] - a[i, 1] * a[j, 0]) / norm
    if n0 * null[k, 0] + n1 * null[k, 1] + n2 * null[k, 2] < 0:
        n0, n1, n2, norm = -n0, -n1, -n2, -norm
    # d(a_i x a_j) = a_i' x a_j + a_i x a_j', then its part normal to n, over the cross product's (signed) size
    t, b = turned, a
    d0 = t[i, 1] * b[j, 2] - t[i, 2] * b[j, 1] + b[i, 1] * t[j, 2] - b[i, 2] * t[j, 1]
    d1 = t[i, 2] * b[j, 0] - t[i, 0] * b[j, 2] + b[i, 2] * t[j, 0] - b[i, 0] * t[j, 2]
    d2 = t[i, 0] * b[j, 1] - t[i, 1] * b[j, 0] + b[i, 0] * t[j, 1] - b[i, 1] * t[j, 0]
    along = d0 * n0 + d1 * n1 + d2 * n2
    return n0, n1, n2, (d0 - along * n0) / norm, (d1 - along * n1) / norm, (d2 - along * n2) / norm


def newton(target, px, py, sign, lines, pivots, ratios, null, turns, angles):
    """The turn at which the angle of ``P``'s velocity is `target` on the branch: Newton's method from the table's
    interpolation, within the table's bracket (bisection where a step leaves it); and ``n`` there: ``(u, n0, n1,
    n2)``."""
    k = min(max(int(np.searchsorted(angles, target)), 1), len(angles) - 1)
    lo, hi = min(turns[k - 1], turns[k]), max(turns[k - 1], turns[k])
    u = float(np.interp(target, angles, turns))
    xs, ys = (turns, angles) if sign > 0 else (turns[::-1], angles[::-1])
    for _ in range(NEWTON_STEPS):
        n0, n1, n2, d0, d1, d2 = direction(u, lines, pivots, ratios, null)
        gx, gy = n0 - py * n2, n1 + px * n2  # points._point_map
        dgx, dgy = d0 - py * d2, d1 + px * d2
        near = float(np.interp(u, xs, ys))
        f = near + remainder(math.atan2(gy, gx) - near, TWO_PI) - target
        if abs(f) <= ANGLE_TOL:
            return u, n0, n1, n2
        if f * sign < 0:
            lo = u
        else:
            hi = u
        slope = (gx * dgy - gy * dgx) / (gx * gx + gy * gy)
        step = u - f / slope if slope * sign > 0 else math.nan
        u = step if lo < step < hi else 0.5 * (lo + hi)
    n0, n1, n2, _, _, _ = direction(u, lines, pivots, ratios, null)
    return u, n0, n1, n2


def solve(vx, vy, px, py, sign, u0, lines, pivots, ratios, null, turns, angles):
    """``(s, u, n0, n1, n2)``: the speed, the turn and ``n(u)`` giving the control point ``(px, py)`` the velocity
    ``(vx, vy)`` [m/s, robot frame]: forward when its direction is within the branch's arc, else backward when the
    opposite one is, else at the branch's nearer end (least squares in ``s`` there); at rest ``(0, u0, n(u0))``."""
    if vx == 0.0 and vy == 0.0:
        n0, n1, n2, _, _, _ = direction(u0, lines, pivots, ratios, null)
        return 0.0, u0, n0, n1, n2
    want, lo, hi = math.atan2(vy, vx), angles[0], angles[-1]
    forward, backward = lo + (want - lo) % TWO_PI, lo + (want + math.pi - lo) % TWO_PI
    if forward <= hi:
        target = forward
    elif backward <= hi:
        target = backward
    else:  # the nearer end of the branch, either way (lo on a tie)
        near_lo = min(abs(remainder(want - lo, TWO_PI)), abs(remainder(want + math.pi - lo, TWO_PI)))
        near_hi = min(abs(remainder(want - hi, TWO_PI)), abs(remainder(want + math.pi - hi, TWO_PI)))
        target = lo if near_lo <= near_hi else hi
    u, n0, n1, n2 = newton(target, px, py, sign, lines, pivots, ratios, null, turns, angles)
    gx, gy = n0 - py * n2, n1 + px * n2
    return (gx * vx + gy * vy) / (gx * gx + gy * gy), u, n0, n1, n2


def twist(vx, vy, px, py, sign, u0, lines, pivots, ratios, null, turns, angles):
    """The admissible body twist ``s n(u)`` giving the point that velocity (:func:`solve`), as three scalars."""
    s, _, n0, n1, n2 = solve(vx, vy, px, py, sign, u0, lines, pivots, ratios, null, turns, angles)
    return s * n0, s * n1, s * n2
