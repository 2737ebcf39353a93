"""``wmrkit batch odometry|calibrate|montecarlo`` and ``wmrkit sweep``: fleet-scale work on Dask (or serially)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import WmrkitError, name_list
from ..kinematics.linalg import characteristic_length
from ._common import (
    SCHEMES_HELP,
    OptionError,
    add_json_flag,
    add_robot_argument,
    check_plot_path,
    load_robot,
    parse_angle,
    parse_assignments,
    parse_mount,
    parse_value,
    print_json,
    quantity,
    renaming,
    seed,
    warn,
)
from ._shown import fixed, tidy_pose, written
from .main import one_line  # a log's name may hold a line break: the answer stays one line per log
from .slip import ESTIMATOR_METHODS, add_estimator_options, check_estimator_options, estimator_from_args, resolve_method


def _engine_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("engine")
    g.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address (default: an embedded local cluster)")
    g.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of the local cluster (default: the CPU count; 0: serial, no Dask)")
    g.add_argument("--quiet", action="store_true", help="no progress bar")
    add_json_flag(p)


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``batch`` (subcommands) and ``sweep``."""
    from ..odometry.integrators import METHODS

    batch = commands.add_parser("batch", help="fleet-scale odometry, calibration and Monte Carlo (Dask)")
    sub = batch.add_subparsers(dest="batch_command", metavar="SUBCOMMAND", required=True)

    p = sub.add_parser("odometry", help="odometry of many logs in parallel, one summary row per log (Parquet)")
    add_robot_argument(p)
    p.add_argument("logs", nargs="+", metavar="LOG", help="CSV logs, ROS 2 bags, globs or folders")
    p.add_argument("--method", choices=(*METHODS, *ESTIMATOR_METHODS),
                   help=f"integration scheme: {SCHEMES_HELP}; or a slip-aware estimator: wls (weighted least "
                        "squares), fk1 or fk2 (Kalman filters) (default: the description's odometry.method, as for "
                        "'wmrkit odometry', else exact)")
    p.add_argument("--out", metavar="FILE", help="summary table (Parquet); a rerun skips the logs done")
    p.add_argument("--trajectories", metavar="DIR", help="write each log's trajectory to DIR/NAME.tum")
    p.add_argument("--trajectory-format", choices=("tum", "csv"), help="trajectory files (default tum)")
    p.add_argument("--closed", action="store_true", help="every run ends at its start: report the closure error")
    p.add_argument("--no-resume", action="store_true", help="redo every log even if --out has it")
    p.add_argument("--imu", metavar="TOPIC", help="sensor_msgs/Imu topic of the bags whose yaw checks the odometry's "
                   "heading (default: each bag's only Imu topic, if it has one)")
    p.add_argument("--imu-mount", nargs=3, metavar=("ROLL", "PITCH", "YAW"),
                   help="the IMU's orientation on the robot (URDF/REP-103 rpy, Rz Ry Rx), radians or with 'deg'; "
                        "overrides each bag's /tf_static (default: /tf_static's, else level)")
    _log_options(p)
    add_estimator_options(p)
    _engine_options(p)
    p.set_defaults(run=run_odometry)

    p = sub.add_parser("calibrate", help="fit wheel radii and track from many logs, with confidence intervals")
    add_robot_argument(p)
    p.add_argument("logs", nargs="+", metavar="LOG", help="CSV logs, ROS 2 bags, globs or folders")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--reference", metavar="DIR", help="reference trajectories DIR/NAME.tum (or .csv) per log")
    src.add_argument("--closed", action="store_true", help="every run ends at its start")
    p.add_argument("--param", action="append", metavar="FIELDS", default=[],
                   help="a parameter: WHEEL.FIELD names moved together, comma-separated, '-' to oppose (repeat; "
                        "default: spin wheels' radii (their ratio with --closed) and the track)")
    p.add_argument("--ci", choices=("jacobian", "bootstrap"), help="interval method (default jacobian)")
    p.add_argument("--level", type=quantity("number", "--level"), default=0.95, help="confidence level (default 0.95)")
    p.add_argument("--bootstrap", type=int, metavar="B", help="bootstrap replicates of --ci bootstrap (default 200)")
    p.add_argument("--method", choices=METHODS, default="exact",
                   help=f"integration scheme: {SCHEMES_HELP} (default: exact)")
    p.add_argument("--slip", action="store_true", help="fit the slip weights (WLS ratio, effective track) instead")
    p.add_argument("--reference-noise", metavar="XY,HEADING",
                   help="the references' noise: std of x and y [m or mm] and of heading [rad or deg], under which a "
                        "still robot's reference may move unsaid (default 1mm,1e-3)")
    _log_options(p)
    _engine_options(p)
    p.set_defaults(run=run_calibrate)

    p = sub.add_parser("montecarlo", help="sensor errors sampled N times vs the analytic covariance (paper 003)")
    add_robot_argument(p)
    p.add_argument("log", nargs="?", metavar="LOG", help="CSV log taken as the truth (or --path)")
    p.add_argument("--path", metavar="NAME", help="a built-in path: square, loop, arc")
    p.add_argument("-n", "--runs", type=int, default=1000, help="Monte Carlo runs (default 1000)")
    p.add_argument("--noise", type=quantity("number", "--noise"), default=1e-4, metavar="RAD2_PER_RAD",
                   help="random-walk variance per radian of joint travel (default 1e-4)")
    p.add_argument("--resolution", metavar="ANGLE", default="0", help="encoder resolution [rad or deg] (default 0)")
    p.add_argument("--slip", type=quantity("number", "--slip"), default=0.0, metavar="STD",
                   help="std of a run's wheel slip ratio (default 0: no slip)")
    p.add_argument("--rate", type=quantity("frequency", "--rate"), metavar="HZ",
                   help="sample rate of a built-in path [Hz, or with a unit: '1 kHz'] (default 20)")
    p.add_argument("--seed", type=seed, default=0, help="random seed of the runs (default 0)")
    p.add_argument("--method", choices=METHODS, default="exact",
                   help=f"integration scheme: {SCHEMES_HELP} (default: exact)")
    p.add_argument("--plot", metavar="FILE", help="final positions with both 95 %% ellipses")
    _engine_options(p)
    p.set_defaults(run=run_montecarlo)

    p = commands.add_parser("sweep", help="a design metric over a product of description fields (Dask)")
    add_robot_argument(p)
    p.add_argument("--vary", action="append", required=True, metavar="FIELD=START:STOP:N",
                   help="wheels.NAME.FIELD or wheels[I].FIELD: a geometry field of the description, heading "
                        "(0 = straight ahead) or x, y (the position); comma-join fields moved together; units allowed")
    p.add_argument("--metric", choices=("kappa_mean", "kappa_max", "inv_kappa_mean", "singular_margin"),
                   default="kappa_mean", help="design metric (default kappa_mean; see docs/batch.md)")
    p.add_argument("--length", metavar="D", help="characteristic length [m] (default: each design's natural one)")
    p.add_argument("--configs", type=int, default=64, help="steering configurations per design (default 64)")
    p.add_argument("--chunk", type=int, default=4096, help="designs per chunk (default 4096)")
    p.add_argument("--top", type=int, default=10, help="best designs reported (default 10, at most 10000)")
    p.add_argument("--out", metavar="FILE", help="every design and its metric (Parquet)")
    p.add_argument("--plot", metavar="FILE", help="the metric over the first one or two axes")
    _engine_options(p)
    p.set_defaults(run=run_sweep)


def _log_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("logs")
    g.add_argument("--time-column", default="time", help="name of the CSV time column (default: time)")
    g.add_argument("--time-unit", choices=("s", "ms", "us", "ns"),
                   help="unit of the time column (default: the header's, 'time [ms]', else s)")
    g.add_argument("--column", action="append", metavar="JOINT=COLUMN", default=[], help="column of a joint (repeat)")
    g.add_argument("--sensed", action="append", metavar="WHEEL.JOINT", help="use only these sensed joints (repeat)")
    g.add_argument("--topic", default="/joint_states", help="JointState topic of bags (default: /joint_states)")
    g.add_argument("--joint-name", action="append", metavar="ROS=JOINT", default=[], help="bag joint names (repeat)")


def _options(args: argparse.Namespace) -> dict:
    """Log reading options: each CSV log's header units, with these settings over them (as ``wmrkit odometry``)."""
    return {"sensed": args.sensed, "topic": args.topic,
            "joint_names": parse_assignments(args.joint_name, "--joint-name") or None,
            "header": {"time_column": args.time_column, "time_unit": args.time_unit,
                       "columns": parse_assignments(args.column, "--column")}}


def _runner(args: argparse.Namespace):
    from ..batch.engine import engine

    return engine(args.scheduler, args.workers, quiet=args.json)


def _progress(args: argparse.Namespace) -> bool:
    return not args.quiet and not args.json and sys.stderr.isatty()


#: Inconsistent logs the summary line of ``batch odometry`` names before counting the rest (the JSON lists them all).
NAMED = 3


def run_odometry(args: argparse.Namespace) -> int:
    """Batch odometry; prints the number of logs done, skipped, failed and inconsistent (naming the first
    :data:`NAMED` of those, each failure). Exit code 1 when a log failed (the others are done and written; a bag
    lacking the --imu topic, or whose named IMU cannot be used, fails); an inconsistent log is a warning, as in
    ``wmrkit odometry`` (exit code 0). A note on stderr names the IMU topics found by themselves, as that command's."""
    from ..batch.fleet import batch_odometry

    robot = load_robot(args.robot)
    settings = resolve_method(args)  # --method, --scheme: the options, else the description's odometry block
    check_estimator_options(args)
    spec = estimator_from_args(robot, args, settings) if args.method in ESTIMATOR_METHODS else None
    mount = parse_mount(args.imu_mount)
    if args.trajectory_format is not None and args.trajectories is None:  # no trajectory written: it was ignored
        raise WmrkitError("--trajectory-format is the format of the --trajectories files; give --trajectories DIR")
    with _runner(args) as runner:
        estimator = {} if spec is None else {"scheme": spec.scheme, "slip_weights": spec.weights,
                                             "noise": spec.noise, "thesis_double_q": spec.thesis_double_q}
        result = batch_odometry(robot, args.logs, runner=runner, method=args.method, out=args.out,
                                trajectories=args.trajectories, trajectory_format=args.trajectory_format or "tum",
                                closed=args.closed, resume=not args.no_resume, progress=_progress(args),
                                imu=args.imu, imu_mount=mount, imu_mount_option="--imu-mount", **estimator,
                                **_options(args))
    if args.out:
        written("table", args.out)
    if args.trajectories and any(r["trajectory"] for r in result.rows):  # every log failed: none was written
        written("trajectories", args.trajectories)
    for r in result.rows:  # they were only in the table's 'warnings' column (or nowhere, without --out)
        if r["warnings"]:  # a failed log's too, said before its error as wmrkit odometry says them
            warn(one_line(f"{r['log']}: {r['warnings']}"))  # a name with a line break: one line still
    found = [r["imu"] for r in result.rows if r["imu"] and not r["error"]]
    if found and args.imu is None:  # each bag's own Imu topic, found by itself: wmrkit odometry's note
        print(f"wmrkit: note: heading of {len(found)} bag{'s' if len(found) > 1 else ''} checked against the IMU on "
              f"each bag's one sensor_msgs/msg/Imu topic ({', '.join(sorted(set(found)))}; --imu TOPIC chooses it; "
              "each row's imu names the topic)", file=sys.stderr)
    if args.json:
        print_json({"robot": robot.name, **result.to_dict(), "rows": [dict(r) for r in result.rows]})
        return 1 if result.failed else 0
    odd = result.inconsistent
    print(f"{len(result.rows)} logs: {len(result.rows) - result.failed} done ({result.skipped} from an earlier run), "
          f"{result.failed} failed, {len(odd)} inconsistent" + (f" ({one_line(name_list(odd, NAMED))})" if odd else ""))
    size = characteristic_length(robot)
    for r in result.rows:
        if r["error"]:  # a worker that died more often than allowed: its message does not name the log
            failed = r["error"] if r["error"].startswith(r["log"]) else f"{r['log']}: {r['error']}"
            print(f"  failed: {one_line(failed)}")
        elif not args.out:  # round-off printed as 0 (._shown)
            x, y, theta = (fixed(v, 4) for v in tidy_pose((r["x"], r["y"], r["theta"]), r["path_length"], size))
            print(f"  {one_line(r['log'])}: x {x} m, y {y} m, theta {theta} rad, "
                  f"path {r['path_length']:.4g} m" + (f", heading checked against the IMU on {r['imu']}"
                                                      if r["imu"] else ""))
    return 1 if result.failed else 0  # a pipeline must tell a batch with failed logs from a complete one


def _reference_noise(text: str | None) -> tuple[float, float]:
    """``--reference-noise XY,HEADING`` as ``(m, rad)``, checked as ``reference_noise`` is (default
    :data:`~wmrkit.batch.motions.REFERENCE_NOISE`)."""
    from ..batch.motions import REFERENCE_NOISE, check_reference_noise

    if text is None:
        return REFERENCE_NOISE
    parts = text.split(",")
    if len(parts) != 2:
        raise WmrkitError(f"--reference-noise: expected XY,HEADING (e.g. 1mm,0.1deg), got '{text}'")
    noise = parse_value(parts[0], "length", "--reference-noise"), parse_angle(parts[1], "--reference-noise")
    try:
        return check_reference_noise(noise)
    except WmrkitError as err:
        raise WmrkitError(f"--reference-noise: {str(err).partition(': ')[2]}") from None


def run_calibrate(args: argparse.Namespace) -> int:
    """Fleet calibration; prints each fitted field with its interval."""
    from ..batch.calibrate import (
        check_bootstrap,
        check_level,
        default_parameters,
        fleet_calibrate,
        level_text,
        load_runs,
    )
    from ..batch.fleet import expand_logs
    from ..odometry.calibration import UndeterminedError, apply_parameters

    robot = load_robot(args.robot)
    if args.slip and (args.param or args.ci or args.sensed or args.reference_noise):  # the slip fit has its own two
        given = ("--param" if args.param else "--ci" if args.ci else "--sensed" if args.sensed  # parameters, interval
                 else "--reference-noise")  # and judging, and takes every sensed joint
        raise WmrkitError(f"{given} is for the geometry fit; --slip fits slip weights")
    if args.bootstrap is not None and args.ci != "bootstrap":
        raise WmrkitError("--bootstrap is the number of replicates of --ci bootstrap")
    args.ci, args.bootstrap = args.ci or "jacobian", 200 if args.bootstrap is None else args.bootstrap
    params = ([tuple(n.strip() for n in p.split(",") if n.strip()) for p in args.param] if args.param
              else [] if args.slip else default_parameters(robot, closed=args.closed, sensed=args.sensed))
    if () in params:  # '--param ,': the library's 'an empty parameter group' named no option
        raise WmrkitError(f"--param {args.param[params.index(())]!r}: names no WHEEL.FIELD")
    if args.param:
        with renaming({"parameter '": "--param '"}):  # its names, before the logs are read
            apply_parameters(robot, params, [0.0] * len(params))
    if args.reference is not None and not Path(args.reference).is_dir():  # "LOG: no reference ... in nope"
        raise WmrkitError(f"--reference {args.reference}: "
                          f"{'not a folder' if Path(args.reference).exists() else 'no such folder'}")
    check_bootstrap(args.bootstrap, "--bootstrap")
    check_level(args.level, "--level")
    noise = _reference_noise(args.reference_noise)
    logs = expand_logs(args.logs)
    if args.slip and len(logs) < 2:  # the library's 'need at least two runs' came after a cluster had started
        raise OptionError(f"LOG: slip weights with an interval (--slip) need at least two logs, got {len(logs)}",
                          field="LOG")
    with _runner(args) as runner:
        runs = load_runs(robot, logs, reference_dir=args.reference, closed=args.closed,
                         runner=runner, options=_options(args), progress=_progress(args))
        if args.slip:
            from ..batch.calibrate import fleet_slip_calibrate

            result = fleet_slip_calibrate(robot, runs, runner=runner, level=args.level, method=args.method,
                                          progress=_progress(args))
        else:
            try:
                result = fleet_calibrate(robot, runs, params, runner=runner, ci=args.ci, level=args.level,
                                         n_boot=args.bootstrap, method=args.method, sensed=args.sensed,
                                         progress=_progress(args), reference_noise=noise)
            except UndeterminedError as err:  # at fault: the parameters chosen, else the runs given
                raise OptionError(str(err), field="--param" if args.param else "LOG") from None
    for warning in result.warnings:
        warn(one_line(warning))  # a run's name with a line break: one line still
    if args.json:
        print_json(result.to_dict())
        return 0
    if args.slip:
        print(result.format())
        return 0
    print(f"robot {robot.name}: {result.runs} runs, {result.residuals} residuals, RMS {result.rms_before:.4g} -> "
          f"{result.rms_after:.4g}; {level_text(result.level)} intervals ({result.ci})")
    for name, nominal, value, lo, hi in result.values:
        print(f"  {name:<24} {nominal:.6g} -> {value:.6g}  [{lo:.6g}, {hi:.6g}]")
    if result.not_judged:
        print(f"  not judged: {result.not_judged}")
    return 0


def run_montecarlo(args: argparse.Namespace) -> int:
    """Monte Carlo against the analytic covariance; prints both standard deviations."""
    from ..batch.montecarlo import check_study, monte_carlo, path_log, plot_monte_carlo

    robot = load_robot(args.robot)
    check_plot_path(args.plot)
    if (args.log is None) == (args.path is None):  # both: --path is the one too many, as argparse names it
        raise OptionError("give a LOG or --path NAME (one of the two)", field="LOG" if args.path is None else "--path")
    from ..odometry.files import is_bag
    from ..odometry.model import odometry_model

    model = odometry_model(robot)
    resolution = parse_angle(args.resolution, "--resolution")  # before the log is read or the path sampled
    check_study(args.runs, args.noise, resolution, args.slip, ("-n/--runs", "--noise", "--resolution", "--slip"))
    if args.log is not None and args.rate is not None:  # the log's own times are used: it was ignored silently
        raise WmrkitError("--rate sets the sample rate of a built-in --path; a LOG keeps its own times")
    if args.log is not None and Path(args.log).exists() and not Path(args.log).is_file():  # a FIFO: read forever
        raise WmrkitError(f"{args.log}: not a regular file (a folder, FIFO or device); LOG is a CSV log")
    if args.log is not None and Path(args.log).is_file() and is_bag(args.log):  # read as CSV: 'bytes not UTF-8'
        raise WmrkitError(f"{args.log}: a ROS 2 bag: batch montecarlo takes a CSV joint log as the truth (LOG), or a "
                          "built-in --path")
    if args.log is not None:  # read as its header says, as 'wmrkit odometry' reads it
        from ..limits import check_table_size
        from ..odometry.header import header_format
        from ..odometry.logs import load_csv

        check_table_size(args.log, WmrkitError, "Monte Carlo log")  # read whole, before monte_carlo's bounds
        log = load_csv(args.log, model.joints, header_format(args.log, robot.name, model.joints), robot=robot)
    else:
        rate = 20.0 if args.rate is None else args.rate
        if not rate > 0:
            raise WmrkitError(f"--rate must be > 0 Hz, got {rate}")
        with renaming({"rate": "--rate", "unknown path": "--path: unknown path",  # 'rate: expected a finite ...'
                       "profile: ": f"--path {args.path}: "}):  # a path the robot cannot drive (no option 'profile')
            log = path_log(robot, args.path, rate)
    with _runner(args) as runner:
        result = monte_carlo(robot, log, args.runs, per_rad=args.noise, resolution=resolution, slip_std=args.slip,
                             method=args.method, seed=args.seed, runner=runner, progress=_progress(args))
    if args.plot:
        plot_monte_carlo(result, args.plot)
        written("plot", args.plot)
    castors = [j for j in model.rate_joints if j in model.steer_joints]
    if castors:  # their noisy angles are both increments and configuration
        warn(f"the analytic covariance (003, first order) leaves out the configuration error that the noise of the "
             f"castor angles {', '.join(castors)} builds up: trust the Monte Carlo spread")
    if args.json:
        print_json(result.to_dict())
        return 0
    d = result.to_dict()
    print(f"robot {robot.name}: {result.runs} runs over {result.samples} samples")
    for i, name in enumerate(("x [m]", "y [m]", "theta [rad]")):
        print(f"  std {name:<12} Monte Carlo {d['std'][i]:.4g}   analytic (003) {d['analytic_std'][i]:.4g}")
    return 0


def run_sweep(args: argparse.Namespace) -> int:
    """A design sweep; prints the best designs."""
    from ..batch.sweep import STATUS, check_counts, metric_status, plot_sweep, sweep
    from ..batch.sweep_kernel import parse_vary

    check_counts(args.chunk, args.top, ("--chunk", "--top"))  # by the options' names, before the robot is read
    robot = load_robot(args.robot)
    check_plot_path(args.plot)
    axes = [parse_vary(v, robot) for v in args.vary]
    length = None if args.length is None else parse_value(args.length, "length", "--length")
    if args.configs < 1:
        raise WmrkitError(f"--configs must be >= 1, got {args.configs}")
    with _runner(args) as runner:
        result = sweep(robot, axes, args.metric, runner=runner, chunk=args.chunk, out=args.out, top=args.top,
                       length=length, configs=args.configs, progress=_progress(args))
    if args.out:
        written("table", args.out)
    if args.plot:
        plot_sweep(result, args.plot)
        written("plot", args.plot)
    if args.json:
        print_json(result.to_dict())
        return 0
    print(f"robot {robot.name}: {args.metric} over {result.total:,} designs in {result.wall_time:.3g} s")
    for b in result.best:
        fields = ", ".join(f"{a.label} = {a.shown(b[a.label]):.6g} {a.shown_unit}" for a in axes)
        status = metric_status(b[args.metric])
        shown = f"{b[args.metric]:.6g}" if status == "finite" else f"{status} ({STATUS[status]})"
        print(f"  {args.metric} {shown} (D {b['length']:.4g} m): {fields}")
    return 0
