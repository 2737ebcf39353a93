"""Design by isotropy (thesis ch. 5, future work 2): sweep an omni robot's geometry and check the best design.

The condition number kappa (5.28) of the map from the body twist ``(vx, vy, D omega)`` to the wheel rates says how
evenly a robot transmits motion and errors in every direction: 1 is isotropic, infinite is singular. Here the
three-wheel omni robot (``omni-3``, a kiwi drive) is redesigned: its front-left wheel moves around the body
(angle ``alpha``, its rolling direction ``beta`` turned with it) and the back wheel in or out (distance ``l``).
``wmrkit.batch.sweep`` evaluates every design of the grid vectorised, with the characteristic length D chosen per
design (serially here: no Dask cluster needed). The best designs are then rebuilt by hand from the description and
checked with the per-robot analysis functions, and the winner is the symmetric kiwi drive, kappa 1.
Run: ``python examples/design_sweep.py [DIR]`` (the sweep's map into DIR, default a temporary folder).
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from wmrkit import Robot, catalog
from wmrkit.analysis import classify, natural_length, twist_condition_number
from wmrkit.batch import parse_vary, sweep
from wmrkit.batch.sweep import plot_sweep

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="wmrkit-sweep-"))
out_dir.mkdir(parents=True, exist_ok=True)
omni = catalog.load("omni-3")
D0, KAPPA0 = natural_length(omni)  # the D minimising kappa, and that kappa
print(f"{omni.name}: type {classify(omni).type}, kappa at its natural length D = {D0:.4f} m: {KAPPA0:.6f}")

# alpha and beta of wheel 0 move together from 30 to 90 deg (13 values), the back wheel's l from 0.15 to 0.25 m
axes = [parse_vary("wheels[0].alpha,wheels[0].beta=30deg:90deg:13", omni),
        parse_vary("wheels.back.l=0.15:0.25:11", omni)]
ALPHA, BACK_L = (axis.label for axis in axes)  # the keys of each design's row
result = sweep(omni, axes, "kappa_mean", top=3)
print(f"{result.total} designs in {result.wall_time:.2f} s; the best three:")
for row in result.best:
    print(f"  alpha = beta = {math.degrees(row[ALPHA]):4.1f} deg, back l = {row[BACK_L]:.3f} m: "
          f"kappa {row['kappa_mean']:.6f} at D = {row['length']:.4f} m")
plot_sweep(result, out_dir / "sweep-omni-3.png")


def design(alpha: float, back_l: float) -> Robot:
    """omni-3 with wheel 0 at angle alpha (its beta too) and the back wheel at distance back_l, from its description."""
    data = omni.to_dict(thesis=True)  # the thesis's l, alpha, beta, which the sweep varies
    data["wheels"][0].update(alpha=alpha, beta=alpha)
    next(w for w in data["wheels"] if w["name"] == "back")["l"] = back_l
    return Robot.from_dict(data, source="design")


# the sweep against the per-robot functions, on its best designs and on its worst (result.grid: every design)
i, j = np.unravel_index(np.argmax(result.grid), result.grid.shape)
worst = {ALPHA: axes[0].values[i], BACK_L: axes[1].values[j], "kappa_mean": result.grid[i, j]}
for row in (*result.best, worst):
    robot = design(row[ALPHA], row[BACK_L])
    length, kappa = natural_length(robot)  # minimises kappa over D
    check = float(twist_condition_number(robot, length=length))
    print(f"  rebuilt: alpha {math.degrees(row[ALPHA]):4.1f} deg, l {row[BACK_L]:.3f} m: kappa {kappa:.6f} "
          f"at D = {length:.4f} m (twist_condition_number {check:.6f}); the sweep's: {row['kappa_mean'] - kappa:+.1e}")
print(f"figure in {out_dir}")
