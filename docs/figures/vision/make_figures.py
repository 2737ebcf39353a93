"""Draw the figures and example files of docs/vision.md: ``python docs/figures/vision/make_figures.py``.

Writes into this folder: camera files (``*-camera.yaml``), the chufa points file, synthetic camera images with
their detected lines (PNG) and a line-following animation (GIF). Everything is synthetic (wmrkit.vision.render).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2

from wmrkit import catalog
from wmrkit.vision.animation import save_animation, save_detection_figure
from wmrkit.vision.camera import Camera
from wmrkit.vision.follow import follow_line
from wmrkit.vision.render import Scene, render

HERE = Path(__file__).parent


def main() -> None:
    thesis = Camera(325.7, math.radians(45), 0.134, 320, 240)  # the calibration of Fig. 9.7
    chufa = Camera(545.0, math.radians(76), 1.42, 640, 480)  # the chufa field camera (Figs. 9.10-9.11)
    follower = Camera(150.0, math.radians(60), 0.3, 320, 240)  # on the line follower of §9.2.3
    forklift = Camera(272.5, math.radians(60), 1.42, 320, 240)  # on the forklift's mast
    for name, cam in (("thesis", thesis), ("chufa", chufa), ("follower", follower), ("forklift", forklift)):
        cam.to_file(HERE / f"{name}-camera.yaml")
    points = {"lines": [{"n": -1, "points": [[-10, -93], [-90, 93]]}, {"n": 0, "points": [[4, -93], [-2, 93]]},
                        {"n": 1, "points": [[18, -93], [83, 93]]}]}
    (HERE / "chufa-points.json").write_text(json.dumps(points, indent=1) + "\n")

    cal = render(thesis, (0, 0, 0), Scene(ns=(), extra=(-0.035, 0.035), width=0.008), noise=2.0, blur=0.7)
    cv2.imwrite(str(HERE / "calibration.png"), cal)
    three = render(thesis, (0.0, -0.0583, math.radians(35.434)), Scene((-1, 0, 1), 0.035, 0.006), noise=3.0,
                   blur=0.7, clutter=4, seed=1)
    cv2.imwrite(str(HERE / "three-lines.png"), three)
    save_detection_figure(thesis, three, HERE / "three-lines-detected.png", n_lines=3)
    rows = render(chufa, (0.0, -0.05, math.radians(0.57)),
                  Scene((-2, -1, 0, 1, 2), 0.6, 0.25, style="crops"), noise=6.0, blur=1.0, clutter=8, seed=0)
    cv2.imwrite(str(HERE / "crop-rows.png"), rows)
    save_detection_figure(chufa, rows, HERE / "crop-rows-detected.png", n_lines=5)

    robot = catalog.load("line-follower")
    run = follow_line(robot, follower, gain=0.3, duration=20, noise=(0.02, math.radians(3)), keep_images=True)
    save_animation(run, robot, follower, HERE / "follow-line.gif")


if __name__ == "__main__":
    main()
