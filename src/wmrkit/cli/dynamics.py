"""``wmrkit tyre`` (traction models, thesis §7.3) and ``wmrkit simulate`` (the dynamic model, §7.2)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from ..errors import WmrkitError
from ..kinematics.linalg import characteristic_length
from ..kinematics.wheel_ik import rate_kind
from ..limits import MAX_SPEED
from ..robot import TWIST_NAMES
from ._common import (
    add_json_flag,
    add_robot_argument,
    check_plot_path,
    dynamic_model,
    json_values,
    load_robot,
    parse_assignments,
    parse_value,
    print_json,
    renaming,
    warn,
)
from ._shown import no_negative_zero, tidy, tidy_pose, tidy_twist, written

#: ``simulate --step`` when not given [s].
DEFAULT_STEP = 0.001
#: ``simulate --method adaptive``'s relative tolerance (LSODA chooses its steps: ``--step`` is refused with it).
ADAPTIVE_RTOL = 1e-6


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``tyre`` and ``simulate``."""
    from ..dynamics.programs import PATHS
    from ..dynamics.tyres import TYRES

    p = commands.add_parser("tyre", help="tyre forces of a traction model at a slip ratio and slip angle (thesis 7.3)")
    p.add_argument("model", metavar="MODEL", choices=list(TYRES), help=f"one of: {', '.join(TYRES)}")
    p.add_argument("--load", required=True, metavar="FZ", help="normal load [N]")
    slip = p.add_mutually_exclusive_group()
    slip.add_argument("--slip-ratio", metavar="S",
                      help="longitudinal slip ratio (7.31), in (-1, 2]; positive: the contact slides forward "
                           "(braking) (default 0)")
    slip.add_argument("--kappa", metavar="K",
                      help="or the practical slip of SAE J670 / ISO 8855 (Pacejka), (r phi_dot - v) / v, at least -2; "
                           "positive: driving")
    p.add_argument("--slip-angle", default="0", metavar="A",
                   help="slip angle (7.35): radians, or degrees with 'deg'; positive: the contact slides left "
                        "(default 0)")
    p.add_argument("--speed", default="2", metavar="V",
                   help="wheel speed [m/s] (pacejka's coefficients use it; default 2)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE", help="a model parameter (repeat)")
    p.add_argument("--plot", metavar="FILE", help="plot the curves against slip ratio and slip angle (png/svg/pdf)")
    add_json_flag(p)
    p.set_defaults(run=run_tyre)

    p = commands.add_parser("simulate", help="simulate the dynamic model from joint torques (thesis 7.2)")
    add_robot_argument(p)
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--torques", metavar="FILE", help="CSV 'time,<wheel>.spin,...' of torques [N m]")
    source.add_argument("--path", metavar="NAME", choices=list(PATHS), help=f"built-in program: {', '.join(PATHS)}")
    p.add_argument("--tyre", choices=list(TYRES), help="tyre model for every wheel (default: each wheel's own)")
    p.add_argument("--duration", metavar="S", help="simulated time [s, or with a unit: '500 ms'] (default: the "
                                                   "program's or the file's)")
    p.add_argument("--step", metavar="DT",
                   help=f"integration step [s, or with a unit: '1 ms'] of the fixed-step methods (default "
                        f"{DEFAULT_STEP:g})")
    p.add_argument("--method", default="semi-implicit", choices=["semi-implicit", "rk4", "adaptive"],
                   help="integrator: semi-implicit Euler (default; stable with stiff tyres at 1 ms), rk4 (fixed "
                        "step, non-stiff tyres only: docs/dynamics.md) or adaptive (LSODA)")
    p.add_argument("--speed", metavar="V", help="speed of a --path program [m/s] (default 2)")
    p.add_argument("--initial-twist", nargs=3, metavar=("VX", "VY", "OMEGA"),
                   help="initial twist [m/s, m/s, rad/s], rolling without slip (a twist at which a fixed wheel "
                        "would slip sideways is refused)")
    p.add_argument("--out", metavar="FILE", help="write the samples: .csv (one row per sample) or .json")
    p.add_argument("--plot", metavar="FILE", help="plot the path and the twist (png/svg/pdf)")
    add_json_flag(p)
    p.set_defaults(run=run_simulate)


def run_tyre(args: argparse.Namespace) -> int:
    """Print the forces (and plot the curves)."""
    from ..dynamics.tyres import MAX_LOAD, Tyre, beyond_fit

    check_plot_path(args.plot)
    params = {k: math.inf if k == "k" and v.strip().lower() in ("inf", "+inf", "infinity") else  # discontinuous
              parse_value(v, "number", f"--param {k}") for k, v in parse_assignments(args.param, "--param").items()}
    with renaming({"tyre parameter ": "--param ", "tyre model ": "--param: tyre model "}):
        tyre = Tyre.of(args.model, params)
    load = _positive(parse_value(args.load, "number", "--load"), "--load", zero=True)
    if load > MAX_LOAD:
        raise WmrkitError(f"--load: at most {MAX_LOAD:g} N (a thousand tonnes on one tyre), got {load:g} N")
    a = parse_value(args.slip_angle, "angle", "--slip-angle")
    speed = _positive(parse_value(args.speed, "speed", "--speed"), "--speed")
    with renaming({f"{name.replace('-', ' ')}: ": f"--{name}: " for name in ("kappa", "slip-ratio", "slip-angle",
                                                                           "speed")}):
        s, kappa = _slip_ratio(args)
        f = tyre.forces_at_slip(load, s, a, speed)
    fx, fy = float(f.longitudinal) + 0.0, float(f.lateral) + 0.0  # no "-0"
    if not (math.isfinite(fx) and math.isfinite(fy)):
        raise WmrkitError("the model gives no finite force at these inputs")
    mu_long, mu_lat = (-fx / load + 0.0, -fy / load + 0.0) if load else (None, None)  # undefined without a load
    if mu_long is not None and not (math.isfinite(mu_long) and math.isfinite(mu_lat)):
        raise WmrkitError(f"--load: at {load:g} N the friction coefficients Fx/Fz, Fy/Fz of the {tyre.model} model's "
                          f"forces ({fx:.6g} N, {fy:.6g} N) overflow (its forces do not scale with the load)")
    if args.plot:
        _plot_tyre(tyre, load, s, a, speed, args.plot)
        written("plot", args.plot)
    warning = beyond_fit(tyre.model, speed)
    if warning:
        warn(warning)
    if args.json:
        print_json({"model": tyre.model, "params": tyre.as_dict(), "load": load, "slip_ratio": s,
                    "kappa": kappa, "slip_angle": a,
                    "speed": speed, "Fx": fx, "Fy": fy, "mu_long": mu_long, "mu_lat": mu_lat})
    else:
        print(f"{tyre.model} tyre, load {load:g} N, slip ratio {s:g} (kappa {kappa:g}), "
              f"slip angle {a:g} rad, wheel speed {speed:g} m/s")
        print(f"Fx (longitudinal) = {fx:.6g} N")
        print(f"Fy (lateral)      = {fy:.6g} N")
        print("(force of the ground on the tyre, opposing the slip"
              + ("; with shifts = 1 the magic formula's shifts add a force at any slip, zero slip included: rolling "
                 "resistance and a lateral bias, appendix 7.A1)" if tyre.as_dict().get("shifts") else ")"))
    return 0


def _check_steps(step: float, duration: float, source: str, culprit: str, step_given: bool) -> None:
    """Refuse a `step` [s] longer than the run's `duration` [s] or more than ``simulate.MAX_STEPS`` of them, the
    message starting with what to change (the field of the JSON error): --step when it was given and the duration
    fits the default step, or when nothing given set the duration; else `culprit`, what set the duration
    (``--duration D s``, ``FILE: the file ends at t = D s``, ``--speed V m/s: --path NAME at this speed lasts D s``);
    `source` says what set it after --step. '--path turn --step 10' named --path."""
    from ..dynamics.simulate import MAX_STEPS

    def fits(dt: float) -> bool:
        return 0 < dt <= duration and duration / dt <= MAX_STEPS

    if fits(step):
        return
    need = f"need 0 < step <= duration and at most {MAX_STEPS:.0e} steps"
    if (step_given and fits(DEFAULT_STEP)) or not culprit:
        raise WmrkitError(f"--step {step:g} s: {source} {duration:g} s; {need}")
    raise WmrkitError(f"{culprit}; --step {step:g} s: {need}")


def _slip_ratio(args: argparse.Namespace) -> tuple[float, float]:
    """The slip ratio (7.31) and the practical slip kappa (SAE/ISO) of ``--slip-ratio``, else of ``--kappa``
    (:func:`~wmrkit.dynamics.tyres.slip_ratio_from_kappa`), else 0 (the library's errors: ``slip ratio: ...``,
    ``kappa: ...``)."""
    from ..dynamics.tyres import kappa_from_slip_ratio, slip_ratio_from_kappa

    if args.kappa is None:
        s = parse_value(args.slip_ratio or "0", "number", "--slip-ratio")
        return s, float(kappa_from_slip_ratio(s))
    kappa = parse_value(args.kappa, "number", "--kappa")
    return float(slip_ratio_from_kappa(kappa)), kappa


def _check_program_step(step: float, name: str) -> None:
    """Refuse a fixed `step` [s] longer than the time constant of a --path program's servos (1 /
    ``programs.BANDWIDTH``), which it cannot resolve (nor the program's parts shorter than it, which they smooth):
    '--step 1e9 --duration 1e9' took one step at the inputs of t = 0, at rest: a robot that never moved, exit 0."""
    from ..dynamics.programs import BANDWIDTH

    if step > 1.0 / BANDWIDTH:
        raise WmrkitError(f"--step {step:g} s: longer than the time constant of the servos that drive the wheels of "
                          f"--path {name} (1 / {BANDWIDTH:g} rad/s = {1.0 / BANDWIDTH:.4g} s), a step cannot resolve "
                          "their motion; give a shorter step (default 0.001 s)")


def run_simulate(args: argparse.Namespace) -> int:
    """Simulate, print a summary, write and plot on request."""
    from ..dynamics.deviation import deviation_warning
    from ..dynamics.linkages import SetpointKnotsError
    from ..dynamics.programs import path_program, read_torques
    from ..dynamics.runs import at_door
    from ..dynamics.simulate import recordable_step, simulate

    if args.out is not None and Path(args.out).suffix.lower() not in (".csv", ".json"):  # not CSV under another name
        raise WmrkitError(f"--out {args.out}: the samples are written as .csv or .json")
    model = dynamic_model(load_robot(args.robot), args.robot, args.tyre)
    check_plot_path(args.plot)
    if args.speed is not None and not args.path:  # it sets a program's speed: with --torques it would be ignored
        raise WmrkitError("--speed applies to --path (the speed of a built-in program; it would be ignored)")
    speed = _positive(parse_value("2" if args.speed is None else args.speed, "speed", "--speed"), "--speed")
    if args.path:
        with renaming({"speed: ": "--speed: "}):
            inputs, duration = path_program(model, args.path, speed=speed)
    else:
        inputs = read_torques(model, args.torques)
        duration = float(inputs.time[-1])
        if duration <= 0 and args.duration is None:
            raise WmrkitError(f"{args.torques}: the file ends at t = {duration:g} s: give --duration")
    if args.duration is not None:
        duration = _positive(parse_value(args.duration, "time", "--duration"), "--duration")
    if args.step is not None and args.method == "adaptive":  # below 0.01 s it was dropped, above it set the records
        raise WmrkitError(f"--step {args.step}: the adaptive method chooses its own steps (LSODA, to a relative "
                          f"tolerance of {ADAPTIVE_RTOL:g}; it records every 0.01 s); --step applies to semi-implicit "
                          "and rk4")
    step = _positive(parse_value(f"{DEFAULT_STEP}" if args.step is None else args.step, "time", "--step"), "--step")
    source = ("--duration" if args.duration is not None else f"{args.torques}: the file ends at t =" if args.torques
              else f"--path {args.path} at --speed {speed:g} m/s lasts")  # what set the duration
    culprit = (f"--duration {duration:g} s" if args.duration is not None else
               f"{args.torques}: the file ends at t = {duration:g} s" if args.torques else
               f"--speed {speed:g} m/s: --path {args.path} at this speed lasts {duration:g} s" if args.speed else "")
    _check_steps(step, duration, source, culprit, args.step is not None)
    if args.path and args.method != "adaptive":
        _check_program_step(step, args.path)
    steps = round(duration / step)  # what the fixed steps run; a program's own duration may end within a step
    if args.method != "adaptive" and (args.duration or args.torques) and abs(duration / step - steps) > 1e-6:
        which = " is" if args.duration else ", which is"  # "the file ends at t = 1 s is not": no sentence
        raise WmrkitError(f"{source} {duration:g} s{which} not a whole number of --step {step:g} s steps: the run "
                          f"would end at t = {steps * step:g} s; give a step that divides it")
    twist = [0.0, 0.0, 0.0] if args.initial_twist is None else [
        parse_value(v, rate_kind(name), f"--initial-twist {name.upper()}")
        for name, v in zip(TWIST_NAMES, args.initial_twist, strict=True)]
    _check_rolling(model, twist)
    record = recordable_step(model, duration, step, max(step, min(0.01, duration)))
    try:  # re-checked at a shorter step where needed
        with renaming({"initial twist ": "--initial-twist "}):
            sim = simulate(model, inputs, duration, step=step, method=args.method, initial_twist=twist,
                           record_step=record, rtol=ADAPTIVE_RTOL, progress=False if args.json else None)
    except SetpointKnotsError as err:  # the knots between the torque file's rows (the program's)
        raise WmrkitError(f"{args.torques or f'--path {args.path}'}: {err}") from None
    except WmrkitError as err:  # a stop's re-check, or the step's, names the step as the CLI sets it
        raise at_door(err, "(--step) or the adaptive method") from None
    if args.out:
        _write(sim, args.out)
        written("samples", args.out)
    if args.plot:
        _plot_simulation(sim, model.robot.name, args.plot)
        written("plot", args.plot)
    pose, tw, end = sim.pose[-1], sim.twist[-1], float(sim.t[-1])  # the last sample: the record step's multiple
    travelled = float(np.sum(np.hypot(*np.diff(sim.pose[:, :2], axis=0).T)))
    max_slip = float(np.hypot(sim.slip[..., 0], sim.slip[..., 1]).max())  # a contact's slip speed, not a component
    deviation = sim.deviation()
    warnings = _tyre_warnings(model, sim.twist)
    if deviation and deviation.large:
        warnings.append(deviation_warning(model, inputs, deviation, max_slip))
    for warning in warnings:
        warn(warning)
    if args.json:
        adaptive = sim.method == "adaptive"  # no fixed step: its tolerance instead ('step 0.001 s' was printed)
        print_json({"robot": model.robot.name, "method": sim.method, "step": None if adaptive else step,
                    "rtol": ADAPTIVE_RTOL if adaptive else None, "duration": duration,
                    "samples": len(sim.t), "final_time": end, "final_pose": pose.tolist(), "final_twist": tw.tolist(),
                    "path_length": travelled, "max_slip_speed": max_slip,
                    "deviation": deviation.to_dict() if deviation else None,
                    "step_check": sim.step_check.to_dict() if sim.step_check else None, "out": args.out})
    else:
        how = (f"LSODA, rtol {ADAPTIVE_RTOL:g}, recorded every {record:g} s" if sim.method == "adaptive" else
               f"step {step:g} s")
        print(f"{model.robot.name}: {duration:g} s simulated ({sim.method}, {how}), {len(sim.t)} samples")
        size = characteristic_length(model.robot)  # round-off printed as 0 (._shown)
        x, y, theta = tidy_pose(pose, travelled, size)
        vx, vy, omega = tidy_twist(tw, size)
        print(f"final pose (t = {end:g} s): x = {x:.6g} m, y = {y:.6g} m, theta = {theta:.6g} rad")
        print(f"final twist (t = {end:g} s): vx = {vx:.6g} m/s, vy = {vy:.6g} m/s, omega = {omega:.6g} rad/s")
        print(f"distance travelled: {travelled:.6g} m; largest slip speed {max_slip:.3g} m/s")
        if deviation:  # the heading's round-off as the final pose's (tidy_pose)
            end_heading = tidy(deviation.end_heading, max(abs(deviation.end_heading), travelled / size))
            print(f"from the programmed path: {deviation.max_position:.3g} m at most (t = {deviation.max_time:g} s), "
                  f"{deviation.end_position:.3g} m and {end_heading:.3g} rad at the end")
        if sim.step_check:
            c = sim.step_check
            print(f"step check: a run at step {c.step:g} s to t = {c.until:g} s is within {c.apart.max_position:.3g} m "
                  f"and {abs(c.apart.max_heading):.3g} rad of this one")
    return 0


def _check_rolling(model, twist: list[float]) -> None:
    """Refuse an ``--initial-twist`` at which a fixed wheel would slip sideways, a gear's joints turn out of its
    ratios or the wheels steer as a linkage cannot: the start rolls without slip (the forklift, whose origin is at
    the fork tips, turns with ``vy = -omega x_axle``; a skid steer cannot turn so, nor a solid axle)."""
    from ..dynamics.linkages import linkage_breach
    from ..dynamics.programs import SLIP_TOL, feasible_twists
    from ..kinematics.wheel_ik import wheel_commands

    if not np.all(np.abs(twist) <= MAX_SPEED):  # left to initial_state's message
        return
    cmd = wheel_commands(model.robot, twist, slip_tol=SLIP_TOL)
    slip = np.abs(cmd.slip)
    if slip.max() <= SLIP_TOL:
        for c, ok in zip(model.robot.couplings, cmd.in_gear.tolist(), strict=True):
            if not ok:
                raise WmrkitError(f"--initial-twist {' '.join(f'{v:g}' for v in twist)}: it turns "
                                  f"{c.joints_words()} out of its ratios ({', '.join(f'{k:g}' for k in c.ratios)}), "
                                  "which the gear holds together, and the simulation starts rolling without slip "
                                  "(wmrkit ik says which twists the gear allows)")
        breach = linkage_breach(model, np.asarray(cmd.beta, dtype=float))
        if breach:
            raise WmrkitError(f"--initial-twist {' '.join(f'{v:g}' for v in twist)}: its wheels' steering breaks "
                              f"a linkage ({breach}), which the dynamics hold, and the simulation starts rolling "
                              "without slip")
        return
    w = int(np.argmax(slip))
    rolling = feasible_twists(model, [twist])[0]
    hint = (f"with this VX and OMEGA it rolls at VY = {rolling[1] + 0.0:.6g} m/s"  # + 0.0: no "-0"
            if np.abs(wheel_commands(model.robot, rolling).slip).max() <= SLIP_TOL else "no VY makes it roll")
    raise WmrkitError(f"--initial-twist {' '.join(f'{v:g}' for v in twist)}: fixed wheel "
                      f"'{model.robot.wheel_names[w]}' would slip sideways at {slip[w]:.3g} m/s, and the simulation "
                      f"starts rolling without slip ({hint})")


def _tyre_warnings(model, twist: np.ndarray) -> list[str]:
    """Warnings for tyres used beyond their fitted speeds: the fastest speed of a wheel's mounting point over the
    recorded twists (the tyres see their rolling components, at most that)."""
    from ..dynamics.tyres import beyond_fit

    x, y = np.array([w.position for w in model.robot.wheels]).T
    fastest = float(np.max(np.hypot(twist[:, :1] - twist[:, 2:] * y, twist[:, 1:2] + twist[:, 2:] * x)))
    return sorted({w for w in (beyond_fit(t.model, fastest) for t in model.tyres) if w})


def _positive(x: float, what: str, *, zero: bool = False) -> float:
    if x < 0 or (x == 0 and not zero):
        raise WmrkitError(f"{what}: must be {'>= 0' if zero else '> 0'}, got {x:g}")
    return x


def _write(sim, out: str) -> None:
    path = Path(out)
    try:
        if path.suffix.lower() == ".json":
            import json

            path.write_text(json.dumps(json_values(sim.to_dict())) + "\n", encoding="utf-8")
            return
        position_names, positions = sim.joint_table()
        # a joint log as `wmrkit odometry` and `calibrate` read it: units in the header, a steered wheel's heading
        # as its 'WHEEL.steer' column, every other column's name not a joint's (x, WHEEL.spin.rate, ...)
        cols = ["time [s]", "x [m]", "y [m]", "theta [rad]", "vx [m/s]", "vy [m/s]", "omega [rad/s]",
                *(f"{n.removesuffix('.heading')}.steer [rad]" if n.endswith(".heading") else f"{n} [rad]"
                  for n in position_names),
                *(f"{j}.rate [rad/s]" for j in sim.joint_names),
                *(f"{c}.{k} [N]" for c in sim.contacts for k in ("f_lat", "f_long", "load"))]
        data = np.column_stack([sim.t, sim.pose, sim.twist, positions, sim.joint_rates,
                                np.concatenate([sim.forces, sim.loads[..., None]], axis=-1).reshape(len(sim.t), -1)])
        np.savetxt(path, no_negative_zero(data), delimiter=",", header=",".join(cols), comments="", fmt="%.9g")
    except OSError as err:
        raise WmrkitError(f"--out {out}: cannot write ({err.strerror or err})") from None


def _savefig(fig, out: str) -> None:
    try:
        fig.savefig(out)
    except (OSError, ValueError) as err:
        raise WmrkitError(f"--plot {out}: cannot write ({getattr(err, 'strerror', None) or err})") from None


def _plot_tyre(tyre, load: float, s: float, a: float, speed: float, out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ss = np.linspace(-0.9, 1.0, 381)
    aa = np.linspace(-1.2, 1.2, 481)
    f1, f2 = tyre.forces_at_slip(load, ss, a, speed), tyre.forces_at_slip(load, s, aa, speed)
    ax1.plot(ss, f1.longitudinal, label="Fx (longitudinal)")
    ax1.plot(ss, f1.lateral, label="Fy (lateral)")
    ax1.set(xlabel="slip ratio", ylabel="force [N]", title=f"slip angle {a:g} rad")
    ax2.plot(aa, f2.lateral, label="Fy (lateral)")
    ax2.plot(aa, f2.longitudinal, label="Fx (longitudinal)")
    ax2.set(xlabel="slip angle [rad]", ylabel="force [N]", title=f"slip ratio {s:g}")
    for ax in (ax1, ax2):
        ax.grid(True)
        ax.legend()
    fig.suptitle(f"{tyre.model} tyre, load {load:g} N, wheel speed {speed:g} m/s")
    fig.tight_layout()
    try:
        _savefig(fig, out)
    finally:  # a failed write leaves no open figure behind (a long-lived process calls this many times)
        plt.close(fig)


def _plot_simulation(sim, name: str, out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(sim.pose[:, 0], sim.pose[:, 1], label="simulated")
    if sim.nominal_pose is not None:
        ax1.plot(sim.nominal_pose[:, 0], sim.nominal_pose[:, 1], "--", label="programmed (no slip)")
        ax1.legend()
    ax1.set(xlabel="x [m]", ylabel="y [m]", title=f"{name}: path", aspect="equal")
    for k, label in enumerate(("vx [m/s]", "vy [m/s]", "omega [rad/s]")):
        ax2.plot(sim.t, sim.twist[:, k], label=label)
    ax2.set(xlabel="time [s]", ylabel="vx, vy [m/s]; omega [rad/s]", title="twist (robot frame)")
    for ax in (ax1, ax2):
        ax.grid(True)
    ax2.legend()
    fig.tight_layout()
    try:
        _savefig(fig, out)
    finally:
        plt.close(fig)
