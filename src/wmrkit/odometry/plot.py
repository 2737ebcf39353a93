"""Trajectory plots (matplotlib, no display needed): paths from above with start and end marked."""

from __future__ import annotations

import os
from collections.abc import Mapping

import numpy as np

#: Most points drawn per path: a longer one is drawn every k-th pose, its last included (10^7 poses took 21 s and
#: 1.1 GB to draw; the figure is 720 px wide).
MAX_PLOT_POINTS = 100_000


def thin_path(poses: np.ndarray, most: int = MAX_PLOT_POINTS) -> np.ndarray:
    """Every k-th row of `poses` ``(N, k)`` and the last, at most about `most` rows (a view when N <= `most`)."""
    n = len(poses)
    if n <= most:
        return poses
    return poses[np.unique(np.r_[np.arange(0, n, -(-n // most)), n - 1])]


def _drawable(label: str, poses: object) -> np.ndarray:
    """`poses` as ``(N, 3)`` finite floats, N >= 1, or :class:`~wmrkit.plotting.files.PlotError` naming `label`
    (a NaN or an infinity was drawn as a gap, or not at all, and the file written; an empty path raised an
    IndexError)."""
    from .._shapes import as_vectors
    from ..plotting.files import PlotError

    p = as_vectors(poses, 3, label)
    if p.ndim != 2 or len(p) == 0:
        raise PlotError(f"{label}: expected poses (N, 3) with N >= 1, got shape {p.shape}")
    bad = ~np.isfinite(p).all(axis=1)
    if bad.any():
        raise PlotError(f"{label}: pose {int(np.argmax(bad))} is not finite ({', '.join(map(str, p[bad][0]))}): "
                        "nothing to draw there")
    return p


def save_trajectory_plot(path: str | os.PathLike[str], trajectories: Mapping[str, np.ndarray], *,
                         title: str = "odometry") -> None:
    """Draw planar paths ``{label: poses (N, 3)}`` [m] from above, equal axes, to `path` (.png, .svg, .pdf); at
    most about :data:`MAX_PLOT_POINTS` poses of each (:func:`thin_path`). A path that is empty or not finite is
    refused, naming its label, before anything is drawn."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..plotting.files import check_figure_path

    check_figure_path(path)
    paths = {label: _drawable(label, poses) for label, poses in trajectories.items()}
    fig, ax = plt.subplots(figsize=(6, 6))
    try:
        for label, poses in paths.items():
            p = thin_path(poses)
            (line,) = ax.plot(p[:, 0], p[:, 1], label=label, lw=1.2)
            ax.plot(p[0, 0], p[0, 1], "o", color=line.get_color(), ms=5)
            ax.plot(p[-1, 0], p[-1, 1], "s", color=line.get_color(), ms=5)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
        fig.savefig(path, dpi=120, bbox_inches="tight")
    finally:
        plt.close(fig)
