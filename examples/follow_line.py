"""Vision line following (thesis §9.2): a simulated camera in the loop of a differential robot and of a Mecanum one.

Every period T = 0.5 s the synthetic camera renders what the robot sees, the painted line is extracted from the
image (Hough transform and a robust fit), the robot's heading psi and distance h to the line come out of
(9.10)-(9.11), and the command computed from them reaches the wheels one period later. The thesis's robot
(``line-follower``: a differential drive, tracked point 0.39 m ahead of its axle) starts 0.3 m left of the line at
0.1 m/s. With a = 0.3 1/s it approaches without overshoot; with a = 0.8 1/s the delay makes it overshoot. The
camera-in-the-loop runs are compared with the same runs measuring the exact (psi, h) (the thesis's simulation),
and a holonomic robot, whose lateral error obeys ``h[k+1] = h[k] - a T h[k-1]`` exactly (§9.2.3), checks the
whole image path against that recursion. Run: ``python examples/follow_line.py [DIR]`` (the first camera image
with the line found, into DIR, default a temporary folder; needs ``pip install 'wmrkit[vision]'``, OpenCV).
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.vision import Camera, follow_line
from wmrkit.vision.animation import save_detection_figure

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="wmrkit-vision-"))
out_dir.mkdir(parents=True, exist_ok=True)
# focal length 150 px, tilted 60 deg from the vertical, 0.3 m high, 320 x 240 image (docs/figures/vision/)
camera = Camera(150.0, math.radians(60), 0.3, 320, 240)
follower = catalog.load("line-follower")
PERIOD = 0.5  # [s] one image per period

for gain in (0.3, 0.8):
    run = follow_line(follower, camera, gain=gain, period=PERIOD, start=(0.0, 0.3, 0.0), keep_images=gain == 0.3)
    exact = follow_line(follower, camera, gain=gain, period=PERIOD, start=(0.0, 0.3, 0.0), from_image=False)
    summary = run.to_dict()
    print(f"line-follower, a = {gain} 1/s: h {run.lateral[0] * 100:.0f} cm -> {run.lateral[-1] * 100:.2f} cm in "
          f"{run.time[-1]:.0f} s, overshoot {summary['overshoot'] * 100:.2f} cm, 95 % settling "
          f"{run.settling_time():.1f} s, images lost {summary['lost_images']}; exact measurements give "
          f"h within {np.max(np.abs(run.lateral - exact.lateral)) * 1e3:.2f} mm of it")
    if run.images:
        save_detection_figure(camera, run.images[0], out_dir / "follow-line-first-image.png", title="t = 0")

# a Mecanum robot keeps its heading: its lateral error follows the delayed recursion exactly
gain = 0.8
run = follow_line(catalog.load("mecanum-4"), camera, gain=gain, period=PERIOD, start=(0.0, 0.3, 0.0))
h = run.lateral
recursion = [h[0], h[0] * (1 - gain * PERIOD)]  # the first two periods both use the image taken at the start
for _ in range(len(h) - 2):
    recursion.append(recursion[-1] - gain * PERIOD * recursion[-2])
print(f"mecanum-4, a = {gain} 1/s, camera in the loop: final h {h[-1] * 1e3:.3f} mm; largest departure from "
      f"h[k+1] = h[k] - a T h[k-1]: {np.max(np.abs(h - recursion)) * 1e3:.3f} mm")
print(f"figure in {out_dir}")
