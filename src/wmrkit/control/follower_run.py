"""A path follower's default run (:func:`.track.track` without a duration): how long it may last within the loop's
limits (:func:`follower_bound`), where it ends (:func:`ended`), and the warning when it ends away from the path's
end (:func:`check_arrival`)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .trackers import ARRIVAL_FRACTION, ArrivalWarning, PathFollower, arrived, follower_duration

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


def _out_of_reach(follower: PathFollower, t: np.ndarray, pose: np.ndarray) -> str:
    """Why a follower passed the path's end beside it, from its run (times `t` ``(n,)`` [s], poses ``(n, 3)``):
    from the first sample after the last one where the end lay ahead of its tracked point, on the arc of a turn
    within its tightest, that point's arc through the end needed a tighter turn (or the end was behind it); "" when
    it never was (or the follower tells no axle). The tracked point ``F`` is ``L`` (`offset`) ahead of the axle
    point ``A`` (pure pursuit: ``L = 0``; Stanley: its front point): ``A`` on a circle of radius ``R`` (centre
    ``A + R n``) carries ``F`` on one of radius ``sqrt(R^2 + L^2)``, through the end ``E`` for
    ``1 / R = 2 y / (|E - A|^2 - L^2)``, ``y`` the end's side of ``A`` (closed form)."""
    if follower.axle is None:
        return ""
    end, offset = follower.path.xy[-1], follower.offset
    axle = [follower.axle(p) for p in pose]
    d = np.array([end - a for a, _ in axle])
    h = np.array([psi for _, psi in axle])
    ahead, side = d[:, 0] * np.cos(h) + d[:, 1] * np.sin(h), d[:, 1] * np.cos(h) - d[:, 0] * np.sin(h)
    need = 2.0 * np.abs(side) / np.maximum(np.abs(np.sum(d * d, axis=1) - offset**2), 1e-300)
    reach = np.flatnonzero((ahead > offset) & (need <= follower.tightest))
    k = int(reach[-1]) + 1 if len(reach) else 0
    if k >= len(t):
        return ""
    gap = float(np.hypot(*(end - follower.tracked(pose[k]))))
    at = f"from t = {t[k]:.4g} s, {gap:.3g} m from it,"
    if ahead[k] <= offset:
        return f"{at} the end was behind it"
    turn = f"a turn of radius {1 / need[k]:.3g} m"
    if offset > 0:  # Stanley: its steering limit
        turn += (f" (of its axle point, {offset:.3g} m behind its tracked point), tighter than Stanley's tightest "
                 f"({1 / follower.tightest:.3g} m: its steering limit)")
    else:
        turn += f", tighter than the robot's tightest ({1 / follower.tightest:.3g} m)"
    return f"{at} the end needed {turn}: start farther from the end, or on the path"


def check_arrival(follower: PathFollower, t: np.ndarray, pose: np.ndarray, cut: Limit | None = None,
                  delay: int | None = None) -> None:
    """Warn (:class:`.trackers.ArrivalWarning`) when a follower's default run (times `t` ``(n,)`` [s], poses
    ``(n, 3)``) ended with its tracked point more than its ``arrival_tol`` (``ARRIVAL_FRACTION`` of its length
    ``L``) from the path's end: still on its way after
    the bounded run (its extra time `cut` by a limit of the loop, if given), or past the end beside it (and why,
    where its turning radius tells: :func:`_out_of_reach`); `delay`: the loop's (:meth:`.PathFollower.stop_rule`)."""
    end, last = float(t[-1]), pose[-1]
    gap = follower.end_distance(last)
    if gap <= follower.arrival_tol:
        return
    rule = follower.stop_rule(delay)
    if follower.path.at_rest:
        why = ("the reference is at rest (its path has zero length): a path follower has no path to drive and stays "
               "where it starts; start on the reference's pose (the default), or use the p controller")
    elif [rule(float(t[k]), pose[k]) for k in range(max(len(t) - 2, 0), len(t))][-1]:
        q, p = (follower.tracked(x) for x in pose[-2:]) if len(t) > 1 else (None, None)
        step = 0.0 if q is None else float(np.hypot(*(p - q)))
        if delay is not None and step > 0 and arrived(q, p, follower.path.xy[-1], (1 + delay) * step):
            why = (f"it passed the path's end between its last two samples, {step:.3g} m apart (the sampled loop's "
                   f"step, its pose seen {delay} period(s) late): a shorter period (--period) stops it nearer")
        else:
            reason = _out_of_reach(follower, t, pose)
            why = "it passed the path's end beside it" + (f": {reason}" if reason else "")
    else:
        s = follower.path.project(follower.tracked(last), end)[0]
        at = f"at {s:.4g} m of the path's {follower.path.s[-1]:.4g} m"
        total = follower.path.ref.duration
        why = (f"the run ended at {end:.4g} s (the reference's duration, {total:.4g} s, and the followers' extra "
               f"time) {at}: give a longer duration (--duration)" if cut is None else
               f"the run ended at {end:.4g} s {at}: the followers' extra time after the reference's {total:.4g} s "
               f"was cut to {end - total:.4g} s by {cut.what}; {cut.remedy}")
    warnings.warn(f"the path follower did not reach the path's end: its tracked point ended {gap:.4g} m from it, "
                  f"beyond the {follower.arrival_tol:.4g} m tolerance ({ARRIVAL_FRACTION:g} of its length "
                  f"{follower.length:.4g} m); {why}", ArrivalWarning, stacklevel=3)
