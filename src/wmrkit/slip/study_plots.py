"""Figures of the forklift slip study (:mod:`.study`): the sweep (Figs 7.9-7.10), examples (7.12-7.14), paths
(7.15-7.23). matplotlib, no display."""

from __future__ import annotations

import os

import numpy as np

from ..odometry.plot import save_trajectory_plot
from .models import wls


def save_study_figures(report, sw: dict, examples: list, pth: dict) -> list[str]:
    """Write the figures into directory `report` (created); the file names."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from .study import DRIVES, at_axle, forklift_weights

    os.makedirs(report, exist_ok=True)
    out = []
    rates, beta, ref, k11, k12 = sw["_data"]
    ok = ref.converged
    mcd_t = at_axle(ref.twist[ok])
    from .. import catalog

    wls_t = at_axle(wls(catalog.load("forklift"), DRIVES, rates[ok], beta[ok], forklift_weights(k11, k12)).twist)
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for i, (ax, label) in enumerate(zip(axes, ("vx [m/s]", "vy [m/s]", "omega [rad/s]"), strict=True)):
        ax.plot(mcd_t[:, i], ".", ms=2, label="MCD")
        ax.plot(wls_t[:, i] - mcd_t[:, i], ".", ms=2, label="WLS - MCD")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize="small")
    axes[-1].set_xlabel("sweep point")
    fig.suptitle(f"k11/k12 sweep: k11 = {k11:.3g}, k12 = {k12:.3g} (cf. Figs 7.9-7.10)")
    out.append(_save(fig, report, "sweep.png"))
    for e in examples:
        t, twists, _pose = e["_data"]
        fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
        for i, (ax, label) in enumerate(zip(axes, ("vx [m/s]", "vy [m/s]", "omega [rad/s]"), strict=True)):
            for name, tw in twists.items():
                ax.plot(t, tw[:, i], label=name, lw=1.2 if name == "MD" else 0.9)
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        axes[0].legend(fontsize="small", ncol=4)
        axes[-1].set_xlabel("t [s]")
        j = {m: 100 * v for m, v in e["J"].items()}
        fig.suptitle(f"example {e['example']}: J_MQE {j['MQE']:.3g} %, J_MCD {j['MCD']:.3g} %, J_WLS {j['WLS']:.3g} %"
                     " (drive-axle twist)")
        out.append(_save(fig, report, f"example-{e['example']}.png"))
    for name, paths in pth["_data"].items():
        path = os.path.join(report, f"path-{name}.png")
        save_trajectory_plot(path, {k: np.asarray(v) for k, v in paths.items()}, title=f"forklift: {name}")
        out.append(path)
    return out


def _save(fig, report, name: str) -> str:
    import matplotlib.pyplot as plt

    path = os.path.join(report, name)
    try:
        fig.savefig(path, dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)
    return path
