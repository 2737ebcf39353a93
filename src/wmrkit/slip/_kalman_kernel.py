"""Compiled loop of the velocity Kalman filters FK1/FK2 (thesis (7.71)-(7.75)) in information form (numba).

Per sample, with ``H = C^T R^-1 C`` and ``M = -C^T R^-1 A_a`` precomputed per steering configuration:
``P- = P + Q``, ``P+ = (P-^-1 + H)^-1``, ``x+ = P+ (P-^-1 x + M qdot_a)`` (the Woodbury form of the gain
(7.73)-(7.75); two symmetric 3x3 inverses, no m x m inverse). ``double_q`` adds Q once more after the update, as
(7.75) is printed. The increment of the sample is ``x+ dt``; its slip indicator ``|C x+ - y| dt`` [m].
"""

from __future__ import annotations

import numba
import numpy as np

from .._jit import jit as _jit

_IN = numba.types.Array(numba.float64, 2, "A", readonly=True)
_IN1 = numba.types.Array(numba.float64, 1, "A", readonly=True)
_IN3 = numba.types.Array(numba.float64, 3, "A", readonly=True)
_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)


@numba.njit(inline="always")
def _inverse_sym(a00, a01, a02, a11, a12, a22):
    """Inverse of a symmetric 3x3 matrix by cofactors: the six upper entries."""
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a01 * c01 + a02 * c02
    inv = 1.0 / det
    return (c00 * inv, c01 * inv, c02 * inv, (a00 * a22 - a02 * a02) * inv, (a02 * a01 - a00 * a12) * inv,
            (a00 * a11 - a01 * a01) * inv)


@_jit(numba.void(_IN, _IN1, _IN3, _IN3, _IN3, _IN3, _INDEX, numba.float64, numba.boolean, _IN1, _IN,
                 numba.float64[:, :], numba.float64[:], numba.float64[:], numba.float64[:, :]))
def kalman_chunk(rates, dt, h, m, c, aa, index, q, double_q, x0, p0, out, slip, x_end, p_end):
    """Filter `rates` ``(N, n_a)`` [rad/s] sampled with steps `dt` ``(N,)``; body increments into `out` ``(N, 3)``,
    slip into `slip` ``(N,)``; the final state and covariance into `x_end` ``(3,)``, `p_end` ``(3, 3)``.

    `h` ``(U, 3, 3)``, `m` ``(U, 3, n_a)``, `c` ``(U, rows, 3)``, `aa` ``(U, rows, n_a)``; `index` ``(N,)`` the
    configuration of each sample (empty: configuration 0 throughout); `q` the process variance per step.
    """
    n, n_a = rates.shape
    n_rows = c.shape[1]
    x_0, x_1, x_2 = x0[0], x0[1], x0[2]
    p00, p01, p02, p11, p12, p22 = p0[0, 0], p0[0, 1], p0[0, 2], p0[1, 1], p0[1, 2], p0[2, 2]
    constant = index.shape[0] == 0
    for k in range(n):
        u = 0 if constant else index[k]
        # prediction (7.71)-(7.72)
        p00 += q
        p11 += q
        p22 += q
        i00, i01, i02, i11, i12, i22 = _inverse_sym(p00, p01, p02, p11, p12, p22)
        # information vector P-^-1 x + M qdot_a
        b0 = i00 * x_0 + i01 * x_1 + i02 * x_2
        b1 = i01 * x_0 + i11 * x_1 + i12 * x_2
        b2 = i02 * x_0 + i12 * x_1 + i22 * x_2
        for j in range(n_a):
            r = rates[k, j]
            b0 += m[u, 0, j] * r
            b1 += m[u, 1, j] * r
            b2 += m[u, 2, j] * r
        p00, p01, p02, p11, p12, p22 = _inverse_sym(i00 + h[u, 0, 0], i01 + h[u, 0, 1], i02 + h[u, 0, 2],
                                                    i11 + h[u, 1, 1], i12 + h[u, 1, 2], i22 + h[u, 2, 2])
        x_0 = p00 * b0 + p01 * b1 + p02 * b2
        x_1 = p01 * b0 + p11 * b1 + p12 * b2
        x_2 = p02 * b0 + p12 * b1 + p22 * b2
        if double_q:  # (7.75) as printed
            p00 += q
            p11 += q
            p22 += q
        d = dt[k]
        out[k, 0] = x_0 * d
        out[k, 1] = x_1 * d
        out[k, 2] = x_2 * d
        s = 0.0
        for i in range(n_rows):
            e = c[u, i, 0] * x_0 + c[u, i, 1] * x_1 + c[u, i, 2] * x_2
            for j in range(n_a):
                e += aa[u, i, j] * rates[k, j]
            s += e * e
        slip[k] = np.sqrt(s) * d
    x_end[0], x_end[1], x_end[2] = x_0, x_1, x_2
    p_end[0, 0], p_end[0, 1], p_end[0, 2] = p00, p01, p02
    p_end[1, 0], p_end[1, 1], p_end[1, 2] = p01, p11, p12
    p_end[2, 0], p_end[2, 1], p_end[2, 2] = p02, p12, p22
