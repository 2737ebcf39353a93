"""Compiled hot loops of odometry (numba): the sensed model's linear maps, SE(2) composition, both fused.

The block helpers below hold the one implementation of each step: :func:`_apply_row` / :func:`_norm_rows` of
the sensed model's maps (4.11), :func:`_headings`, :func:`_rotations`, :func:`_positions` of the schemes of
:mod:`.integrators`. The kernels chain them: :func:`compose` (increments to poses), :func:`linear_maps` (joint
increments to body increments and slip), :func:`odometry_chunk` (joint increments to poses, slip and path
sums in one pass over memory, the pipeline's hot path), :func:`steered_chunk` (the same from the joint positions
of a steering robot, each interval's maps found among those of the configurations met so far, looked up only
when the steering angles change, and applied run by run), :func:`time_steps`. This module is imported on
first use (numba takes about 0.4 s to import). Each kernel is compiled on its first call for one signature of
strided arrays that also accepts read-only ones (so any layout runs without a new compilation), cached on disk
next to this file or in the user's cache directory, and compiled in memory when no cache directory is writable
(a read-only installation).

Every kernel works in blocks of :data:`BLOCK` samples held in small buffers (the L1 cache), with loops over
the block innermost: loads into the buffers, the maps (vectorised by the compiler), the heading as a running
sum (sequential), the rotation of every body displacement (independent per sample, vectorised), the positions
as running sums (sequential). Sine and cosine are inlined: a Cody-Waite reduction by pi/2 in three 33-bit
parts with exact error terms, then fdlibm's kernels on ``[-pi/4, pi/4]`` (Sun Microsystems 1993, freely
redistributable); error below 1 ulp (0.8 measured; tested against mpmath). Angles beyond :data:`TRIG_MAX`
use libm, as do chord factors of steps turning more than ``pi/2``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._jit import drop_stale_cache
from .._jit import jit as _jit
from . import _steering_kernels
from ._steering_kernels import _block_segments, _configurations_from, _is_steering, _wrap

drop_stale_cache([__file__], [_steering_kernels.__file__])

#: Samples per block: a dozen block buffers take about 25 KB.
BLOCK = 256
#: Runs of one configuration up to this many samples are mapped sample by sample, longer ones vectorised.
SHORT = 4
#: Largest |angle| [rad] for the inlined sine and cosine (the reduction's products stay exact below it).
TRIG_MAX = 2.0**20
#: Largest |h| [rad] for the sinc polynomial (fdlibm's sine kernel divided by h).
SINC_MAX = math.pi / 4

# fdlibm k_sin.c, k_cos.c: minimax polynomials of sin and cos on [-pi/4, pi/4]
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
# fdlibm e_rem_pio2.c: pi/2 = P1 + P2 + P3 + P3T, the first three of 33 bits (so n * Pi is exact for n < 2^20)
_P1, _P2, _P3 = 1.57079632673412561417e+00, 6.07710050630396597660e-11, 2.02226624871116645580e-21
_P3T = 8.47842766036889956997e-32
_INV_PIO2 = 6.36619772367581382433e-01
_ROUND = 6755399441055744.0  # 1.5 * 2^52: (x + _ROUND) - _ROUND rounds x to the nearest integer


_IN = numba.types.Array(numba.float64, 2, "A", readonly=True)  # inputs: any strides, read-only accepted
_IN1 = numba.types.Array(numba.float64, 1, "A", readonly=True)
_IN3 = numba.types.Array(numba.float64, 3, "A", readonly=True)
_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)
_OUT1, _OUT2, _OUT3 = numba.float64[:], numba.float64[:, :], numba.float64[:, :, :]


@numba.njit(inline="always")
def _two_diff_error(a: float, b: float, d: float) -> float:
    """Rounding error of ``d = a - b`` (Knuth's TwoSum): ``a - b = d + error`` exactly."""
    bb = d - a
    return (a - (d - bb)) + (-b - bb)


@numba.njit(inline="always")
def _cos_sin(x: float) -> tuple[float, float]:
    """``(cos x, sin x)`` for ``|x| <= TRIG_MAX``, branch free (vectorisable), error below 1 ulp."""
    n = (x * _INV_PIO2 + _ROUND) - _ROUND  # nearest multiple of pi/2
    r1 = x - n * _P1  # exact
    w = n * _P2  # exact
    r2 = r1 - w
    err = _two_diff_error(r1, w, r2)
    w = n * _P3
    r3 = r2 - w
    err += _two_diff_error(r2, w, r3)
    tail = err - n * _P3T
    y0 = r3 + tail  # x - n pi/2 = y0 + y1, |y0| <= pi/4
    y1 = (r3 - y0) + tail
    z = y0 * y0
    zz = z * z
    v = z * y0
    rs = _S2 + z * (_S3 + z * _S4) + z * zz * (_S5 + z * _S6)
    s = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * _S1)
    rc = z * (_C1 + z * (_C2 + z * _C3)) + zz * zz * (_C4 + z * (_C5 + z * _C6))
    hz = 0.5 * z
    wc = 1.0 - hz
    c = wc + (((1.0 - wc) - hz) + (z * rc - y0 * y1))
    q = n - 4.0 * np.floor(0.25 * n)  # quadrant 0..3, in floating point (no int conversion of a NaN)
    swap = (q == 1.0) or (q == 3.0)
    cos_x = s if swap else c
    sin_x = c if swap else s
    if q == 1.0 or q == 2.0:
        cos_x = -cos_x
    if q >= 2.0:
        sin_x = -sin_x
    return cos_x, sin_x


@numba.njit(inline="always")
def _sinc(h: float) -> float:
    """``sin(h) / h`` for ``|h| <= SINC_MAX``: fdlibm's sine polynomial over h, no division (1 at 0)."""
    z = h * h
    zz = z * z
    return 1.0 + z * (_S1 + z * (_S2 + z * (_S3 + z * _S4) + z * zz * (_S5 + z * _S6)))


# -- block helpers: `m` samples from `start`; buffers are (BLOCK,) or (rows, BLOCK) ----------------------------

@numba.njit
def _load(source, start, m, buffer):
    """``buffer[j] = source[start + j]`` for a strided 1-D `source`."""
    for j in range(m):
        buffer[j] = source[start + j]


@numba.njit
def _load_differences(source, before, start, m, buffer):
    """``buffer[j] = source[start + j] - source[start + j - 1]``, with `before` as ``source[-1]``."""
    last = before if start == 0 else source[start - 1]
    for j in range(m):
        value = source[start + j]
        buffer[j] = value - last
        last = value


@numba.njit
def _segments(index, start, m, seg_u, seg_start):
    """Runs of one configuration among the `m` samples from `start`: configuration ``seg_u[g]`` on samples
    ``seg_start[g]:seg_start[g + 1]``; returns their count. An empty `index` is configuration 0 throughout."""
    if index.shape[0] == 0:
        seg_u[0], seg_start[0], seg_start[1] = 0, 0, m
        return 1
    count, last = 0, -1
    for j in range(m):
        u = index[start + j]
        if u != last:
            seg_u[count], seg_start[count], last = u, j, u
            count += 1
    seg_start[count] = m
    return count


@numba.njit(inline="always")
def _segment_row(maps, u, row, first, j0, length, cols, acc):
    """``acc[j0 + k] = maps[u, row, first:] @ cols[first:, j0 + k]`` for the `length` samples of one segment; (4.11).

    Indexed ``j0 + k`` with `j0` >= 0 known to the compiler (callers pass ``max(.., 0)``): an index it cannot prove
    >= 0 costs a wraparound test per element, which keeps a loop from vectorising."""
    if length <= SHORT:  # too short to vectorise (a steering step's interval): the same sums, sample by sample
        for k in range(length):
            total = 0.0
            for a in range(first, cols.shape[0]):
                total += maps[u, row, a] * cols[a, j0 + k]
            acc[j0 + k] = total
        return
    for k in range(length):
        acc[j0 + k] = 0.0
    for a in range(first, cols.shape[0]):
        c = maps[u, row, a]
        for k in range(length):
            acc[j0 + k] += c * cols[a, j0 + k]


@numba.njit
def _apply_row(maps, row, seg_u, seg_start, count, cols, acc):
    """``acc[j] = maps[u, row] @ cols[:, j]`` with ``u`` the configuration of sample j's segment; (4.11)."""
    for g in range(count):
        j0 = max(seg_start[g], 0)
        _segment_row(maps, seg_u[g], row, 0, j0, seg_start[g + 1] - j0, cols, acc)


@numba.njit
def _norm_rows(maps, seg_u, seg_start, count, cols, triangular, acc, norm):
    """``norm[j] = |maps[u] @ cols[:, j]|``, squares accumulated row by row (no cancelling quadratic form),
    segment by segment; a `triangular` map's row ``i`` starts at column ``i``."""
    for g in range(count):
        j0 = max(seg_start[g], 0)
        length = seg_start[g + 1] - j0
        for k in range(length):
            norm[j0 + k] = 0.0
        for row in range(maps.shape[1]):
            _segment_row(maps, seg_u[g], row, row if triangular else 0, j0, length, cols, acc)
            for k in range(length):
                norm[j0 + k] += acc[j0 + k] * acc[j0 + k]
        for k in range(length):
            norm[j0 + k] = math.sqrt(norm[j0 + k])


@numba.njit
def _headings(theta0, dtheta, heading, start, m, fraction, head, turn, theta):
    """Pass 1 (sequential): ``theta[j]`` after each step from `theta0`, the step's turn and its rotation heading
    ``theta_before + fraction * turn``; returns the last theta and ``sum |turn|``. `heading` ``(N + 1,)``, when
    not empty, replaces `dtheta`: ``turn = heading[k + 1] - heading[k]``, ``theta = heading[k + 1]``."""
    th, rotation = theta0, 0.0
    with_heading = heading.shape[0] > 0
    for j in range(m):
        if with_heading:
            th_next = heading[start + j + 1]
            d = th_next - th
        else:
            d = dtheta[j]
            th_next = th + d
        head[j], turn[j], theta[j] = th + fraction * d, d, th_next
        rotation += abs(d)
        th = th_next
    return th, rotation


@numba.njit
def _rotations(head, turn, m, exact, cf, sf):
    """Pass 2 (vectorised): ``(cf, sf) = f (cos head, sin head)``, ``f = sinc(turn / 2)`` when `exact`, else 1
    (003 (20)-(26), 002 (15)); libm where an angle is out of the inlined functions' range (rare)."""
    outside = 0
    for j in range(m):
        a, h = head[j], 0.5 * turn[j]
        c, s = _cos_sin(a)
        f = _sinc(h) if exact else 1.0
        cf[j], sf[j] = c * f, s * f
        outside += (abs(a) > TRIG_MAX) + (exact and abs(h) > SINC_MAX)
    if outside:
        for j in range(m):
            a, h = head[j], 0.5 * turn[j]
            # an infinite angle (an infinite position in the log, named by the caller) takes the inlined branch:
            # NaN there, as in compiled code, where Python's math.cos(inf) raises ValueError
            c, s = (math.cos(a), math.sin(a)) if TRIG_MAX < abs(a) < math.inf else _cos_sin(a)
            f = (math.sin(h) / h if SINC_MAX < abs(h) < math.inf else _sinc(h)) if exact else 1.0
            cf[j], sf[j] = c * f, s * f


@numba.njit
def _positions(x, y, cf, sf, dx, dy, with_dy, theta, m, out, start):
    """Pass 3 (sequential): positions after each step, ``(x, y) += Rot(cf, sf) (dx, dy)``; writes ``out[start +
    j] = (x, y, theta[j])``, returns the last ``(x, y)`` and the path length ``sum |(dx, dy)|``. `dy` is ignored
    (zero) unless `with_dy`."""
    distance = 0.0
    for j in range(m):
        u = dx[j]
        if with_dy:
            v = dy[j]
            x += cf[j] * u - sf[j] * v
            y += sf[j] * u + cf[j] * v
            distance += math.sqrt(u * u + v * v)
        else:
            x += cf[j] * u
            y += sf[j] * u
            distance += abs(u)
        k = start + j
        out[k, 0], out[k, 1], out[k, 2] = x, y, theta[j]
    return x, y, distance


# -- kernels ----------------------------------------------------------------------------------------------------

@_jit(numba.void(_IN, _IN, _IN, _IN, _IN, numba.float64, numba.boolean, _OUT3))
def compose(pose0, dx, dy, dtheta, heading, fraction, exact, out):
    """Poses after each body increment: ``out[b, k] = step(out[b, k - 1], increment[b, k])``.

    ``pose0 (B, 3), dx (B, N), dy (B, N) or (B, 0), dtheta (B, N), heading (B, N + 1) or (B, 0), out (B, N, 3)``.
    The step of :func:`.integrators.step`: displacement rotated by ``theta + fraction * dtheta`` and, when
    `exact`, scaled by ``sinc(dtheta / 2)``. An empty `dy` means zero; a non-empty `heading` replaces `dtheta`
    and the start heading by the external heading (``dtheta = heading[k + 1] - heading[k]``).
    """
    n = out.shape[1]
    with_dy, with_heading = dy.shape[1] > 0, heading.shape[1] > 0
    bx, by, bth = np.empty(BLOCK), np.empty(BLOCK), np.empty(BLOCK)
    head, turn, theta, cf, sf = (np.empty(BLOCK), np.empty(BLOCK), np.empty(BLOCK), np.empty(BLOCK),
                                 np.empty(BLOCK))
    for b in range(out.shape[0]):
        x, y = pose0[b, 0], pose0[b, 1]
        th = heading[b, 0] if with_heading else pose0[b, 2]
        for start in range(0, n, BLOCK):
            m = min(BLOCK, n - start)
            _load(dx[b], start, m, bx)
            if with_dy:
                _load(dy[b], start, m, by)
            if not with_heading:
                _load(dtheta[b], start, m, bth)
            th = _headings(th, bth, heading[b], start, m, fraction, head, turn, theta)[0]
            _rotations(head, turn, m, exact, cf, sf)
            x, y = _positions(x, y, cf, sf, bx, by, with_dy, theta, m, out[b], start)[:2]


@_jit(numba.void(_IN, _IN3, _IN3, _INDEX, _OUT2, _OUT1))
def linear_maps(dq, plain, squared, index, out, norm):
    """Products of per-interval matrices with joint increments, and norms of products, in one pass (4.11).

    ``dq (N, n), plain (U, P, n), squared (U, Q, n), index (N,) or (0,) -> out (N, P), norm (N,)``:
    ``out[k] = plain[u] @ dq[k]``, ``norm[k] = |squared[u] @ dq[k]|``, ``u = index[k]`` (0 when `index` is
    empty); `norm` is left untouched when Q = 0.
    """
    n, n_a = dq.shape
    cols, acc, norm_b = np.empty((n_a, BLOCK)), np.empty(BLOCK), np.empty(BLOCK)
    seg_u, seg_start = np.empty(BLOCK, dtype=np.int64), np.empty(BLOCK + 1, dtype=np.int64)
    for start in range(0, n, BLOCK):
        m = min(BLOCK, n - start)
        for a in range(n_a):
            _load(dq[:, a], start, m, cols[a])
        count = _segments(index, start, m, seg_u, seg_start)
        for row in range(plain.shape[1]):
            _apply_row(plain, row, seg_u, seg_start, count, cols, acc)
            for j in range(m):
                out[start + j, row] = acc[j]
        if squared.shape[1] > 0:
            _norm_rows(squared, seg_u, seg_start, count, cols, False, acc, norm_b)
            _load(norm_b, 0, m, norm[start:])


@numba.njit
def _maps_by_segments(maps, residual, seg_u, seg_start, count, cols, m, with_dy, buf):
    """Body increments ``buf[0:3]`` and slip ``buf[3]`` of the `m` samples of `cols` ``(n, BLOCK)``, by segments
    of one configuration (vectorised); ``buf[1]`` is left alone unless `with_dy`, ``buf[3]`` when R = 0."""
    if maps.shape[2] == 2 and residual.shape[1] <= 2:
        _maps_two_rates(maps, residual, seg_u, seg_start, count, cols, with_dy, buf)
        return
    _apply_row(maps, 0, seg_u, seg_start, count, cols, buf[0])
    if with_dy:
        _apply_row(maps, 1, seg_u, seg_start, count, cols, buf[1])
    _apply_row(maps, 2, seg_u, seg_start, count, cols, buf[2])
    if residual.shape[1] > 0:
        _norm_rows(residual, seg_u, seg_start, count, cols, False, buf[9], buf[3])


@numba.njit
def _maps_two_rates(maps, residual, seg_u, seg_start, count, cols, with_dy, buf):
    """:func:`_maps_by_segments` of two sensed rates (a differential drive, the forklift's drive wheels) and at most
    two residual rows: every row of a segment in one vectorised loop, instead of a loop per row and column (which
    costs more than the arithmetic on the short runs of a quantised steering angle). The same sums in the same
    order as :func:`_segment_row` and :func:`_norm_rows`, so the same numbers."""
    n_r = residual.shape[1]
    x, dy, th, slip = buf[0], buf[1], buf[2], buf[3]
    for g in range(count):
        u, j0, j1 = seg_u[g], max(seg_start[g], 0), seg_start[g + 1]
        x0, x1, y0, y1, t0, t1 = maps[u, 0, 0], maps[u, 0, 1], maps[u, 1, 0], maps[u, 1, 1], maps[u, 2, 0], \
            maps[u, 2, 1]
        r00 = r01 = r10 = r11 = 0.0
        if n_r > 0:
            r00, r01 = residual[u, 0, 0], residual[u, 0, 1]
        if n_r > 1:
            r10, r11 = residual[u, 1, 0], residual[u, 1, 1]
        for k in range(j0, j1):
            c0, c1 = cols[0, k], cols[1, k]
            x[k] = (0.0 + x0 * c0) + x1 * c1
            th[k] = (0.0 + t0 * c0) + t1 * c1
            if with_dy:
                dy[k] = (0.0 + y0 * c0) + y1 * c1
            if n_r == 1:
                a = (0.0 + r00 * c0) + r01 * c1
                slip[k] = math.sqrt(0.0 + a * a)
            elif n_r == 2:
                a, b = (0.0 + r00 * c0) + r01 * c1, (0.0 + r10 * c0) + r11 * c1
                slip[k] = math.sqrt((0.0 + a * a) + b * b)


@numba.njit
def _compose_block(with_slip, start, m, with_dy, heading, fraction, exact, buf, state, poses, slip):
    """The rest of a block of :func:`odometry_chunk`: the body increments ``buf[0:3]`` composed from ``state = (x,
    y, theta, distance, rotation, max slip, sum slip^2)`` (updated), poses and the slip ``buf[3]`` (0 unless
    `with_slip`) written from sample `start`. `buf` ``(10, BLOCK)``: the increments, slip, then scratch rows."""
    bx, by, bth, bslip, head, turn, theta, cf, sf = buf[0], buf[1], buf[2], buf[3], buf[4], buf[5], buf[6], buf[7], \
        buf[8]
    th, turned = _headings(state[2], bth, heading, start, m, fraction, head, turn, theta)
    _rotations(head, turn, m, exact, cf, sf)
    x, y, travelled = _positions(state[0], state[1], cf, sf, bx, by, with_dy, theta, m, poses, start)
    state[0], state[1], state[2], state[3], state[4] = x, y, th, state[3] + travelled, state[4] + turned
    if with_slip:
        max_slip, sq_slip = state[5], state[6]
        for j in range(m):
            slip[start + j] = bslip[j]
            max_slip = max(max_slip, bslip[j])
            sq_slip += bslip[j] * bslip[j]
        state[5], state[6] = max_slip, sq_slip
    else:  # write only where not already 0: fresh zeroed memory stays untouched (no page written)
        for j in range(m):
            if slip[start + j] != 0.0:
                slip[start + j] = 0.0


@numba.njit
def _has_dy(maps):
    """Whether any map has a lateral row (row 1) that is not zero."""
    for u in range(maps.shape[0]):
        for a in range(maps.shape[2]):
            if maps[u, 1, a] != 0.0:
                return True
    return False


@_jit(numba.types.UniTuple(numba.float64, 4)(_IN, _IN1, _IN3, _IN3, _INDEX, _IN1, _IN1, numba.float64,
                                              numba.boolean, _OUT2, _OUT1))
def odometry_chunk(rates, before, maps, residual, index, pose0, heading, fraction, exact, poses, slip):
    """Joint increments to poses in one pass: :func:`linear_maps` then :func:`compose`, fused (4.11; 003 (20)-(26)).

    ``rates (N, n), before (n,) or (0,), maps (U, 3, n), residual (U, R, n), index (N,) or (0,), pose0 (3,),
    heading (N + 1,) or (0,) -> poses (N, 3), slip (N,)``. The joint increments ``dq[k]`` are the rows of
    `rates`, or, when `before` is given, the differences of consecutive rows of `rates` (joint positions), with
    `before` the row before the first. Body increments ``maps[u] @ dq[k]`` are composed from `pose0` (`heading`
    as in :func:`compose`); the slip is ``|residual[u] @ dq[k]|`` (0 when R = 0). Returns the sums over the
    chunk ``(sum |(dx, dy)|, sum |dtheta|, max slip, sum slip^2)``.
    """
    n, n_a = rates.shape
    differences = before.shape[0] > 0
    with_dy = _has_dy(maps)
    cols, buf = np.empty((n_a, BLOCK)), np.empty((10, BLOCK))
    seg_u, seg_start = np.empty(BLOCK, dtype=np.int64), np.empty(BLOCK + 1, dtype=np.int64)
    state = np.zeros(7)
    state[0], state[1], state[2] = pose0[0], pose0[1], heading[0] if heading.shape[0] > 0 else pose0[2]
    for start in range(0, n, BLOCK):
        m = min(BLOCK, n - start)
        for a in range(n_a):
            if differences:
                _load_differences(rates[:, a], before[a], start, m, cols[a])
            else:
                _load(rates[:, a], start, m, cols[a])
        count = _segments(index, start, m, seg_u, seg_start)
        _maps_by_segments(maps, residual, seg_u, seg_start, count, cols, m, with_dy, buf)
        _compose_block(residual.shape[1] > 0, start, m, with_dy, heading, fraction, exact, buf, state, poses, slip)
    return state[3], state[4], state[5], state[6]


@_jit(numba.types.UniTuple(numba.int64, 2)(_IN, _IN1, _INDEX, _INDEX, numba.int64, _IN, _INDEX, _IN3, _IN3,
                                           _IN1, numba.float64, numba.boolean, _OUT1, _OUT2, _OUT1, _OUT2))
def steered_chunk(positions, before, rate_cols, steer_cols, start, keys, ids, maps, residual, heading, fraction,
                  exact, state, poses, slip, missing):
    """:func:`odometry_chunk` for a steering robot: joint positions to poses in one pass, the maps of each
    interval's steering configuration (its angles at mid-interval) found among the known ones.

    ``positions (N, n_j), before (n_j,)`` the sample before the first, ``rate_cols (n,)``, ``steer_cols (s,)``
    their columns; ``keys (U, s)`` the known configurations sorted lexicographically, ``ids (U,)`` their maps'
    rows in ``maps (V, 3, n)`` and ``residual (V, R, n)``; ``state (7,)`` = pose, then the path sums of
    :func:`odometry_chunk`, updated; samples from `start` on. The maps are looked up only when the steering
    angles change. Returns ``(reached, count)``: ``(N, 0)`` when done; else interval `reached` has a
    configuration not in `keys`, and ``missing[:count]`` ``(M, s)`` holds the configurations of the intervals from
    there on (each run of equal angles once, while `missing` has room): add their maps and call again from
    `reached`.
    """
    n, n_a, n_s = positions.shape[0], rate_cols.shape[0], steer_cols.shape[0]
    with_dy = _has_dy(maps)
    cols, buf = np.empty((n_a, BLOCK)), np.empty((10, BLOCK))
    seg_u, seg_start = np.empty(BLOCK, dtype=np.int64), np.empty(BLOCK + 1, dtype=np.int64)
    mid = np.full(n_s, np.nan)
    for block in range(start, n, BLOCK):
        full = min(BLOCK, n - block)
        m, count = _block_segments(positions, before, steer_cols, block, full, keys, ids, mid, seg_u, seg_start)
        unknown = m < full  # the block ends at an unknown configuration
        for a in range(n_a):
            c = rate_cols[a]
            _load_differences(positions[:, c], before[c], block, m, cols[a])
            if _is_steering(c, steer_cols):
                for j in range(m):
                    cols[a, j] = _wrap(cols[a, j])
        _maps_by_segments(maps, residual, seg_u, seg_start, count, cols, m, with_dy, buf)
        _compose_block(residual.shape[1] > 0, block, m, with_dy, heading, fraction, exact, buf, state, poses, slip)
        if unknown:
            return block + m, _configurations_from(positions, before, steer_cols, block + m, missing)
    return n, 0


@_jit(numba.types.Tuple((numba.int64, numba.float64))(_IN1, _IN1))
def time_steps(time, before):
    """How many steps of `time` ``(N,)`` are not numbers > 0 (NaN included), and the largest step (0 without
    steps); the first step is from ``before[0]`` when `before` ``(1,)`` is not empty."""
    n, first = time.shape[0], 0 if before.shape[0] > 0 else 1
    bad, largest = 0, np.zeros(4)  # four running maxima: independent dependency chains
    for k in range(first, n):
        d = time[k] - (before[0] if k == 0 else time[k - 1])
        bad += not d > 0.0
        largest[k % 4] = max(largest[k % 4], d)
    return bad, largest.max()
