"""The nearest segment of a path polyline near a time (:meth:`.trackers.PathIndex._segment`), one pass in scalar
arithmetic: a path follower asks it at every evaluation of its loop, where the same search in NumPy operations cost
about 100 µs a call (a dozen small array operations); compiled, a few µs. Plain Python below the interpret budget
(:func:`wmrkit._jit.jit`). Imported lazily (numba)."""

from __future__ import annotations

import math

import numba
import numpy as np

from .._jit import drop_stale_cache
from .._jit import jit as _jit

drop_stale_cache([__file__])

_IN = numba.float64[::1]
_XY = numba.float64[:, ::1]


@numba.njit(inline="always")
def _dist(xy, k, px, py):
    """Distance [m] from `(px, py)` to sample `k`."""
    return math.hypot(xy[k, 0] - px, xy[k, 1] - py)


@numba.njit(inline="always")
def _nearest(xy, lo, hi, px, py, near):
    """The smaller of `near` and the distance [m] from `(px, py)` to the nearest of samples ``lo .. hi - 1``:
    squared distances first, then the distance of each within round-off of the smallest (as a minimum of the
    distances themselves, at a fraction of the cost)."""
    least = math.inf
    for k in range(lo, hi):
        dx, dy = xy[k, 0] - px, xy[k, 1] - py
        least = min(least, dx * dx + dy * dy)
    bound = least * (1.0 + 1e-9)
    for k in range(lo, hi):
        dx, dy = xy[k, 0] - px, xy[k, 1] - py
        if dx * dx + dy * dy <= bound:
            near = min(near, math.hypot(dx, dy))
    return near


@numba.njit(inline="always")
def _below(xy, half, j, px, py):
    """A lower bound [m] of the distance from `(px, py)` to segment `j`: the nearer end's, less half its length."""
    return min(_dist(xy, j, px, py), _dist(xy, j + 1, px, py)) - half[j]


@numba.njit(inline="always")
def _beyond(xy, half, j, px, py, reach):
    """Whether :func:`_below` of segment `j` exceeds `reach` [m]: squared distances decide where they surely do
    (no root), :func:`_below` itself elsewhere."""
    dx0, dy0, dx1, dy1 = xy[j, 0] - px, xy[j, 1] - py, xy[j + 1, 0] - px, xy[j + 1, 1] - py
    cut = (reach + half[j]) * (1.0 + 1e-9)
    if reach + half[j] >= 0 and min(dx0 * dx0 + dy0 * dy0, dx1 * dx1 + dy1 * dy1) > cut * cut:
        return True
    return _below(xy, half, j, px, py) > reach


@numba.njit(inline="always")
def _foot(xy, j, px, py):
    """Distance [m] from `(px, py)` to segment `j` and the fraction ``u`` along it of its foot."""
    ax, ay = xy[j, 0], xy[j, 1]
    dx, dy = xy[j + 1, 0] - ax, xy[j + 1, 1] - ay
    n2 = dx * dx + dy * dy
    u = ((px - ax) * dx + (py - ay) * dy) / (n2 if n2 > 0 else 1.0)
    u = min(max(u, 0.0), 1.0)
    return math.hypot(px - ax - u * dx, py - ay - u * dy), u


@_jit(numba.types.Tuple((numba.int64, numba.float64))(_XY, _IN, _IN, numba.float64, numba.float64, numba.float64,
                                                      numba.float64, numba.float64))
def nearest_segment(xy, half, ts, px, py, t, window, tie):
    """The segment ``j`` of the polyline `xy` ``(m + 1, 2)`` (sampled at times `ts` ``(m + 1,)``; `half`: its
    segments' half lengths ``(m,)``) nearest to `(px, py)` near time `t`, and its foot's fraction ``u``: the search
    :meth:`.trackers.PathIndex._segment` documents (within `window` [s] of `t`, extended beyond either end while the
    path stays within reach; ties within `tie` [m] between adjacent segments: the one ahead)."""
    m = xy.shape[0] - 1
    lo = min(int(np.searchsorted(ts, t - window)), m - 1)  # past the reference's end: its last segment
    hi = min(max(int(np.searchsorted(ts, t + window)), lo + 1), m)
    first, last = lo, hi
    near = _nearest(xy, lo, hi + 1, px, py, math.inf)
    reach = 2.0 * near + tie
    width = max(hi - lo, 2)
    while lo > 0 and not _beyond(xy, half, lo - 1, px, py, reach):  # the path before the window, within reach
        start = max(lo - width, 0)
        far = -1
        for j in range(lo - 1, start - 1, -1):
            if _beyond(xy, half, j, px, py, reach):
                far = j
                break
        if far >= 0:
            lo = far + 1
            break
        lo = start
    while hi < m and not _beyond(xy, half, hi, px, py, reach):  # and after it
        stop = min(hi + width, m)
        far = -1
        for j in range(hi, stop):
            if _beyond(xy, half, j, px, py, reach):
                far = j
                break
        if far >= 0:
            hi = far
            break
        hi = stop
    near = _nearest(xy, last + 1, hi + 1, px, py, _nearest(xy, lo, first, px, py, near))  # the extended range's
    best, best_d, best_u = -1, math.inf, 0.0  # the segments that may hold the nearest point: the first nearest
    for j in range(lo, hi):
        if not _beyond(xy, half, j, px, py, near):
            d, u = _foot(xy, j, px, py)
            if d < best_d:
                best, best_d, best_u = j, d, u
    j = best
    while j + 1 < hi and not _beyond(xy, half, j + 1, px, py, near):  # a corner's tie: the segment ahead
        d, u = _foot(xy, j + 1, px, py)
        if not d <= best_d + tie:
            break
        j, best_d, best_u = j + 1, d, u
    return j, best_u
