"""Parallel parking (thesis §9.3): plan, check the parked car against the slot by hand, and drive the plan.

The planner of ``wmrkit.parking`` drives past the parked cars, reverses in an S to the approach point and then
makes manoeuvres of two equal circular arcs, backward and forward, until the car is as close to the curb as asked.
Here it plans the thesis's two examples (Tables 9.1 and 9.2: 2 and 4 manoeuvres). The parked pose is checked
independently: the car's four corners, computed here from its pose and dimensions, must lie in the slot (between
the parked cars at x = -H and x = 0, between the curb at y = -J and the road at y = 0). Then the plan is driven by
the car's kinematic model, open loop and with the thesis's P law (8.2), and a slot too short shows the shortest
one that works. Run: ``python examples/park_car.py [DIR]`` (figures into DIR, default a temporary folder;
``pip install 'wmrkit[parking]'`` for the exact collision check with shapely).
"""

from __future__ import annotations

import math
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from wmrkit import WmrkitError
from wmrkit.parking import plan_parking, shortest_slot
from wmrkit.parking.execute import execute_plan
from wmrkit.parking.plot import save_plan_figure
from wmrkit.parking.problem import load_problem
from wmrkit.parking.verify import check_plan

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="wmrkit-park-"))
out_dir.mkdir(parents=True, exist_ok=True)


def corners(vehicle, pose):
    """The body's corners (4, 2) [m] at P_f's pose (rear-axle midpoint; a1 ahead of it, b1 behind, c1 wide)."""
    x, y, theta = pose
    body = np.array([[vehicle.a1, vehicle.c1 / 2], [vehicle.a1, -vehicle.c1 / 2],
                     [-vehicle.b1, -vehicle.c1 / 2], [-vehicle.b1, vehicle.c1 / 2]])
    rotation = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    return np.array([x, y]) + body @ rotation.T


for name in ("thesis-9.1", "thesis-9.2"):
    problem = load_problem(name)
    car, slot = problem.vehicle, problem.space
    plan = plan_parking(car, slot)
    print(f"{name}: car {car.length:.2f} x {car.c1:.2f} m in a {slot.H:.2f} x {slot.J:.2f} m slot: "
          f"{plan.maneuvers} manoeuvres, final gap to the curb {plan.final_gap * 100:.1f} cm "
          f"(asked: below {slot.final_gap * 100:.0f} cm)")
    for arc in plan.arcs:
        print(f"    {'backward' if arc.direction < 0 else 'forward ':8} radius {arc.rho:6.3f} m, "
              f"arc {math.degrees(arc.xi):5.2f} deg, gap after {arc.gap_after * 100:5.1f} cm")
    c = corners(car, plan.final_pose)
    inside = bool(np.all((c[:, 0] >= -slot.H) & (c[:, 0] <= 0) & (c[:, 1] >= -slot.J) & (c[:, 1] <= 0)))
    print(f"    parked corners inside the slot: {inside}; gap to the curb from the corners "
          f"{(c[:, 1].min() + slot.J) * 100:.1f} cm, heading {math.degrees(plan.final_pose[2]):.2f} deg")
    try:
        report = check_plan(car, slot, plan.segments)
        print(f"    exact check (shapely) over {len(report.poses)} poses: collision-free {report.collision_free}")
    except WmrkitError as error:  # the 'parking' extra (shapely) is not installed
        print(f"    exact check skipped: {error}")
    driven = execute_plan(plan)  # open loop: inverse kinematics, wheel rates back to a twist, exact integration
    print(f"    driven open loop in {driven.duration:.1f} s: P_f at most {driven.deviation.max():.1e} m off the plan")
    save_plan_figure(plan, out_dir / f"park-{name}.png", execution=driven)

first = load_problem("thesis-9.1")
plan = plan_parking(first.vehicle, first.space)
driven = execute_plan(plan, controller="p", gain=1.0)  # wmrkit.control.track on the steering axle's midpoint
print(f"thesis-9.1 with the P law (a = 1/s): P_f at most {driven.deviation.max() * 100:.2f} cm off the plan, "
      f"parked {np.hypot(*(driven.pose[-1, :2] - plan.final_pose[:2])) * 100:.2f} cm from the planned pose")
short = replace(first.space, H=2.6, dx2=0.9)
print(f"thesis-9.1's car in a {short.H} m slot: {plan_parking(first.vehicle, short).reason}; "
      f"shortest slot that works: {shortest_slot(first.vehicle, short):.3f} m")
print(f"figures in {out_dir}")
