"""Positioning from a 640 x 480 camera image (thesis §9.2.1): extraction, (9.10)-(9.11), against naive baselines.

Target (issue "vision"): under 5 ms per image on this machine. Baselines measured in the same run on the same
images: the threshold + per-row centroid script users copy (binarise, centroid of each row's bright pixels, a
line fitted through the centroids; one line only, no clutter rejection), and the thesis's own robot, about 4
positionings per second (250 ms, §9.2.3; a fixed figure, not re-measured). Images: a single painted line with
noise and clutter (what a line follower sees), and three crop rows. Times are the best of several calls after a
warm-up call.
"""

from __future__ import annotations

import math

import numpy as np

from wmrkit.vision.camera import Camera
from wmrkit.vision.follow import locate_image
from wmrkit.vision.positioning import locate_points
from wmrkit.vision.render import Scene, render

from ._harness import Result, best_time

THESIS_S = 0.25  # "en torno a los cuatro posicionamientos por segundo" (§9.2.3)
TARGET_S = 5e-3


def centroid_script(camera: Camera, image: np.ndarray) -> tuple[float, float]:
    """The student script: threshold, centroid per row, least-squares line, then (9.10)-(9.11)."""
    mask = image > 128
    rows = np.flatnonzero(mask.any(axis=1))
    xs = np.array([np.flatnonzero(mask[r]).mean() for r in rows])
    cx, cy = camera.centre
    slope, x0 = np.polyfit(rows - cy, xs - cx, 1)
    a = camera.rows / 4
    fix = locate_points(camera, [(0, [[x0 - slope * a, -a], [x0 + slope * a, a]])])
    return fix.psi, fix.h


def run(quick: bool) -> list[Result]:
    cam = Camera(300.0, math.radians(60), 0.3, 640, 480)
    pose = (0.0, 0.08, math.radians(8))
    single = render(cam, pose, Scene(ns=(0,), width=0.03), noise=5.0, clutter=8, seed=1)
    crops_cam = Camera(545.0, math.radians(76), 1.42, 640, 480)
    crops = render(crops_cam, (0.0, -0.05, 0.01), Scene(ns=(-2, -1, 0, 1, 2), spacing=0.6, width=0.25,
                                                       style="crops"), noise=6.0, clutter=20, seed=2)
    repeat = 5 if quick else 30
    ours_1 = best_time(lambda: locate_image(cam, single), repeat=repeat)
    ours_3 = best_time(lambda: locate_image(crops_cam, crops, spacing=0.6), repeat=repeat)
    naive = best_time(lambda: centroid_script(cam, single), repeat=repeat)
    fix = locate_image(cam, single)
    psi_naive, h_naive = centroid_script(cam, single)
    verdict = "MET" if max(ours_1, ours_3) < TARGET_S else "NOT MET"
    print(f"target: positioning from a 640x480 image < {TARGET_S * 1e3:.0f} ms: {verdict} "
          f"(one line {ours_1 * 1e3:.2f} ms, three crop rows {ours_3 * 1e3:.2f} ms; thesis's robot "
          f"{THESIS_S * 1e3:.0f} ms -> {THESIS_S / ours_1:.0f}x)")
    print(f"errors on the cluttered line image: wmrkit h {abs(fix.h - pose[1]) * 1e3:.2f} mm, psi "
          f"{abs(math.degrees(fix.psi + pose[2])):.2f} deg; centroid script h {abs(h_naive - pose[1]) * 1e3:.1f} mm,"
          f" psi {abs(math.degrees(psi_naive + pose[2])):.2f} deg")
    return [
        Result("vision: locate one line (640x480, clutter)", 1, ours_1, "threshold+centroid script", naive,
               "< 5 ms"),
        Result("vision: locate three crop rows (640x480)", 1, ours_3, "thesis robot (4/s, fixed)", THESIS_S,
               "< 5 ms"),
    ]
