"""``wmrkit odometry ROBOT LOG``: a trajectory from a joint log (CSV or ROS 2 bag), papers 002/003, thesis (3.15)."""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import replace

import numpy as np

from ..errors import WmrkitError
from ..kinematics.linalg import characteristic_length
from ..limits import check_chunk_size
from ..odometry.bags import imu_topic
from ..odometry.covariance import CrowleyNoise
from ..odometry.diagnostics import diagnose, imu_check, odometry_name
from ..odometry.files import first_samples, is_bag, odometry_file
from ..odometry.header import header_format
from ..odometry.imu_mount import ASSUMED_LEVEL
from ..odometry.integrators import METHODS
from ..odometry.logs import TIME_UNITS
from ..odometry.model import odometry_model
from ..odometry.pipeline import OdometrySummary, check_start_pose
from ..slip.estimators import check_slip_sensing
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
    warn,
)
from ._shown import fixed, tidy, tidy_pose, written
from .slip import ESTIMATOR_METHODS, add_estimator_options, check_estimator_options, estimator_from_args, resolve_method


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``odometry``."""
    p = commands.add_parser("odometry", help="integrate a joint log (CSV or ROS 2 bag) into a trajectory")
    add_robot_argument(p)
    p.add_argument("log", metavar="LOG", help="CSV log (time, WHEEL.spin, WHEEL.steer columns) or ROS 2 bag")
    p.add_argument("--method", choices=(*METHODS, *ESTIMATOR_METHODS),
                   help=f"integration scheme of the no-slip model, {SCHEMES_HELP}; or a slip-aware estimator: wls "
                        "(weighted least squares), fk1, fk2 (Kalman filters), see docs/slip.md (default: the "
                        "description's odometry.method, else exact)")
    p.add_argument("--out", metavar="FILE", help="trajectory output: .csv, .tum/.txt (TUM), or a name without a "
                   "suffix: a new ROS 2 bag (another suffix is refused unless --format says)")
    p.add_argument("--format", dest="out_format", choices=("csv", "tum", "bag"), help="output format (default: "
                   "from the --out extension)")
    p.add_argument("--plot", metavar="FILE", help="draw the path to FILE (.png, .svg or .pdf)")
    p.add_argument("--pose", nargs=3, metavar=("X", "Y", "THETA"), default=("0", "0", "0"),
                   help="pose at the first sample: x, y [m], theta [rad, or 'deg'] (default 0 0 0)")
    p.add_argument("--sensed", action="append", metavar="WHEEL.JOINT", help="use only these sensed joints (repeat)")
    p.add_argument("--weight", action="append", metavar="WHEEL=W", default=[],
                   help="least-squares weight of a wheel's no-slip equations (default 1; repeat)")
    p.add_argument("--covariance", action="store_true",
                   help="propagate the pose covariance of Crowley's error model (Bermudez, paper 003 (17): "
                        "docs/odometry.md)")
    p.add_argument("--crowley", nargs=3, type=quantity("number", "--crowley"),
                   metavar=("K_D", "K_DTHETA", "K_THETA"),
                   help="with --covariance: Crowley's coefficients (default 0.001 0.003 0.001)")
    g = p.add_argument_group("CSV logs")
    g.add_argument("--time-column", default="time", help="name of the time column (default: time)")
    g.add_argument("--time-unit", choices=tuple(TIME_UNITS), help="unit of the time column (default: the header's "
                   "'time [ms]', else s)")
    g.add_argument("--column", action="append", metavar="JOINT=COLUMN", default=[], help="column of a joint (repeat)")
    g.add_argument("--spin", choices=("angle", "counts", "velocity"),
                   help="spin columns: cumulative angle [rad], encoder counts, or velocity [rad/s] (default: the "
                        "header's units, e.g. 'left.spin [counts:u16]', or the wheel's travel 'left.spin [m]' or "
                        "speed '[m/s]', 'left.spin [deg]', '[rpm]'; else angle)")
    g.add_argument("--steer", choices=("angle", "degrees", "counts"),
                   help="steer columns: angle [rad], degrees or counts (default: the header's units, else angle)")
    g.add_argument("--steer-convention", choices=("heading", "beta"),
                   help="steer columns hold headings (0 = straight ahead) or the thesis's beta (logs of older "
                        "wmrkit versions; default: the header's 'steer.steer [deg:beta]', else heading)")
    g.add_argument("--cpr", type=quantity("number", "--cpr"),
                   help="encoder counts per revolution (default: the catalog's, if any)")
    g.add_argument("--gear", type=quantity("number", "--gear"),
                   help="encoder revolutions per wheel revolution (default: the catalog's, else 1)")
    g.add_argument("--counter-bits", type=int, help="width of a wrapping hardware counter (default: the header's)")
    g.add_argument("--signed-counter", action="store_true", help="the counter is signed")
    g.add_argument("--steer-resolution", metavar="ANGLE", help="steering encoder resolution [rad, or 'deg']")
    g.add_argument("--heading-column", help="absolute heading column used instead of the wheels' heading: rad, or "
                   "deg when its header says so ('yaw [deg]')")
    g.add_argument("--gyro-column", help="yaw-rate column integrated instead of the wheels' heading: rad/s, or deg/s "
                   "when its header says so ('gz [deg/s]')")
    g.add_argument("--max-gap", type=quantity("time", "--max-gap"), metavar="TIME",
                   help="refuse time steps longer than this: seconds, or with a unit ('50 ms')")
    g = p.add_argument_group("ROS 2 bags")
    g.add_argument("--topic", default="/joint_states", help="JointState topic (default: /joint_states)")
    g.add_argument("--joint-name", action="append", metavar="ROS=JOINT", default=[],
                   help="map a ROS joint name to a robot joint WHEEL.spin/WHEEL.steer (repeat)")
    g.add_argument("--imu", metavar="TOPIC", help="sensor_msgs/Imu topic whose yaw checks the odometry's heading "
                   "(default: the bag's only Imu topic, if it has one)")
    g.add_argument("--imu-mount", nargs=3, metavar=("ROLL", "PITCH", "YAW"),
                   help="the IMU's orientation on the robot (URDF/REP-103 rpy, Rz Ry Rx), radians or with 'deg'; "
                        "overrides the bag's /tf_static (default: /tf_static's, else level)")
    p.add_argument("--chunk-size", type=int, default=1 << 16, help="samples per chunk (memory bound; default 65536)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_estimator_options(p)
    add_json_flag(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Parse the options into a log format, run :func:`wmrkit.odometry.files.odometry_file`, print the summary."""
    robot = load_robot(args.robot)
    settings = resolve_method(args)  # --method, --scheme: the options, else the description's odometry block
    check_estimator_options(args)
    if args.crowley is not None and not args.covariance:
        raise WmrkitError("--crowley applies with --covariance (it would be ignored)")
    args.crowley = args.crowley or (0.001, 0.003, 0.001)
    check_chunk_size(args.chunk_size, WmrkitError, "--chunk-size")
    if not all(math.isfinite(k) and k >= 0 for k in args.crowley):
        raise WmrkitError(f"--crowley: coefficients must be finite and >= 0, got {' '.join(map(str, args.crowley))}")
    with renaming({"": "--sensed: "} if args.sensed else {}):  # a joint the robot has not, or that cannot tell
        model = odometry_model(robot, args.sensed)  # the no-slip model of the diagnostics (the run's, no weights)
        if args.sensed and args.method in ESTIMATOR_METHODS:  # and with slip: one side of a skid steer
            check_slip_sensing(robot, args.sensed)
    weights = _weights(robot, args)
    joints = model.joints
    steer_option = "--steer" if args.steer else "--steer-convention" if args.steer_convention else None
    if steer_option and not any(j.endswith(".steer") for j in joints):  # it would be ignored silently
        raise WmrkitError(f"{steer_option} applies to steering columns; robot '{robot.name}' reads none (sensed: "
                          f"{', '.join(joints)}): another robot's log?")
    options = {"--cpr": args.cpr is not None, "--gear": args.gear is not None,
               "--counter-bits": args.counter_bits is not None, "--signed-counter": args.signed_counter}
    steer_res = None if args.steer_resolution is None else parse_angle(args.steer_resolution, "--steer-resolution")
    for option, value in (("--cpr", args.cpr), ("--gear", args.gear), ("--steer-resolution", steer_res)):
        if value is not None and not (math.isfinite(value) and value > 0):  # the library's messages name its fields
            raise WmrkitError(f"{option} must be a finite number > 0, got {value:g}")
    mount = parse_mount(args.imu_mount)
    if os.path.isfile(args.log) and not is_bag(args.log) and (args.joint_name or args.topic != "/joint_states"
                                                               or args.imu is not None or mount is not None):
        option = "--joint-name" if args.joint_name else "--topic" if args.topic != "/joint_states" else \
            "--imu" if args.imu is not None else "--imu-mount"
        raise WmrkitError(f"{option} applies to ROS 2 bags; LOG {args.log} is read as a CSV log (it would be ignored; "
                          "a CSV's columns are renamed by --column)")
    imu, note = imu_topic(args.log, args.imu) if is_bag(args.log) and os.path.exists(args.log) else (None, None)
    if mount is not None and imu is None and is_bag(args.log) and os.path.exists(args.log):  # it would be ignored
        raise WmrkitError(f"--imu-mount applies to the IMU the heading is checked against; {args.log} has "
                          + ("several Imu topics: choose one with --imu TOPIC" if note else "no Imu topic"))
    if note and imu is None:  # several Imu topics: the heading is not checked, a warning (batch odometry's too)
        warn(note)
    if args.max_gap is not None and not args.max_gap > 0:
        raise WmrkitError(f"--max-gap must be > 0 s, got {args.max_gap:g}")
    if args.counter_bits is not None and not 2 <= args.counter_bits <= 64:
        raise WmrkitError(f"--counter-bits must be between 2 and 64, got {args.counter_bits}")
    fmt = header_format(args.log, robot.name, joints, time_column=args.time_column, time_unit=args.time_unit,
                        columns=parse_assignments(args.column, "--column"), spin=args.spin, steer=args.steer,
                        steer_convention=args.steer_convention, counter_bits=args.counter_bits,
                        signed=args.signed_counter, cpr=args.cpr, gear=args.gear, steer_resolution=steer_res,
                        heading_column=args.heading_column, gyro_column=args.gyro_column, max_gap=args.max_gap)
    given = [o for o, v in options.items() if v]
    if given and not any(j.endswith(".spin") for j, _ in fmt.encoders):  # it would be ignored silently
        raise WmrkitError(f"{given[0]} applies to spin columns of encoder counts (--spin counts, or a header "
                          "'WHEEL.spin [counts]')")
    if steer_res is not None and not any(j.endswith(".steer") for j, _ in fmt.encoders):  # ignored as well
        raise WmrkitError("--steer-resolution applies to steer columns of encoder counts (--steer counts, or a header "
                          "'WHEEL.steer [counts]')")
    check_plot_path(args.plot)
    pose0 = [parse_value(args.pose[0], "length", "--pose X"), parse_value(args.pose[1], "length", "--pose Y"),
             parse_angle(args.pose[2], "--pose")]
    check_start_pose(np.array(pose0), "--pose")
    spec = estimator_from_args(robot, args, settings) if args.method in ESTIMATOR_METHODS else None
    slip_model = spec.build(robot) if spec is not None else None
    what = odometry_name(args.method if slip_model is not None else None, "--weight" if args.weight else None)
    # the IMU read now: a named one that fails is refused before any output is written
    check, unread = imu_check(args.log, imu, what, named=args.imu is not None, mount=mount,
                              mount_option="--imu-mount") if imu else (None, None)
    if check and check.mounting.note:  # --imu-mount and the bag's /tf_static disagree
        warn(check.mounting.note)
    summary = odometry_file(
        robot, args.log, fmt=fmt, method=args.scheme if slip_model is not None else args.method, pose0=pose0,
        sensed=args.sensed, model=slip_model,
        noise=CrowleyNoise(*args.crowley) if args.covariance else None, out=args.out, out_format=args.out_format,
        plot=args.plot, progress=not args.quiet and sys.stderr.isatty(), chunk_size=args.chunk_size,
        topic=args.topic, joint_names=parse_assignments(args.joint_name, "--joint-name"),
        weights=weights,
        sinks=[check] if check else (), check=check.judge if check else None,
        label=f"{spec.name}, {spec.scheme}" if spec is not None else None)
    for what, path in (("trajectory", args.out), ("plot", args.plot)):
        if path:
            written(what, path)
    if spec is not None:
        summary = replace(summary, method=spec.label)
    for line in slip_model.notes() if args.method in ("fk1", "fk2") else ():
        warn(line)
    names = parse_assignments(args.joint_name, "--joint-name")
    filtered = args.method if args.method in ("fk1", "fk2") else None
    diagnosis = diagnose(summary, model, lambda: first_samples(robot, args.log, model.joints, fmt=fmt, topic=args.topic,
                                                               joint_names=names), fmt, filtered=filtered)
    for line in diagnosis.warnings:
        warn(line)
    consistent, mounted = diagnosis.consistent, None
    if imu is not None:
        imu = check.topic if check and check.checked else None
        mounted = check.mounting.source if imu else None
        consistent = consistent and not (imu and check.line)
        if note and imu:  # said once checked: an IMU found, then not usable, is only the warning that says so
            print(f"wmrkit: note: {note}", file=sys.stderr)
        line = check.line if check else unread
        if line:
            warn(line)
    if args.json:
        print_json(summary.to_dict() | {"consistent": consistent}
                   | ({"imu": imu, "imu_mount": mounted} if is_bag(args.log) else {}))
    else:
        print(format_summary(summary, characteristic_length(robot))
              + (f"\nheading checked against the IMU on {imu}, its mounting "
                 f"{'' if mounted == ASSUMED_LEVEL else 'from '}{mounted}" if imu else ""))
    return 0


def format_summary(s: OdometrySummary, size: float) -> str:
    """Human-readable summary of an odometry run of a robot of characteristic length `size` [m], round-off printed
    as 0 (:mod:`._shown`): the rotation's scale is the path length over `size`, the slip indicator's an interval's
    mean travel (path length and rotation times `size`, over the intervals)."""
    x, y, th = tidy_pose(s.final_pose, s.path_length, size)
    rotation = tidy(s.rotation, s.path_length / size)
    step = (s.path_length + s.rotation * size) / max(s.samples - 1, 1)
    lines = [f"robot {s.robot}, method {s.method}: {s.samples} samples over {s.end_time - s.start_time:.6g} s",
             f"final pose: x = {fixed(x, 6)} m, y = {fixed(y, 6)} m, theta = {fixed(th, 6)} rad "
             f"({fixed(math.degrees(th), 3)} deg)",
             f"path length {s.path_length:.6g} m, rotation {rotation:.6g} rad, longest step {s.max_dt:.6g} s",
             f"slip indicator: max {tidy(s.max_slip, step):.3g} m, rms {tidy(s.rms_slip, step):.3g} m per interval"]
    if s.final_covariance is not None:
        c = s.final_covariance
        lines.append(f"final std: x {math.sqrt(c[0][0]):.4g} m, y {math.sqrt(c[1][1]):.4g} m, "
                     f"theta {math.sqrt(c[2][2]):.4g} rad")
    return "\n".join(lines)


def _weights(robot, args: argparse.Namespace) -> dict[str, float]:
    """The ``--weight WHEEL=W`` options, each refused naming the option and its wheel (the JSON error's field and
    wheel: 'weight of wheel ... must be > 0' named neither), then together (their ratio)."""
    weights = {}
    for wheel, text in parse_assignments(args.weight, "--weight").items():
        try:
            weights[wheel] = parse_value(text, "number", f"--weight {wheel}")
            odometry_model(robot, args.sensed, weights={wheel: weights[wheel]})
        except WmrkitError as err:
            raise OptionError(f"--weight {wheel}={text}: {str(err).removeprefix(f'--weight {wheel}: ')}",
                              wheel=wheel) from None
    with renaming({"weights ": "--weight: weights "}):
        odometry_model(robot, args.sensed, weights=weights)
    return weights
