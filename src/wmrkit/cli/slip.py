"""Slip commands (thesis ch. 7): ``wmrkit calibrate`` (slip weights, effective track) and ``wmrkit slip-study``,
and the options of the slip-aware estimators of ``wmrkit odometry --method wls|fk1|fk2``."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from ..errors import WmrkitError
from ..robot import Robot
from ._common import (
    SCHEMES_HELP,
    add_json_flag,
    add_robot_argument,
    load_robot,
    parse_assignments,
    parse_value,
    print_json,
    quantity,
    seed,
    warn,
)
from ._shown import written

ESTIMATOR_METHODS = ("wls", "fk1", "fk2")


def add_estimator_options(p: argparse.ArgumentParser) -> None:
    """Options of ``odometry --method wls|fk1|fk2``."""
    g = p.add_argument_group("slip-aware estimators (--method wls|fk1|fk2, thesis §7.4-7.5)")
    g.add_argument("--scheme", choices=("exact", "rk2", "euler", "paper002"),
                   help=f"integration scheme of the estimated twists: {SCHEMES_HELP} (default: the description's "
                        "odometry.scheme, else exact)")
    g.add_argument("--mu", action="append", metavar="WHEEL=LAT,LONG", default=[],
                   help="WLS: friction coefficients of a wheel, lateral and longitudinal (only ratios matter; "
                        "default: the wheel's slip in the description, else 1,1; repeat)")
    g.add_argument("--mu-default", metavar="LAT,LONG",
                   help="WLS: coefficients of the wheels not named by --mu (default: the description's "
                        "odometry.slip, else 1,1)")
    g.add_argument("--slip-weights", metavar="FILE", help="WLS: coefficients from 'wmrkit calibrate --json' output")
    g.add_argument("--kf-noise", nargs=3, type=quantity("number", "--kf-noise"), metavar=("PROCESS", "LAT", "LONG"),
                   help="FK1/FK2: process noise (the thesis's k13, (7.68)) [m/s per nominal sample period] and "
                        "the lateral / longitudinal row noise [m/s] (default: the description's odometry.noise, "
                        "else 1 1 1)")
    g.add_argument("--kf-period", metavar="TIME",
                   help="FK1/FK2: the nominal sample period T of the process noise, seconds or with a unit ('10 ms'): "
                        "a step of n = max(1, round(dt / T)) periods adds n Q (default: the description's "
                        "odometry.noise.period, else the median of the log's first 1000 intervals)")
    g.add_argument("--kf-wheel", action="append", metavar="WHEEL=LAT,LONG", default=[],
                   help="FK1/FK2: row noise of one wheel (default: the wheel's slip.noise in the description, "
                        "else --kf-noise's; repeat)")
    g.add_argument("--thesis-double-q", action="store_true",
                   help="FK1/FK2: add Q again after the update, as (7.75) is printed (see docs/errata.md)")


def _pair(text: str, what: str) -> tuple[float, float]:
    parts = text.split(",")
    try:
        a, b = (float(x) for x in parts)
    except ValueError:
        raise WmrkitError(f"{what}: expected two numbers LAT,LONG, got '{text}'") from None
    if not all(math.isfinite(v) and v > 0 for v in (a, b)):
        raise WmrkitError(f"{what}: values must be finite numbers > 0, got '{text}'")
    return a, b


def resolve_method(args: argparse.Namespace):
    """Fill ``args.method`` and ``args.scheme`` from the description's ``odometry`` block where the command line
    left them out (then ``exact``); returns the description's :class:`~wmrkit.slip.settings.OdometrySettings`."""
    from ..slip.settings import odometry_settings

    settings = odometry_settings(args.robot)
    if args.scheme is not None and (args.method or settings.method) not in ESTIMATOR_METHODS:
        raise WmrkitError(f"--scheme applies to --method wls, fk1 or fk2 (their integration); --method "
                          f"{args.method or settings.method or 'exact'} is a scheme itself (it would be ignored)")
    args.method_described = args.method is None and settings.method is not None  # named in its errors
    args.method = args.method or settings.method or "exact"
    args.scheme = args.scheme or settings.scheme or "exact"
    return settings


def weights_from_args(args: argparse.Namespace, settings=None, robot: Robot | None = None):
    """The WLS friction coefficients: the description's (`settings`), replaced by a ``--slip-weights`` file, then
    ``--mu-default`` and ``--mu`` options. With `robot`, a file naming a wheel it lacks is refused by place."""
    from ..slip.weights import SlipWeights

    base = settings.weights() if settings is not None else SlipWeights()
    mu: dict[str, tuple[float, float]] = {n: (a, b) for n, a, b in base.mu}
    default = base.default
    described = settings is not None and settings.slip is not None  # where each coefficient comes from (below)
    given = "the description's odometry.slip" if described else "the default 1,1"
    origin = {n: f"the description's wheels.{n}.slip" for n in mu}
    if args.slip_weights:
        default, mu = _weights_file(args.slip_weights, robot)
        given, origin = f"--slip-weights {args.slip_weights}", {n: f"--slip-weights {args.slip_weights}" for n in mu}
    if args.mu_default is not None:
        default, given = _pair(args.mu_default, "--mu-default"), "--mu-default"
    for name, value in parse_assignments(args.mu, "--mu").items():
        _check_wheel(robot, name, "--mu")
        mu[name], origin[name] = _pair(value, f"--mu {name}"), f"--mu {name}"
    weights = SlipWeights.of(mu, default)
    if robot is not None:
        _check_spread(robot, weights, {w.name: origin.get(w.name, given) for w in robot.wheels})
    return weights


def _check_spread(robot: Robot, weights, origin: dict[str, str]) -> None:
    """Refuse coefficients too far apart (``SlipWeights.row_mu``, which refused them only when odometry ran) now,
    naming the options or file that gave them."""
    from ..slip.weights import SlipWeightError

    try:
        weights.row_mu(robot)
    except SlipWeightError as err:
        if not err.wheels:
            raise
        raise WmrkitError(f"{' and '.join(dict.fromkeys(origin[w] for w in err.wheels))}: {err}") from None


def _check_wheel(robot: Robot | None, name: str, option: str) -> None:
    """Refuse `option` ``NAME=...`` for a wheel `robot` lacks, naming the option."""
    if robot is not None and name not in robot.wheel_names:
        raise WmrkitError(f"{option} {name}: robot '{robot.name}' has no wheel '{name}' (wheels: "
                          f"{', '.join(robot.wheel_names)})")


#: The layout of a ``--slip-weights`` file (what ``wmrkit calibrate --json`` writes under ``weights``).
WEIGHTS_LAYOUT = '{"weights": {"default": [LAT, LONG], "wheels": {NAME: [LAT, LONG]}}}'


def _weights_file(path: str, robot: Robot | None) -> tuple[tuple[float, float], dict[str, tuple[float, float]]]:
    """``(default, {wheel: (lat, long)})`` of a ``--slip-weights`` file; errors name the file and the field."""
    from ..errors import DescriptionError

    def fail(message: str, loc: tuple[str | int, ...]) -> None:
        raise DescriptionError(message, source=path, loc=loc)

    data = _read_json(path)
    w = data.get("weights", data) if isinstance(data, dict) else None
    loc: tuple[str | int, ...] = ("weights",) if isinstance(data, dict) and "weights" in data else ()
    if not isinstance(w, dict) or "default" not in w:
        fail(f"expected {WEIGHTS_LAYOUT} (the output of 'wmrkit calibrate --json')", loc)
    unknown = [k for k in w if k not in ("default", "wheels")]
    if unknown:
        fail(f"unknown field '{unknown[0]}' (fields: default, wheels)", loc)
    wheels = w.get("wheels", {})
    if not isinstance(wheels, dict):
        fail("must be a mapping {NAME: [LAT, LONG]}", (*loc, "wheels"))
    if robot is not None:
        lacking = next((n for n in wheels if n not in robot.wheel_names), None)
        if lacking is not None:
            fail(f"robot '{robot.name}' has no wheel '{lacking}' (wheels: {', '.join(robot.wheel_names)})",
                 (*loc, "wheels", lacking))

    def pair(value: object, at: tuple[str | int, ...]) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            fail("expected two friction coefficients [LAT, LONG]", at)
        for j, v in enumerate(value):  # type: ignore[arg-type]
            if isinstance(v, bool) or not isinstance(v, int | float) or not (math.isfinite(v) and v > 0):
                fail(f"expected a finite number > 0, got {json.dumps(v)}", (*at, j))
        return float(value[0]), float(value[1])  # type: ignore[index]

    return pair(w["default"], (*loc, "default")), {str(k): pair(v, (*loc, "wheels", k)) for k, v in wheels.items()}


def check_estimator_options(args: argparse.Namespace) -> None:
    """Refuse an estimator option that the chosen ``--method`` does not use (it would be ignored silently): the
    friction coefficients belong to wls, the noises to fk1 and fk2."""
    groups = {("wls",): {"--mu": args.mu, "--mu-default": args.mu_default is not None,
                         "--slip-weights": args.slip_weights},
              ("fk1", "fk2"): {"--kf-noise": args.kf_noise, "--kf-period": args.kf_period is not None,
                               "--kf-wheel": args.kf_wheel, "--thesis-double-q": args.thesis_double_q}}
    for applies, given in groups.items():
        option = next((o for o, value in given.items() if value), None)
        if option is not None and args.method not in applies:
            raise WmrkitError(f"{option} applies to --method {' or '.join(applies)}, not to --method {args.method}")


def estimator_from_args(robot: Robot, args: argparse.Namespace, settings=None):
    """The estimator of ``--method wls|fk1|fk2`` (:class:`~wmrkit.slip.estimators.EstimatorSpec`, integrated by
    ``--scheme``) with its options over the description's `settings`, checked by building it once."""
    from ..slip.estimators import EstimatorSpec
    from ..slip.kalman import check_period, noise_from_options

    if getattr(args, "weight", None):
        other = "--mu WHEEL=LAT,LONG" if args.method == "wls" else "--kf-wheel WHEEL=LAT,LONG"
        raise WmrkitError(f"--weight applies to the kinematic methods; with --method {args.method} use {other}")
    if getattr(args, "covariance", False):
        raise WmrkitError(f"--covariance is not available with --method {args.method} (kinematic methods only)")
    described = settings.kalman_noise() if settings is not None else None
    k = args.kf_noise or (described and (described.process, described.lateral, described.longitudinal)) \
        or (1.0, 1.0, 1.0)
    wheels = {n: (a, b) for n, a, b in (described.wheels if described else ())}
    for n, v in parse_assignments(args.kf_wheel, "--kf-wheel").items():
        _check_wheel(robot, n, "--kf-wheel")
        wheels[n] = _pair(v, f"--kf-wheel {n}")
    period = described.period if described else None
    if args.kf_period is not None:  # a time with its unit, then the filter's range, named by the option
        period = check_period(parse_value(args.kf_period, "time", "--kf-period"), "--kf-period")
    try:
        noise = noise_from_options(k[0], k[1], k[2], wheels, period) if args.method != "wls" else None
    except WmrkitError as e:  # the description's noise was checked when it was read: an option is at fault
        given = [o for o, v in (("--kf-noise", args.kf_noise), ("--kf-wheel", args.kf_wheel)) if v]
        raise WmrkitError(f"{' with '.join(given)}: {e}") from None
    weights = weights_from_args(args, settings, robot) if args.method == "wls" else None
    spec = EstimatorSpec(args.method, args.scheme, None if args.sensed is None else tuple(args.sensed), weights,
                         noise, args.thesis_double_q)
    try:
        chosen = spec.build(robot)
    except WmrkitError as err:  # a method the user did not type: say where it came from
        if not getattr(args, "method_described", False):
            raise
        raise WmrkitError(f"{args.robot}: odometry.method {args.method} (--method overrides it): {err}") from None
    rows = chosen.rows if args.method == "wls" else chosen.model.rows
    used = {robot.wheel_names[robot.row_wheels[r]] for r in rows}
    option = "--mu" if args.method == "wls" else "--kf-wheel"
    for name in parse_assignments(args.mu if args.method == "wls" else args.kf_wheel, option):
        if name not in used:  # its coefficients would weigh no row: ignored silently
            raise WmrkitError(f"{option} {name}: wheel '{name}' has no no-slip rows in the {args.method} model of the "
                              f"sensed joints (its rows hold rates that are not sensed); its coefficients would be "
                              f"ignored (wheels with rows: {', '.join(n for n in robot.wheel_names if n in used)})")
    return spec


def _read_json(path: str):
    """A JSON file read as documents are (bounded size, duplicate keys refused, located errors)."""
    from ..documents import read_document, read_file

    return read_document(read_file(path, "slip weights file"), path, "json")[0]


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``calibrate`` and ``slip-study``."""
    p = commands.add_parser("calibrate", help="calibrate slip weights and the effective track from a log with a "
                                              "reference trajectory (skid steering)")
    add_robot_argument(p)
    p.add_argument("log", metavar="LOG", help="CSV joint log (time, WHEEL.spin ... cumulative angles), read as its "
                                             "header says ('time [ms]'; default s and rad), as 'wmrkit odometry'")
    p.add_argument("--reference", required=True, metavar="TRAJ.tum", help="reference trajectory (TUM) of the run")
    p.add_argument("--scheme", choices=("exact", "rk2", "euler", "paper002"), default="exact",
                   help=f"integration scheme: {SCHEMES_HELP} (default: exact)")
    add_json_flag(p)
    p.set_defaults(run=run_calibrate)
    add_study_parser(commands)


def run_calibrate(args: argparse.Namespace) -> int:
    """Fit the WLS lateral/longitudinal ratio and the effective track; print both and their errors."""
    from ..odometry.header import header_format
    from ..odometry.logs import load_csv
    from ..odometry.model import odometry_model
    from ..odometry.trajectories import read_tum
    from ..slip.calibration import calibrate_slip

    robot = load_robot(args.robot)
    joints = odometry_model(robot).joints
    log = load_csv(args.log, joints, header_format(args.log, robot.name, joints), robot=robot)  # as odometry reads it
    if not Path(args.reference).is_file():
        raise WmrkitError(f"{args.reference}: {'not a file' if Path(args.reference).exists() else 'no such file'}")
    try:
        ref = read_tum(args.reference)
    except WmrkitError:
        raise
    except ValueError as err:
        raise WmrkitError(f"{args.reference}: not a TUM trajectory ({err})") from None
    result = calibrate_slip(robot, log, ref, method=args.scheme, source=args.reference)
    for line in result.warnings:
        warn(line)
    if args.json:
        print_json(result.to_dict())
    else:
        print(result.format())
    return 0


def add_study_parser(commands: argparse._SubParsersAction) -> None:
    """Register ``slip-study``."""
    p = commands.add_parser("slip-study", help="reproduce the slip studies: thesis §7.5 on the forklift, or the "
                                               "skid-steer comparison of docs/slip.md")
    p.add_argument("study", choices=("forklift", "skid-steer-4"), metavar="STUDY",
                   help="which study: forklift or skid-steer-4")
    p.add_argument("--report", metavar="DIR", help="write the figures into DIR")
    p.add_argument("--quick", action="store_true", help="forklift: fewer sweep points and shorter runs (a smoke run)")
    p.add_argument("--seed", type=seed, help="forklift: seed of the experiments' speeds and encoder phases (default 0)")
    p.add_argument("--drive", choices=("differential", "servo"),
                   help="forklift: drive wheels through the open differential of one traction motor (default, the "
                        "forklift's drivetrain) or each through its own rate servo")
    p.add_argument("--source", choices=("md", "quasi-static"),
                   help="skid-steer-4: motion from the dynamic model (md, default) or the quasi-static slip model")
    add_json_flag(p)
    p.set_defaults(run=run_study)


#: The options of each study (the others are refused: they would be ignored).
STUDY_OPTIONS = {"forklift": ("quick", "seed", "drive"), "skid-steer-4": ("source",)}


def run_study(args: argparse.Namespace) -> int:
    """Run a study, print its numbers (``--json``: the whole result), write figures with ``--report``."""
    for study, options in STUDY_OPTIONS.items():
        for option in options if study != args.study else ():
            if getattr(args, option) not in (None, False):  # it would be ignored
                raise WmrkitError(f"slip-study {args.study}: --{option} applies to the {study} study")
    if args.study == "skid-steer-4":
        from ..slip.skid import save_skid_figures, skid_comparison

        result = skid_comparison(load_robot("skid-steer-4"), source=args.source or "md")
        figures = save_skid_figures(result, args.report) if args.report else []
        for figure in figures:
            written("figure", figure)
        data = {"robot": args.study} | {k: v for k, v in result.items() if k != "paths"} | {"figures": figures}
        if args.json:
            print_json(data)
        else:
            print(f"calibrated: WLS ratio {data['ratio']:.4g}, effective track multiplier "
                  f"{data['wheel_separation_multiplier']:.4g}")
            for name, models in data["runs"].items():
                print(f"{name}: " + ", ".join(f"{m} rms {v['rms_position_error']:.3g} m" for m, v in models.items()))
        return 0
    from ..slip.study import forklift_study

    result = forklift_study(report=args.report, quick=args.quick, seed=0 if args.seed is None else args.seed,
                            drive=args.drive or "differential")
    for figure in result["figures"]:
        written("figure", figure)
    if args.json:
        print_json({"robot": args.study, **result})  # the study's robot, as every command's answer names it
    else:
        from ..slip.study import format_study

        print(format_study(result))
    return 0
