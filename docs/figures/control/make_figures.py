"""Figures and the comparison table of docs/control.md: ``python docs/figures/control/make_figures.py``."""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.control import (
    builtin_reference,
    feasibility,
    forklift_real_loops,
    from_thesis_pose,
    track,
    with_steer_range,
)
from wmrkit.control.plots import plot_feasibility, plot_run

HERE = Path(__file__).resolve().parent


def figures() -> None:
    fork = catalog.load("forklift")
    run = track(fork, builtin_reference("arc-line"), gain=2.0, initial_pose=from_thesis_pose([0, 4, math.pi]),
                output_dt=0.02)
    plot_run(run, HERE / "forklift-example-1.png")
    run = track(fork, builtin_reference("corner"), gain=2.0, initial_pose=from_thesis_pose([0, 0, 0]),
                policy="2-quadrant", output_dt=0.02)
    plot_run(run, HERE / "forklift-example-2.png")
    truck = with_steer_range(fork, "steer", -math.pi / 2, math.pi / 2)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for a in (0.5, 1.0, 2.0):
            r = track(truck, builtin_reference("line", duration=40), gain=a, initial_pose=[0, 0.5, 0],
                      loops=forklift_real_loops(), gate=1.5, period=0.1, delay=1, duration=20, policy="2-quadrant")
            ax.plot(r.t, r.tracked[:, 1], label=f"a = {a:g} 1/s")
    ax.set_ylim(-0.6, 0.6)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("lateral error of the fork tips [m]")
    ax.legend()
    ax.set_title("real forklift loops (steer 1.5 s, traction 3.5 s + 15 %), T = 0.1 s, 1 sample late", fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "forklift-real-loops.png", dpi=110)
    plt.close(fig)
    plot_feasibility(feasibility(fork, builtin_reference("square")), builtin_reference("square"),
                     HERE / "feasibility-forklift-square.png", robot=fork.name)


CASES = {"forklift": 1.0, "diff-drive": 1.0, "swerve-4": 1.0, "ackermann": 3.0}


def table() -> list[str]:
    rows = ["| robot | reference | controller | RMS cross-track [mm] | max cross-track after 5 s [mm] | "
            "RMS tracking error [mm] |", "|---|---|---|---|---|---|"]
    for name, scale in CASES.items():
        robot = catalog.load(name)
        for ref_name in ("circle", "figure-eight", "square"):
            ref = builtin_reference(ref_name, size=scale * {"circle": 3, "figure-eight": 6, "square": 6}[ref_name])
            for controller in ("p", "pure-pursuit", "stanley"):
                # each controller's own tracked point 0.3 m off the reference's start (track's default start puts
                # that point on it: the thesis law's control point, pure pursuit's axle point, Stanley's front point)
                on = track(robot, ref, controller=controller, duration=0.05).pose[0]
                run = track(robot, ref, controller=controller, initial_pose=on + np.array([0.0, 0.3, 0.0]),
                            output_dt=0.05)
                s, late = run.summary(), run.summary(settle=5.0)
                rows.append(f"| {name} | {ref_name} | {controller} | {1e3 * s['rms_cross_track']:.1f} | "
                            f"{1e3 * late['max_cross_track']:.1f} | {1e3 * s['rms_error']:.1f} |")
                print(rows[-1], flush=True)
    return rows


if __name__ == "__main__":
    if "table" not in sys.argv[1:]:
        figures()
    if "figures" not in sys.argv[1:]:
        (HERE / "comparison.md").write_text("\n".join(table()) + "\n")
