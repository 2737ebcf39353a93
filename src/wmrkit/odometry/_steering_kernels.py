"""Steering configurations in the compiled odometry kernels: the angles at mid-interval (steps wrapped: a turn of
a sensed steering angle is no motion), and their lookup among the configurations whose maps are known (sorted
keys). Shared by :mod:`._kernels` (odometry) and :mod:`wmrkit.slip._kalman_kernel` (FK1/FK2).
"""

from __future__ import annotations

import numba
import numpy as np

from .._jit import jit as _jit

_IN = numba.types.Array(numba.float64, 2, "A", readonly=True)
_INDEX = numba.types.Array(numba.int64, 1, "A", readonly=True)


@numba.njit(inline="always")
def _wrap(angle):
    """`angle` [rad] into ``[-pi, pi)`` (as :func:`.model.wrap_angle`); no fmod call within one turn."""
    t = angle + np.pi
    if not 0.0 <= t < 2 * np.pi:
        t = t % (2 * np.pi)
    return (t + 0.0) - np.pi


@numba.njit
def _is_steering(col, steer_cols):
    """Whether joint column `col` is a steering angle (a sensed castor's: its step is wrapped, a turn is 0)."""
    for s in range(steer_cols.shape[0]):
        if steer_cols[s] == col:
            return True
    return False


@numba.njit(inline="always")
def _find_one(keys, ids, v):
    """:func:`_find` of one angle `v` (the common case): halving by conditional moves, without the data-dependent
    jumps a processor mispredicts half the time."""
    n, base = keys.shape[0], 0
    if n == 0:
        return -1
    while n > 1:
        half = n >> 1
        base = base + half if keys[base + half, 0] <= v else base
        n -= half
    return ids[base] if keys[base, 0] == v else -1


@numba.njit
def _find(keys, ids, value):
    """``ids[i]`` of the row ``keys[i]`` equal to `value` ``(s,)`` in `keys` ``(U, s)`` sorted lexicographically
    (binary search), -1 when absent."""
    if value.shape[0] == 1:
        return _find_one(keys, ids, value[0])
    lo, hi = 0, keys.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        order = 0
        for i in range(value.shape[0]):
            if keys[mid, i] != value[i]:
                order = -1 if keys[mid, i] < value[i] else 1
                break
        if order == 0:
            return ids[mid]
        if order < 0:
            lo = mid + 1
        else:
            hi = mid
    return -1


@numba.njit(inline="always")
def _mid_angle(before, after):
    """A steering angle at the middle of an interval from its values at the ends: the step wrapped (a turn is no
    motion) and halved."""
    return before + 0.5 * _wrap(after - before)


@numba.njit
def _steering_mid(positions, before, steer_cols, k, out):
    """Steering angles at the middle of interval `k` into `out`: the step wrapped into ``[-pi, pi)`` (as
    :func:`.model.wrap_angle`), halved, from the sample before; returns whether they differ from `out`'s values."""
    changed = False
    for s in range(steer_cols.shape[0]):
        c = steer_cols[s]
        last = before[c] if k == 0 else positions[k - 1, c]
        mid = _mid_angle(last, positions[k, c])
        changed = changed or mid != out[s]
        out[s] = mid
    return changed


@numba.njit
def _block_segments(positions, before, steer_cols, block, m, keys, ids, mid, seg_u, seg_start):
    """Runs of one steering configuration among the `m` intervals from `block`: configuration ``seg_u[g]`` (its
    row among the known ones, :func:`_find`) on intervals ``seg_start[g]:seg_start[g + 1]`` of the block, looked up
    when the angles at mid-interval (`mid` ``(s,)``, carried from block to block) change. Returns ``(reached,
    count)``: `reached` < `m` when interval ``block + reached`` has a configuration not in `keys` (the block ends
    there)."""
    count = 0
    if steer_cols.shape[0] == 1:  # one angle (the common case): the same, with its values kept in registers
        c = steer_cols[0]
        last, previous = before[c] if block == 0 else positions[block - 1, c], mid[0]
        for j in range(m):
            value = positions[block + j, c]
            angle = _mid_angle(last, value)
            last = value
            if angle != previous or j == 0:
                u = _find_one(keys, ids, angle)
                if u < 0:
                    m = j
                    previous = angle
                    break
                seg_u[count], seg_start[count] = u, j
                count += 1
            previous = angle
        mid[0] = previous
    else:
        for j in range(m):
            if _steering_mid(positions, before, steer_cols, block + j, mid) or j == 0:
                u = _find(keys, ids, mid)
                if u < 0:
                    m = j
                    break
                seg_u[count], seg_start[count] = u, j
                count += 1
    seg_start[count] = m
    return m, count


@numba.njit
def _configurations_from(positions, before, steer_cols, first, out):
    """The configuration of each run of equal steering angles from interval `first` on into `out` (rows, while
    there is room); their count (see :func:`steered_chunk`)."""
    mid = np.full(steer_cols.shape[0], np.nan)
    count = 0
    for k in range(first, positions.shape[0]):
        if _steering_mid(positions, before, steer_cols, k, mid):
            if count == out.shape[0]:
                break
            out[count] = mid
            count += 1
    return count


@_jit(numba.void(_IN, _INDEX, _IN, numba.int64[:]))
def find_configurations(keys, ids, values, out):
    """``out[i]`` = the id of ``values[i]`` ``(s,)`` among `keys` ``(U, s)`` (sorted lexicographically), -1 when
    absent (:func:`_find` for each row)."""
    for i in range(values.shape[0]):
        out[i] = _find(keys, ids, values[i])
