"""A path follower's default run (:func:`.track.track` without a duration): how long it may last within the loop's
limits (:func:`follower_bound`), where it ends (:func:`ended`), and the warning when it ends away from the path's
end (:func:`check_arrival`)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .trackers import ARRIVAL_TOL, ArrivalWarning, PathFollower, follower_duration

__all__ = ["Limit", "check_arrival", "ended", "follower_bound", "span"]


class Limit(NamedTuple):
    """The longest run [s] a loop allows (``seconds``), ``what`` limits it, and how to lift it (``remedy``)."""

    seconds: float
    what: str
    remedy: str


def span(count: int, step: float) -> float:
    """The longest duration [s] of at most `count` steps of `step` [s]: ``d / step <= count`` in floating point."""
    d = count * step
    while d / step > count:
        d = math.nextafter(d, 0.0)
    return d


def follower_bound(duration: float, limits: list[Limit]) -> tuple[float, Limit | None]:
    """A follower's default run on a reference of `duration` [s]: :func:`.trackers.follower_duration`, its extra
    time cut to what the tightest of `limits` allows (the reference's own duration is run as any other, and refused
    when a limit refuses it); with the limit that cut it, else None."""
    longest = follower_duration(duration)
    tight = min(limits, key=lambda lim: lim.seconds, default=None)
    if tight is None or tight.seconds >= longest:
        return longest, None
    return max(duration, tight.seconds), tight


def ended(out: dict[str, Any], until: Callable[[float, np.ndarray], bool]) -> dict[str, Any]:
    """`out` of a loop (a dict of per-sample arrays) up to the first sample where `until(t, pose)` holds: where the
    loops through the dynamics stop by their own `until` (:func:`.dynamic_plant.simulate_dynamics`,
    :func:`.slip_loop.simulate_slip_control`); the trimming their whole run would need, to check them against."""
    t = out["t"]
    done = next((k for k in range(len(t)) if until(float(t[k]), out["pose"][k])), len(t) - 1)
    return {key: v[:done + 1] if isinstance(v, np.ndarray) and len(v) == len(t) else v for key, v in out.items()}


def check_arrival(follower: PathFollower, end: float, pose: np.ndarray, cut: Limit | None = None) -> None:
    """Warn (:class:`.trackers.ArrivalWarning`) when a follower's default run ended with its tracked point more than
    ``ARRIVAL_TOL`` from the path's end: still on its way after the bounded run (its extra time `cut` by a limit of
    the loop, if given), or past the end beside it."""
    gap = follower.end_distance(pose)
    if gap <= ARRIVAL_TOL:
        return
    if follower.finished(end, pose):
        why = "it passed the path's end beside it"
    else:
        s = follower.path.project(follower.tracked(pose), end)[0]
        at = f"at {s:.4g} m of the path's {follower.path.s[-1]:.4g} m"
        total = follower.path.ref.duration
        why = (f"the run ended at {end:.4g} s (the reference's duration, {total:.4g} s, and the followers' extra "
               f"time) {at}: give a longer duration (--duration)" if cut is None else
               f"the run ended at {end:.4g} s {at}: the followers' extra time after the reference's {total:.4g} s "
               f"was cut to {end - total:.4g} s by {cut.what}; {cut.remedy}")
    warnings.warn(f"the path follower did not reach the path's end: its tracked point ended {gap:.4g} m from it, "
                  f"beyond the {ARRIVAL_TOL:g} m tolerance; {why}", ArrivalWarning, stacklevel=3)
