"""The parallel-parking planner of the thesis (§9.3.2): Algorithms 3, 4 and 5 and the three phases (Fig. 9.17).

:func:`plan_parking` is the one call: detection pass (phase 1), a reverse S to the approach point (phase 2), then
alternating backward/forward manoeuvres of two symmetric arcs (phase 3) until the lateral gap to the curb is
below the desired one. Every loop is bounded; an impossible slot gets ``feasible=False`` and the reason
(:func:`shortest_slot` then searches the length that works). The ambiguities of the printed algorithms are
resolved as in ``docs/errata.md`` (§9.3 entries). World frame and poses: :mod:`wmrkit.parking.path`.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, replace
from typing import Literal

from .._shapes import as_real
from ..errors import WmrkitError
from .collisions import approach_offset_closed_form, front_rear_collision, lateral_reach, trailing_dip
from .geometry import (
    Space,
    Vehicle,
    arcs_displacement,
    arcs_through,
    blackburn_min_length,
    check_problem,
    steering_angle,
    xi_from_lateral,
    xi_from_longitudinal,
)
from .path import Pose, Segment, arc_end, path_length

#: Default decrement of the steering angle in Algorithm 3 (the thesis does not say; 1 deg reproduces §9.3.3).
PHI_STEP = math.radians(1.0)
#: Resolution and range of the pass-end search of Algorithm 4 (its Delta dy3 and the bound the thesis lacks), in
#: units of the car's larger dimension (:func:`size`; 1 cm and 5 m for example 1's 2 m car): in metres, a 2 mm
#: car searched 2500 car lengths past the front car in steps of 5 car lengths, and a 2 km car a fraction of its
#: length.
DY3_STEP, DY3_RANGE = 1 / 200, 2.5
#: Default bound on the number of manoeuvres (Fig. 9.30 shows 21 at a 20 % length ratio).
MAX_MANEUVERS = 100
#: Step of the part lengths :func:`best_part` tries [car lengths], and the most it tries.
PART_STEP, MAX_PARTS = 1 / 200, 400
#: Where a plan failed (``ParkingPlan.failed_at``): the slot's size, Algorithm 3's approach point, Algorithm 4's pass
#: to it, phase 3's manoeuvres; "" for a plan.
FailedAt = Literal["", "slot", "approach", "pass", "maneuvers"]
#: Geometric tolerance of the stopping and inside-the-slot tests, in units of :func:`size` (1e-9 m measured a
#: 2 mm car to 5e-7 of its length and a 2 km one to 5e-13, at the rounding of its coordinates).
TOL = 1e-9
#: Most steering angles Algorithm 3 tries (``phi_max / phi_step``): each costs ~5 us, and phi_step = 1e-12 rad
#: meant 6e11 tries, days of looping.
MAX_PHI_STEPS = 100_000


@dataclass(frozen=True, slots=True)
class Maneuver:
    """One symmetric-arc manoeuvre of phase 3: ``direction`` (+1 forward, -1 backward), radius ``rho`` [m],
    arc angle ``xi`` [rad], lateral ``X`` and longitudinal ``Y`` displacement (9.31) [m], gap to the curb after it."""

    direction: int
    rho: float
    xi: float
    X: float
    Y: float
    gap_after: float


@dataclass(frozen=True, slots=True)
class ParkingPlan:
    """Result of :func:`plan_parking`. Frozen.

    ``feasible`` and ``reason`` (empty when feasible); ``maneuvers`` the phase-3 manoeuvres (the first backward
    one included: the thesis's count); ``segments`` the whole path (phases 1-3) as stop-to-stop segments;
    ``arcs`` the manoeuvres' geometry; ``dx1`` the approach point's lateral offset of P_f from the obstacles'
    side line, ``dy3`` how far the pass runs past the front obstacle, ``pass_offset`` the lateral offset of the
    pass actually driven [m]; ``final_gap`` the final gap to the curb [m]; ``warnings`` input adjustments;
    ``used_H`` the length of the part of the slot behind the front obstacle the car parks in, when it is not
    the whole slot [m] (:func:`plan_parking`); ``failed_at`` the stage that failed (:data:`FailedAt`).
    """

    vehicle: Vehicle
    space: Space
    feasible: bool
    reason: str
    maneuvers: int
    segments: tuple[Segment, ...]
    arcs: tuple[Maneuver, ...]
    dx1: float
    dy3: float
    pass_offset: float
    final_gap: float
    warnings: tuple[str, ...] = ()
    used_H: float | None = None
    failed_at: FailedAt = ""

    @property
    def final_pose(self) -> Pose:
        """P_f's pose at the end of the path (world frame of :mod:`wmrkit.parking.path`)."""
        return self.segments[-1].end if self.segments else (math.nan, math.nan, math.nan)


def plan_parking(vehicle: Vehicle, space: Space, *, phi_step: float = PHI_STEP,
                 max_maneuvers: int = MAX_MANEUVERS) -> ParkingPlan:
    """Plan a parallel parking manoeuvre (thesis §9.3.2, Algorithms 1-5); never loops without bound.

    `phi_step` [rad] is Algorithm 3's steering decrement (at least ``phi_max / MAX_PHI_STEPS``); `max_maneuvers`
    (an integer >= 1) bounds phase 3. A slot up to :func:`roomy_length` gets :func:`plan_thesis`'s plan when it
    has one; otherwise, and in any longer slot, the car parks in the part of the slot behind the front obstacle
    where the thesis's planner does best (:func:`best_part`): a plan there is a plan in the whole slot, whose
    rear obstacle only lies farther back. Algorithm 3 reverses along the whole slot, so a long slot meant a long,
    shallow S and, past about 11 car lengths, no plan at all.
    """
    check_problem(vehicle, space)
    phi_step = _check_options(vehicle, phi_step, max_maneuvers)
    roomy = roomy_length(vehicle, space)
    plan = None
    if space.H <= roomy:
        plan = plan_thesis(vehicle, space, phi_step=phi_step, max_maneuvers=max_maneuvers)
        if plan.failed_at == "pass":
            plan = _gentler_first(vehicle, space, plan, phi_step, max_maneuvers)
        if plan.feasible:
            return plan
    part = best_part(vehicle, space, min(space.H, roomy), phi_step, max_maneuvers)
    if part is None:
        return plan if plan is not None else plan_thesis(vehicle, space, phi_step=phi_step,
                                                         max_maneuvers=max_maneuvers)
    return _in_slot(part, space)


def _gentler_first(vehicle: Vehicle, space: Space, failed: ParkingPlan, phi_step: float,
                   max_maneuvers: int) -> ParkingPlan:
    """`failed` (Algorithm 4 cannot reach Algorithm 3's approach point) retried with the first manoeuvre steering
    less: the plan of the largest smaller angle whose approach point Algorithm 4 reaches (feasible, or failing for
    another reason), else `failed`. Algorithm 3 lowers the steering while the curb sweep needs the approach point
    beyond the pass, not while the front obstacle's corner (Algorithm 2) does: a wider slot, whose curb no longer
    forced a gentler angle, had no plan where a narrower one had."""
    for skip in range(1, math.ceil(vehicle.phi_max / phi_step)):
        plan = plan_thesis(vehicle, space, phi_step=phi_step, max_maneuvers=max_maneuvers, skip_angles=skip)
        if plan.failed_at != "pass":  # a plan, or no approach point at all from here on, or phase 3 fails
            return plan if plan.failed_at in ("", "maneuvers") else failed  # phase 3 got further
    return failed


def plan_thesis(vehicle: Vehicle, space: Space, *, phi_step: float = PHI_STEP,
                max_maneuvers: int = MAX_MANEUVERS, skip_angles: int = 0) -> ParkingPlan:
    """The thesis's planner as printed (with its errata) on the whole slot: the first backward manoeuvre reverses
    from the approach point to ``MS`` from the rear obstacle (Algorithm 3), whatever the slot's length.
    `skip_angles` > 0 starts Algorithm 3 that many steps of `phi_step` below ``phi_max`` (not the thesis's:
    :func:`plan_parking`'s retry)."""
    v, sp = vehicle, space
    phi_step = _check_options(v, phi_step, max_maneuvers)
    tol = TOL * size(v)
    warnings: list[str] = []
    pass_offset = sp.dx2
    if sp.dx2 < v.c1 / 2 - tol:  # (not "70 cm" against "140 cm" / 2 in floating point)
        pass_offset = v.c1 / 2 + sp.MS
        warnings.append(f"dx2 = {sp.dx2:.4g} m puts the car over the parked cars (c1/2 = {v.c1 / 2:.4g} m); "
                        f"the detection pass is driven at c1/2 + MS = {pass_offset:.4g} m")
    fail = _failure(v, sp, pass_offset, warnings)
    free = sp.effective_length - v.length  # phase-3 longitudinal travel (Alg. 5, erratum: H' - (a1 + b1))
    if free <= tol:
        return fail("slot", f"the slot is too short: H - 2 MS = {sp.effective_length:.4g} m leaves no room for a "
                    f"car of length a1 + b1 = {v.length:.4g} m")
    if sp.J < v.c1:
        return fail("slot", f"the slot is narrower (J = {sp.J:.4g} m) than the car (c1 = {v.c1:.4g} m)")
    first = approach_point(v, sp, pass_offset, phi_step, skip_angles)
    if first is None:
        span = first_reach(v, phi_step)
        if sp.H - sp.MS - v.b1 > span:
            return fail("approach", "the slot is longer than the first backward manoeuvre can span: Algorithm 3 "
                        f"reverses along the whole slot, at most 2 rho = {span:.4g} m at the smallest steering angle "
                        "tried")
        return fail("approach", "no steering angle lets the first backward manoeuvre enter the slot without touching "
                    "the curb, the rear obstacle or the front obstacle (Algorithm 3)")
    rho1, xi1, dx1 = first
    if abs(dx1 - pass_offset) <= tol:
        dx1 = pass_offset
    pre = pass_end(v, dx1, pass_offset)
    if pre is None and dx1 < pass_offset:  # the rear corner would cut the obstacle's corner: approach farther out
        dx1 = min(pass_offset, dx1 + lead_overshoot(v, dx1, pass_offset))
        pre = pass_end(v, dx1, pass_offset)
    if pre is None:
        return fail("pass", f"from a pass at {pass_offset:.4g} m the approach point at {dx1:.4g} m cannot be reached "
                    f"without touching the front obstacle (Algorithm 4 within {DY3_RANGE * size(v):.4g} m); pass "
                    "farther out")
    dy3, rho2, xi2 = pre

    segments: list[Segment] = []
    start: Pose = (-sp.H - v.a1, pass_offset, 0.0)
    segments.append(_straight(v, 1, 0, start, dy3 - start[0]))
    if dx1 != pass_offset:
        segments += _symmetric_arcs(v, 2, 0, segments[-1].end, -1, 1 if dx1 > pass_offset else -1, rho2, xi2)
    approach: Pose = (0.0, dx1, 0.0)
    X1, Y1, _ = arcs_displacement(rho1, xi1)
    segments += _symmetric_arcs(v, 3, 1, approach, -1, -1, rho1, xi1)
    y = dx1 - X1
    arcs = [Maneuver(-1, rho1, xi1, X1, Y1, y + sp.J - v.c1 / 2)]
    direction = 1
    while True:
        gap = y + sp.J - v.c1 / 2
        if gap < sp.final_gap and y + v.c1 / 2 <= tol:
            break
        if len(arcs) >= max_maneuvers:
            return fail("maneuvers", f"more than {max_maneuvers} manoeuvres needed (gap to the curb still {gap:.4g} m)")
        step = maneuver_arcs(v, free, y + sp.J, direction)
        if step is None:
            return fail("maneuvers", f"no manoeuvre gets closer to the curb (gap {gap:.4g} m) without touching it")
        rho, xi = step
        X, Y, _ = arcs_displacement(rho, xi)
        segments += _symmetric_arcs(v, 3, len(arcs) + 1, _end(segments), direction, -1, rho, xi)
        y -= X
        arcs.append(Maneuver(direction, rho, xi, X, Y, y + sp.J - v.c1 / 2))
        direction = -direction
    return ParkingPlan(v, sp, True, "", len(arcs), tuple(segments), tuple(arcs), dx1, dy3, pass_offset,
                       y + sp.J - v.c1 / 2, tuple(warnings))


def approach_point(vehicle: Vehicle, space: Space, pass_offset: float, phi_step: float = PHI_STEP,
                   skip: int = 0) -> tuple[float, float, float] | None:
    """Algorithm 3: ``(rho, xi, dx1)`` of the first backward manoeuvre from the approach point, or None.

    The steering angle starts at ``phi_max`` and drops by `phi_step` (bounded: at most ``phi_max / phi_step``
    tries) while the travel ``D_y = H - MS - b1`` exceeds ``2 rho`` ((9.31)b has no solution: erratum) or the
    P1 sweep would need the approach point beyond the pass (step 7). A rear overshoot (Algorithm 1 with P3) sets
    ``rho = c1/2``. ``dx1`` is the more restrictive of the curb sweep (9.33) and Algorithm 2, at least ``c1/2``.
    The first `skip` angles are not tried (0: the thesis).
    """
    v, sp = vehicle, space
    d_y = sp.H - sp.MS - v.b1
    tries = math.ceil(v.phi_max / phi_step)
    for k in range(skip, tries):
        phi = v.phi_max - k * phi_step
        rho = v.h1 / math.tan(phi)
        xi = xi_from_longitudinal(d_y, rho)
        if xi is not None and front_rear_collision(v, rho, xi, 3):
            rho = v.c1 / 2
            xi = xi_from_longitudinal(d_y, rho)
        if xi is None:
            continue
        sweep = lateral_reach(v, rho, xi, 1) - sp.J
        corner = approach_offset_closed_form(v, rho, xi)
        corner = -math.inf if corner is None else corner
        if sweep > corner:
            if sweep > pass_offset:
                continue
            dx1 = sweep
        else:
            dx1 = corner
        if not math.isfinite(dx1):
            return None
        return rho, xi, max(dx1, v.c1 / 2)
    return None


def pass_end(vehicle: Vehicle, dx1: float, pass_offset: float) -> tuple[float, float, float] | None:
    """Algorithm 4: ``(dy3, rho, xi)`` of the reverse S from the end of the pass to the approach point, or None.

    ``X = |dx1 - pass_offset|``; the shortest S uses ``rho_min`` (``xi <= 90 deg``: for ``X > 2 rho_min`` the
    radius grows to ``X / 2``). The check (with its printed branches swapped back) is exact for the front
    obstacle: moving toward it, the leading rear corner's reach (9.33) must stay on the road side of the
    obstacle's side line, which it crosses exactly at the obstacle's face; moving away, the trailing front
    corner's swing in the first arc (:func:`trailing_dip`) must fit in the pass's clearance. The printed loop
    ``dy3 += Delta`` may never end (the overshoot only tends to 0); here it is a bisection over a bounded range.
    """
    v = vehicle
    tol = TOL * size(v)
    X = abs(dx1 - pass_offset)
    if X <= tol:
        return 0.0, math.inf, 0.0

    def arcs(dy3: float) -> tuple[float, float]:
        return arcs_through(X, dy3)

    def clear(rho: float, xi: float) -> bool:
        if dx1 < pass_offset:
            return lateral_reach(v, rho, xi, 1) <= pass_offset + tol
        return trailing_dip(v, rho, xi, 2) <= pass_offset - v.c1 / 2 + tol

    lo, rho, xi = shortest_s(v, X)
    if clear(rho, xi):
        return lo, rho, xi
    hi = lo + DY3_RANGE * size(v)
    if not clear(*arcs(hi)):
        return None
    while hi - lo > DY3_STEP * size(v):
        mid = 0.5 * (lo + hi)
        if clear(*arcs(mid)):
            hi = mid
        else:
            lo = mid
    return (hi, *arcs(hi))


def shortest_s(vehicle: Vehicle, X: float) -> tuple[float, float, float]:
    """``(Y, rho, xi)`` of the shortest reverse S shifting P_f by ``X`` (9.31)a with ``rho_min``, ``xi <= 90 deg``."""
    rho = vehicle.rho_min
    xi = xi_from_lateral(X, rho) if X < 2 * rho else None
    if xi is None:
        rho, xi = X / 2, math.pi / 2
    return 2 * rho * math.sin(xi), rho, xi


def lead_overshoot(vehicle: Vehicle, dx1: float, pass_offset: float) -> float:
    """How far the leading rear corner crosses the obstacles' side line on the longest S Algorithm 4 tries [m].

    Moving toward the obstacles (``dx1 < pass_offset``) with ``dx1`` near ``c1/2`` the corner's overshoot only
    tends to 0 as the S lengthens; moving the approach point out by this much makes the longest S clear.
    """
    X = pass_offset - dx1
    rho, xi = arcs_through(X, shortest_s(vehicle, X)[0] + DY3_RANGE * size(vehicle))
    return max(0.0, lateral_reach(vehicle, rho, xi, 1) - pass_offset) + TOL * size(vehicle)


def maneuver_arcs(vehicle: Vehicle, free: float, room: float, direction: int) -> tuple[float, float] | None:
    """Algorithm 5: ``(rho, xi)`` of a phase-3 manoeuvre with longitudinal travel `free` and lateral `room`.

    `room` (W_max) is P_f's distance to the curb; the leading outer corner (P2 forward, P1 backward) must stay
    within it (9.33). ``rho = max(rho_min, c1/2)`` (Algorithm 1), ``xi`` from (9.31)b (for ``free > 2 rho`` the
    radius grows to ``free / 2``, ``xi = 90 deg``); when the corner would pass the curb, ``rho`` grows until the
    reach equals `room` (a root in ``rho``; it exists iff ``room > c1/2``). None when no manoeuvre fits.
    """
    v = vehicle
    corner = 2 if direction > 0 else 1
    rho = max(v.rho_min, v.c1 / 2)
    if free > 2 * rho:
        rho = free / 2
    xi = xi_from_longitudinal(free, rho) or 0.0

    def excess(r: float) -> float:
        return lateral_reach(v, r, math.asin(min(1.0, free / (2 * r))), corner) - room

    if excess(rho) <= 0:
        return rho, xi
    if room <= v.c1 / 2 + TOL * size(v):
        return None
    lo, hi = rho, 2 * rho
    for _ in range(200):  # the reach tends to c1/2 as rho grows, so a bracket exists
        if excess(hi) <= 0:
            break
        lo, hi = hi, 2 * hi
    else:
        return None
    f_lo, f_hi = excess(lo), excess(hi)
    for _ in range(100):  # Illinois false position, keeping the feasible end `hi`
        mid = hi - f_hi * (hi - lo) / (f_hi - f_lo)
        if not lo < mid < hi:
            mid = 0.5 * (lo + hi)
        f_mid = excess(mid)
        if f_mid <= 0:
            hi, f_hi = mid, f_mid
            f_lo *= 0.5
        else:
            lo, f_lo = mid, f_mid
            f_hi *= 0.5
        if hi - lo <= 1e-9 * hi:
            break
    return hi, math.asin(free / (2 * hi))


def first_reach(vehicle: Vehicle, phi_step: float = PHI_STEP) -> float:
    """How far [m] Algorithm 3's first backward manoeuvre can reach along the slot: ``2 rho`` at the smallest
    steering angle it tries (``phi_max`` down in steps of `phi_step`); a slot longer than ``MS + b1`` plus this
    cannot be entered so."""
    smallest = vehicle.phi_max - (math.ceil(vehicle.phi_max / phi_step) - 1) * phi_step
    return 2 * vehicle.h1 / math.tan(smallest) if smallest > 0 else math.inf


def shortest_slot(vehicle: Vehicle, space: Space, *, step: float = 0.01, span: float | None = None,
                  max_maneuvers: int = MAX_MANEUVERS) -> float | None:
    """The shortest slot length ``H`` [m] for which :func:`plan_parking` succeeds, the rest of `space` kept.

    Scans upward from ``a1 + b1 + 2 MS`` in steps of `step` over `span` (default ten car lengths, at least 10 m;
    never beyond the longest slot Algorithm 3 can enter, :func:`first_reach`; at most 2000 steps: the step grows
    for huge cars), then bisects the last step to 1 mm. None when no length in the range works (e.g. the slot is
    too narrow).
    """
    check_problem(vehicle, space)
    step, span = as_real(step, "step"), None if span is None else as_real(span, "span")  # '1': a bare TypeError
    for name, value in (("step", step), ("span", span)):
        if value is not None and not 0 < value < math.inf:  # NaN included
            raise WmrkitError(f"{name}: must be a finite length > 0 m, got {value}")
    _check_max_maneuvers(max_maneuvers)
    lo = vehicle.length + 2 * space.MS
    span = max(10.0, 10 * vehicle.length) if span is None else span
    span = min(span, space.MS + vehicle.b1 + first_reach(vehicle) - lo)  # feasible slots are not monotonic in H:
    if span <= 0:  # a coarse step over lengths no plan can enter would jump over the ones that work
        return None
    step = max(step, span / 2000)

    def works(h: float) -> bool:  # plan_parking's shortest slot is plan_thesis's: its parts are such slots
        return plan_thesis(vehicle, replace(space, H=h), max_maneuvers=max_maneuvers).feasible

    n = math.ceil(span / step)
    prev = lo
    for k in range(1, n + 1):
        h = lo + k * step
        if works(h):
            while h - prev > 1e-3:
                mid = 0.5 * (prev + h)
                prev, h = (prev, mid) if works(mid) else (mid, h)
            return h
        prev = h
    return None


def size(vehicle: Vehicle) -> float:
    """The car's larger dimension, ``max(a1 + b1, c1)`` [m]: the unit of the planner's search steps and
    tolerances, so that a car and its slot scaled together plan the same manoeuvres, scaled."""
    return max(vehicle.length, vehicle.c1)


def roomy_length(vehicle: Vehicle, space: Space) -> float:
    """A slot length [m] past which the car never needs more of the slot: twice Blackburn's shortest
    one-manoeuvre slot (:func:`~wmrkit.parking.geometry.blackburn_min_length`) plus the two margins. Beyond it
    :func:`plan_parking` parks in the best part of the slot up to this length."""
    return 2 * blackburn_min_length(vehicle) + 2 * space.MS


def best_part(vehicle: Vehicle, space: Space, upto: float, phi_step: float = PHI_STEP,
              max_maneuvers: int = MAX_MANEUVERS) -> ParkingPlan | None:
    """The best :func:`plan_thesis` plan in a slot of length ``H <= upto`` (the part of `space` behind the front
    obstacle), or None: fewest manoeuvres, then the shortest path after the detection pass, then the shortest
    part. The lengths tried are ``a1 + b1 + 2 MS + k step`` with a step of ``PART_STEP`` car lengths (at most
    ``MAX_PARTS`` of them up to :func:`roomy_length`); they do not depend on `upto` or ``space.H``, so a longer
    slot tries every length a shorter one does. The plan keeps the part's slot (see :func:`plan_parking`)."""
    lo = vehicle.length + 2 * space.MS
    step = max(vehicle.length * PART_STEP, (roomy_length(vehicle, space) - lo) / MAX_PARTS)
    best, best_key = None, None
    for k in range(1, MAX_PARTS + 2):
        H = lo + k * step
        if H > upto:
            break
        plan = plan_thesis(vehicle, replace(space, H=H), phi_step=phi_step, max_maneuvers=max_maneuvers)
        if plan.feasible:
            rank = (plan.maneuvers, path_length([s for s in plan.segments if s.phase > 1]), H)
            if best_key is None or rank < best_key:
                best, best_key = plan, rank
    return best


def _in_slot(part: ParkingPlan, space: Space) -> ParkingPlan:
    """`part` (a plan in the front part of `space`) as a plan in `space`: the detection pass from the whole
    slot's start, ``used_H`` the part's length."""
    v, first = part.vehicle, part.segments[0]
    start: Pose = (-space.H - v.a1, first.start[1], 0.0)
    detection = _straight(v, 1, 0, start, first.end[0] - start[0])
    return replace(part, space=space, segments=(detection, *part.segments[1:]), used_H=part.space.H)


def _check_options(vehicle: Vehicle, phi_step: float, max_maneuvers: object) -> float:
    """`phi_step` as a float, or :class:`WmrkitError` naming it (or `max_maneuvers`)."""
    phi_step = as_real(phi_step, "phi_step")  # the Python API reads no units: '1' raised a bare TypeError
    if not vehicle.phi_max / MAX_PHI_STEPS <= phi_step < math.inf:  # NaN included
        raise WmrkitError(f"phi_step: must be a finite angle >= phi_max / {MAX_PHI_STEPS} = "
                          f"{vehicle.phi_max / MAX_PHI_STEPS:.3g} rad (at most {MAX_PHI_STEPS} steering angles "
                          f"tried), got {phi_step} rad")
    _check_max_maneuvers(max_maneuvers)
    return phi_step


def _check_max_maneuvers(max_maneuvers: object) -> None:
    if isinstance(max_maneuvers, bool) or not isinstance(max_maneuvers, numbers.Integral) or max_maneuvers < 1:
        raise WmrkitError(f"max_maneuvers: must be an integer >= 1, got {max_maneuvers!r}")


def _failure(v: Vehicle, sp: Space, pass_offset: float, warnings: list[str]):
    def fail(stage: FailedAt, reason: str) -> ParkingPlan:
        return ParkingPlan(v, sp, False, reason, 0, (), (), math.nan, math.nan, pass_offset, math.nan,
                           tuple(warnings), failed_at=stage)

    return fail


def _end(segments: list[Segment]) -> Pose:
    end = segments[-1].end
    return (end[0], end[1], 0.0)  # parallel at every stop between manoeuvres (exact up to rounding)


def _straight(v: Vehicle, phase: int, maneuver: int, start: Pose, distance: float) -> Segment:
    direction = 1 if distance >= 0 else -1
    length = abs(distance)
    return Segment(phase, maneuver, direction, 0.0, length, 0.0, start, arc_end(start, direction, 0.0, length))


def _symmetric_arcs(v: Vehicle, phase: int, maneuver: int, start: Pose, direction: int, side: int,
                    rho: float, xi: float) -> list[Segment]:
    """Two arcs of angle `xi`, radius `rho`, opposite curvature, displacing toward `side` (+1 left, -1 right)."""
    out = []
    pose = start
    for kappa in (side / rho, -side / rho):
        end = arc_end(pose, direction, kappa, rho * xi)
        out.append(Segment(phase, maneuver, direction, kappa, rho * xi, steering_angle(v.h1, kappa), pose, end))
        pose = end
    return out
