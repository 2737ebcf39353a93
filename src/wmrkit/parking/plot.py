"""Pictures of a parking plan: the scene, the path, the car at every stop (PNG/SVG/PDF), and an animation (GIF/HTML).

matplotlib's object API (no pyplot, no GUI backend). World frame of :mod:`wmrkit.parking.path`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Polygon, Rectangle

from ..errors import WmrkitError
from ..plotting.files import check_count, save_gif, save_html, spread_indices
from .execute import Execution, execute_plan
from .geometry import Space, Vehicle, footprint
from .path import sample_poses
from .planner import ParkingPlan, size

FORWARD, BACKWARD = "#1f77b4", "#d62728"
#: Most samples of the trail an animation draws, spread evenly (every sample of a plan driven in under 10 min; each
#: frame drew every sample up to it: 800 frames of a 9.8 km plan, 394,511 samples, ran over 6 min).
MAX_TRAIL = 12_000
#: Most frames of an animation (matplotlib embeds at most 20 MB in an HTML page; a GIF frame is about 0.25 MB).
MAX_FRAMES = 800
#: Spacing of the drawn path's samples, and the shortest rear axle drawn, in car sizes (:func:`size`; 2 cm and 5 cm for
#: example 1's 2 m car). In metres, a 2 mm car's arcs were drawn as chords and its axle as a 5 cm bar.
PATH_STEP, MIN_AXLE = 0.01, 0.025


def car_outline(vehicle: Vehicle, pose: np.ndarray) -> np.ndarray:
    """The body's corners in the world at P_f's `pose` ``(3,)``: ``(4, 2)`` [m]."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    body = np.array(footprint(vehicle))
    return pose[:2] + body @ np.array([[c, s], [-s, c]])


def draw_scene(ax: Axes, space: Space, extent: float = 2.0) -> None:
    """Parked cars (grey, `extent` [m] long), the curb, the slot and its safety margins."""
    H, J = space.H, space.J
    ax.add_patch(Rectangle((0, -J), extent, J, color="0.75", zorder=0))
    ax.add_patch(Rectangle((-H - extent, -J), extent, J, color="0.75", zorder=0))
    ax.add_patch(Rectangle((-H - extent, -J - 0.15 * extent), H + 2 * extent, 0.15 * extent, color="0.45", zorder=0))
    ax.plot([-H, 0, 0, -H, -H], [0, 0, -J, -J, 0], color="0.3", lw=0.8, ls="--", zorder=1)
    for x in (-H + space.MS, -space.MS):
        ax.plot([x, x], [-J, 0], color="0.5", lw=0.6, ls=":", zorder=1)


def draw_car(ax: Axes, vehicle: Vehicle, pose: np.ndarray, steering: float = 0.0, *, color: str = "k",
             alpha: float = 1.0, fill: bool = False) -> list:
    """The car's body, rear axle and equivalent steering wheel at `pose`; returns the artists."""
    corners = car_outline(vehicle, pose)
    body = Polygon(corners, closed=True, fill=fill, facecolor=color if fill else "none", edgecolor=color,
                   alpha=alpha, lw=1.2, zorder=3)
    ax.add_patch(body)
    c, s = math.cos(pose[2]), math.sin(pose[2])
    front = pose[:2] + vehicle.h1 * np.array([c, s])
    w = 0.15 * vehicle.h1
    d = np.array([math.cos(pose[2] + steering), math.sin(pose[2] + steering)]) * w
    wheel, = ax.plot([front[0] - d[0], front[0] + d[0]], [front[1] - d[1], front[1] + d[1]], color=color,
                     lw=3, alpha=alpha, zorder=4)
    half = np.array([-s, c]) * max(vehicle.track, MIN_AXLE * size(vehicle)) / 2
    axle, = ax.plot([pose[0] - half[0], pose[0] + half[0]], [pose[1] - half[1], pose[1] + half[1]], color=color,
                    lw=2, alpha=alpha, zorder=4)
    return [body, wheel, axle]


def plot_plan(plan: ParkingPlan, execution: Execution | None = None, *, name: str | None = None) -> Figure:
    """The scene, P_f's path (blue forward, red backward), the car at every stop, the final car filled, and a legend
    naming each (outside the frame); `name` (the problem's, and its robot's) starts the title."""
    fig = Figure(figsize=(11, 5.2))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    v, sp = plan.vehicle, plan.space
    draw_scene(ax, sp, size(v))
    for seg in plan.segments:
        xy = sample_poses([seg], PATH_STEP * size(v))
        ax.plot(xy[:, 0], xy[:, 1], color=FORWARD if seg.direction > 0 else BACKWARD, lw=1.4, zorder=2)
        if seg.phase == 3:
            draw_car(ax, v, np.array(seg.end), seg.steering, color="0.35", alpha=0.45)
    if execution is not None:
        ax.plot(execution.pose[:, 0], execution.pose[:, 1], color="k", lw=0.8, ls="--", zorder=2)
    if plan.segments:
        draw_car(ax, v, np.array(plan.final_pose), 0.0, color="#2ca02c", alpha=0.5, fill=True)
    plural = "" if plan.maneuvers == 1 else "s"
    verdict = f"{plan.maneuvers} manoeuvre{plural}" if plan.feasible else f"infeasible: {plan.reason[:70]}"
    part = "" if plan.used_H is None else f" (parks in the {plan.used_H:.3g} m behind the front car)"
    ax.set_title(f"{'' if name is None else f'{name}: '}H = {sp.H:.3g} m{part}, J = {sp.J:.3g} m, car "
                 f"{v.length:.3g} x {v.c1:.3g} m: {verdict}", fontsize=9)
    ax.legend(handles=_legend(plan, execution), loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0,
              fontsize=8)
    _frame(ax, plan)
    fig.tight_layout()
    ax.set_anchor("E")
    return fig


def _legend(plan: ParkingPlan, execution: Execution | None) -> list:
    """Legend entries of :func:`plot_plan`, one per kind of element drawn (it named the executed path alone)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    drawn = {s.direction for s in plan.segments}
    handles = [Line2D([], [], color=color, lw=1.4, label=f"planned path of the rear axle's midpoint, {way}")
               for way, color, d in (("forward", FORWARD, 1), ("backward", BACKWARD, -1)) if d in drawn]
    if execution is not None:
        handles.append(Line2D([], [], color="k", lw=0.8, ls="--", label=f"executed path ({execution.mode})"))
    if any(s.phase == 3 for s in plan.segments):
        handles.append(Patch(facecolor="none", edgecolor="0.35", alpha=0.45, label="car at each stop"))
    if plan.segments:
        handles.append(Patch(facecolor="#2ca02c", edgecolor="#2ca02c", alpha=0.5, label="car parked (goal)"))
    return [*handles, Patch(color="0.75", label="parked cars"), Patch(color="0.45", label="curb"),
            Line2D([], [], color="0.3", lw=0.8, ls="--", label="slot"),
            Line2D([], [], color="0.5", lw=0.6, ls=":", label="safety margins (MS)")]


def save_plan_figure(plan: ParkingPlan, path: str | os.PathLike[str], execution: Execution | None = None, *,
                     name: str | None = None) -> None:
    """Write :func:`plot_plan` to a PNG, SVG or PDF file."""
    from ..plotting.files import check_figure_path

    check_figure_path(path)
    plot_plan(plan, execution, name=name).savefig(path, dpi=120, bbox_inches="tight")


def animate_plan(plan: ParkingPlan, path: str | os.PathLike[str], execution: Execution | None = None, *,
                 fps: int = 20, max_frames: int = 400) -> int:
    """Write an animation of the executed plan: ``.gif`` or ``.html`` (a page with a player; ``save_gif``,
    ``save_html``).

    The car drives P_f's executed poses with its steering wheel turned to the commanded heading; the trail is
    coloured by direction. Returns the number of frames (at most `max_frames`, 2 to :data:`MAX_FRAMES`, evenly
    spaced in time); `fps` frames a second, 1 to 100.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".html"):
        raise WmrkitError(f"{path}: the animation is written as .gif or .html")
    # max_frames = 10**9 drew every executed sample (up to 500,000 frames: hours), 2.5 raised a TypeError; fps = 0
    # a ZeroDivisionError once the whole animation was rendered
    check_count("max_frames", max_frames, 2, MAX_FRAMES)
    check_count("fps", fps, 1, 100)
    run = execute_plan(plan) if execution is None else execution
    dots = spread_indices(len(run.t), MAX_TRAIL)  # the trail's samples (all of a short run)
    fig = Figure(figsize=(8, 4.6))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    draw_scene(ax, plan.space, size(plan.vehicle))
    _frame(ax, plan)
    first = _first_in_view(plan.vehicle, run.pose, ax.get_xlim())
    frames = first + spread_indices(len(run.t) - first, max_frames)
    direction = np.array([s.direction for s in plan.segments])[run.segment]
    trail_f, = ax.plot([], [], ".", color=FORWARD, ms=1.5)
    trail_b, = ax.plot([], [], ".", color=BACKWARD, ms=1.5)
    artists: list = []
    title = ax.set_title("", fontsize=9)

    def update(k: int) -> list:
        for a in artists:
            a.remove()
        artists.clear()
        i = frames[k]
        artists.extend(draw_car(ax, plan.vehicle, run.pose[i], float(run.steering[i]), color="#2ca02c",
                                alpha=0.8, fill=True))
        upto = dots[:np.searchsorted(dots, i, side="right")]
        fwd = direction[upto] > 0
        trail_f.set_data(run.pose[upto][fwd, 0], run.pose[upto][fwd, 1])
        trail_b.set_data(run.pose[upto][~fwd, 0], run.pose[upto][~fwd, 1])
        seg = plan.segments[run.segment[i]]
        title.set_text(f"t = {run.t[i]:5.1f} s   phase {seg.phase}   manoeuvre {seg.maneuver}/{plan.maneuvers}   "
                       f"steering {math.degrees(run.steering[i]):+5.1f} deg")
        return [*artists, trail_f, trail_b, title]

    if suffix == ".gif":
        save_gif(fig, update, range(len(frames)), path, fps=fps, dpi=80, blit=True)
    else:
        save_html(fig, update, range(len(frames)), path, fps=fps, dpi=80)
    return len(frames)


def _first_in_view(vehicle: Vehicle, pose: np.ndarray, xlim: tuple[float, float]) -> int:
    """The first sample of `pose` ``(n, 3)`` at which the car can be seen between `xlim`: the animation starts
    there. Its frames were spread over the whole drive: in a 1 km slot, framed like the plot (:func:`_frame`), 197
    of 200 showed the car on the detection pass, outside the frame."""
    body = np.array(footprint(vehicle))  # (4, 2) corners in the car's frame
    x = pose[:, :1] + np.cos(pose[:, 2:]) * body[:, 0] - np.sin(pose[:, 2:]) * body[:, 1]  # (n, 4) in the world
    seen = (x.max(axis=1) >= xlim[0]) & (x.min(axis=1) <= xlim[1])
    return int(np.argmax(seen)) if seen.any() else 0


def _frame(ax: Axes, plan: ParkingPlan) -> None:
    """The slot (or the part of a long slot the car parks in, ``used_H``) and the path after the detection pass,
    padded in units of the car's size: in metres, a 2 mm car was a dot in a 2 m frame, and a 1 km slot hid the
    manoeuvre."""
    sp, v = plan.space, plan.vehicle
    unit = size(v)
    shown = sp.H if plan.used_H is None else plan.used_H
    xs = [-shown - 0.5 * unit, 0.5 * unit]
    ys = [-sp.J - 0.2 * unit, 0.25 * unit]
    for seg in plan.segments:
        for p in (seg.start, seg.end):
            if seg.phase > 1 or plan.used_H is None or p is seg.end:
                xs.append(p[0])
                ys.append(p[1])
    pad = v.length
    ax.set_xlim(min(xs) - pad * 0.3, max(xs) + pad)
    ax.set_ylim(min(ys) - 0.1 * unit, max(ys) + v.c1 / 2 + 0.2 * unit)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (along the road)")
    ax.set_ylabel("y [m]")
