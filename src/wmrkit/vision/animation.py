"""Figures of vision line following: a camera image with its detected lines, and the run as a GIF (camera view
beside the plan view). matplotlib object API only (no pyplot); GIFs through matplotlib's PillowWriter."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..errors import WmrkitError
from ..plotting.files import check_figure_path, save_gif, spread_indices
from ..plotting.robot import footprint
from ..robot import Robot
from .camera import Camera, CameraError, distort
from .follow import LineFollowing
from .lines import DetectedLine, extract_lines

__all__ = ["draw_camera_view", "save_animation", "save_detection_figure"]


def draw_camera_view(ax, camera: Camera, image: np.ndarray, lines: tuple[DetectedLine, ...]) -> None:
    """The image with each detected line drawn over it, below the horizon (back through the lens distortion)."""
    ax.imshow(image, cmap="gray", vmin=0, vmax=255)
    cx, cy = camera.centre
    horizon = -camera.focal_px / math.tan(camera.tilt)  # image row of the horizon (no roll)
    ys = np.linspace(max(-cy, horizon), cy, 60)
    for line in lines:
        xy = distort(np.stack([line.x0 + line.slope * ys, ys], -1), camera.k1, camera.focal_px)
        ax.plot(xy[:, 0] + cx, xy[:, 1] + cy, color="#f28e2b", linewidth=1.5)
    ax.set_xlim(-0.5, camera.width - 0.5)
    ax.set_ylim(camera.rows - 0.5, -0.5)
    ax.set_xticks([])
    ax.set_yticks([])


def _found_lines(camera: Camera, image: np.ndarray, n_lines: int) -> tuple:
    """The lines :func:`.lines.extract_lines` finds in `image`, none where it finds only noise (drawn as it is)."""
    try:
        return extract_lines(image, n_lines=n_lines, k1=camera.k1, focal_px=camera.focal_px)
    except CameraError:
        return ()


def save_detection_figure(camera: Camera, image: np.ndarray, path: str | os.PathLike[str], *,
                          n_lines: int = 1, title: str = "") -> None:
    """A PNG/SVG/PDF of `image` with the lines :func:`.lines.extract_lines` finds in it."""
    check_figure_path(path)  # 'x.txt' raised matplotlib's ValueError, and 'x' wrote x.png
    fig = Figure(figsize=(camera.width / 100, camera.rows / 100 + (0.3 if title else 0)), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1 if not title else camera.rows / (camera.rows + 30)))
    draw_camera_view(ax, camera, image, _found_lines(camera, image, n_lines))
    if title:
        fig.suptitle(title, fontsize=9)
    fig.savefig(path)


#: Most frames of a GIF: a longer run shows every k-th image (a frame costs about 0.25 s and 1.5 MB until the GIF
#: is written: 400 frames took 106 s and 640 MB, and follow-line allows 10^4 periods).
MAX_FRAMES = 200


def _plan_limits(pose: np.ndarray) -> tuple[tuple[float, float], tuple[float, float]]:
    """``(xlim, ylim)`` [m] of the plan view: the whole path ``(N, 3)`` with a margin, x increasing whichever way
    the robot drives (from the start's x to the end's, a run along -x had an inverted axis, the robot out of view)."""
    x, y = pose[:, 0], pose[:, 1]
    span = max(float(np.ptp(y)), 0.3)
    return ((float(x.min()) - 0.6, float(x.max()) + 0.6),
            (min(float(y.min()), 0.0) - 0.3 - 0.5 * span, max(float(y.max()), 0.0) + 0.3 + 0.5 * span))


def save_animation(run: LineFollowing, robot: Robot, camera: Camera, path: str | os.PathLike[str], *,
                   fps: float = 4.0) -> None:
    """A GIF of `run` (made with ``keep_images=True``): camera view (left) beside the plan view (right); at most
    :data:`MAX_FRAMES` frames, evenly spread over the run (the last one included)."""
    if run.images is None:
        raise WmrkitError("animation: the run kept no camera images (follow_line(..., keep_images=True))")
    if Path(path).suffix.lower() != ".gif":
        raise WmrkitError(f"{path}: the animation is written as a GIF (.gif)")
    fig = Figure(figsize=(9, 3.6), dpi=80)
    cam_ax, plan_ax = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    pose = run.pose
    outline = footprint(robot, origin=True)  # the mount points and the tracked point P
    plan_ax.axhline(0.0, color="#222222", linewidth=2, label="line")
    xlim, ylim = _plan_limits(pose)
    plan_ax.set_xlim(*xlim)
    plan_ax.set_ylim(*ylim)
    plan_ax.set_aspect("equal")
    plan_ax.set_xlabel("x along the line [m]")
    plan_ax.set_ylabel("y [m]")
    plan_ax.set_title(f"{robot.name}: plan view", fontsize=9)  # the robot was named nowhere in the GIF
    path_line, = plan_ax.plot([], [], "--", color="#1f77b4", label="path of P (tracked point)")
    body = plan_ax.fill([], [], color="#c9d6e3", edgecolor="#6b7f94")[0]
    plan_ax.legend(loc="upper right", fontsize=8)
    text = fig.text(0.02, 0.02, "", fontsize=8)

    def frame(k: int):
        cam_ax.clear()
        img = run.images[k]
        draw_camera_view(cam_ax, camera, img, _found_lines(camera, img, 1))
        cam_ax.set_title("camera", fontsize=9)
        path_line.set_data(pose[:k + 1, 0], pose[:k + 1, 1])
        c, s = math.cos(pose[k, 2]), math.sin(pose[k, 2])
        world = outline @ np.array([[c, s], [-s, c]]) + pose[k, :2]
        body.set_xy(world)
        text.set_text(f"t = {run.time[k]:.1f} s   h = {pose[k, 1] * 100:+.1f} cm   "
                      f"psi = {math.degrees(-pose[k, 2]):+.1f} deg")
        return body, path_line

    n = len(run.images)
    frames = spread_indices(n, MAX_FRAMES).tolist()
    save_gif(fig, frame, frames, path, fps=fps)
