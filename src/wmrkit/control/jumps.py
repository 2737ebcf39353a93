"""Discontinuities of a sampled signal (for :mod:`.feasibility`): a sample-to-sample change larger than
``jump_factor`` times the typical one where it is (the median of its block of 21 steps, or of a neighbouring block
when larger) is a discontinuity where it, or its run of such changes of one sign (a sampled step split by finite
differences), is larger than an absolute floor, reported once: the spike of a derivative around a step of its signal
is that step (:func:`_folded`). Undefined samples (NaN) are bridged: a jump across them is the change from the last
sample before to the first after, compared with as many typical steps as it spans.
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
    # the typical step where each one is: the median of its block of steps, or of a neighbouring block when larger
    # (a global median is 0 for a reference mostly at rest, and its every moving step was a jump)
    n = len(size)
    if held is None:
        blocks = np.median(np.pad(size / span, (0, -n % BLOCK), mode="edge").reshape(-1, BLOCK), axis=1) if n else size
    else:  # of the steps of the signal (per sample step for a bridged one), not of the 0s held over undefined ones
        typical = np.pad(np.where(held, np.nan, size / span), (0, -n % BLOCK), mode="edge").reshape(-1, BLOCK)
        count = (~np.isnan(typical)).sum(axis=1)
        typical = np.sort(typical, axis=1)  # NaN last; np.nanmedian gives the same, 7x slower on rows of 21
        rows = np.arange(len(typical))
        mid = 0.5 * (typical[rows, np.maximum(count - 1, 0) // 2] + typical[rows, count // 2 - (count == 0)])
        blocks = np.where(count > 0, mid, 0.0)
    near = np.maximum(blocks, np.maximum(np.r_[blocks[:1], blocks[:-1]], np.r_[blocks[1:], blocks[-1:]]))
    # a step bridged over k undefined samples is the change of k steps: compared with k typical ones (at 10 Hz, a
    # smooth curvature changing by 0.09 over 6 samples whose speed changed too fast to judge them was a 'jump')
    limit = factor * span * np.repeat(near, BLOCK)[:n]
    # central differences halve a step: two over half the limit whose sum is over it are one (a speed step on an arc)
    pair = np.sqrt(np.nansum((_wrap(d[:-1] + d[1:], turn) if turn else d[:-1] + d[1:]) ** 2, axis=-1))
    half = (size[:-1] > limit[:-1] / 2) & (size[1:] > limit[1:] / 2) & (pair > np.maximum(limit[:-1], limit[1:]))
    part = (size > floor * 1e-3) & ((size > limit) | np.r_[half, False] | np.r_[False, half])  # 1e-3: rounding
    # the floor is compared with the whole step: finite differences split a sampled one into a run of changes of one
    # sign, each maybe under it (the forklift's turn-rate step of 0.033 rad/s on an S-curve at 0.05 m/s was 2 x 0.017)
    dz = np.where(part[:, None], np.nan_to_num(d.reshape(n, -1)), 0.0)
    start = part & ~np.r_[False, part[:-1] & (np.sum(dz[1:] * dz[:-1], axis=-1) > 0)]
    starts, cz = np.flatnonzero(start), np.r_[np.zeros((1, dz.shape[1])), np.cumsum(dz, axis=0)]
    run = np.r_[np.sqrt(((cz[np.r_[starts[1:], n]] - cz[starts]) ** 2).sum(axis=-1)), 0.0][np.cumsum(start) - 1]
    hit = np.flatnonzero(part & ((size > floor) | (run > floor)))
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
    """Whether the jump of step `k` (from sample k to k + 1) is still larger than `floor` between the samples
    :data:`PERSIST` before and after it (undefined there: kept)."""
    before, after = x[max(k - PERSIST, 0)], x[min(k + 1 + PERSIST, len(x) - 1)]
    return not (np.isfinite(before) and np.isfinite(after)) or abs(float(after - before)) > floor



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

