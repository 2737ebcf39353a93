"""The skid-steer comparison of ``docs/slip.md``: no-slip least squares, effective track and WLS on simulated logs.

A Husky-like robot (the catalog's ``skid-steer-4``: four fixed wheels, 50 kg, Dugoff tyres) is driven through
segments of wheel speeds: the no-slip wheel rates of body twists ``(duration, v, omega)``, followed by rate servos.
Its motion comes from the dynamic model (``source="md"``, :mod:`wmrkit.dynamics`, 1 ms steps) or from the
quasi-static slip model with its tyres (``"quasi-static"``, :func:`.synthetic.wheel_speed_run`: instant changes).
Both one-parameter models are calibrated on one run (:func:`.calibration.calibrate_slip`) and evaluated on others
they were not fitted to.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import numpy as np

from .._shapes import real_number
from ..errors import ShapeError, WmrkitError
from ..odometry.pipeline import odometry
from ..odometry.plot import save_trajectory_plot
from ..robot import Robot
from .calibration import calibrate_slip, effective_track_model
from .synthetic import wheel_speed_run
from .weights import SlipWeights, wls_model

#: Calibration run: arcs both ways and a straight, segments ``(duration [s], v [m/s], omega [rad/s])``.
CALIBRATION = ((4.0, 1.0, 0.4), (2.0, 1.0, 0.0), (4.0, 1.0, -0.4), (3.0, 1.0, 0.8))
#: Test runs: a loop of tight arcs, a slalom, and a square with turns on the spot.
TESTS = {
    "tight loop": ((9.0, 1.0, 1.2),),
    "slalom": ((2.0, 1.0, 0.6), (2.0, 1.0, -0.6)) * 3,
    "square, spot turns": ((2.0, 1.0, 0.0), (1.4, 0.0, 1.2)) * 4,
}


def segment_run(robot: Robot, segments: Sequence[tuple[float, float, float]], rate: float, source: str = "md"):
    """``(log, truth poses (N, 3))`` of `robot` driven by twist segments, from the dynamic model or the
    quasi-static slip model (module docstring)."""
    from ..kinematics.wheel_ik import wheel_commands
    from ..odometry.logs import JointLog
    from ..odometry.model import odometry_model

    if source not in ("md", "quasi-static"):  # any other name ran the dynamic model
        raise WmrkitError(f"source must be 'md' or 'quasi-static', got {source!r}")
    if not (real_number(rate) and rate > 0):  # 0 divided by zero in the dynamic model's record step; text: TypeError
        raise ShapeError(f"rate must be a finite number > 0 [Hz], got {rate!r}")
    if source == "quasi-static":
        spins = [robot.rate_names.index(j) for j in odometry_model(robot).rate_joints]
        run = wheel_speed_run(robot, [(d, wheel_commands(robot, [v, 0.0, w]).rates[spins]) for d, v, w in segments],
                              rate)
        return run.log, run.truth
    from ..dynamics.model import DynamicModel
    from ..dynamics.programs import twist_program
    from ..dynamics.simulate import simulate

    model = DynamicModel.of(robot)
    t, twists, end = [0.0], [(0.0, 0.0, 0.0)], 0.0
    for d, v, w in segments:
        t += [end + 0.2, end + d]
        twists += [(v, 0.0, w)] * 2
        end += d
    sim = simulate(model, twist_program(model, np.array(t), np.array(twists), allow_slip=True), end, step=1e-3,
                   record_step=1 / rate, check=False)  # off its path by design (a skid turns), at the checked step
    names, joints = list(sim.joint_names), odometry_model(robot).joints
    log = JointLog(sim.t, joints, sim.joint_positions[:, [names.index(j) for j in joints]], source="<md>")
    return log, np.asarray(sim.pose)


def skid_comparison(robot: Robot, *, rate: float = 50.0, calibration=CALIBRATION,
                    tests: Mapping[str, Sequence] | None = None, source: str = "md") -> dict:
    """Calibrate on `calibration` segments, evaluate on `tests`: JSON-ready results plus the paths.

    Returns ``{"ratio", "wheel_separation_multiplier", "runs": {name: {model: {"rms_position_error": m,
    "final_position_error": m}}}, "paths": {name: {label:
    poses}}}`` (``paths`` holds arrays, for plotting).
    """
    cal_log, cal_truth = segment_run(robot, calibration, rate, source)
    cal = calibrate_slip(robot, cal_log, (cal_log.time, cal_truth))
    models = {"no slip (LS)": wls_model(robot),
              "effective track": effective_track_model(robot, cal.multiplier),
              "WLS": wls_model(robot, SlipWeights.uniform(cal.ratio, 1.0))}
    runs, paths = {}, {}
    for name, segments in {"calibration run": calibration, **(TESTS if tests is None else tests)}.items():
        log, truth = segment_run(robot, segments, rate, source)
        paths[name] = {"truth": truth}
        runs[name] = {}
        for label, model in models.items():
            p = odometry(model, log).poses
            d = np.hypot(*(p[:, :2] - truth[:, :2]).T)
            runs[name][label] = {"rms_position_error": float(np.sqrt(np.mean(d * d))),
                                      "final_position_error": float(d[-1])}
            paths[name][label] = p
    return {"source": source, "ratio": cal.ratio, "wheel_separation_multiplier": cal.multiplier, "runs": runs,
            "paths": paths}  # the multiplier's name as calibrate's JSON (and ROS's diff_drive_controller) say it


def save_skid_figures(result: dict, directory: str | os.PathLike[str]) -> list[str]:
    """One plot per run into `directory` (created); the file names."""
    os.makedirs(directory, exist_ok=True)
    out = []
    for name, paths in result["paths"].items():
        path = os.path.join(directory, "skid-" + name.replace(",", "").replace(" ", "-") + ".png")
        save_trajectory_plot(path, paths, title=f"skid steer: {name}")
        out.append(path)
    return out
