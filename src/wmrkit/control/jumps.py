"""Discontinuities of a sampled signal (for :mod:`.feasibility`): a sample-to-sample change larger than
``jump_factor`` times the typical one where it is (the median of its block of 21 steps, or of a neighbouring block
when larger) is a discontinuity where it, or its run of such changes of one sign (a sampled step split by finite
differences), is larger than an absolute floor, reported once: the spike of a derivative around a step of its signal
is that step (:func:`_folded`). A change is also compared with the one its neighbours predict
(:func:`_unpredicted`): what is left is a discontinuity where larger than ``jump_factor`` times the typical change of
a step (or of what is left) and than the floor, which a signal that turns by a typical step every sample (the velocity
on an arc) hides from the first comparison. Undefined samples (NaN) are bridged: a jump across them is the change
from the last sample before to the first after, compared with as many typical steps as it spans. Long signals are
judged by the compiled passes of :mod:`._jump_kernels` (the same bits).
"""

from __future__ import annotations

import math

import numpy as np

from ..wheels import wrap_angle

_FLOOR = {"position": 1e-3, "theta": 0.02, "velocity": 0.02, "omega": 0.02, "acceleration": 0.05, "omega_rate": 0.05,
          "chi": 0.05, "chi_rate": 0.02, "kappa": 0.02, "kappa_rate": 0.02}


#: Steps in a block: a step's typical size is the median of its block or of a neighbouring one, whichever is larger.
BLOCK = 21


def _jumps(x: np.ndarray, t: np.ndarray, turn: float | None, floor: float, factor: float,
           at_rest: np.ndarray | None = None, across_rest: bool = False) -> list[tuple[int, int, float]]:
    """The jumps of `x` ``(n, ...)``: ``(first step, last step, size)`` of each (step k: from sample k to k + 1)."""
    x = x.reshape(len(x), -1)
    cut = held = None
    # typical sample steps each step covers: its time over the median sample spacing (more for one bridged over
    # undefined samples, or across a gap in a file's samples: a smooth circle with 0.5 s of samples missing was a
    # 'position jump' of 0.26 m)
    spacing = float(np.median(np.diff(t)))
    span = np.diff(t) / spacing
    if at_rest is not None and np.isnan(x).any():
        # undefined samples (NaN) are bridged: the step into the first defined sample after them is the change since
        # the last defined one (a jump while starting or stopping is still found), unless the reference rests
        # between them (there the signal is undefined, and a vehicle at rest may re-orient, the remedy) and
        # `across_rest` is False
        n = len(x)
        last = np.maximum.accumulate(np.where(np.isnan(x).any(axis=-1), -1, np.arange(n)))
        rests = np.cumsum(at_rest)
        cut = (last[:-1] < 0) | ((rests[1:] - rests[np.maximum(last[:-1], 0)] > 0) & (not across_rest))
        span = (t[1:] - t[np.maximum(last[:-1], 0)]) / spacing
        held = last[1:] < np.arange(1, n)  # steps into an undefined sample: no step of the signal
        x = x[np.maximum(last, 0)]
        x[last < 0] = np.nan
    d = np.diff(x, axis=0)
    if turn:
        d = _wrap(d, turn)
    size = np.sqrt(np.nansum(d * d, axis=-1))
    size[np.any(np.isnan(d), axis=-1)] = 0.0
    if cut is not None:
        size[cut] = 0.0
    n = len(size)
    steps = np.where(held, np.nan, size / span) if held is not None else size / span
    part, run = _outliers(d, size, factor * span * _typical(steps), floor, turn)
    # a step is also compared with the one its neighbours predict (:func:`_unpredicted`), and what is left with the
    # typical change of a step (or that left, when larger): on an arc the velocity turns by a typical step every
    # sample, and a speed doubling there (1 -> 2 m/s, curvature 0.5 1/m at 32 Hz) was 16 typical steps, under the
    # factor, and 250 typical changes of a step
    skip = np.isnan(steps) | np.isnan(d.reshape(n, -1)).any(axis=-1) | (False if cut is None else cut)
    r, rsize, change = _remainders(d.reshape(n, -1), span, skip)
    limit = factor * span * np.maximum(_typical(np.where(skip, np.nan, rsize / span)), _typical(change))
    rpart, rrun = _outliers(r, rsize, limit, floor, turn)
    hit = np.flatnonzero((part & ((size > floor) | (run > floor))) | (rpart & ((rsize > floor) | (rrun > floor))))
    events: list[list[int]] = []  # [first step, last step, step of the largest]
    for k in hit:  # a jump spread over consecutive samples (finite differences) is one event
        if events and k - events[-1][1] <= 2:
            events[-1][1] = int(k)
            if size[k] > size[events[-1][2]]:
                events[-1][2] = int(k)
        else:
            events.append([int(k), int(k), int(k)])
    out = []
    for first, last, top in events:  # its size: the whole change across it (a sampled corner splits in halves),
        total = x[last + 1] - x[first]  # or its largest step when that is larger (a spike: up, then back down)
        if turn:
            total = _wrap(total, turn)
        whole = float(np.sqrt(np.nansum(total * total)))
        out.append((first, last, max(whole, float(size[top])) if np.all(np.isfinite(total)) else float(size[top])))
    return out


def _typical(steps: np.ndarray) -> np.ndarray:
    """The typical size of each of `steps` ``(n,)`` (NaN: not a step of the signal, left out): the median of its
    block of :data:`BLOCK`, or of a neighbouring block when larger (a global median is 0 for a reference mostly at
    rest, and its every moving step was a jump)."""
    blocks = _block_medians(steps)
    blocks = np.where(np.isnan(blocks), 0.0, blocks)
    near = np.maximum(blocks, np.maximum(np.r_[blocks[:1], blocks[:-1]], np.r_[blocks[1:], blocks[-1:]]))
    return np.repeat(near, BLOCK)[:len(steps)]


def _block_medians(values: np.ndarray) -> np.ndarray:
    """The median of each block of :data:`BLOCK` of `values` ``(n,)`` (the last one padded with its last value; NaN
    left out: NaN for a block of NaN only)."""
    n = len(values)
    blocks = np.pad(values, (0, -n % BLOCK), mode="edge").reshape(-1, BLOCK)
    count = (~np.isnan(blocks)).sum(axis=1)
    blocks = np.sort(blocks, axis=1)  # NaN last; np.nanmedian gives the same, 7x slower on rows of 21
    rows = np.arange(len(blocks))
    mid = 0.5 * (blocks[rows, np.maximum(count - 1, 0) // 2] + blocks[rows, count // 2 - (count == 0)])
    return np.where(count > 0, mid, np.nan)


def _detrended(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """`x` ``(n,)`` (NaN: undefined) less its slope, integrated over time: the median rate of each block of
    :data:`BLOCK` steps. A step that finite differences spread over several samples then stands out of a signal
    with a steep slope as out of a level one (the curvature rate's step of 0.3 1/(m s) on a slope of 1 1/(m s^2) at
    100 Hz was five changes, each under 20 times the slope's step), while a curved signal keeps its typical steps
    (the changes of its slope across a block): a small step is no jump where the slope itself changes fast."""
    dt = np.diff(t)
    blocks = _block_medians(np.diff(x) / dt)
    rate = np.repeat(np.where(np.isnan(blocks), 0.0, blocks), BLOCK)[:len(dt)]
    return x - np.r_[0.0, np.cumsum(rate * dt)]


#: Samples from which a signal is judged by the compiled passes of :mod:`._jump_kernels` (the same bits): below, numpy
#: answers before numba would have compiled them.
COMPILED_FROM = 1 << 19


def _remainders(d: np.ndarray, span: np.ndarray, skip: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What of each of the steps `d` ``(n, m)`` its neighbours do not predict (:func:`_unpredicted` of the steps per
    sample, ``d / span``; none where `skip`), NaN as 0, its size, and the size of the change of each step per sample
    to the next (NaN: the last)."""
    q = d / span[:, None]  # per sample; NaN: no step of the signal
    q[skip] = np.nan
    if len(q) >= COMPILED_FROM and q.shape[1] < 8:  # numpy sums 8 or more numbers pairwise
        from ._jump_kernels import unpredicted_sizes

        r, rsize, change = np.empty(q.shape), np.empty(len(q)), np.empty(len(q))
        unpredicted_sizes(q, np.ascontiguousarray(span), r, rsize, change)
        return r, rsize, change
    r = np.nan_to_num(_unpredicted(q) * span[:, None])
    return r, np.sqrt((r * r).sum(axis=-1)), np.r_[np.sqrt((np.diff(q, axis=0) ** 2).sum(axis=-1)), np.nan]


def _unpredicted(q: np.ndarray, chunk: int = 1 << 16) -> np.ndarray:
    """What of each of the steps `q` ``(n, m)`` (per sample; NaN: none) its neighbours do not predict: the step less
    the one extrapolated linearly from the steps two and three before it or after it, or the mean of the two,
    whichever is nearest (NaN where a side has none: a start's first steps are too few to predict); then the
    smallest of that and its sum with the next one's or the previous one's. The steps next to it are left out of the
    prediction (central differences spread a sampled step over two); a kink of the signal (a step of its steps, no
    jump of its own) follows one side or their mean, or central differences spread it over two steps whose
    remainders cancel (a heading-rate reversal on an S-curve: +a/2 and -a/2); what is left of a kink between the
    samples is under half the change between the sides' predictions, and is dropped (an arc meeting a line, read from
    a file, was a 'velocity jump' of 0.0016 m/s). A smooth signal errs by about ``3 h^2 q''``. In chunks of `chunk`
    rows, to bound the memory of a dense file."""
    n = len(q)
    if n > chunk:
        out = np.empty_like(q)
        for a in range(0, n, chunk):  # 4 rows on each side: the prediction's 3 and the sum's 1
            lo = max(a - 4, 0)
            out[a:a + chunk] = _unpredicted(q[lo:a + chunk + 4], chunk + 8)[a - lo:a - lo + chunk]
        return out
    qp = np.pad(q, ((3, 3), (0, 0)), constant_values=np.nan)
    left, right = 3 * qp[1:n + 1] - 2 * qp[:n], 3 * qp[5:n + 5] - 2 * qp[6:n + 6]
    r = _nearest(q - left, q - right, q - 0.5 * (left + right))
    z = np.nan_to_num(r)
    after, before = np.r_[z[1:], 0 * z[-1:]], np.r_[0 * z[:1], z[:-1]]
    z = _nearest(z, z + after, z + before)
    # a kink spread by central differences leaves steps between its sides' (convex combinations): at most a quarter
    # of the change between them from the nearest prediction, and no more than half of it is a jump
    kink = 0.25 * ((left - right) ** 2).sum(axis=-1)
    return np.where(np.isnan(r), np.nan, np.where(((z * z).sum(axis=-1) > kink)[:, None], z, 0.0))


def _nearest(*options: np.ndarray) -> np.ndarray:
    """The smallest of `options` (each ``(n, m)``) for each of the n (NaN where one of them is NaN)."""
    best, least = options[0], np.nan_to_num((options[0] ** 2).sum(axis=-1), nan=-1.0)  # a NaN one first
    for z in options[1:]:
        size = np.nan_to_num((z * z).sum(axis=-1), nan=-1.0)
        best, least = np.where((size < least)[:, None], z, best), np.minimum(size, least)
    return best


def _outliers(d: np.ndarray, size: np.ndarray, limit: np.ndarray, floor: float,
              turn: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Which of the steps `d` ``(n, ...)`` of sizes `size` are over `limit`, or one of two consecutive ones each over
    half of it whose sum is over it (central differences halve a step: a speed step on an arc), and each one's run:
    the size of the sum of its run of such steps of one sign (finite differences split a sampled step into such a
    run, each maybe under the floor: the forklift's turn-rate step of 0.033 rad/s on an S-curve at 0.05 m/s was
    2 x 0.017). `turn`: the period of an angle signal, or None."""
    n = len(size)
    if n >= COMPILED_FROM and d.reshape(n, -1).shape[1] < 8:
        from ._jump_kernels import outliers

        part, run = np.empty(n, dtype=bool), np.empty(n)
        outliers(*map(np.ascontiguousarray, (d.reshape(n, -1), size, limit)), floor, float(turn or 0.0), part, run)
        return part, run
    z = np.nan_to_num(d.reshape(n, -1))
    pair = np.sqrt(((_wrap(z[:-1] + z[1:], turn) if turn else z[:-1] + z[1:]) ** 2).sum(axis=-1))
    half = (size[:-1] > limit[:-1] / 2) & (size[1:] > limit[1:] / 2) & (pair > np.maximum(limit[:-1], limit[1:]))
    part = (size > floor * 1e-3) & ((size > limit) | np.r_[half, False] | np.r_[False, half])  # 1e-3: rounding
    dz = np.where(part[:, None], z, 0.0)
    start = part & ~np.r_[False, part[:-1] & (np.sum(dz[1:] * dz[:-1], axis=-1) > 0)]
    starts, cz = np.flatnonzero(start), np.r_[np.zeros((1, dz.shape[1])), np.cumsum(dz, axis=0)]
    run = np.r_[np.sqrt(((cz[np.r_[starts[1:], n]] - cz[starts]) ** 2).sum(axis=-1)), 0.0][np.cumsum(start) - 1]
    return part, run


#: Period of the angle signals: a heading's turn, and half a turn for the tangent, which (8.29) defines as
#: ``arctan(dy/dx)``: a reversal of the direction of travel (a cusp) leaves it continuous, and every vehicle of the
#: table follows one without a jump of its wheels (a 2-quadrant root of (8.9) keeps the steering, the spins change
#: sign). It was compared over a whole turn, so a smooth back-and-forth was a tangent-angle jump of pi.
_TURN = {"theta": 2 * math.pi, "chi": math.pi}


def _wrap(d: np.ndarray, turn: float) -> np.ndarray:
    """Angle differences wrapped to ``(-turn / 2, turn / 2]``."""
    return wrap_angle(d * (2 * math.pi / turn)) * (turn / (2 * math.pi))


#: Samples on each side of a curvature-rate jump over which the change must persist. ``kappa_rate`` is a third finite
#: difference of the positions: a kink of the speed profile (a jerk step, e.g. where a short ramp from rest ends)
#: rings over about four samples (+0.04 then back, on a 2 m curve after a 0.5 s ramp at 100 Hz) with no step in the
#: curvature rate itself, while a true step persists.
PERSIST = 4


def _persists(x: np.ndarray, k: int, floor: float) -> bool:
    """Whether the jump of step `k` (from sample k to k + 1) is still larger than `floor` across the samples
    :data:`PERSIST` before and after it, less its slope's change (:func:`_held`; undefined there: kept): the
    curvature rate of a parabola driven from a 0.5 s ramp changed by 0.03 1/(m s) over those samples, its own steady
    slope, and the ringing of the ramp's end between them was a 'curvature-rate jump'."""
    return not abs(_held(x, k, k)) <= floor


def _held(x: np.ndarray, first: int, last: int) -> float:
    """The change of `x` from :data:`PERSIST` samples before step `first` to as many after step `last` (clipped to
    the signal), less the change the signal's slope on either side (over the :data:`PERSIST` samples beyond them,
    where defined) predicts across them: the step of a signal with a steady slope, which finite differences spread
    over several samples (NaN: undefined at either end)."""
    n = len(x)
    lo, hi = max(first - PERSIST, 0), min(last + 1 + PERSIST, n - 1)
    slopes = [(x[a] - x[b]) / (a - b) for a, b in ((lo, lo - PERSIST), (hi + PERSIST, hi)) if 0 <= b and a < n]
    slopes = [s for s in slopes if np.isfinite(s)]
    trend = float(np.mean(slopes)) * (hi - lo) if slopes else 0.0
    return float(x[hi] - x[lo]) - trend


def _middle(x: np.ndarray, t: np.ndarray, first: int, last: int) -> int:
    """The first sample at or after the middle of the jump of `x` ``(n,)`` (:func:`_detrended`) over steps `first`
    to `last`: the mean time of its steps, weighted by their share of its change. Finite differences spread a
    step over several samples on either side of it (a curvature-rate step over about five), and the first of them
    was reported, two samples early on a level signal and one to three on a slope."""
    d = np.nan_to_num(np.diff(x[first:last + 2]))
    w = np.clip(d * np.sign(d.sum()), 0.0, None)
    if not w.sum() > 0:
        return first + 1
    middle = float(np.dot(w, 0.5 * (t[first:last + 1] + t[first + 1:last + 2])) / w.sum())
    return int(min(max(np.searchsorted(t, middle), first + 1), last + 1))


#: The signal each one is a derivative of (the tangent: of the position's direction). A sampled step of a signal is a
#: spike of its finite-difference derivative over the samples around it, starting one sample earlier: a position
#: step of a file was a 'velocity jump' at t - dt and a 'position jump' at t, two violations for one discontinuity.
_SOURCE = {"velocity": "position", "chi": "position", "omega": "theta", "acceleration": "velocity",
           "omega_rate": "omega", "chi_rate": "chi", "kappa": "chi", "kappa_rate": "kappa"}


def _folded(span: tuple[str, float, float], seen: list[tuple[str, float, float]]) -> bool:
    """Whether the jump `span` ``(signal, from, to)`` [s] overlaps one found of a signal it is a derivative of (or
    of that one's, and so on): the spike of that step, not a discontinuity of its own."""
    name, t0, t1 = span
    sources = set()
    while name in _SOURCE:
        name = _SOURCE[name]
        sources.add(name)
    return any(other in sources and a <= t1 and t0 <= b for other, a, b in seen)

