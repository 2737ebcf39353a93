"""Compiled loop of the velocity Kalman filters FK1/FK2 (thesis (7.71)-(7.75)) in information form (numba).

Per sample, with ``H = C^T R^-1 C`` and ``M = -C^T R^-1 A_a`` of the sample's steering configuration:
``P- = P + n Q``, ``P+ = (P-^-1 + H)^-1``, ``x+ = P+ (P-^-1 x + M qdot_a)`` (the Woodbury form of the gain
(7.73)-(7.75); two symmetric 3x3 inverses, no m x m inverse), with ``n = max(1, round(dt / T))`` the nominal sample
periods T in the step (halves rounded up; 1 for every step shorter than 1.5 T, so a uniform or jittered log runs the
thesis's recursion, Q per sample). ``double_q`` adds ``n Q`` once more after the update, as (7.75) is printed. The
increment of the sample is ``x+ dt``; its slip indicator ``|C x+ + A_a qdot_a| dt`` [m], computed as
``|T (x+, qdot_a)| dt`` with T the triangular factor of ``[C, A_a]`` (an orthogonal change of rows).

The covariance recursion depends on the data only through the configurations and the long steps (n > 1): when a
step of one period gives back the covariance it started from (bitwise) and the configuration stays the same, every
next step of one period would compute the same two inverses, so they are kept instead of recomputed, and such
steps update ``x+ = A x + G qdot_a`` with the transition ``A = P+ P-^-1`` and the gain ``G = P+ M`` formed once
(only ``A x`` is then on the chain from sample to sample; the rates' part is summed first in both forms), until the
configuration changes or a long step leaves the fixed point. Exact, not an approximation: the results are those of
the plain recursion that computes both inverses at every step and takes this form at its fixed points, bit for bit,
and they do not depend on where the log is cut into chunks. One pass reads the joint positions and times
(increments, rates, the steering configuration at mid-interval, as :mod:`wmrkit.odometry.model` defines them),
filters, and composes the poses with the blocks of :mod:`wmrkit.odometry._kernels`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._jit import drop_stale_cache
from .._jit import jit as _jit
from ..odometry import _kernels, _steering_kernels
from ..odometry._kernels import BLOCK, _headings, _norm_rows, _positions, _rotations
from ..odometry._steering_kernels import _block_segments, _configurations_from, _is_steering, _wrap

drop_stale_cache([__file__], [_kernels.__file__, _steering_kernels.__file__])

_IN = numba.types.Array(numba.float64, 2, "A", readonly=True)
_IN1 = numba.types.Array(numba.float64, 1, "A", readonly=True)
_IN3 = numba.types.Array(numba.float64, 3, "A", readonly=True)
_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)
#: Most periods a step's process variance counts: ``P + n Q`` keeps the cubes of its entries (the 3x3 inverses) far
#: from overflow. Below it what the prediction adds over a step is about ``(R / Q) x T`` whatever its length; beyond
#: it (a step longer than 1e90 periods: times near 1e308 s) that grows with the step, and the pose goes out of range.
MAX_PERIODS = 1e90


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


@_jit(numba.types.UniTuple(numba.int64, 2)(_IN, _IN1, _IN1, numba.float64, _INDEX, _INDEX, numba.int64, _IN, _INDEX,
                                           _IN3, _IN3, _IN3, numba.float64, numba.float64, numba.boolean,
                                           numba.float64[:],
                                           numba.float64[:], numba.float64, numba.boolean, numba.float64[:, :],
                                           numba.float64[:, :], numba.float64[:], numba.float64[:, :]))
def kalman_chunk(positions, before, time, time_before, rate_cols, steer_cols, start, keys, ids, h, m, ca, q,
                 period, double_q, filt, pose, fraction, exact, increments, poses, slip, missing):
    """Filter the intervals of joint `positions` ``(N, n_j)`` [rad] at `time` ``(N,)`` [s], each from the sample
    before (`before` ``(n_j,)`` at `time_before` for the first), from interval `start` on.

    ``rate_cols (n_a,)``, ``steer_cols (s,)``: the columns of the sensed rates and steering angles; ``keys (U, s)``
    the known configurations sorted lexicographically, ``ids (U,)`` their rows in ``h (V, 3, 3)``, ``m (V, 3,
    n_a)``, ``ca (V, r, 3 + n_a)`` the triangular factor T (QR) of ``[C, A_a]``, so that ``|C x + A_a qdot| =
    |T (x, qdot)|`` (without steering: one key of length 0); `q` the process
    variance per nominal sample `period` [s] (a step of ``n = max(1, round(dt / period))`` periods adds ``n q``).
    ``filt (9,)``: the state ``x`` then the upper entries of ``P`` (00, 01, 02, 11, 12, 22),
    updated. Body increments into `increments` ``(N, 3)`` and poses composed from ``pose (7,)`` (pose, path sums as
    :func:`wmrkit.odometry._kernels.steered_chunk`, updated) into `poses` ``(N, 3)``, each skipped when empty
    ``(0, 3)``; slip into `slip` ``(N,)``. Returns ``(reached, count)`` as
    :func:`wmrkit.odometry._kernels.steered_chunk`: ``missing[:count]`` the configurations to add before resuming.
    """
    n, n_a, n_s = positions.shape[0], rate_cols.shape[0], steer_cols.shape[0]
    with_increments, with_poses = increments.shape[0] > 0, poses.shape[0] > 0
    x_0, x_1, x_2 = filt[0], filt[1], filt[2]
    p00, p01, p02, p11, p12, p22 = filt[3], filt[4], filt[5], filt[6], filt[7], filt[8]
    i00 = i01 = i02 = i11 = i12 = i22 = u00 = u01 = u02 = u11 = u12 = u22 = 0.0
    a00 = a01 = a02 = a10 = a11 = a12 = a20 = a21 = a22 = 0.0
    gain = np.zeros((3, n_a))
    steady, last_u = False, -1
    long_step = 1.5 * period  # the shortest step of two periods or more
    mid = np.full(n_s, np.nan)
    seg_u, seg_start = np.empty(BLOCK, dtype=np.int64), np.empty(BLOCK + 1, dtype=np.int64)
    z, buf = np.empty((3 + n_a, BLOCK)), np.empty((11, BLOCK))  # z: the twist, then the rates
    norm, acc = buf[9], buf[10]
    rates = z[3:]
    bx, by, bth, head, turn, theta, cf, sf, dt = buf[0], buf[1], buf[2], buf[3], buf[4], buf[5], buf[6], buf[7], buf[8]
    for block in range(start, n, BLOCK):
        full = min(BLOCK, n - block)
        bm, count = _block_segments(positions, before, steer_cols, block, full, keys, ids, mid, seg_u, seg_start)
        unknown = bm < full  # the block ends at an unknown configuration
        _rates(positions, before, time, time_before, rate_cols, steer_cols, block, bm, dt, rates)
        gap = _next_gap(dt, 0, bm, long_step)
        for g in range(count):  # the recursion, sequential, over the runs of one configuration
            u, j, run_end = seg_u[g], seg_start[g], seg_start[g + 1]
            if u != last_u:
                steady, last_u = False, u
            while j < run_end:  # the run's parts between long steps, a long step a part of its own
                q_j, end = q, min(run_end, gap)
                if j == gap:  # n periods in the step: n Q (a random walk's variance grows with time)
                    q_j, end, steady = q * np.floor(min(dt[j] / period, MAX_PERIODS) + 0.5), j + 1, False
                    gap = _next_gap(dt, j + 1, bm, long_step)
                while j < end and not steady:  # a transient: prediction (7.71)-(7.72), the update's covariance
                    i00, i01, i02, i11, i12, i22 = _inverse_sym(p00 + q_j, p01, p02, p11 + q_j, p12, p22 + q_j)
                    u00, u01, u02, u11, u12, u22 = _inverse_sym(i00 + h[u, 0, 0], i01 + h[u, 0, 1],
                                                                i02 + h[u, 0, 2], i11 + h[u, 1, 1],
                                                                i12 + h[u, 1, 2], i22 + h[u, 2, 2])
                    n00, n11, n22 = (u00 + q_j, u11 + q_j, u22 + q_j) if double_q else (u00, u11, u22)  # (7.75)
                    steady = q_j == q and (n00 == p00 and u01 == p01 and u02 == p02 and n11 == p11 and u12 == p12
                                           and n22 == p22)
                    p00, p01, p02, p11, p12, p22 = n00, u01, u02, n11, u12, n22
                    if steady:  # a fixed point: this sample and the rest of the part take the form below
                        a00, a01, a02 = u00 * i00 + u01 * i01 + u02 * i02, u00 * i01 + u01 * i11 + u02 * i12, \
                            u00 * i02 + u01 * i12 + u02 * i22
                        a10, a11, a12 = u01 * i00 + u11 * i01 + u12 * i02, u01 * i01 + u11 * i11 + u12 * i12, \
                            u01 * i02 + u11 * i12 + u12 * i22
                        a20, a21, a22 = u02 * i00 + u12 * i01 + u22 * i02, u02 * i01 + u12 * i11 + u22 * i12, \
                            u02 * i02 + u12 * i12 + u22 * i22
                        for a in range(n_a):
                            gain[0, a] = u00 * m[u, 0, a] + u01 * m[u, 1, a] + u02 * m[u, 2, a]
                            gain[1, a] = u01 * m[u, 0, a] + u11 * m[u, 1, a] + u12 * m[u, 2, a]
                            gain[2, a] = u02 * m[u, 0, a] + u12 * m[u, 1, a] + u22 * m[u, 2, a]
                        break
                    c0 = c1 = c2 = 0.0  # x+ = P+ b, information vector b = P-^-1 x + M qdot_a, the rates' part first
                    for a in range(n_a):
                        c0 += m[u, 0, a] * rates[a, j]
                        c1 += m[u, 1, a] * rates[a, j]
                        c2 += m[u, 2, a] * rates[a, j]
                    b0 = (c0 + i00 * x_0) + (i01 * x_1 + i02 * x_2)
                    b1 = (c1 + i01 * x_0) + (i11 * x_1 + i12 * x_2)
                    b2 = (c2 + i02 * x_0) + (i12 * x_1 + i22 * x_2)
                    x_0 = u00 * b0 + u01 * b1 + u02 * b2
                    x_1 = u01 * b0 + u11 * b1 + u12 * b2
                    x_2 = u02 * b0 + u12 * b1 + u22 * b2
                    z[0, j], z[1, j], z[2, j] = x_0, x_1, x_2
                    j += 1
                for k in range(j, end):  # at the fixed point: x+ = A x + G qdot_a, A = P+ P-^-1, G = P+ M kept
                    c0 = c1 = c2 = 0.0  # the rates' part first: only A x is on the chain from sample to sample
                    for a in range(n_a):
                        c0 += gain[0, a] * rates[a, k]
                        c1 += gain[1, a] * rates[a, k]
                        c2 += gain[2, a] * rates[a, k]
                    x_0, x_1, x_2 = ((c0 + a00 * x_0) + (a01 * x_1 + a02 * x_2),
                                     (c1 + a10 * x_0) + (a11 * x_1 + a12 * x_2),
                                     (c2 + a20 * x_0) + (a21 * x_1 + a22 * x_2))
                    z[0, k], z[1, k], z[2, k] = x_0, x_1, x_2
                j = end
        for j in range(bm):
            d = dt[j]
            bx[j], by[j], bth[j] = z[0, j] * d, z[1, j] * d, z[2, j] * d
        _slip_norms(ca, seg_u, seg_start, count, z, acc, norm)  # |C x + A_a qdot| = |T z|, z = (x, qdot)
        for j in range(bm):
            slip[block + j] = norm[j] * dt[j]
        if with_increments:
            for j in range(bm):
                increments[block + j, 0], increments[block + j, 1], increments[block + j, 2] = bx[j], by[j], bth[j]
        if with_poses:
            th, turned = _headings(pose[2], bth, np.empty(0), block, bm, fraction, head, turn, theta)
            _rotations(head, turn, bm, exact, cf, sf)
            px, py, travelled = _positions(pose[0], pose[1], cf, sf, bx, by, True, theta, bm, poses, block)
            pose[0], pose[1], pose[2], pose[3], pose[4] = px, py, th, pose[3] + travelled, pose[4] + turned
        if unknown:
            _store(filt, x_0, x_1, x_2, p00, p01, p02, p11, p12, p22)
            return block + bm, _configurations_from(positions, before, steer_cols, block + bm, missing)
    _store(filt, x_0, x_1, x_2, p00, p01, p02, p11, p12, p22)
    return n, 0


@numba.njit(inline="always")
def _next_gap(dt, first, m, long_step):
    """The first of the steps ``dt[first:m]`` of at least `long_step` [s]; `m` if none. A block's first call
    (`first` 0) counts them first, a loop the compiler vectorises: most blocks have none; the calls after a long
    step search on (counting the rest again at each of them made a block of long steps quadratic)."""
    if first == 0:
        count = 0
        for j in range(m):
            count += dt[j] >= long_step
        if count == 0:
            return m
    for j in range(first, m):
        if dt[j] >= long_step:
            return j
    return m


@numba.njit
def _slip_norms(ca, seg_u, seg_start, count, z, acc, norm):
    """``norm[j] = |T z[:, j]|``, T = ``ca[u]`` triangular (:func:`_norm_rows`). With two sensed rates (T of five
    columns: the forklift's drive wheels, a differential drive) every row of a run in one loop, instead of a loop
    per row and column (which costs more than the arithmetic on the short runs of a quantised steering angle), as
    :func:`wmrkit.odometry._kernels._maps_two_rates`: the same sums in the same order, so the same numbers."""
    n_r = ca.shape[1]
    if ca.shape[2] != 5 or n_r > 5:
        _norm_rows(ca, seg_u, seg_start, count, z, True, acc, norm)
        return
    t00 = t01 = t02 = t03 = t04 = t11 = t12 = t13 = t14 = t22 = t23 = t24 = t33 = t34 = t44 = 0.0
    for g in range(count):
        u, j0, j1 = seg_u[g], max(seg_start[g], 0), seg_start[g + 1]
        if n_r > 0:
            t00, t01, t02, t03, t04 = ca[u, 0, 0], ca[u, 0, 1], ca[u, 0, 2], ca[u, 0, 3], ca[u, 0, 4]
        if n_r > 1:
            t11, t12, t13, t14 = ca[u, 1, 1], ca[u, 1, 2], ca[u, 1, 3], ca[u, 1, 4]
        if n_r > 2:
            t22, t23, t24 = ca[u, 2, 2], ca[u, 2, 3], ca[u, 2, 4]
        if n_r > 3:
            t33, t34 = ca[u, 3, 3], ca[u, 3, 4]
        if n_r > 4:
            t44 = ca[u, 4, 4]
        for k in range(j0, j1):
            z0, z1, z2, z3, z4 = z[0, k], z[1, k], z[2, k], z[3, k], z[4, k]
            total = 0.0
            if n_r > 0:
                a = ((((0.0 + t00 * z0) + t01 * z1) + t02 * z2) + t03 * z3) + t04 * z4
                total += a * a
            if n_r > 1:
                a = (((0.0 + t11 * z1) + t12 * z2) + t13 * z3) + t14 * z4
                total += a * a
            if n_r > 2:
                a = ((0.0 + t22 * z2) + t23 * z3) + t24 * z4
                total += a * a
            if n_r > 3:
                a = (0.0 + t33 * z3) + t34 * z4
                total += a * a
            if n_r > 4:
                a = 0.0 + t44 * z4
                total += a * a
            norm[k] = math.sqrt(total)


@numba.njit
def _rates(positions, before, time, time_before, rate_cols, steer_cols, start, m, dt, rates):
    """Steps ``dt[j]`` and rates ``rates[a, j]`` (increment over step) of the `m` intervals from `start` (a sensed
    steering angle's increment wrapped: a turn is no motion)."""
    for j in range(m):
        k = start + j
        dt[j] = time[k] - (time_before if k == 0 else time[k - 1])
    for a in range(rate_cols.shape[0]):
        col = rate_cols[a]
        last = before[col] if start == 0 else positions[start - 1, col]
        if _is_steering(col, steer_cols):
            for j in range(m):
                value = positions[start + j, col]
                rates[a, j] = _wrap(value - last) / dt[j]
                last = value
        else:  # the common case, a loop the compiler vectorises
            for j in range(m):
                value = positions[start + j, col]
                rates[a, j] = (value - last) / dt[j]
                last = value


@numba.njit
def _store(filt, x_0, x_1, x_2, p00, p01, p02, p11, p12, p22):
    """The filter's state into `filt` ``(9,)``."""
    filt[0], filt[1], filt[2] = x_0, x_1, x_2
    filt[3], filt[4], filt[5], filt[6], filt[7], filt[8] = p00, p01, p02, p11, p12, p22
