"""``wmrkit vision locate|calibrate`` and ``wmrkit follow-line``: thesis §9.2 (camera model, positioning,
calibration, closed-loop line following by vision)."""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

import numpy as np

from ..errors import WmrkitError
from ._common import (
    OptionError,
    add_json_flag,
    add_robot_argument,
    load_robot,
    parse_angle,
    parse_value,
    print_json,
    quantity,
    renaming,
    seed,
)
from ._shown import fixed, written
from .control import check_animation_path


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``vision`` (subcommands locate, calibrate) and ``follow-line``."""
    p = commands.add_parser("vision", help="camera positioning and calibration against lines (thesis 9.2)")
    sub = p.add_subparsers(dest="vision_command", metavar="SUBCOMMAND", required=True)

    loc = sub.add_parser("locate", help="heading psi and distance h to a line, from an image or image points")
    src = loc.add_mutually_exclusive_group(required=True)
    src.add_argument("image", nargs="?", metavar="IMAGE", help="camera image (PNG, JPEG, ...)")
    src.add_argument("--points", metavar="FILE", help='JSON {"lines": [{"n": -1|0|1, "points": '
                     '[[xu, yu], [xu, yu]]}]} [px from the centre, y down]')
    loc.add_argument("--camera", required=True, metavar="FILE", help="camera file (what 'calibrate --out' writes)")
    loc.add_argument("--spacing", default="0", metavar="D",
                     help="distance between parallel lines [m, or 'cm'] (default 0: one line)")
    loc.add_argument("--lines", type=int, metavar="N", help="lines in the image: 1 (default without --spacing), "
                     "2 (road: n = -1, 1) or 3 (crops: n = -1, 0, 1, default with --spacing)")
    loc.add_argument("--z-p", default="0", metavar="Z",
                     help="distance along the optical axis from the lens to P, the tracked point (the robot's "
                          "origin) [m] (default 0: P below the lens)")
    loc.add_argument("--mode", choices=("threshold", "gradient"),
                     help="pixels of interest: the reference (threshold, default) or its contour (gradient)")
    add_json_flag(loc)
    loc.set_defaults(run=run_locate)

    cal = sub.add_parser("calibrate", help="tilt, focal length and height from two parallel stripes (9.18-9.24)")
    cal.add_argument("image", nargs="?", metavar="IMAGE", help="image of two stripes in the calibration pose")
    cal.add_argument("--rows", required=True, type=quantity("number", "--rows"),
                     metavar="A", help="image rows +-A [px] used")
    cal.add_argument("--x1", type=quantity("number", "--x1"),
                     help="half-distance between the stripes on row +A [px] (instead of IMAGE)")
    cal.add_argument("--x2", type=quantity("number", "--x2"), help="half-distance between the stripes on row -A [px]")
    cal.add_argument("--half-separation", required=True, metavar="XW",
                     help="real half-distance between the stripes [m]")
    cal.add_argument("--row-distance", required=True, metavar="YW",
                     help="real distance along the stripes between the points seen on rows +A and -A [m]")
    cal.add_argument("--size", nargs=2, type=int, metavar=("W", "H"),
                     help="image size for the camera file with --x1/--x2 (default 640 480)")
    cal.add_argument("--out", metavar="FILE", help="write the camera file (.yaml/.yml; .json for JSON)")
    add_json_flag(cal)
    cal.set_defaults(run=run_calibrate)

    f = commands.add_parser("follow-line", help="simulate vision line following (thesis 9.2.3)")
    add_robot_argument(f)
    f.add_argument("--camera", required=True, metavar="FILE", help="camera file of the robot's camera")
    f.add_argument("--gain", type=quantity("number", "--gain"),
                   default=0.3, metavar="A", help="lateral gain a_x [1/s] (default 0.3)")
    f.add_argument("--speed", default="0.1", metavar="V", help="following speed [m/s] (default 0.1)")
    f.add_argument("--period", type=quantity("time", "--period"), default=0.5, metavar="T",
                   help="control period = image time [s, or with a unit: '500 ms'] (default 0.5)")
    f.add_argument("--duration", type=quantity("time", "--duration"), default=20.0, metavar="S",
                   help="simulated time [s, or with a unit]: the whole periods within it (default 20)")
    f.add_argument("--start", nargs=2, default=("0.3", "0"), metavar=("H", "THETA"),
                   help="start: distance to the line [m, left positive] and heading [rad, or 'deg'] (default "
                        "0.3 0: the thesis's p(0) = (-0.3 m, 0, 0))")
    f.add_argument("--noise", nargs=2, metavar=("H", "PSI"), help="bounds of uniform noise on h [m] and psi [rad, "
                   "or 'deg'] (the thesis's example 2: 0.02 3deg)")
    f.add_argument("--image-noise", type=quantity("number", "--image-noise"), default=0.0, metavar="SIGMA",
                   help="image noise [grey levels] (default 0)")
    f.add_argument("--blur", type=quantity("number", "--blur"),
                   default=0.0, metavar="SIGMA", help="image blur [px] (default 0)")
    f.add_argument("--clutter", type=int, default=0, metavar="N", help="bright blobs on the ground (default 0)")
    f.add_argument("--line-width", default="0.02", metavar="W", help="painted line width [m] (default 0.02)")
    f.add_argument("--z-p", default="0", metavar="Z",
                   help="distance along the optical axis from the lens to P, the tracked point (the robot's "
                        "origin) [m] (default 0: P below the lens)")
    f.add_argument("--seed", type=seed, default=0, help="random seed (noise, clutter; default 0)")
    f.add_argument("--animate", metavar="FILE", help="write a GIF: camera view beside the plan view")
    add_json_flag(f)
    f.set_defaults(run=run_follow)


def _camera(path: str):
    from ..vision.camera import Camera

    return Camera.from_file(path)


def read_image(path: str) -> np.ndarray:
    """A grey image from a file, or a WmrkitError naming it. Images larger than the camera's ``MAX_PIXELS`` a
    side are refused: from their header when this process has not imported OpenCV yet (its decoding limits are
    read then), else once read."""
    from ..vision.camera import MAX_PIXELS

    for side in ("WIDTH", "HEIGHT"):  # a small file may decode to gigabytes (a PNG of 30000 x 30000 px: 1.8 GB)
        os.environ.setdefault(f"OPENCV_IO_MAX_IMAGE_{side}", str(MAX_PIXELS))
    from ..vision.lines import cv2_module

    if Path(path).is_dir():  # it said 'no such image file' of a folder that exists
        raise WmrkitError(f"{path}: a folder; an image is a file")
    if not Path(path).is_file():
        raise WmrkitError(f"{path}: no such image file")
    too_large = f"{path}: larger than the {MAX_PIXELS} px a side wmrkit handles (docs/limits.md)"
    cv2 = cv2_module()
    level = cv2.utils.logging.getLogLevel()
    cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)  # a broken file printed OpenCV's own line
    try:
        img = cv2.imread(path, 0)
    except cv2.error as err:  # beyond OpenCV's decoding limits (it raised a traceback), or a broken file
        raise WmrkitError(too_large if "CV_IO_MAX_IMAGE" in str(err) else f"{path}: not an image OpenCV can read "
                          f"({str(err).strip().splitlines()[-1]})") from None
    finally:
        cv2.utils.logging.setLogLevel(level)
    if img is None:
        raise WmrkitError(f"{path}: not an image OpenCV can read")
    if max(img.shape) > MAX_PIXELS:
        raise WmrkitError(too_large)
    return img


def _calibration_starts(image: str | None) -> dict[str, str]:
    """What :func:`._common.renaming` puts at the start of ``calibration: ...`` errors: the option of the measurement
    the command line gave (rows A, the ground lengths; x1, x2 without an IMAGE), after the IMAGE when there is one;
    the IMAGE for what it shows and the camera it gives."""
    given = {"rows A": "--rows", "half-separation": "--half-separation", "row distance": "--row-distance"}
    if image is None:
        given |= {"x1": "--x1", "x2": "--x2"}
    file = "" if image is None else f"{image}: "
    starts = {f"calibration: {name} ": f"{file}{option}: {name} " for name, option in given.items()}
    return starts if image is None else starts | {"image: ": file, "calibration: ": file}


def run_locate(args: argparse.Namespace) -> int:
    """``wmrkit vision locate``."""
    from ..vision.follow import locate_image
    from ..vision.positioning import check_placement, locate_points, read_points

    camera = _camera(args.camera)
    spacing = parse_value(args.spacing, "length", "--spacing")
    z_p = parse_value(args.z_p, "length", "--z-p")
    check_placement(spacing, z_p, ("--spacing", "--z-p"))  # before an image is read and its lines extracted
    if args.points is not None:
        for option, value in (("--lines", args.lines), ("--mode", args.mode)):
            if value is not None:  # it would be ignored
                raise WmrkitError(f"locate: {option} applies to an IMAGE, not to --points")
        with renaming({"points: ": f"{args.points}: ", "spacing: ": "--spacing: "}):
            fix = locate_points(camera, read_points(args.points), spacing=spacing, z_p=z_p)
    else:
        layouts = {1: (0,), 2: (-1, 1), 3: (-1, 0, 1)}
        if args.lines is not None and args.lines not in layouts:
            raise WmrkitError(f"--lines must be 1, 2 or 3, got {args.lines}")
        if args.lines == 1 and spacing > 0:  # one line (n = 0) does not use it: it would be ignored
            raise WmrkitError("locate: --spacing applies to 2 or 3 lines, not to --lines 1")
        if args.lines in (2, 3) and not spacing > 0:  # it failed after the extraction, naming 'points: lines[0]'
            raise WmrkitError(f"locate: --lines {args.lines} needs --spacing D > 0, the distance between the lines")
        ns = layouts[args.lines] if args.lines else None
        image = read_image(args.image)
        if image.shape != (camera.rows, camera.width):
            raise WmrkitError(f"{args.image}: {image.shape[1]} x {image.shape[0]} px, the camera file says "
                              f"{camera.width} x {camera.rows}")
        with renaming({"image: ": f"{args.image}: ", "spacing: ": "--spacing: "}):
            fix = locate_image(camera, image, spacing=spacing, ns=ns, z_p=z_p, mode=args.mode or "threshold")
    if args.json:
        print_json(fix.to_dict())
    else:
        print(f"psi = {fixed(fix.psi, 6)} rad ({fixed(math.degrees(fix.psi), 3)} deg), h = {fixed(fix.h, 5)} m")
        for line in fix.lines:
            print(f"  line n = {line.n:+d}: psi = {fixed(math.degrees(line.psi), 3)} deg, h = {fixed(line.h, 5)} m")
    return 0


def run_calibrate(args: argparse.Namespace) -> int:
    """``wmrkit vision calibrate``."""
    from ..vision.calibration import calibrate, calibrate_image
    from ..vision.camera import MAX_PIXELS

    xw = parse_value(args.half_separation, "length", "--half-separation")
    yw = parse_value(args.row_distance, "length", "--row-distance")
    by_points = args.x1 is not None or args.x2 is not None
    if by_points == (args.image is not None):  # both: the --x1/--x2 typed are the field (cli.main._option_place)
        raise OptionError("calibrate: give either IMAGE or both --x1 and --x2", field=None if by_points else "IMAGE")
    if by_points:
        if args.x1 is None or args.x2 is None:
            raise WmrkitError("calibrate: --x1 and --x2 go together")
        width, rows = args.size or (640, 480)
        if not 8 <= min(width, rows) <= max(width, rows) <= MAX_PIXELS:  # 0 0 asked for A below 0 px; 1e5 px was
            # refused after the calibration as the camera's 'width'
            raise WmrkitError(f"calibrate: --size: the image is {width} x {rows} px, expected 8 to {MAX_PIXELS} px a "
                              "side (a camera's)")
        for option, value, half in (("--rows", args.rows, rows / 2), ("--x1", args.x1, width / 2),
                                    ("--x2", args.x2, width / 2)):
            if value >= half:  # inside the image, as from IMAGE (NaN: named by calibrate); it named --size
                raise WmrkitError(f"calibrate: {option} {value:g} px: measured from the centre of a {width} x {rows} "
                                  f"px image (the size the camera file gets, default 640 480), it must be below "
                                  f"{half:g} px")
        with renaming(_calibration_starts(None)):
            cal = calibrate(args.x1, args.x2, args.rows, xw, yw)
    else:
        if args.size is not None:  # it would be ignored
            raise WmrkitError("calibrate: --size applies to --x1/--x2 (the camera file of an image has its size)")
        image = read_image(args.image)
        with renaming(_calibration_starts(args.image)):
            cal = calibrate_image(image, args.rows, xw, yw)
        rows, width = image.shape
    if args.out:
        cal.camera(width=width, rows=rows).to_file(args.out)
        written("camera file", args.out)
    if args.json:
        print_json(cal.to_dict())
    else:
        print(f"tilt = {cal.tilt:.6f} rad ({math.degrees(cal.tilt):.3f} deg), focal = {cal.focal_px:.2f} px, "
              f"height = {cal.height:.5g} m")
    return 0


def run_follow(args: argparse.Namespace) -> int:
    """``wmrkit follow-line``."""
    from ..vision.follow import follow_line
    from ..vision.render import Scene

    check_animation_path(args.animate)  # before the run
    robot, camera = load_robot(args.robot), _camera(args.camera)
    noise = (0.0, 0.0) if not args.noise else (parse_value(args.noise[0], "length", "--noise H"),
                                                parse_angle(args.noise[1], "--noise PSI"))
    start = (0.0, parse_value(args.start[0], "length", "--start H"), parse_angle(args.start[1], "--start THETA"))
    with renaming({"scene: width ": "--line-width: width "}):
        scene = Scene(ns=(0,), width=parse_value(args.line_width, "length", "--line-width"))
    run = follow_line(robot, camera, gain=args.gain, speed=parse_value(args.speed, "speed", "--speed"),
                      period=args.period, duration=args.duration, start=start,
                      z_p=parse_value(args.z_p, "length", "--z-p"), noise=noise, image_noise=args.image_noise,
                      blur=args.blur, clutter=args.clutter, seed=args.seed, keep_images=bool(args.animate),
                      scene=scene)
    failure = run.failure()
    if failure is not None:  # a run that did not follow the line is no result (as track's diverged loop): no
        raise WmrkitError(failure)  # animation either (it was written and announced beside the error)
    if args.animate:
        from ..vision.animation import save_animation

        save_animation(run, robot, camera, args.animate)
        written("animation", args.animate)
    summary = run.to_dict()
    if args.json:
        print_json(summary)
    else:
        settling = ("undefined (the run starts on the line)" if run.started_on_line
                    else "not reached within the run" if summary["settling_time_95"] is None
                    else f"{summary['settling_time_95']:.1f} s")
        print(f"robot {robot.name}: a = {run.gain:g} 1/s, T = {run.period:g} s, {len(run.time) - 1} periods; "
              f"final h = {fixed(summary['final_h'] * 100, 2)} cm, "
              f"psi = {fixed(math.degrees(summary['final_psi']), 2)} deg, "
              f"overshoot {fixed(summary['overshoot'] * 100, 2)} cm, 95 % settling {settling}")
    return 0

