"""Closed-loop tracking with the forklift of thesis ch. 8: the P law, its closed form, and the plant with tyres.

``wmrkit.control.track`` closes the loop of Fig. 8.1 for any robot: a position law (8.2) turns the reference and
the measured pose into a twist, the per-wheel inverse kinematics (§8.4) into steering headings and wheel spins,
and a plant moves the robot. The forklift is rear-steered with a fixed drive axle, so the point controlled is its
origin, the fork tips, 1 m ahead of the axle (§8.3). Starting 0.5 m off a circle of radius 3 m, the ideal loop
makes the fork tips' error exactly ``0.5 exp(-a t)`` (checked below), and a PI law (8.3) its critically damped
solution; through the chapter-7 dynamics (Pacejka tyres, wheel servos, a 50 Hz controller) the tyres' slip leaves
about a millimetre. Run: ``python examples/track_forklift.py [DIR]`` (a plot of the last run into DIR, default a
temporary folder; the first run of the dynamic plant compiles it, which can take a minute).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.control import builtin_reference, track
from wmrkit.control.plots import plot_run

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="wmrkit-track-"))
out_dir.mkdir(parents=True, exist_ok=True)
forklift = catalog.load("forklift")
circle = builtin_reference("circle", speed=0.5, size=3.0, duration=20.0)  # radius 3 m at 0.5 m/s
GAIN = 1.0  # the pole a [1/s] of each controlled coordinate
start = [0.0, 0.5, 0.0]  # fork tips 0.5 m to the left of the reference's start, heading along x

# 1. P + feedforward, continuous time, ideal joints: the error is e(0) exp(-a t), exactly
run = track(forklift, circle, controller="p", gain=GAIN, initial_pose=start)
closed_form = run.error[0] * np.exp(-GAIN * run.t)
print(f"P law:  error {run.error[0]:.2f} m -> {run.error[-1]:.1e} m after {run.t[-1]:.0f} s; "
      f"largest departure from 0.5 exp(-a t): {np.max(np.abs(run.error - closed_form)):.1e} m")
heading = np.degrees(run.heading[:, 0])
print(f"        steered wheel between {heading.min():.1f} and {heading.max():.1f} deg (0 = straight ahead), "
      f"drive spins up to {np.max(np.abs(run.commands.spin)):.2f} rad/s")

# 2. PI + feedforward (8.3), integral gain b = a^2/4 by default: a double pole at -a/2, so from rest the error is
#    e(0) (1 - a t/2) exp(-a t/2): it crosses the reference once, at t = 2/a, and decays more slowly
pi = track(forklift, circle, controller="pi", gain=GAIN, initial_pose=start)
pi_form = np.abs(pi.error[0] * (1 - GAIN * pi.t / 2) * np.exp(-GAIN * pi.t / 2))
print(f"PI law: error {pi.error[-1]:.1e} m at the end; largest departure from its closed form "
      f"{np.max(np.abs(pi.error - pi_form)):.1e} m")

# 3. the same P law at 50 Hz through the Lagrange dynamics with tyres: the tyres slip, the loop corrects it
dyn = track(forklift, circle, controller="p", gain=GAIN, initial_pose=start, dynamics=True, period=0.02)
tail = dyn.error[dyn.t >= 10.0]
print(f"dynamics: final error {dyn.error[-1] * 1e3:.2f} mm, at most {tail.max() * 1e3:.2f} mm after t = 10 s "
      f"(kinematic loop: {run.error[-1] * 1e3:.1e} mm)")
plot_run(dyn, out_dir / "track-dynamics.png")  # path, error and steering against time
print(f"plot in {out_dir}")
