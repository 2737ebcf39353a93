"""Compiled passes of :mod:`.jumps` for long signals (:data:`.jumps.COMPILED_FROM` samples or more):
:func:`unpredicted_sizes` (the remainders of :func:`.jumps._unpredicted`, their sizes and the changes of the steps) and
:func:`outliers` (:func:`.jumps._outliers`), each one pass over the samples with no ``(n, m)`` temporaries. The same
arithmetic in the same order as the numpy formulation in :mod:`.jumps` (tests/control/test_jump_kernels.py compares
the bits), which judges shorter signals before numba would be imported and these loaded. Imported lazily."""

from __future__ import annotations

import math

import numpy as np

from .._jit import compile_cached, drop_stale_cache

drop_stale_cache([__file__])

_BIG = np.finfo(np.float64).max
_TWO_PI = 2 * math.pi


def _finite(v: float) -> float:
    """np.nan_to_num of one number."""
    if v != v:
        return 0.0
    if v == math.inf:
        return _BIG
    if v == -math.inf:
        return -_BIG
    return v


def _top(a: float, b: float) -> float:
    """np.maximum of two numbers (NaN when either is)."""
    return a if a != a else (b if b != b else max(a, b))


def _wrapped(v: float, turn: float) -> float:
    """:func:`.jumps._wrap` of one number (:func:`wmrkit.wheels.wrap_angle`'s arithmetic)."""
    a = v * (_TWO_PI / turn)
    y = a - _TWO_PI * np.rint(a / _TWO_PI)
    if y <= -math.pi:
        y = y + _TWO_PI
    elif y > math.pi:
        y = y - _TWO_PI
    return y * (turn / _TWO_PI)


def _add(total: float, v: float, j: int) -> float:
    """`total` plus the square of `v`, or the square alone for the first column: numpy's order for a short last
    axis (one after the other)."""
    return v * v if j == 0 else total + v * v


def _least(s: float) -> float:
    """A squared size as :func:`.jumps._nearest` compares it: NaN as -1, infinity as the largest float."""
    return -1.0 if s != s else _finite(s)


# The kernels take scalars from their arrays in their own loops: a compiled helper given an array costs two
# reference-count updates a call, which made the first pass 3 times slower.
def _unpredicted_sizes(q, span, r, rsize, change):  # pragma: no cover - compiled
    """Into `r` ``(n, m)``, `rsize` ``(n,)`` and `change` ``(n,)``: ``nan_to_num(_unpredicted(q) * span)`` of the
    steps per sample `q` (NaN: none), its row sizes and the sizes of the changes of `q` (NaN at the last), as
    :func:`.jumps._remainders` computes them. The first pass keeps each step's nearest prediction's remainder in `r`
    and its kink bound in `rsize`, the second one overwrites them."""
    n, m = q.shape
    for k in range(n):
        # the step less the one predicted from the left, from the right, or their mean: the nearest (a NaN one first)
        s0 = s1 = s2 = 0.0
        for j in range(m):
            left = 3 * q[k - 2, j] - 2 * q[k - 3, j] if k >= 3 else math.nan
            right = 3 * q[k + 2, j] - 2 * q[k + 3, j] if k + 3 < n else math.nan
            s0 = _add(s0, q[k, j] - left, j)
            s1 = _add(s1, q[k, j] - right, j)
            s2 = _add(s2, q[k, j] - 0.5 * (left + right), j)
        s0, s1, s2 = _least(s0), _least(s1), _least(s2)
        which = 1 if s1 < s0 else 0
        which = 2 if s2 < min(s0, s1) else which
        ends = 0.0
        for j in range(m):
            left = 3 * q[k - 2, j] - 2 * q[k - 3, j] if k >= 3 else math.nan
            right = 3 * q[k + 2, j] - 2 * q[k + 3, j] if k + 3 < n else math.nan
            r[k, j] = q[k, j] - (left if which == 0 else (right if which == 1 else 0.5 * (left + right)))
            ends = _add(ends, left - right, j)
        rsize[k] = 0.25 * ends  # the kink's bound (a quarter of the squared change between the predictions)
    before, own = np.zeros(m), np.empty(m)  # the finite remainders of steps k - 1 and k
    for k in range(n):
        # the remainder, its sum with the next one's or with the previous one's (0 past an end): the smallest
        s0 = s1 = s2 = 0.0
        for j in range(m):
            own[j] = _finite(r[k, j])
            after = _finite(r[k + 1, j]) if k + 1 < n else 0 * own[j]
            s0 = _add(s0, own[j], j)
            s1 = _add(s1, own[j] + after, j)
            s2 = _add(s2, own[j] + (before[j] if k > 0 else 0 * own[j]), j)
        s0, s1, s2 = _least(s0), _least(s1), _least(s2)
        which = 1 if s1 < s0 else 0
        which = 2 if s2 < min(s0, s1) else which
        keep, total, step = 0.0, 0.0, 0.0
        for j in range(m):
            after = _finite(r[k + 1, j]) if k + 1 < n else 0 * own[j]
            v = own[j] + (0.0 if which == 0 else (after if which == 1 else (before[j] if k > 0 else 0 * own[j])))
            keep = _add(keep, own[j] if which == 0 else v, j)
        for j in range(m):
            after = _finite(r[k + 1, j]) if k + 1 < n else 0 * own[j]
            v = own[j] if which == 0 else own[j] + (after if which == 1 else (before[j] if k > 0 else 0 * own[j]))
            v = math.nan if r[k, j] != r[k, j] else (v if keep > rsize[k] else 0.0)
            before[j] = own[j]
            v = _finite(v * span[k])
            r[k, j] = v
            total = _add(total, v, j)
            if k + 1 < n:
                step = _add(step, q[k + 1, j] - q[k, j], j)
        rsize[k] = math.sqrt(total)
        change[k] = math.sqrt(step) if k + 1 < n else math.nan


def _outliers(z, size, limit, floor, turn, part, run):  # pragma: no cover - compiled
    """Into `part` and `run` ``(n,)``: :func:`.jumps._outliers` of the steps `z` ``(n, m)`` (NaN as 0) of sizes
    `size` over `limit`; `turn` 0 for no angle."""
    n, m = z.shape
    half = np.zeros(n + 1, dtype=np.bool_)  # half[k + 1]: steps k and k + 1 are one halved step
    for k in range(n - 1):
        pair = 0.0
        for j in range(m):
            v = _finite(z[k, j]) + _finite(z[k + 1, j])
            pair = _add(pair, _wrapped(v, turn) if turn else v, j)
        half[k + 1] = (size[k] > limit[k] / 2 and size[k + 1] > limit[k + 1] / 2
                       and math.sqrt(pair) > _top(limit[k], limit[k + 1]))
    for k in range(n):
        part[k] = size[k] > floor * 1e-3 and (size[k] > limit[k] or half[k + 1] or half[k])
    total, at_start = np.zeros(m), np.zeros(m)
    first = 0  # the current run's first step (before any: 0, its run 0)
    for k in range(n + 1):
        start = k == n or part[k]
        if 0 < k < n and part[k] and part[k - 1]:
            dot = 0.0
            for j in range(m):
                v = _finite(z[k, j]) * _finite(z[k - 1, j])
                dot = v if j == 0 else dot + v
            start = not dot > 0
        if start:
            size_run = 0.0
            for j in range(m):
                size_run = _add(size_run, total[j] - at_start[j], j)
            size_run = math.sqrt(size_run)
            for i in range(first, k):
                run[i] = size_run
            first = k
            at_start[:] = total
        if k < n and part[k]:
            for j in range(m):
                total[j] += _finite(z[k, j])


for _name in ("_finite", "_top", "_wrapped", "_add", "_least"):
    globals()[_name] = compile_cached(globals()[_name], None)
unpredicted_sizes = compile_cached(_unpredicted_sizes, None)
outliers = compile_cached(_outliers, None)
