"""Parking benchmark: median planning time per slot of the thesis's planner (§9.3; target < 0.25 ms, the thesis
reports 0.44 and 1.3 ms on 2007 hardware) against a Reeds-Shepp planner (rsplan) on the same slots in the same run.

Slots: example 1's car (Table 9.1) and example 2's (Table 9.2) in slots of random length, width and pass offset.
Reeds-Shepp is timed from the same start (the end of the detection pass) to the same goal (the thesis planner's
final pose, or the slot's centre line when it finds none). Each call is timed alone; the median is reported.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from wmrkit.parking import plan_parking
from wmrkit.parking.geometry import Space, Vehicle

from ._harness import Result, peer

CAR_91 = Vehicle(a1=1.50, b1=0.50, c1=1.40, h1=1.05, track=0.50, phi_max=math.radians(46))
SLOT_91 = Space(H=3.35, J=2.00, MS=0.20, dx2=0.70, final_gap=0.07)
CAR_92 = Vehicle(a1=0.75, b1=0.15, c1=3.50, h1=0.60, track=1.30, phi_max=math.radians(46))
SLOT_92 = Space(H=3.30, J=3.60, MS=0.12, dx2=0.17, final_gap=0.17)


def slots(n: int) -> list[tuple[Vehicle, Space]]:
    """`n` random slots around the thesis's two examples (fixed seed)."""
    rng = np.random.default_rng(12)
    out = []
    for k in range(n):
        car, slot = (CAR_91, SLOT_91) if k % 2 == 0 else (CAR_92, SLOT_92)
        out.append((car, replace(slot, H=slot.H * rng.uniform(0.95, 1.4), J=slot.J * rng.uniform(1.0, 1.2),
                                 dx2=car.c1 / 2 + rng.uniform(0.0, 0.6))))
    return out


def _median_call(fn, items, repeat: int) -> float:
    times = []
    for item in items:
        best = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            fn(*item)
            best = min(best, time.perf_counter() - t0)
        times.append(best)
    return float(np.median(times))


def run(quick: bool) -> list[Result]:
    """Median per-slot planning time, thesis planner vs rsplan."""
    n = 100 if quick else 1000
    cases = slots(n)
    ours = _median_call(lambda car, slot: plan_parking(car, slot), cases, repeat=5)
    feasible = sum(plan_parking(car, slot).feasible for car, slot in cases)
    rs = peer("rsplan.planner")
    peer_s = None
    if rs is not None:
        goals = []
        for car, slot in cases:
            plan = plan_parking(car, slot)
            start = next(s.start for s in plan.segments if s.phase >= 2) if plan.feasible else (0.0, slot.dx2, 0.0)
            goal = plan.final_pose if plan.feasible else (-slot.H / 2, -slot.J + car.c1 / 2, 0.0)
            goals.append((tuple(start), tuple(goal), car.rho_min))
        peer_s = _median_call(lambda s, g, r: rs.path(s, g, r, 0.0, 0.05), goals, repeat=5)
    met = "met" if ours < 0.25e-3 else "NOT met"
    print(f"   median per slot: thesis planner {ours * 1e3:.4f} ms ({feasible}/{n} feasible), "
          f"rsplan {'ABSENT' if peer_s is None else f'{peer_s * 1e3:.4f} ms'}; target < 0.25 ms: {met}")
    if peer_s is not None:
        print(f"   ratio rsplan / thesis planner: {peer_s / ours:.1f}x")
    return [Result("parking plan, median per slot x slots", n, ours * n, "rsplan.planner.path",
                   None if peer_s is None else peer_s * n, f"median < 0.25 ms per slot: {met}")]
