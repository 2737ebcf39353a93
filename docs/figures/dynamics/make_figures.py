"""Figures of docs/dynamics.md: ``python docs/figures/dynamics/make_figures.py`` (writes next to this file)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from wmrkit import catalog
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program
from wmrkit.dynamics.simulate import simulate
from wmrkit.dynamics.tyres import Tyre

HERE = Path(__file__).parent
LOAD = 8175.0  # a forklift wheel's static load [N]


def tyre_curves() -> None:
    s = np.linspace(-0.9, 1.0, 381)
    a = np.linspace(-1.0, 1.0, 401)
    tyres = {"pacejka (7.A1, 2 m/s)": Tyre.of("pacejka"), "dugoff": Tyre.of("dugoff"),
             "coulomb (k = 50 s/m)": Tyre.of("coulomb"), "linear": Tyre.of("linear", {"c_lat": 2e4, "c_long": 2e4})}
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for label, tyre in tyres.items():
        ax1.plot(s, -tyre.forces_at_slip(LOAD, s, 0.0, 2.0).longitudinal / LOAD, label=label)
        ax2.plot(a, -tyre.forces_at_slip(LOAD, 0.0, a, 2.0).lateral / LOAD, label=label)
    ax1.set(xlabel="slip ratio s (7.31, sign-corrected)", ylabel="-F_long / Fz", title="pure longitudinal slip",
            ylim=(-1.3, 1.3))
    ax2.set(xlabel="slip angle [rad] (7.35)", ylabel="-F_lat / Fz", title="pure lateral slip", ylim=(-1.3, 1.3))
    for ax in (ax1, ax2):
        ax.grid(True)
        ax.axhline(0, color="k", lw=0.5)
    ax1.legend(fontsize=8)
    fig.suptitle(f"Traction models at Fz = {LOAD:g} N, wheel speed 2 m/s (force opposes the slip)")
    fig.tight_layout()
    fig.savefig(HERE / "tyre-curves.png", dpi=110)
    plt.close(fig)


def forklift_paths() -> None:
    model = DynamicModel.of(catalog.load("forklift"))
    fig, axes = plt.subplots(1, 3, figsize=(12, 4))
    for ax, name in zip(axes, ("rectangle", "figure-eight", "triple-loop"), strict=True):
        inputs, duration = path_program(model, name)
        sim = simulate(model, inputs, duration, record_step=0.02)
        ax.plot(sim.pose[:, 0], sim.pose[:, 1])
        ax.plot(*sim.pose[0, :2], "go")
        ax.plot(*sim.pose[-1, :2], "rx")
        ax.set(title=f"forklift '{name}' (pacejka)", xlabel="x [m]", ylabel="y [m]", aspect="equal")
        ax.grid(True)
    fig.tight_layout()
    fig.savefig(HERE / "forklift-programs.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    tyre_curves()
    forklift_paths()
