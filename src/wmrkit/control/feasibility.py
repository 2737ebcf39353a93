"""Which references a robot can follow with zero error (thesis §8.5, Table 8.1), where a reference breaks that, and
the remedy.

The column of Table 8.1 follows from the vehicle type (:func:`wmrkit.analysis.classify`) and where the tracking point
(the robot origin R, or a given point) lies: on the fixed axle (``beta_f - alpha_f = 0``) or off it, and for types 3
and 5 whether some steered wheel is away from it (``l_oi != 0``). The *kinematic* framework lets wheel rates jump;
the *dynamic* one needs them continuous, so every condition goes one derivative higher (§8.5). For types 3 and 5 with
some ``l_oi != 0`` a velocity or heading-rate step (kinematic), an acceleration or angular-acceleration step
(dynamic), is a violation only where a steered wheel's heading, respectively steering rate, changes across it
(:func:`_steered_turn`): a twist that only scales keeps them (docs/errata.md); a velocity or heading-rate step under
its floor is one too where it turns a steered wheel (:func:`_slow_turns`: a steering angle is a state at any speed).

Signals of the reference, sampled: position, tangent angle ``chi`` (8.29) and its rate ``omega_g`` (8.31), curvature
``kappa`` (8.33) and its rate, heading ``theta``, velocity and acceleration. A sample-to-sample change larger than
``jump_factor`` times the typical one where it is (the median of its block of 21 steps, or of a neighbouring block
when larger) is a discontinuity where it, or its run of such changes of one sign (a sampled step split by finite
differences), is larger than an absolute floor, reported once: the spike of a derivative around a step of its signal
is that step (:func:`_folded`).

``kappa`` and the rates are not judged where the reference rests or starts or stops (its speed changes by more than
5 % in a sample step), ``chi`` at rest and where the speed changes by more than itself in a step: there they come
from a velocity near zero (finite differences of positions that hardly move, for a file). A jump across such samples is
still found, as the change from the last sample before to the first after (compared with as many typical steps as it
spans), where it is reported; across a rest only for a car's tangent (R on the fixed axle of a type 4 cannot turn at
rest; any other vehicle re-orients there, the remedy of Table 8.1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..analysis.classification import classify
from ..limits import MAX_SIZE
from ..robot import Robot
from ..wheels import wrap_angle
from .points import ControlError, control_point
from .references import Reference, reference_from_samples

__all__ = ["COLUMNS", "Feasibility", "Requirement", "Violation", "feasibility", "requirement"]

_VEHICLE = "stop and re-orient the vehicle"
_WHEEL = "stop and re-orient the orientable wheel"
_WHEELS = "stop and re-orient the orientable wheels"
#: Table 8.1: column -> (pose references, kinematic signals, dynamic signals, remedy, footnote). The dynamic
#: framework of every column also needs the velocity continuous: the drive wheels' rates are proportional to the
#: speed, and the table's conditions on chi alone rest on (8.34) 'chi C1 => v_a C0', which a speed step on a line
#: (chi constant) contradicts. Its conditions include the kinematic ones (C1 is C0 too): a reference whose pose
#: jumps while its given derivatives stay smooth was 'feasible: yes' in the dynamic framework of types 1 and 2 off
#: the axle.
COLUMNS: dict[str, tuple[int, tuple[str, ...], tuple[str, ...], str]] = {
    "type 1": (3, ("position", "theta"), ("position", "theta", "velocity", "omega"),
               "the reference must be continuous"),
    "type 2, off axle": (2, ("position",), ("position", "velocity"), "the reference must be continuous"),
    "type 2, on axle": (2, ("position", "chi"), ("position", "chi", "velocity", "chi_rate"), _VEHICLE),
    "type 4, off axle": (2, ("position", "chi"), ("position", "chi", "velocity", "chi_rate"), _WHEEL),
    "type 4, on axle": (2, ("position", "chi", "kappa"), ("position", "chi", "velocity", "kappa", "kappa_rate"),
                        _WHEEL + " (both tangent and curvature jump: the vehicle, re-orienting the wheel twice)"),
    "types 3 and 5, l_o != 0": (3, ("position", "theta", "velocity", "omega"),
                                ("position", "theta", "velocity", "omega", "acceleration", "omega_rate"), _WHEELS),
    "type 3, l_o = 0": (3, ("position", "theta", "chi"), ("position", "theta", "chi", "velocity", "omega", "chi_rate"),
                        _WHEEL),
}
#: What each signal's continuity means in the thesis's words.
KINDS = {"position": "position jump (p_ref not C0)", "theta": "heading jump (theta_ref not C0)",
         "velocity": "velocity jump (p_ref not C1)", "omega": "heading-rate jump (theta_ref not C1)",
         "acceleration": "acceleration jump (p_ref not C2)",
         "omega_rate": "angular-acceleration jump (theta_ref not C2)", "chi": "tangent-angle jump (chi not C0)",
         "chi_rate": "turn-rate jump (chi not C1)", "kappa": "curvature jump (kappa not C0)",
         "kappa_rate": "curvature-rate jump (kappa not C1)"}


@dataclass(frozen=True)
class Requirement:
    """The Table 8.1 cell of a robot: ``column``, vehicle ``type``, number of pose ``references`` (2 or 3), the
    ``signals`` that must be continuous in the chosen ``framework``, and the ``remedy`` when one is not."""

    column: str
    type: int
    references: int
    framework: str
    signals: tuple[str, ...]
    remedy: str


@dataclass(frozen=True)
class Violation:
    """One discontinuity of the reference: time ``t`` [s], ``signal``, ``kind`` (text), ``size`` of the jump
    (m, rad, m/s, ... per signal), ``remedy``."""

    t: float
    signal: str
    kind: str
    size: float
    remedy: str

    def to_dict(self) -> dict[str, object]:
        """``{"t", "kind", "signal", "size", "remedy"}``."""
        return {"t": self.t, "kind": self.kind, "signal": self.signal, "size": self.size, "remedy": self.remedy}


@dataclass(frozen=True)
class Feasibility:
    """Result of :func:`feasibility`: ``feasible`` and the ``violations`` of ``requirement``."""

    requirement: Requirement
    violations: tuple[Violation, ...]

    @property
    def feasible(self) -> bool:
        """No violation: the reference is followed with zero error by ideal blocks from matching initial conditions."""
        return not self.violations

    def to_dict(self) -> dict[str, object]:
        """``{"feasible", "column", "type", "framework", "signals", "violations": [...]}`` (the CLI's JSON)."""
        r = self.requirement
        return {"feasible": self.feasible, "column": r.column, "type": r.type, "framework": r.framework,
                "signals": list(r.signals), "violations": [v.to_dict() for v in self.violations]}


def requirement(robot: Robot, framework: Literal["kinematic", "dynamic"] = "kinematic", *,
                point: tuple[float, float] | None = None) -> Requirement:
    """The Table 8.1 cell of `robot` tracked at `point` (default: its origin R, as in the thesis)."""
    if framework not in ("kinematic", "dynamic"):
        raise ControlError(f"framework must be 'kinematic' or 'dynamic', got {framework!r}")
    c = classify(robot)
    if c.type is None:
        raise ControlError(f"robot '{robot.name}' is degenerate ({'; '.join(c.reasons)}): Table 8.1 does not apply")
    p = np.zeros(2) if point is None else np.asarray(point, dtype=float)
    if p.shape != (2,) or not (np.abs(p) <= MAX_SIZE).all():  # NaN read as a point on the axle
        raise ControlError(f"point: expected (x, y), finite and within {MAX_SIZE:g} m of the robot origin, got "
                           f"{p.tolist()}")
    if c.type in (2, 4):
        on_axle = _on_axle(robot, p)
        column = f"type {c.type}, {'on' if on_axle else 'off'} axle"
    elif c.type == 1:
        column = "type 1"
    else:
        steered = [w for w in robot.wheels if w.type in ("steerable", "double")]
        away = any(np.hypot(*(np.asarray(w.position) - p)) > 1e-9 for w in steered)
        column = "types 3 and 5, l_o != 0" if (away or c.type == 5) else "type 3, l_o = 0"
    refs, kin, dyn, remedy = COLUMNS[column]
    return Requirement(column, c.type, refs, framework, kin if framework == "kinematic" else dyn, remedy)


def _on_axle(robot: Robot, p: np.ndarray) -> bool:
    """The point's velocity cannot be assigned in the admissible twist space: it lies on the fixed axle."""
    try:
        control_point(robot, (float(p[0]), float(p[1])), reduced=True)
    except ControlError:
        return True
    return False


def signals(reference: Reference, *, speed_tol: float = 1e-6, slow: float = 0.05) -> dict[str, np.ndarray]:
    """The sampled signals of `reference` ``(n,)`` each, and ``at_rest`` ``(n,)`` (speed at most `speed_tol`).

    ``chi`` and its rate, ``kappa`` and its rate are NaN at rest, where they are undefined, and the last three
    where the speed changes by more than `slow` (5 %) of itself in one sample step (``dt |v . a| / |v|^2``), ``chi``
    where by more than itself: a reference starting or stopping, where they come from ``v`` and ``a`` near zero
    and, for a sampled reference, from finite differences of positions that hardly move (a 3 m circle from rest at
    100 Hz had a curvature of 0 to 1.6 1/m over its first 0.15 s, and a tangent pointing backwards at its first
    sample). A constant-speed reference, or
    one with exact derivatives at a steady speed, has none of them undefined."""
    p, v, a = reference.pose, reference.velocity, reference.acceleration
    speed = np.hypot(v[:, 0], v[:, 1])
    t = reference.t
    at_rest = ~(speed > speed_tol)
    with np.errstate(invalid="ignore", divide="ignore"):
        change = np.gradient(t) * np.abs(v[:, 0] * a[:, 0] + v[:, 1] * a[:, 1])  # of the speed in a step
        # (times the speed), or to a neighbouring sample when larger: a file's finite differences at its last sample,
        # where it comes to rest, give a velocity of 1e-5 m/s across the path, square to its acceleration, whose
        # tangent was a 'tangent-angle jump' of a quarter turn
        change = np.maximum(change, speed * np.maximum(np.abs(np.diff(speed, prepend=speed[:1])),
                                                       np.abs(np.diff(speed, append=speed[-1:]))))
        steady = ~at_rest & (change <= slow * speed**2)
        chi = np.where(~at_rest & (change <= speed**2), np.arctan2(v[:, 1], v[:, 0]), np.nan)
        cross = v[:, 0] * a[:, 1] - v[:, 1] * a[:, 0]
        kappa = np.where(steady, cross / speed**3, np.nan) * _travel_sign(chi)
        chi_rate = np.where(steady, cross / speed**2, np.nan)
    return {"position": p[:, :2], "theta": p[:, 2], "velocity": v[:, :2], "omega": v[:, 2], "acceleration": a[:, :2],
            "omega_rate": a[:, 2],
            "chi": chi, "chi_rate": chi_rate, "kappa": kappa,
            "kappa_rate": np.gradient(kappa, t) * (t[1] - t[0]), "at_rest": at_rest}


def _travel_sign(chi: np.ndarray) -> np.ndarray:
    """+1, then -1 after each reversal of the direction of travel (the tangent ``atan2`` turning by more than a
    quarter turn between defined samples), so that the curvature is the path's, signed against the vehicle and not
    against its direction of travel: (8.41) divides by the signed speed. A car reversing along a curve keeps its
    steering; ``omega_g / v_a`` of (8.33) flipped sign there."""
    defined = np.flatnonzero(np.isfinite(chi))
    sign = np.ones(len(chi))
    if len(defined) > 1:
        flips = np.abs(wrap_angle(np.diff(chi[defined]))) > math.pi / 2
        sign[defined[1:]] = np.where(np.cumsum(flips) % 2, -1.0, 1.0)
        sign[: defined[0]] = 1.0
        sign = sign[np.maximum.accumulate(np.where(np.isfinite(chi), np.arange(len(chi)), 0))]
    return sign


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


def feasibility(robot: Robot, reference: Reference, framework: Literal["kinematic", "dynamic"] = "kinematic", *,
                point: tuple[float, float] | None = None, jump_factor: float = 20.0) -> Feasibility:
    """Check `reference` against the Table 8.1 cell of `robot` (§8.5): every discontinuity and its remedy.

    A jump is a step of a signal larger than `jump_factor` (> 1) times the typical step where it is (the median of
    its block of ``BLOCK`` steps, or of a neighbouring block when larger) and than a floor."""
    if not 1 < jump_factor < math.inf:  # NaN included: at 0 or NaN every step above the floor was a jump
        raise ControlError(f"jump_factor: expected a finite number > 1 (times the median step), got {jump_factor}")
    req = requirement(robot, framework, point=point)
    sig = signals(reference)
    dense = _curvature_reference(reference) if set(req.signals) & set(_CURVATURE) else None
    dense_sig = None if dense is None else signals(dense)
    found: list[Violation] = []
    seen: list[tuple[str, float, float]] = []  # (signal, from, to) of each jump reported or folded into another
    for name in req.signals:
        ref, s = (dense, dense_sig) if dense is not None and name in _CURVATURE else (reference, sig)
        x = s[name]
        if name == "kappa_rate":
            x = x / (ref.t[1] - ref.t[0])
        floor = _FLOOR[name]
        # a car (R on the fixed axle of a type 4) cannot turn at rest: its tangent is compared across a stop
        across = name == "chi" and req.column == "type 4, on axle"
        jumps = _jumps(x, ref.t, _TURN.get(name), floor, jump_factor, s["at_rest"], across)
        slow = []
        if req.column == "types 3 and 5, l_o != 0" and name in ("velocity", "omega"):
            slow = _slow_turns(robot, ref, point, x, jumps, jump_factor)
        for k, last, size in sorted(jumps + slow):
            if name == "kappa_rate" and not _persists(x, k, floor):
                continue  # ringing of a third finite difference, not a step of the curvature rate
            span = (name, float(ref.t[k]), float(ref.t[last + 1]))
            if _folded(span, seen):
                seen.append(span)
                continue  # the spike of a derivative where its signal steps: one discontinuity, reported once
            turns = None
            if req.column == "types 3 and 5, l_o != 0" and name in _STEERED:
                turns = (k, last, size) in slow or _steered_turn(robot, ref, point, k, last + 1, rate=_STEERED[name])
                if not turns and (req.framework == "kinematic" or _STEERED[name]):
                    continue  # the twist only scales (the same ICR): no steered wheel turns, only rates jump
            t = float(ref.t[k + 1])
            seen.append(span)
            if any(v.t == t and v.signal in ("chi", "position") for v in found) and name != "position":
                continue  # already reported by a lower-order signal at the same instant
            found.append(Violation(t, name, KINDS[name], size, _remedy(req, name, turns)))
    found.sort(key=lambda v: v.t)
    return Feasibility(req, tuple(found))


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


#: Signals from the normal acceleration (second differences of the positions, for a file), and the curvature rate
#: (a third), judged at a spacing where the rounding of the positions and times does not dominate them.
_CURVATURE = ("chi_rate", "kappa", "kappa_rate")
#: Rounding noise [1/(m s)] allowed in the curvature rate: 1/200 of its jump floor.
_RATE_NOISE = 1e-4


def _curvature_reference(reference: Reference) -> Reference | None:
    """The reference every few samples, re-differentiated, for the curvature signals when it is so dense that
    rounding dominates them; None when it is not.

    The second difference of positions rounded to ``eps L`` (``L`` their size, plus the distance covered in the
    rounding of the times) over a step ``h`` errs by about ``4 eps L / h^2``, its curvature by that over ``v^2`` and
    the curvature rate by that over ``h``: the step is the smallest multiple of the sample spacing that keeps the rate
    within :data:`_RATE_NOISE` at the typical moving speed ``v`` (a 3 m circle at 1 m/s sampled every 3 us had
    curvature-rate 'jumps' of 3 1/(m s) from rounding alone; it is judged every 0.6 ms, 200 samples)."""
    t, p = reference.t, reference.pose
    n = len(t)
    spacing = (t[-1] - t[0]) / (n - 1)
    speed = np.hypot(*reference.velocity[:: max(1, n // 10_000), :2].T)
    moving = speed[speed > 1e-6]
    if not len(moving):
        return None
    v = float(np.median(moving))
    size = float(np.abs(p[:, :2]).max()) + v * float(np.abs(t).max())
    h = (4 * np.finfo(float).eps * size / (v * v * _RATE_NOISE)) ** (1 / 3)
    step = int(min(math.ceil(h / spacing), (n - 1) // 4))
    if step <= 1:
        return None
    # the heading plays no part in these signals (and every few samples a spinning one may turn by more than half a
    # turn, which a file is refused for)
    return reference_from_samples(reference.name, t[::step], np.column_stack([p[::step, :2], np.zeros(len(t[::step]))]))


#: Signals of types 3 and 5 with some l_o != 0 that break Table 8.1 only where a steered wheel turns: its heading
#: (8.10) jumps with a velocity or heading-rate step (False), its steering rate with an acceleration step (True).
#: Where the twist only scales (the same ICR: a speed step or a trapezoidal profile on a line or a circle) every
#: steered wheel keeps its heading and its steering rate, and only spin rates (kinematic) or spin accelerations
#: (dynamic) jump, which each framework allows: the table's 'p_ref C1 / C2' is sufficient, not necessary.
_STEERED = {"velocity": False, "omega": False, "acceleration": True, "omega_rate": True}


#: Floor of a twist step below the usual one (m/s, rad/s) that may still turn a steered wheel: above the rounding of
#: a smooth reference's finite differences.
_SLOW_FLOOR = 1e-9


def _slow_turns(robot: Robot, reference: Reference, point: tuple[float, float] | None, x: np.ndarray,
                jumps: list[tuple[int, int, float]], factor: float) -> list[tuple[int, int, float]]:
    """The steps of the velocity or heading rate `x` under its floor (away from the `jumps` found above it) that turn
    a steered wheel (:func:`_steered_turns`). A steering angle is a state at any speed: a reference reversing its
    curvature at 0.01 m/s (a heading-rate step of 0.007 rad/s on a 3 m radius) turns a swerve robot's wheels by
    0.2 rad in a sample, and a corner at 0.01 m/s by a quarter turn; under the 0.02 floor of those signals both were
    'feasible: yes'. A wheel at rest on either side turns freely (its heading is undefined there)."""
    slow = [j for j in _jumps(x, reference.t, None, _SLOW_FLOOR, factor)
            if not any(j[0] <= b + 2 and a - 2 <= j[1] for a, b, _ in jumps)]
    if not slow:
        return []
    first, last = np.array([j[0] for j in slow]), np.array([j[1] + 1 for j in slow])
    turns = _steered_turns(robot, reference, point, first, last, rate=False)
    return [j for j, turn in zip(slow, turns, strict=True) if turn]


def _steered_turn(robot: Robot, reference: Reference, point: tuple[float, float] | None, before: int, after: int,
                  *, rate: bool) -> bool:
    """:func:`_steered_turns` of one pair of samples."""
    return bool(_steered_turns(robot, reference, point, np.array([before]), np.array([after]), rate=rate)[0])


def _steered_turns(robot: Robot, reference: Reference, point: tuple[float, float] | None, before: np.ndarray,
                   after: np.ndarray, *, rate: bool) -> np.ndarray:
    """Whether some steered wheel's heading (or, with `rate`, its steering rate) differs between samples `before`
    and `after` (arrays of sample indices, one answer each) of `reference`, tracked at `point`: the direction
    (modulo half a turn, a 2-quadrant root of (8.9)) of the wheel centre's velocity in the robot frame,
    ``u = R^T v + omega J d``, and its rate ``(u x u') / |u|^2`` with ``u' = R^T a - omega J R^T v + alpha J d``
    (``d`` the wheel from the point). A wheel at rest on either side turns freely there."""
    p = np.zeros(2) if point is None else np.asarray(point, dtype=float)
    d = np.array([w.position for w in robot.wheels if w.type in ("steerable", "double")]) - p
    out = []
    for k in (before, after):  # (samples, 1) against (wheels,)
        c, s = np.cos(reference.pose[k, 2])[:, None], np.sin(reference.pose[k, 2])[:, None]
        (vx, vy, w), (ax, ay, al) = reference.velocity[k].T[:, :, None], reference.acceleration[k].T[:, :, None]
        vrx, vry = c * vx + s * vy, -s * vx + c * vy
        ux, uy = vrx - w * d[:, 1], vry + w * d[:, 0]
        dux = c * ax + s * ay + w * vry - al * d[:, 1]
        duy = -s * ax + c * ay - w * vrx + al * d[:, 0]
        speed2 = ux**2 + uy**2
        with np.errstate(invalid="ignore", divide="ignore"):
            out.append((speed2, (ux * duy - uy * dux) / speed2 if rate else np.arctan2(uy, ux)))
    (s0, x0), (s1, x1) = out
    moving = (s0 > 1e-12) & (s1 > 1e-12)
    change = np.abs(x1 - x0) if rate else np.abs(_wrap(x1 - x0, math.pi))
    return np.any(moving & (change > _FLOOR["chi_rate" if rate else "chi"]), axis=1)


#: The rate signals, by name: a jump of one leaves every steering angle and the heading continuous (the wheels'
#: rates jump), unless a steered wheel turns with a velocity or heading-rate step of types 3 and 5 (``turns``).
_RATES = {"velocity": "velocity", "omega": "heading rate", "acceleration": "acceleration",
          "omega_rate": "angular acceleration", "chi_rate": "turn rate", "kappa_rate": "curvature rate"}


def _remedy(req: Requirement, signal: str, turns: bool | None = None) -> str:
    """What to do about a jump of `signal` for `req`: Table 8.1's re-orientation only where an angle the vehicle
    holds (a steering angle, or the heading of a vehicle tracked on its fixed axle) would jump."""
    if signal == "position":
        return "the reference jumps: no vehicle can follow it; the position loop removes the error afterwards"
    if signal == "theta":  # the pose jumps: no wheel's re-orientation follows it
        return "an error appears that the position loop then removes (kinematics allows no jump here)"
    if req.column == "type 4, on axle" and signal == "chi":
        return (f"{_VEHICLE}, re-orienting the orientable wheel twice (tangent and curvature both jump)")
    if req.column == "type 4, on axle" and signal == "kappa":
        return _WHEEL
    if signal in _RATES and not (turns and signal in ("velocity", "omega")):
        if signal in ("velocity", "omega"):
            return (f"the {_RATES[signal]} steps (the wheels' rates would jump, which the dynamic framework "
                    "forbids): an error appears that the position loop then removes")
        # the angles stay continuous, their rates step: at rest on both sides every rate is 0 (the rates are the
        # speed times their rate along the path)
        return (f"the {_RATES[signal]} steps (the wheels' rates would jump, which the dynamic framework forbids; the "
                "angles do not): slow to rest there, or an error appears that the position loop then "
                "removes")
    return req.remedy
