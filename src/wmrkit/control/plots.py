"""Figures of the control chapter: a tracking run (path, error, steering headings), its animation, and a reference
with its Table 8.1 violations. Matplotlib only, off-screen (Agg)."""

from __future__ import annotations

import math
import os

import numpy as np

from ..errors import WmrkitError
from .feasibility import Feasibility
from .references import Reference
from .track import TrackingRun

__all__ = ["animate_run", "plot_feasibility", "plot_run"]


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: str | os.PathLike[str]) -> None:
    from ..plotting.files import PlotError, check_figure_path

    try:
        check_figure_path(path)
        fig.savefig(path, dpi=110)
    except PlotError:
        raise
    except (OSError, ValueError) as err:
        raise WmrkitError(f"{path}: cannot save the figure ({err})") from None
    finally:
        _pyplot().close(fig)


def plot_run(run: TrackingRun, path: str | os.PathLike[str]) -> None:
    """Path of R and of the tracked point over the reference; tracking error; steering headings [deg]."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    ax = axes[0]
    ax.plot(run.reference[:, 0], run.reference[:, 1], "k--", lw=1, label="reference")
    ax.plot(run.tracked[:, 0], run.tracked[:, 1], "C0", lw=1.5, label="tracked point")
    ax.plot(run.pose[:, 0], run.pose[:, 1], "C1", lw=0.8, label="robot origin R")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(fontsize=8)
    ax.set_title(f"{run.robot.name}, controller {run.controller}")
    _errors(axes[1], run.t, {"tracking error": run.error, "cross-track error": run.cross_track})
    if run.heading.shape[1]:
        for k, name in enumerate(run.robot.steer_names):
            axes[2].plot(run.t, np.degrees(run.heading[:, k]), label=name)
        axes[2].legend(fontsize=8)
    else:  # an empty panel read as a plot that failed
        axes[2].text(0.5, 0.5, "no steered wheels", ha="center", va="center", transform=axes[2].transAxes)
    axes[2].set_xlabel("t [s]")
    axes[2].set_ylabel("steering heading [deg]")
    fig.tight_layout()
    _save(fig, path)


#: The least error [m] the error panel's log axis shows: a smaller one (round-off; 0 on a straight line) is drawn at
#: it, and the panel says so (a user read the flat 1e-12 as the error).
ERROR_FLOOR = 1e-12


def _errors(ax, t: np.ndarray, errors: dict[str, np.ndarray]) -> None:
    """The error panel: each of `errors` [m] against `t` [s], on a log axis from :data:`ERROR_FLOOR`, the values
    below it drawn at it with a legend entry saying so; on a linear axis when every value is below it (round-off
    alone: a log axis would show flat lines at the floor, as if the error were 1e-12 m)."""
    below = [bool(np.any(e < ERROR_FLOOR)) for e in errors.values()]
    if all(bool(np.all(e < ERROR_FLOOR)) for e in errors.values()):
        for label, e in errors.items():
            ax.plot(t, e, label=label)
        ax.set_title(f"every error below {ERROR_FLOOR:g} m (round-off)", fontsize=9)
    else:
        for label, e in errors.items():
            ax.semilogy(t, np.maximum(e, ERROR_FLOOR), label=label)
        if any(below):
            ax.axhline(ERROR_FLOOR, color="0.5", lw=0.8, ls=":",
                       label=f"errors below {ERROR_FLOOR:g} m drawn at {ERROR_FLOOR:g} m")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("error [m]")
    ax.legend(fontsize=8)


#: Most frames of a tracking animation, as park --animate's (:data:`wmrkit.parking.plot.MAX_FRAMES`): each is kept,
#: about 0.25 MB, until the GIF is written, and a run has up to 10^6 samples.
MAX_FRAMES = 800


def animate_run(run: TrackingRun, path: str | os.PathLike[str], *, frames: int = 80) -> None:
    """A GIF of the robot (outline and wheels at their headings) following the reference (`path` ends in .gif);
    `frames`: at most that many, 2 to :data:`MAX_FRAMES`, evenly spread over the run."""
    from ..plotting.files import check_count, save_gif, spread_indices
    from ..plotting.robot import footprint

    if os.path.splitext(os.fspath(path))[1].lower() != ".gif":  # x.png was written as one still frame
        raise WmrkitError(f"{os.fspath(path)}: the animation is written as a GIF (.gif)")
    check_count("frames", frames, 2, MAX_FRAMES)  # 0 raised an IndexError; 10**6 drew every sample of the run
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 5))
    idx = spread_indices(len(run.t), frames)
    pts = np.vstack([run.reference[:, :2], run.pose[:, :2]])
    span = float(np.ptp(pts, axis=0).max()) + 2.0
    centre = pts.min(axis=0) + np.ptp(pts, axis=0) / 2
    robot = run.robot
    mounts = np.array([w.position for w in robot.wheels] + [(0.0, 0.0)])
    body = footprint(robot)
    steer = robot.steer_names
    fixed_heading = {w.name: w.heading for w in robot.wheels}

    # the reference under the moving robot (zorder 0.5, the body's fill 1): the frames draw the robot over the
    # figure rendered once, in the order a full redraw would
    ax.plot(run.reference[:, 0], run.reference[:, 1], "k--", lw=1, zorder=0.5)
    tracked, = ax.plot([], [], "C0")
    outline, = ax.fill([], [], color="#c9d6e3", alpha=0.6)
    wheels = [ax.plot([], [], "k", lw=3)[0] for _ in robot.wheels]
    origin, = ax.plot([], [], "C1o", ms=4)
    ax.set_xlim(centre[0] - span / 2, centre[0] + span / 2)
    ax.set_ylim(centre[1] - span / 2, centre[1] + span / 2)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    title = ax.set_title("", fontsize=9)

    def frame(k: int) -> list:
        i = int(idx[k])
        tracked.set_data(run.tracked[: i + 1, 0], run.tracked[: i + 1, 1])
        x, y, th = run.pose[i]
        c, s = math.cos(th), math.sin(th)
        world = np.column_stack([x + c * mounts[:, 0] - s * mounts[:, 1], y + s * mounts[:, 0] + c * mounts[:, 1]])
        outline.set_xy(np.column_stack([x + c * body[:, 0] - s * body[:, 1], y + s * body[:, 0] + c * body[:, 1]]))
        for j, (w, line) in enumerate(zip(robot.wheels, wheels, strict=True)):
            h = th + (run.heading[i, steer.index(w.name)] if w.name in steer else fixed_heading[w.name])
            d = max(w.r, 0.05) * np.array([math.cos(h), math.sin(h)])
            line.set_data([world[j, 0] - d[0], world[j, 0] + d[0]], [world[j, 1] - d[1], world[j, 1] + d[1]])
        origin.set_data([world[-1, 0]], [world[-1, 1]])
        title.set_text(f"{robot.name}, {run.controller}: t = {run.t[i]:.1f} s")
        return [tracked, outline, *wheels, origin, title]

    try:
        save_gif(fig, frame, range(len(idx)), path, fps=12, blit=True)
    except (OSError, ValueError) as err:
        raise WmrkitError(f"{path}: cannot save the animation ({err})") from None
    finally:
        plt.close(fig)


def plot_feasibility(result: Feasibility, reference: Reference, path: str | os.PathLike[str], *,
                     robot: str | None = None) -> None:
    """The reference path with its violations marked and labelled by kind; `robot`: the name the title starts
    with (as every other figure's)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 5))
    ax.plot(reference.pose[:, 0], reference.pose[:, 1], "k", lw=1.2, label="reference")
    jumps = [v for v in result.violations if v.signal != "turn"]
    for k, v in enumerate(jumps):
        p = reference.sample(np.array([v.t]))[0]
        ax.plot(p[0], p[1], "rx", ms=9, mew=2, label="violation" if k == 0 else None)
        ax.annotate(f"{v.signal} @ {v.t:.1f} s", (p[0], p[1]), fontsize=7, xytext=(4, 4), textcoords="offset points")
    for k, v in enumerate(v for v in result.violations if v.signal == "turn"):  # a stretch: TightTurn
        inside = (reference.t >= v.t) & (reference.t <= v.until)  # type: ignore[attr-defined]
        ax.plot(reference.pose[inside, 0], reference.pose[inside, 1], "r", lw=3, alpha=0.6,
                label="tighter than the steering stops" if k == 0 else None)
    r = result.requirement
    ax.set_title(f"{'' if robot is None else f'{robot}: '}Table 8.1 '{r.column}', {r.framework}: "
                 f"{'feasible' if result.feasible else 'NOT feasible'}", fontsize=10)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    _save(fig, path)
