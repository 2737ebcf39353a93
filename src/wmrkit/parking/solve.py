"""One call answering a parking question: the plan, its planning time, and for an impossible slot why and the
shortest slot that works; optionally the exact collision check. What ``wmrkit park`` prints."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

from .geometry import blackburn_min_length, length_ratio
from .path import direction_changes, path_length, sample_poses
from .planner import ParkingPlan, plan_parking, shortest_slot
from .problem import ParkingProblem
from .verify import CollisionReport, check_plan


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

    def to_dict(self, pose_step: float = 0.05) -> dict[str, Any]:
        """``{"maneuvers", "feasible", "reason", "path", "poses", "wall_time", ...}``; SI units, steering as
        headings (the equivalent front wheel's, 0 = straight ahead); poses of P_f every `pose_step` [m]."""
        p, v, sp = self.plan, self.problem.vehicle, self.problem.space
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


def describe_check(report: CollisionReport, what: str = "exact check") -> str:
    """One line: `what` (N poses): collision-free or how many poses hit what, inside the slot, min clearance."""
    c = report
    return (f"{what} ({len(c.poses)} poses): "
            f"{'collision-free' if c.collision_free else f'{c.n_collisions} poses hit the {c.what}'}, "
            f"{'ends inside the slot' if c.inside else 'does NOT end inside the slot'}, "
            f"min clearance {c.min_clearance * 100:.2f} cm")


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
    """The text ``wmrkit park`` prints without ``--json``."""
    p, sp, v = solution.plan, solution.problem.space, solution.problem.vehicle
    lines = [f"problem {solution.problem.name}: slot {sp.H:.4g} x {sp.J:.4g} m, car {v.length:.4g} x {v.c1:.4g} m "
             f"(length ratio {100 * length_ratio(v, sp):.1f} %)"]
    lines += [f"warning: {w}" for w in p.warnings]
    if p.feasible:
        changes = direction_changes(p.segments)
        lines.append(f"feasible: {_count(p.maneuvers, 'manoeuvre')}, final gap to the curb {p.final_gap * 100:.1f} "
                     f"cm, path {path_length(p.segments):.2f} m, {_count(changes, 'direction change')}, "
                     f"planned in {1e3 * solution.wall_time:.3f} ms")
        if p.used_H is not None:
            lines.append(f"parks in the {p.used_H:.4g} m of the slot behind the front car (the planner's best part "
                         "of a long slot; it needs no more)")
        lines.append(f"approach point: dx1 = {p.dx1:.4g} m from the parked cars' side, pass {p.dy3:.4g} m past "
                     "the front one")
        for k, a in enumerate(p.arcs, 1):
            lines.append(f"  {k:2d} {'forward ' if a.direction > 0 else 'backward'} radius {a.rho:8.3f} m  "
                         f"xi {math.degrees(a.xi):6.2f} deg  lateral {a.X * 100:6.1f} cm  "
                         f"gap {a.gap_after * 100:6.1f} cm")
    else:
        lines.append(f"infeasible: {p.reason}")
        if solution.shortest_H is not None:
            lines.append(f"shortest slot that works (all else equal): H = {solution.shortest_H:.3f} m"
                         + (" (park in that much of this slot)" if solution.shortest_H < sp.H else ""))
        else:
            lines.append("no slot length works with this width, car and approach")
    if solution.check is not None:
        lines.append(describe_check(solution.check))
    return "\n".join(lines)
