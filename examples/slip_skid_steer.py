"""Skid-steer odometry with tyre slip: the no-slip model, the effective-track fudge and calibrated WLS.

A Husky-like robot (the catalog's ``skid-steer-4``: four fixed wheels, 50 kg, Dugoff tyres) drives segments of
body twists ``(duration [s], v [m/s], omega [rad/s])``: its wheels turn at the no-slip rates of each twist and the
robot moves as its tyres let it (the quasi-static slip model of ``wmrkit.slip``; docs/slip.md's table uses the
full dynamic model, slower to start). A skid steer turns by scrubbing its tyres sideways, so odometry that assumes
rolling overestimates every turn. Two one-parameter models are fitted to one run with a reference trajectory (what
``wmrkit calibrate`` does) and judged on runs they were not fitted to: ROS's effective track
(``wheel_separation_multiplier`` m) and WLS with the ratio k of lateral to longitudinal slip weights. On a
symmetric skid steer with wheels at (+-a, +-b) they are one model, m = 1 + k (a/b)^2 (docs/slip.md), and give
the same poses. Run: ``python examples/slip_skid_steer.py [DIR]`` (plots into DIR, default a temporary folder).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.odometry.pipeline import odometry
from wmrkit.odometry.plot import save_trajectory_plot
from wmrkit.slip.calibration import calibrate_slip, effective_track_model
from wmrkit.slip.skid import segment_run
from wmrkit.slip.weights import SlipWeights, wls_model

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="wmrkit-skid-"))
out_dir.mkdir(parents=True, exist_ok=True)
robot = catalog.load("skid-steer-4")
a = max(abs(w.position[0]) for w in robot.wheels)  # half wheelbase [m]
b = max(abs(w.position[1]) for w in robot.wheels)  # half track [m]
RATE = 50.0  # log samples per second

# calibration: arcs both ways and a straight, logged with the true poses as reference (the quasi-static slip model)
calibration = ((4.0, 1.0, 0.4), (2.0, 1.0, 0.0), (4.0, 1.0, -0.4), (3.0, 1.0, 0.8))
log, truth = segment_run(robot, calibration, RATE, source="quasi-static")
fit = calibrate_slip(robot, log, (log.time, truth))
print(f"fitted: WLS ratio k = {fit.ratio:.4f}, effective track m = {fit.multiplier:.4f} "
      f"(1 + k (a/b)^2 = {1 + fit.ratio * (a / b) ** 2:.4f} with a = {a:.3f} m, b = {b:.3f} m)")

models = {"no slip": wls_model(robot),  # unweighted least squares: every wheel rolls
          "effective track": effective_track_model(robot, fit.multiplier),
          "WLS": wls_model(robot, SlipWeights.uniform(fit.ratio, 1.0))}
runs = {"calibration run": calibration,
        "tight loop": ((9.0, 1.0, 1.2),),  # not fitted: faster turn than any of the calibration run
        "slalom": ((2.0, 1.0, 0.6), (2.0, 1.0, -0.6)) * 3}
print(f"{'RMS position error [m]':<24}" + "".join(f"{name:>17}" for name in models) + "   WLS vs track, max")
for run_name, segments in runs.items():
    log, truth = segment_run(robot, segments, RATE, source="quasi-static")
    paths = {"truth": truth}
    errors = []
    for label, model in models.items():
        paths[label] = odometry(model, log).poses
        d = np.hypot(*(paths[label][:, :2] - truth[:, :2]).T)
        errors.append(np.sqrt(np.mean(d * d)))
    gap = np.max(np.hypot(*(paths["WLS"][:, :2] - paths["effective track"][:, :2]).T))
    print(f"{run_name:<24}" + "".join(f"{e:>17.4f}" for e in errors) + f"{gap:>19.1e}")
    save_trajectory_plot(out_dir / f"skid-{run_name.replace(' ', '-')}.png", paths, title=f"skid steer: {run_name}")
print(f"plots in {out_dir}")
