"""The thesis's planner against a Reeds-Shepp planner (``rsplan``, optional) on the same slots.

Both start where phase 2 starts (the end of the detection pass) and end at the same pose (the thesis planner's
final pose, or the slot's centre line at the desired gap when it finds none); the Reeds-Shepp path is the
shortest for the minimum turning radius and ignores obstacles, so the exact check (:mod:`.verify`) decides
whether it is usable. Both are timed the same way (median of repeated calls).
"""

from __future__ import annotations

import math
import numbers
import time
from dataclasses import dataclass

import numpy as np

from ..errors import WmrkitError
from .geometry import Space, Vehicle
from .path import direction_changes, path_length
from .planner import plan_parking
from .verify import check_count, check_plan, check_poses


@dataclass(frozen=True, slots=True)
class Outcome:
    """One planner on one slot: ``found`` a path, ``success`` found, collision-free and inside the slot,
    ``length`` [m] of P_f's path (from the end of the pass), ``cusps`` direction changes, ``time_ms`` planning
    time (median), ``colliding`` sampled poses that overlap an obstacle or the curb (exact check)."""

    planner: str
    found: bool
    success: bool
    length: float
    cusps: int
    time_ms: float
    colliding: int


def _median_ms(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def rsplan_module():
    """Import ``rsplan`` (a peer library, not a dependency), or a :class:`WmrkitError` saying how to get it."""
    try:
        import rsplan.planner
    except ImportError:
        raise WmrkitError("the Reeds-Shepp comparison needs rsplan: pip install rsplan") from None
    return rsplan.planner


def compare(vehicle: Vehicle, space: Space, *, repeat: int = 5, step: float = 0.005) -> tuple[Outcome, Outcome]:
    """``(thesis, reeds_shepp)`` outcomes on one slot. `step` [m]: spacing of the Reeds-Shepp poses checked (at
    most :data:`.verify.MAX_CHECK_POSES` of them); `repeat` (an integer >= 1) runs of each planner timed."""
    # step = 0 raised OverflowError, -1 IndexError, NaN ValueError, 1e-7 made 3e7 poses before the check's bound;
    # repeat = 0 timed nothing and gave NaN times
    if not 0 < step < math.inf:
        raise WmrkitError(f"step: must be a finite length > 0 m, got {step!r}")
    if isinstance(repeat, bool) or not isinstance(repeat, numbers.Integral) or repeat < 1:
        raise WmrkitError(f"repeat: must be an integer >= 1, got {repeat!r}")
    rs = rsplan_module()
    plan = plan_parking(vehicle, space)
    ours_ms = _median_ms(lambda: plan_parking(vehicle, space), repeat)
    if plan.feasible:
        moving = [s for s in plan.segments if s.phase >= 2]
        report = check_plan(vehicle, space, moving)
        ours = Outcome("thesis §9.3", True, report.collision_free and report.inside, path_length(moving),
                       direction_changes(moving), ours_ms, report.n_collisions)
        start = moving[0].start
        goal = plan.final_pose
    else:
        ours = Outcome("thesis §9.3", False, False, math.nan, 0, ours_ms, 0)
        start = (0.0, plan.pass_offset, 0.0)
        free = space.effective_length - vehicle.length
        goal = (-space.H + space.MS + vehicle.b1 + max(free, 0.0) / 2,
                -space.J + vehicle.c1 / 2 + space.final_gap / 2, 0.0)
    rho = vehicle.rho_min

    def solve():
        return rs.path(tuple(start), tuple(goal), rho, 0.0, step)

    rs_ms = _median_ms(solve, repeat)
    path = solve()
    check_count(1 + path.total_length / step)  # its waypoints are made on demand: count them first
    poses = np.array([w.pose_2d_tuple for w in path.waypoints()])
    report = check_poses(vehicle, space, poses)
    theirs = Outcome("Reeds-Shepp (rsplan)", True, report.collision_free and report.inside,
                     float(path.total_length), int(path.number_of_cusp_points), rs_ms, report.n_collisions)
    return ours, theirs
