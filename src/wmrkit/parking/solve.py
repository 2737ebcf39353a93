"""One call answering a parking question: the plan, its planning time, and for an impossible slot why and the
shortest slot that works; optionally the exact collision check. What ``wmrkit park`` prints."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

from .geometry import Vehicle, blackburn_min_length, length_ratio
from .path import direction_changes, path_length, sample_poses
from .planner import ParkingPlan, plan_parking, shortest_slot, size
from .problem import ParkingProblem
from .verify import CollisionReport, check_plan

#: Spacing of the JSON answer's poses, in car sizes (:func:`~.planner.size`, the car's larger dimension).
POSE_STEP = 0.025


@dataclass(frozen=True, eq=False)
class Solution:
    """``plan``; ``wall_time`` the planning time (median of `repeat` runs) [s]; ``shortest_H`` [m] the shortest
    slot length that works when the plan is infeasible (None when feasible or when no length works);
    ``check`` the exact collision check (None unless asked)."""

    problem: ParkingProblem
    plan: ParkingPlan
    wall_time: float
    shortest_H: float | None
    check: CollisionReport | None

    def to_dict(self, pose_step: float | None = None) -> dict[str, Any]:
        """``{"maneuvers", "feasible", "reason", "path", "poses", "wall_time", ...}``; SI units, steering as
        headings (the equivalent front wheel's, 0 = straight ahead); poses of P_f every `pose_step` [m] (default
        :data:`POSE_STEP` car sizes: 5 cm for example 1's 2 m car; a fixed 5 cm gave a 2 mm car's path as its
        segment ends alone)."""
        p, v, sp = self.plan, self.problem.vehicle, self.problem.space
        pose_step = POSE_STEP * size(v) if pose_step is None else pose_step
        out: dict[str, Any] = {
            "problem": self.problem.name, "maneuvers": p.maneuvers, "feasible": p.feasible, "reason": p.reason,
            "warnings": list(p.warnings), "wall_time": self.wall_time,
            "length_ratio": length_ratio(v, sp), "blackburn_min_H": blackburn_min_length(v),
            "shortest_H": self.shortest_H, "used_H": p.used_H,
            "approach": {"dx1": _defined(p.dx1), "dy3": _defined(p.dy3), "pass_offset": p.pass_offset},
            "final_gap": _defined(p.final_gap), "path_length": path_length(p.segments),
            "direction_changes": direction_changes(p.segments),
            "arcs": [{"direction": "forward" if a.direction > 0 else "backward", "radius": a.rho, "xi": a.xi,
                      "X": a.X, "Y": a.Y, "gap_after": a.gap_after} for a in p.arcs],
            "path": [s.to_dict() for s in p.segments],
            "poses": sample_poses(p.segments, pose_step).tolist() if p.segments else [],
        }
        if self.check is not None:
            out["check"] = check_dict(self.check)
        return out


def _defined(value: float) -> float | None:
    """A plan's quantity, or None where the plan does not define it (NaN: an infeasible problem has no approach
    point and no final gap)."""
    return None if math.isnan(value) else value


def check_dict(report: CollisionReport) -> dict[str, Any]:
    """An exact check as JSON: ``collision_free``, ``colliding_poses``, ``first_hit``, ``min_clearance`` [m],
    ``inside_slot``, ``poses_checked``."""
    return {"collision_free": report.collision_free, "colliding_poses": report.n_collisions,
            "first_hit": report.what or None, "min_clearance": report.min_clearance, "inside_slot": report.inside,
            "poses_checked": len(report.poses)}


#: The units of the text answer by the car's size: (least size [m], unit, its metres, small unit, its metres).
#: The numbers print at the car's scale: a 2 mm copy of example 1 printed 'final gap to the curb 0.0 cm'.
UNITS = ((0.063, "m", 1.0, "cm", 0.01), (6.3e-5, "mm", 1e-3, "um", 1e-6), (0.0, "um", 1e-6, "nm", 1e-9))


def units(vehicle: Vehicle) -> tuple[str, float, str, float]:
    """``(unit, its metres, small unit, its metres)`` of the text answer for `vehicle`: metres and centimetres
    for a car from 6.3 cm up (example 1's as ever), millimetres and micrometres below, then micrometres and
    nanometres (the JSON stays SI, full precision)."""
    return next(u[1:] for u in UNITS if max(vehicle.length, vehicle.c1) >= u[0])


def describe_check(report: CollisionReport, what: str = "exact check", vehicle: Vehicle | None = None) -> str:
    """One line: `what` (N poses): collision-free or how many poses hit what, inside the slot, min clearance (in
    the small unit of :func:`units`, centimetres without `vehicle`)."""
    c = report
    small, f = ("cm", 0.01) if vehicle is None else units(vehicle)[2:]
    return (f"{what} ({len(c.poses)} poses): "
            f"{'collision-free' if c.collision_free else f'{c.n_collisions} poses hit the {c.what}'}, "
            f"{'ends inside the slot' if c.inside else 'does NOT end inside the slot'}, "
            f"min clearance {c.min_clearance / f:.2f} {small}")


def solve(problem: ParkingProblem, *, check: bool = False, search: bool = True, repeat: int = 5) -> Solution:
    """Plan `problem`, time it, search the shortest working slot if it fails (`search`), check it (`check`)."""
    times = []
    plan = plan_parking(problem.vehicle, problem.space)
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        plan = plan_parking(problem.vehicle, problem.space)
        times.append(time.perf_counter() - t0)
    shortest = None
    if not plan.feasible and search:
        shortest = shortest_slot(problem.vehicle, problem.space)
    report = check_plan(problem.vehicle, problem.space, plan.segments) if check and plan.feasible else None
    return Solution(problem, plan, sorted(times)[len(times) // 2], shortest, report)


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")


def describe(solution: Solution) -> str:
    """The text ``wmrkit park`` prints without ``--json`` (the plan's ``warnings`` apart: the command says them on
    stderr, as every command's)."""
    p, sp, v = solution.plan, solution.problem.space, solution.problem.vehicle
    big, m, small, cm = units(v)
    lines = [f"problem {solution.problem.name}: slot {sp.H / m:.4g} x {sp.J / m:.4g} {big}, car {v.length / m:.4g} x "
             f"{v.c1 / m:.4g} {big} "
             f"(length ratio {100 * length_ratio(v, sp):.1f} %)"]
    if p.feasible:
        changes = direction_changes(p.segments)
        lines.append(f"feasible: {_count(p.maneuvers, 'manoeuvre')}, final gap to the curb {p.final_gap / cm:.1f} "
                     f"{small}, path {path_length(p.segments) / m:.2f} {big}, {_count(changes, 'direction change')}, "
                     f"planned in {1e3 * solution.wall_time:.3f} ms")
        if p.used_H is not None:
            lines.append(f"parks in the {p.used_H / m:.4g} {big} of the slot behind the front car (the planner's best "
                         "part of a long slot; it needs no more)")
        lines.append(f"approach point: dx1 = {p.dx1 / m:.4g} {big} from the parked cars' side, pass "
                     f"{p.dy3 / m:.4g} {big} past the front one")
        for k, a in enumerate(p.arcs, 1):
            lines.append(f"  {k:2d} {'forward ' if a.direction > 0 else 'backward'} radius {a.rho / m:8.3f} {big}  "
                         f"xi {math.degrees(a.xi):6.2f} deg  lateral {a.X / cm:6.1f} {small}  "
                         f"gap {a.gap_after / cm:6.1f} {small}")
    else:
        lines.append(f"infeasible: {p.reason}")
        if solution.shortest_H is not None:
            lines.append(f"shortest slot that works (all else equal): H = {solution.shortest_H / m:.3f} {big}"
                         + (" (park in that much of this slot)" if solution.shortest_H < sp.H else ""))
        else:
            lines.append("no slot length works with this width, car and approach")
    if solution.check is not None:
        lines.append(describe_check(solution.check, vehicle=v))
    return "\n".join(lines)
