"""Thesis §7.5 on the simulated forklift: the k11/k12 sweep, examples 1 and 2 (MD vs MQE, MCD, WLS), the five
paths (WLS, FK1, FK2, differential odometry). What ``wmrkit slip-study forklift`` runs; see ``docs/slip.md``.

The dynamic model (MD) is :mod:`wmrkit.dynamics` (Lagrange model, appendix 7.A1 Pacejka tyres, 1 kHz
semi-implicit steps). On the five paths the drive wheels are driven as on the real truck, by one speed-controlled
traction motor through an open differential (:mod:`.drivetrain`, thesis §8.6.3). Parameters the thesis leaves open
are in :data:`SETTINGS` (sample period, sensor resolutions, filter start, loops; ``docs/slip.md`` gives the source
or reasoning of each). Twists are compared at the drive-axle mid-point (the chapter-7 origin), in REP-103
axes (x forward): the thesis's ``v_y`` is ``vx`` here and its ``v_x`` is ``-vy``.
"""

from __future__ import annotations

import math
import os

import numpy as np

from .. import catalog
from ..errors import ShapeError, WmrkitError
from ..limits import check_seed
from ..odometry.logs import JointLog
from ..odometry.model import odometry_model
from ..odometry.pipeline import odometry
from .kalman import fk1_noise, fk2_noise, kalman_model, kalman_odometry
from .metrics import closure_error, j_model
from .models import mcd, mqe, normal_loads, tyre_friction, wls
from .weights import SlipWeights, wls_model

DRIVES = ("right_drive.spin", "left_drive.spin")
AXLE = (-1.0, 0.0)  # drive-axle mid-point in the catalog forklift's frame (origin at the fork tips)
#: SI units (s, rad, N m, m/s), as every JSON answer: ``slip-study forklift --json`` prints them under ``settings``.
SETTINGS = {"sample_period": 0.05, "md_step": 1e-3, "encoder_counts_per_rev": 8290,
            "steer_resolution": math.radians(1.4118), "example_duration": 10.0, "example2_torque": 30.0,
            "kalman_x0": "least squares of the first interval", "kalman_p0": "Q = k13^2 I, k13 = 1",
            "wls_thesis": (3.2e-3, 19.2), "fk1_thesis": (0.31, 1.09), "fk2_thesis": (0.28, 3.57, 0.28),
            # the five paths (section "Thesis 7.5 on the simulated forklift" of docs/slip.md gives the sources)
            "path_speed": (1.8, 2.2), "drive": "differential", "traction_settling_time": 3.5,
            "traction_overshoot": 0.15, "traction_control_period": 0.01, "traction_grip": 1.0,
            "steer_settling_time": 1.5, "encoder_phase": "uniform random per run", "seed": 0,
            "tuning_iterations": 80}
DRIVE_MODES = ("differential", "servo")
TUNED = ("WLS", "FK1", "FK2", "differential")  # the estimators of §7.5.4
PATH_NAMES = ("rectangle", "corkscrew", "d", "figure-eight", "triple-loop")


def forklift_weights(k11: float, k12: float) -> SlipWeights:
    """(7.67): mu_x12 = 1, mu_y12 = k11, mu_x3 = k12 (the steered wheel's rolling row has its free spin)."""
    return SlipWeights.of({"right_drive": (1.0, k11), "left_drive": (1.0, k11), "steer": (k12, 1.0)})


def at_axle(twist: np.ndarray) -> np.ndarray:
    """Twists of the robot origin ``(..., 3)`` moved to the drive axle: ``v + omega x (axle - origin)``."""
    t = np.array(twist, dtype=float)
    t[..., 0] -= t[..., 2] * AXLE[1]
    t[..., 1] += t[..., 2] * AXLE[0]
    return t


def sweep(robot, quick: bool = False) -> dict:
    """§7.5.3: MCD (Pacejka tyres, static loads) at 11 x 21 x 5 = 1155 input points; k11, k12 fitted so that WLS
    matches it (mean absolute twist difference, Nelder-Mead in log space)."""
    from scipy.optimize import minimize

    step = 1.0 if quick else 0.5
    u1, u2 = np.meshgrid(np.arange(0, 5 + 1e-9, step), np.arange(-5, 5 + 1e-9, step), indexing="ij")
    u1, u2 = u1.ravel(), u2.ravel()
    res = SETTINGS["steer_resolution"]
    v, w = (u1 + u2) / 2, (u1 - u2) / (2 * 0.45)
    l3 = 1.35
    heading = np.where(v != 0, np.arctan(-l3 * w / np.where(v != 0, v, 1.0)), -np.sign(w) * np.pi / 2)
    base = np.round(heading / res) * res
    offsets = (0,) if quick else (0, -2, -1, 1, 2)
    rates, beta = [], []
    for k in offsets:
        h = np.clip(base + k * 2 * res, -np.pi / 2, np.pi / 2)
        rates.append(np.stack([u1, u2], -1) / 0.23)
        beta.append(robot.beta_of_heading(h[:, None]))
    rates, beta = np.concatenate(rates), np.concatenate(beta)
    law, loads = tyre_friction(robot), normal_loads(robot)
    ref = mcd(robot, DRIVES, rates, law, beta, loads=loads)
    ok = ref.converged
    target = at_axle(ref.twist[ok])

    def cost(p: np.ndarray) -> float:
        got = at_axle(wls(robot, DRIVES, rates[ok], beta[ok], forklift_weights(*10.0 ** p)).twist)
        return float(np.mean(np.abs(got - target)))

    fit = minimize(cost, [0.0, 0.0], method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-10})
    k11, k12 = (float(x) for x in 10.0 ** fit.x)
    return {"k11": k11, "k12": k12, "points": len(rates), "converged": int(ok.sum()),
            "mean_abs_difference": float(fit.fun), "max_residual": float(np.max(ref.residual)),
            "_data": (rates, beta, ref, k11, k12)}


def example(robot, number: int, weights: SlipWeights) -> dict:
    """Examples 1 and 2 of §7.5.3: from rolling at (vx, omega) = (2 m/s, 0.3 rad/s) at the axle, the steering held
    by its servo; no torque (1) or +30 N m on each drive wheel for 1 s (2; forward in REP-103 signs)."""
    from ..dynamics.model import DynamicModel
    from ..dynamics.programs import steering_gains
    from ..dynamics.simulate import Inputs, simulate
    from ..kinematics.wheel_ik import wheel_commands

    model = DynamicModel.of(robot)
    twist0 = np.array([2.0, 0.3 * (0.0 - AXLE[0]), 0.3])  # v at the fork tips = v_axle + omega x (1, 0)
    heading = float(wheel_commands(robot, twist0).heading[robot.wheel_names.index("steer")])
    duration = SETTINGS["example_duration"]
    t = np.array([0.0, 1.0, 1.0 + 1e-6, duration])
    tau = np.zeros((4, model.n))
    if number == 2:
        for j in DRIVES:
            tau[:2, model.names.index(j)] = SETTINGS["example2_torque"]
    kp, kd = steering_gains(model, [model.names.index("steer.steer")])
    inputs = Inputs(t, tau, np.zeros_like(tau), np.zeros(model.n), np.full(model.n, np.inf), np.full((4, 1), heading),
                    kp, kd)
    sim = simulate(model, inputs, duration, step=SETTINGS["md_step"], initial_twist=twist0,
                   record_step=SETTINGS["sample_period"])
    names = list(sim.joint_names)
    rates = sim.joint_rates[:, [names.index(j) for j in DRIVES]]
    beta = sim.joint_positions[:, [names.index("steer.steer")]]
    law = tyre_friction(robot)
    twists = {"MD": at_axle(sim.twist),
              "MQE": at_axle(mqe(robot, DRIVES, rates, law, beta).twist),
              "MCD": at_axle(mcd(robot, DRIVES, rates, law, beta, loads=normal_loads(robot)).twist),
              "WLS": at_axle(wls(robot, DRIVES, rates, beta, weights).twist)}
    j = {m: j_model(twists["MD"], twists[m]) for m in ("MQE", "MCD", "WLS")}
    return {"example": number, "J": j,
            "_data": (sim.t, twists, sim.pose)}


def sensor_log(robot, sim, phase: tuple[float, float] = (0.0, 0.0)) -> JointLog:
    """The forklift's sensors sampling a simulation: drive encoders (8290 counts/rev, counting from an arbitrary
    `phase` in counts, [0, 1) each), steering encoder (1.4118 deg, absolute, nearest), at the record step."""
    names = list(sim.joint_names)
    per_count = 2 * np.pi / SETTINGS["encoder_counts_per_rev"]
    res = SETTINGS["steer_resolution"]
    offset = np.asarray(phase, dtype=float) * per_count
    spins = np.floor((sim.joint_positions[:, [names.index(j) for j in DRIVES]] + offset) / per_count) * per_count
    heading = robot.heading_of_beta(sim.joint_positions[:, [names.index("steer.steer")]])
    steer = robot.beta_of_heading(np.round(heading / res) * res)
    joints = odometry_model(robot).joints
    return JointLog(sim.t, joints, np.column_stack([spins, steer]), source="<forklift-sim>")


def drive_path(robot, name: str, speed: float, drive: str = "differential"):
    """One experiment path (``wmrkit.dynamics.programs``) at `speed` simulated with the MD (module docstring of
    :mod:`.drivetrain`): ``differential`` drives both wheels with the equal torques of one speed-controlled
    traction motor (the forklift's drivetrain, thesis §8.6.3), ``servo`` each with its own rate servo."""
    from ..dynamics.model import DynamicModel
    from ..dynamics.programs import path_program
    from ..dynamics.simulate import simulate
    from .drivetrain import TractionLoop, carrier_inertia, differential_joints, simulate_differential

    if drive not in DRIVE_MODES:
        raise WmrkitError(f"drive must be one of {', '.join(DRIVE_MODES)}, got '{drive}'")
    model = DynamicModel.of(robot)
    # the steering servo is critically damped (PD of natural frequency `bandwidth`): 2 % settling in 5.83 / wn
    inputs, duration = path_program(model, name, speed=speed, bandwidth=5.83 / SETTINGS["steer_settling_time"])
    step, record = SETTINGS["md_step"], SETTINGS["sample_period"]
    if drive == "servo":
        return simulate(model, inputs, duration, step=step, record_step=record)
    contacts = [model.contacts.index(j.partition(".")[0]) for j in differential_joints(robot)]
    grip = SETTINGS["traction_grip"] * sum(model.normal_loads()[contacts]) * robot.wheel(DRIVES[0].split(".")[0]).r
    loop = TractionLoop.tuned(carrier_inertia(model), SETTINGS["traction_settling_time"],
                              SETTINGS["traction_overshoot"], grip, SETTINGS["traction_control_period"])
    return simulate_differential(model, inputs, duration, loop, step=step, record_step=record)


def paths(robot, k11: float, k12: float, quick: bool = False, *, seed: int = 0, drive: str = "differential",
          names: tuple[str, ...] | None = None) -> dict:
    """The five experiment paths (speeds drawn in ``SETTINGS["path_speed"]`` from `seed`, encoder phases
    too), simulated with the MD through `drive` (:func:`drive_path`), odometry by every estimator; J_k (7.80)
    against the simulated final pose (open-loop programs do not close exactly), with the thesis's parameters and
    tuned on these runs as the thesis did (``optimised``), and those tuned parameters on fresh runs of seed + 1
    (``held_out``: no tuning on the data judged); ``ranking``: the thesis's finding checked on all three."""
    estimators = {"WLS": estimator_poses(robot, "WLS", (k11, k12)),
                  "WLS (thesis k)": estimator_poses(robot, "WLS", SETTINGS["wls_thesis"]),
                  **{k: estimator_poses(robot, k, SETTINGS.get(f"{k.lower()}_thesis", ())) for k in TUNED[1:]}}
    out, data, logs = {}, {}, []
    runs = _runs(robot, names or (PATH_NAMES[:2] if quick else PATH_NAMES), seed, drive)
    for name, (speed, sim, log) in runs.items():
        logs.append((log, np.asarray(sim.pose[-1])))
        est = {k: f(log) for k, f in estimators.items()}
        jk = {k: float(sum(closure_error(p, sim.pose[-1])) / 2) for k, p in est.items()}
        final = {k: float(np.hypot(*(p[-1, :2] - sim.pose[-1, :2]))) for k, p in est.items()}
        out[name] = {"J_k": jk, "final_position_error": final, "speed": speed}
        data[name] = {"truth (MD)": np.asarray(sim.pose)}
    mean = {k: float(np.mean([v["J_k"][k] for v in out.values()])) for k in estimators}
    opt = optimise(robot, logs, 25 if quick else SETTINGS["tuning_iterations"])
    for name, (log, _) in zip(data, logs, strict=True):  # the figures: tuned estimators, as Figs 7.19-7.23
        data[name] |= {f"{k} (tuned)" if v["params"] else k: estimator_poses(robot, k, v["params"])(log)
                       for k, v in opt.items()}
    fresh = [(log, np.asarray(sim.pose[-1])) for _, sim, log in _runs(robot, tuple(runs), seed + 1, drive).values()]
    held_out = {k: _mean_jk(estimator_poses(robot, k, v["params"]), fresh) for k, v in opt.items()}
    ranking = {"thesis parameters": _ranking({k: mean[k] for k in ("WLS (thesis k)", "FK1", "FK2", "differential")}),
               "tuned": _ranking({k: v["J_k"] for k, v in opt.items()}),
               "held out": _ranking(held_out)}
    return {"runs": out, "mean_J_k": mean, "optimised": opt, "held_out": {"seed": seed + 1, "J_k": held_out},
            "ranking": ranking, "drive": drive, "seed": seed, "_data": data}


def _runs(robot, names, seed: int, drive: str) -> dict:
    """``{path: (speed, simulation, log)}``: each path driven at a speed drawn from `seed`, encoder phases too."""
    rng = np.random.default_rng(seed)
    out = {}
    for name in names:
        speed, phase = float(rng.uniform(*SETTINGS["path_speed"])), tuple(rng.uniform(0.0, 1.0, 2))
        sim = drive_path(robot, name, speed, drive)
        out[name] = (speed, sim, sensor_log(robot, sim, phase))
    return out


def _mean_jk(poses_of, logs: list) -> float:
    """Mean J_k (7.80) of an estimator over ``(log, true final pose)`` runs."""
    return float(np.mean([sum(closure_error(poses_of(log), final)) / 2 for log, final in logs]))


def _ranking(jk: dict) -> dict:
    """The thesis's finding (§7.5.4) on mean J_k values: WLS and FK2 both better than FK1 and differential."""
    wls_key = next(k for k in jk if k.startswith("WLS"))
    best, rest = max(jk[wls_key], jk["FK2"]), min(jk["FK1"], jk["differential"])
    return {"order": sorted(jk, key=jk.get), "reproduced": bool(best < rest), "margin": float(rest / best)}


def optimise(robot, logs: list, maxiter: int) -> dict:
    """The thesis's tuning (§7.5.4): each estimator's parameters minimising the mean J_k over the runs
    (Nelder-Mead in log space from the thesis's optimum). ``{estimator: {"params": [...], "J_k": value}}``."""
    from scipy.optimize import minimize

    out = {}
    for name in TUNED[:3]:
        fit = minimize(lambda p, name=name: _tuning_cost(robot, name, 10.0 ** p, logs),
                       np.log10(SETTINGS[f"{name.lower()}_thesis"]), method="Nelder-Mead",
                       options={"maxiter": maxiter, "xatol": 1e-3, "fatol": 1e-7})
        out[name] = {"params": [float(v) for v in 10.0 ** fit.x], "J_k": float(fit.fun)}
    out["differential"] = {"params": [], "J_k": _mean_jk(estimator_poses(robot, "differential", ()), logs)}
    return out


def _tuning_cost(robot, name: str, params, logs: list) -> float:
    """Mean J_k of estimator `name` with `params`; infinite where the parameters are refused (a spread of noises
    or weights beyond what double precision resolves), so that the search turns back."""
    try:
        return _mean_jk(estimator_poses(robot, name, params), logs)
    except WmrkitError:
        return math.inf


def estimator_poses(robot, name: str, params):
    """``log -> poses (N, 3)`` of estimator `name` (:data:`TUNED`) with the thesis's parameters `params`:
    WLS (k11, k12) (7.67), FK1 (k14, k15), FK2 (k16, k17, k18) (7.77), differential odometry (7.79) (none)."""
    k = tuple(float(v) for v in params)
    if name == "WLS":
        return lambda log: odometry(wls_model(robot, forklift_weights(*k)), log).poses
    if name in ("FK1", "FK2"):
        noise = fk1_noise(*k) if name == "FK1" else fk2_noise(*k)
        return lambda log: kalman_odometry(kalman_model(robot, name.lower(), noise), log).poses
    return lambda log: odometry(odometry_model(robot, DRIVES), log.select(DRIVES)).poses


def forklift_study(report: str | os.PathLike[str] | None = None, quick: bool = False, *, seed: int = 0,
                   drive: str = "differential") -> dict:
    """Everything of §7.5 the simulator allows (module docstring); figures into `report` when given; `seed` and
    `drive` as in :func:`paths`."""
    check_seed(seed, ShapeError)
    robot = catalog.load("forklift")
    if robot.body is None or any(w.tyre is None for w in robot.wheels):
        raise WmrkitError("the catalog forklift lacks mass properties or tyres")
    sw = sweep(robot, quick)
    weights = forklift_weights(sw["k11"], sw["k12"])
    examples = [example(robot, n, weights) for n in (1, 2)]
    pth = paths(robot, sw["k11"], sw["k12"], quick, seed=seed, drive=drive)
    figures = [] if report is None else _figures(report, sw, examples, pth)
    strip = lambda d: {k: v for k, v in d.items() if not k.startswith("_")}  # noqa: E731
    return {"settings": SETTINGS, "sweep": strip(sw), "examples": [strip(e) for e in examples],
            "paths": {**pth["runs"], "mean_J_k": pth["mean_J_k"], "optimised": pth["optimised"],
                      "held_out": pth["held_out"], "ranking": pth["ranking"], "drive": drive, "seed": seed},
            "figures": figures}


def format_study(result: dict) -> str:
    """Human-readable summary of :func:`forklift_study`."""
    s = result["sweep"]
    lines = [f"sweep: {s['converged']}/{s['points']} MCD solves converged; k11 = {s['k11']:.4g}, "
             f"k12 = {s['k12']:.4g}, mean |MCD - WLS| = {s['mean_abs_difference']:.3g}"]
    for e in result["examples"]:
        lines.append(f"example {e['example']}: " + ", ".join(f"J_{m} = {100 * v:.3g} %" for m, v in e["J"].items()))
    p = result["paths"]

    def percents(jk: dict, sweep: str = "") -> str:  # 'WLS' -> 'WLS (sweep k)' where WLS holds the sweep's k
        return ", ".join(f"{k}{sweep if k == 'WLS' else ''} {100 * v:.3g} %" for k, v in jk.items())

    lines.append("J_k per path (WLS with the sweep's k11, k12 and with the thesis's; FK1, FK2 the thesis's):")
    for name, run in p.items():
        if isinstance(run, dict) and "speed" in run:  # a path's run ('held_out' has J_k too: printed as a path)
            lines.append(f"  {name} ({run['speed']:.3g} m/s): {percents(run['J_k'], ' (sweep k)')}")
    lines.append(f"mean J_k: {percents(p['mean_J_k'], ' (sweep k)')}")
    lines.append(f"tuned on these runs, mean J_k: {percents({k: v['J_k'] for k, v in p['optimised'].items()})}")
    lines.append(f"tuned on seed {p['seed']}, judged on fresh runs of seed {p['held_out']['seed']}, mean J_k: "
                 f"{percents(p['held_out']['J_k'])}")
    for what, r in result["paths"]["ranking"].items():
        lines.append(f"ranking ({what}): {' < '.join(r['order'])}; WLS and FK2 better than FK1 and differential: "
                     f"{'yes' if r['reproduced'] else 'no'} (margin x{r['margin']:.3g})")
    return "\n".join(lines)


def _figures(report, sw: dict, examples: list, pth: dict) -> list[str]:
    from .study_plots import save_study_figures

    return save_study_figures(report, sw, examples, pth)
