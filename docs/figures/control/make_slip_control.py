"""Table and figures of docs/slip-control.md: ``python docs/figures/control/make_slip_control.py [--quick]``.

Control through the slip models (thesis future work 4): the forklift and a skid-steer robot track references with
significant lateral acceleration in closed loop through the chapter-7 dynamics with tyres, with wheel commands from
the no-slip IK or from the inverse MQE, and with each feedback. Writes ``slip-control-table.md`` and one figure per
robot next to this script; ``--quick`` runs shorter references (a smoke test).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from wmrkit import catalog
from wmrkit.control import builtin_reference, reference_from_samples, track
from wmrkit.slip.kalman import fk2_noise
from wmrkit.slip.study import SETTINGS, forklift_weights
from wmrkit.slip.weights import SlipWeights

HERE = Path(__file__).resolve().parent
RAMP = 2.0  # [s]: the references start at rest and reach their speed at constant acceleration
PERIOD = 0.05  # [s]: 20 Hz control
HOLD_RAMP = True  # commands reached linearly over each period (first-order hold); False: held (zero-order hold)
SETTLE = 4.0  # [s]: errors are measured after the launch
FEEDBACK = ("pose", "odometry", "wls", "fk2", "mqe")
#: robot, reference, speed [m/s], size [m], duration at speed [s]
CASES = (("forklift", "circle", 2.0, 4.0, 14.0), ("forklift", "figure-eight", 2.0, 5.0, 16.0),
         ("skid-steer-4", "circle", 1.0, 2.0, 14.0), ("skid-steer-4", "figure-eight", 1.0, 2.5, 16.0))


def ramped(name: str, speed: float, size: float, duration: float):
    """The built-in reference `name`, started from rest: the same path, its arc length ``v t^2 / (2 RAMP)`` for
    the first RAMP seconds, then at `speed` (a vehicle at rest cannot follow a reference that starts moving)."""
    base = builtin_reference(name, speed=speed, size=size, duration=duration + RAMP)
    t = np.arange(0.0, duration + RAMP + 1e-9, 0.01)
    tau = np.where(t < RAMP, t * t / (2 * RAMP), t - RAMP / 2)
    return reference_from_samples(f"{name} (from rest)", t, base.sample(tau))


def estimators(robot_name: str):
    """WLS friction coefficients and FK2 noise: the thesis's for the forklift (§7.5.3); for the skid steer the
    linear law of its Dugoff tyres (lateral/longitudinal = calpha/cs) and unit noise."""
    if robot_name == "forklift":
        return forklift_weights(*SETTINGS["wls_thesis"]), fk2_noise(*SETTINGS["fk2_thesis"])
    return SlipWeights.uniform(1500.0 / 2000.0, 1.0), None


def run_all(quick: bool = False) -> tuple[list[dict], dict]:
    rows, runs = [], {}
    for robot_name, ref_name, speed, size, duration in CASES:
        robot = catalog.load(robot_name)
        ref = ramped(ref_name, speed, size, 4.0 if quick else duration)
        weights, noise = estimators(robot_name)
        a_lat = float(np.max(np.abs(ref.velocity[:, 0] * ref.acceleration[:, 1] - ref.velocity[:, 1]
                                    * ref.acceleration[:, 0]) / np.maximum(np.hypot(*ref.velocity[:, :2].T), 1e-9)))
        for feedback in FEEDBACK[:2] if quick else FEEDBACK:
            row = {"robot": robot_name, "reference": ref_name, "a_lat": a_lat, "feedback": feedback}
            for sm in ("none", "mqe"):
                run = track(robot, ref, dynamics=True, period=PERIOD, slip_model=sm, feedback=feedback,
                            weights=weights, noise=noise, ramp=HOLD_RAMP)
                s = run.summary(SETTLE)
                row[sm] = (s["rms_error"], s["max_error"])
                runs[(robot_name, ref_name, feedback, sm)] = run
            rows.append(row)
            print(row, flush=True)
    return rows, runs


def table(rows: list[dict]) -> str:
    out = ["| robot | reference (max lateral acc.) | feedback | RMS error, no-slip IK [mm] | RMS error, MQE [mm] "
           "| max error, no-slip IK [mm] | max error, MQE [mm] |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['robot']} | {r['reference']} ({r['a_lat']:.2f} m/s²) | {r['feedback']} | "
                   f"{1e3 * r['none'][0]:.1f} | {1e3 * r['mqe'][0]:.1f} | {1e3 * r['none'][1]:.1f} | "
                   f"{1e3 * r['mqe'][1]:.1f} |")
    return "\n".join(out) + "\n"


def figure(runs: dict, robot_name: str, ref_name: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    ref = runs[(robot_name, ref_name, "pose", "none")].reference
    axes[0].plot(ref[:, 0], ref[:, 1], "k--", lw=1, label="reference")
    for (rn, fn, fb, sm), run in runs.items():
        if (rn, fn) != (robot_name, ref_name) or fb not in ("pose", "mqe", "odometry"):
            continue
        label = f"{'no-slip IK' if sm == 'none' else 'MQE'} commands, {fb} feedback"
        style = "-" if sm == "mqe" else ":"
        if fb == "pose":
            axes[0].plot(run.tracked[:, 0], run.tracked[:, 1], style, lw=1.2, label=label)
        axes[1].semilogy(run.t, np.maximum(run.error, 1e-5), style, lw=1.2, label=label)
    axes[0].set_aspect("equal", adjustable="datalim")
    axes[0].set_xlabel("x [m]")
    axes[0].set_ylabel("y [m]")
    axes[0].set_title(f"{robot_name}: {ref_name} from rest, true-pose feedback")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("t [s]")
    axes[1].set_ylabel("tracking error of the controlled point [m]")
    axes[1].axvline(SETTLE, color="0.7", lw=0.8)
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str]) -> None:
    quick = "--quick" in argv
    rows, runs = run_all(quick)
    text = table(rows)
    print(text)
    if not quick:
        (HERE / "slip-control-table.md").write_text(text)
        for robot_name, ref_name in (("forklift", "figure-eight"), ("skid-steer-4", "figure-eight")):
            figure(runs, robot_name, ref_name, HERE / f"slip-control-{robot_name}.png")


if __name__ == "__main__":
    main(sys.argv[1:])
