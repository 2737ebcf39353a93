"""Shared helpers of the parking tests: the thesis's cars and an independent corner geometry."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from wmrkit.parking.geometry import Space, Vehicle

#: Tables 9.1 and 9.2 typed in here (independently of the shipped problem files).
CAR_91 = Vehicle(a1=1.50, b1=0.50, c1=1.40, h1=1.05, track=0.50, phi_max=math.radians(46))
SLOT_91 = Space(H=3.35, J=2.00, MS=0.20, dx2=0.70, final_gap=0.07)
CAR_92 = Vehicle(a1=0.75, b1=0.15, c1=3.50, h1=0.60, track=1.30, phi_max=math.radians(46))
SLOT_92 = Space(H=3.30, J=3.60, MS=0.12, dx2=0.17, final_gap=0.17)


def corners_world(vehicle: Vehicle, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x, y)`` ``(N, 4)`` of the body corners rear-right, front-right, front-left, rear-left at P_f's poses,
    by plain rigid-body transformation (no planner code)."""
    body = np.array([(-vehicle.b1, -vehicle.c1 / 2), (vehicle.a1, -vehicle.c1 / 2), (vehicle.a1, vehicle.c1 / 2),
                     (-vehicle.b1, vehicle.c1 / 2)])
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    x = poses[:, None, 0] + c[:, None] * body[:, 0] - s[:, None] * body[:, 1]
    y = poses[:, None, 1] + s[:, None] * body[:, 0] + c[:, None] * body[:, 1]
    return x, y


def arc_poses(start, direction: int, curvature: float, length: float, n: int = 4000) -> np.ndarray:
    """P_f's poses along a constant-curvature stretch, from the unicycle ODE solved in closed form by hand."""
    x0, y0, th0 = start
    s = np.linspace(0.0, length, n + 1) * direction
    th = th0 + curvature * s
    if curvature == 0:
        return np.column_stack([x0 + s * math.cos(th0), y0 + s * math.sin(th0), th])
    r = 1 / curvature
    return np.column_stack([x0 + r * (np.sin(th) - math.sin(th0)), y0 - r * (np.cos(th) - math.cos(th0)), th])


def scaled(car: Vehicle, slot: Space, s: float) -> tuple[Vehicle, Space]:
    """`car` and `slot` with every length multiplied by `s` (angles kept)."""
    return (replace(car, a1=car.a1 * s, b1=car.b1 * s, c1=car.c1 * s, h1=car.h1 * s, track=car.track * s),
            replace(slot, H=slot.H * s, J=slot.J * s, MS=slot.MS * s, dx2=slot.dx2 * s, final_gap=slot.final_gap * s))

#: A car whose approach point, 1.559 m wide slot, needs Algorithm 3 to lower the steering for the curb; from 1.8 m
#: the curb no longer does, the front obstacle's corner puts the approach point 0.9 m out, and Algorithm 4 cannot
#: reach it from the 0.57 m pass: the thesis's planner has no plan.
WIDE_CAR = Vehicle(a1=3.4382196736820223, b1=0.8614207508747462, c1=1.0384271766264899, h1=2.2398390573335183,
                   track=0.8307417413011919, phi_max=0.6473252632996291)
WIDE_SLOT = Space(H=5.507194104501224, J=1.559457498490115, MS=0.05624681031140825, dx2=0.5674678760290668,
                   final_gap=0.05)
