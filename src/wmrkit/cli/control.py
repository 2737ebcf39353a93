"""``wmrkit track`` (closed-loop tracking, thesis ch. 8) and ``wmrkit feasibility`` (Table 8.1)."""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..control.turn_limits import min_turning_radius
from ..couplings import coupling_words
from ..errors import WmrkitError
from ._common import (
    add_json_flag,
    add_robot_argument,
    check_plot_path,
    dynamic_model,
    load_robot,
    parse_value,
    print_json,
    renaming,
    say_caught,
    warn,
)
from ._shown import tidy, written

if TYPE_CHECKING:
    from ..control.feasibility import Feasibility
    from ..control.references import Reference


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``track`` and ``feasibility``."""
    p = commands.add_parser("track", help="track a reference in closed loop (thesis ch. 8): P, PI, pure pursuit, "
                                          "Stanley; continuous or sampled")
    add_robot_argument(p)
    _reference_options(p)
    p.add_argument("--from", dest="start", nargs=3, metavar=("X", "Y", "THETA"),
                   help="initial pose: x, y [m], theta (radians, or degrees with 'deg'); default on the reference")
    p.add_argument("--controller", default="p", choices=("p", "pi", "point", "pure-pursuit", "stanley"),
                   help="p: P + feedforward (8.2), the default; pi: PI + feedforward (8.3); point: (8.1); or a "
                        "geometric tracker")
    p.add_argument("--gain", metavar="A", help="p, pi, point: pole a [1/s] of the position loop (default 1)")
    p.add_argument("--gate", metavar="D", help="p, pi: apply the feedforward only within D [m] of the "
                                               "reference (8.53)")
    p.add_argument("--lookahead", metavar="L", help="pure-pursuit: lookahead distance along the path [m] "
                                                    "(default: the wheelbase of a robot with steered wheels, "
                                                    "else 2 s at the reference's top speed: 1 m at 0.5 m/s)")
    p.add_argument("--stanley-gain", metavar="K", help="stanley: cross-track gain [1/s] (default 1)")
    p.add_argument("--period", metavar="T", help="sample period [s, or with a unit: '50 ms']; without it the loop is "
                                                   "continuous")
    p.add_argument("--delay", type=int, default=0, metavar="N",
                   help="measurement delay in samples (with --period; default 0)")
    p.add_argument("--duration", metavar="S", help="time to simulate [s, or with a unit: '2 s'] (default: the "
                   "reference's length; pure pursuit and Stanley: until they reach the path's end, at most 50%% "
                   "(10 s at least) longer, within the loop's limits)")
    p.add_argument("--steering", default="closest", choices=("closest", "4-quadrant", "2-quadrant"),
                   help="which of the two steering solutions (8.9) a wheel takes (within its steer_range; default "
                        "closest)")
    p.add_argument("--dynamics", action="store_true",
                   help="close the loop through the chapter-7 dynamics with tyres (needs mass properties; "
                        "period default 0.02 s)")
    p.add_argument("--slip-model", default="none", choices=("none", "mqe", "mcd"),
                   help="with --dynamics: wheel commands from the inverse slip model (thesis future work 4) instead "
                        "of the no-slip IK (default none: the no-slip IK)")
    p.add_argument("--feedback", default="pose", choices=("pose", "odometry", "wls", "fk2", "mqe"),
                   help="with --dynamics: what the controller measures: the true pose, no-slip odometry, WLS, the "
                        "FK2 filter (weights and noise from the description), or the MQE slip model as odometry "
                        "(default pose)")
    p.add_argument("--ramp", action="store_true",
                   help="with --dynamics: reach each period's wheel commands linearly over the period (first-order "
                        "hold) instead of holding them")
    p.add_argument("--plot", metavar="FILE", help="save a plot of the run (PNG/SVG/PDF)")
    p.add_argument("--animate", metavar="FILE", help="save an animation of the run (GIF)")
    add_json_flag(p)
    p.set_defaults(run=run_track)

    p = commands.add_parser("feasibility", help="which continuity a reference needs for this robot (Table 8.1), "
                                                "where it breaks it, and the remedy")
    add_robot_argument(p)
    _reference_options(p)
    p.add_argument("--framework", default="kinematic", choices=("kinematic", "dynamic"),
                   help="kinematic (default): wheel rates may jump; dynamic: they must be continuous (§8.5)")
    p.add_argument("--point", nargs=2, metavar=("X", "Y"),
                   help="the tracked point [m, robot frame] (default the robot origin R, as Table 8.1; 'wmrkit track' "
                        "judges the point its controller tracks)")
    p.add_argument("--plot", metavar="FILE", help="save a plot of the reference with its violations")
    add_json_flag(p)
    p.set_defaults(run=run_feasibility)


#: What the tracking error of pure pursuit and Stanley measures (no time law: it grows with every corner).
PATH_FOLLOWER_NOTE = (" (from the reference's pose at the same time: this controller follows the path, not its timing, "
                      "so this measures how far ahead of or behind the reference it is; the cross-track error is its "
                      "distance from the path)")


def _reference_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--reference", required=True, metavar="FILE|NAME",
                   help="line, circle, figure-eight, square, arc-line, corner; or a TUM / CSV (t,x,y,theta) file")
    p.add_argument("--speed", metavar="V", help="speed of a built-in reference [m/s, or e.g. '1.8 km/h'] (default 0.5)")
    p.add_argument("--size", metavar="L", help="size of a built-in reference [m]: circle radius (default 3), "
                                               "figure-eight half width (6), square side (6), arc-line radius (1.5), "
                                               "corner leg (3); a line has none; the circle, figure-eight and "
                                               "arc-line are larger by default for a robot whose steering limits "
                                               "its turns: their tightest turn 1.5 times its minimum turning radius; "
                                               "and the square and corner: legs of that radius plus 4 m, to recover "
                                               "from each corner")


#: What the size of each built-in reference measures (``--size``).
SIZE_WORDS = {"circle": "radius", "figure-eight": "half width", "square": "side", "arc-line": "radius",
              "corner": "leg"}


def _reference(args: argparse.Namespace, robot) -> tuple[Reference, float | None, str]:
    """`robot`'s ``--reference`` (with ``--speed``, ``--size``), the same for ``track`` and ``feasibility``: without
    ``--size``, a built-in shape whose turns tighten with its size is one the robot can drive
    (:func:`wmrkit.control.references.default_size` at :func:`min_turning_radius`). Returns the reference, its size
    [m] (None: a file, or the line) and the words naming it (``circle of radius 6 m (...)``)."""
    from ..control.references import (
        BUILTIN,
        CORNER_RECOVERY,
        TIGHTEST_TURN,
        TURN_MARGIN,
        default_size,
        resolve_reference,
    )

    speed = None if args.speed is None else _positive(args.speed, "--speed", "speed")
    size = None if args.size is None else _positive(args.size, "--size", "length")
    name = args.reference
    turning = min_turning_radius(robot)
    if size is None and name in BUILTIN and name != "line":
        size = default_size(name, turning)
    with renaming({f"reference '{name}' at ": f"reference '{name}' (--speed, --size) at ",  # too many samples
                   "no built-in reference ": "--reference: no built-in reference "}):
        reference = resolve_reference(name, speed=speed, size=size)
    if size is None:
        return reference, None, reference.name
    words = f"{name} of {SIZE_WORDS[name]} {size:g} m"
    if args.size is None and size > BUILTIN[name][2] and name not in TIGHTEST_TURN:  # square, corner
        words += (f" (the robot's minimum turning radius, {turning:.4g} m, plus {CORNER_RECOVERY:g} m at least: "
                  "room to recover from each corner)")
    elif args.size is None and size > BUILTIN[name][2]:
        tightest = "" if TIGHTEST_TURN[name] == 1 else f", of radius {TIGHTEST_TURN[name] * size:.4g} m,"
        words += (f" (its tightest turn{tightest} at least {TURN_MARGIN:g} times the robot's minimum turning radius, "
                  f"{turning:.4g} m)")
    return reference, size, words


def _lookahead(args: argparse.Namespace, robot, reference) -> tuple[float | None, str]:
    """Pure pursuit's ``--lookahead`` [m] (default :func:`wmrkit.control.trackers.default_lookahead` on
    `reference`) and the words the summary line names it with (None and empty for another controller)."""
    from ..control.points import control_point
    from ..control.trackers import (
        MIN_LOOKAHEAD_TIME,
        check_lookahead,
        default_lookahead,
        default_wheelbase,
        steers,
        top_speed,
    )

    if args.lookahead is not None:
        value = _positive(args.lookahead, "--lookahead", "length")
        check_lookahead(value, "--lookahead")
        return value, f" (lookahead {value:g} m)"
    if args.controller != "pure-pursuit":
        return None, ""
    cp, speed = control_point(robot), top_speed(reference)
    value = default_lookahead(cp, speed)
    wheelbase = value == default_wheelbase(cp) and (steers(cp) or speed == 0)
    why = (", the robot's wheelbase" if wheelbase else
           f", {MIN_LOOKAHEAD_TIME:g} s at the reference's top speed {speed:.4g} m/s")
    return value, f" (lookahead {value:.4g} m{why})"


def _positive(text: str, what: str, kind: str = "number") -> float:
    value = parse_value(text, kind, what)  # type: ignore[arg-type]
    if not value > 0 or value == float("inf"):
        raise WmrkitError(f"{what}: expected a positive number, got {text}")
    return value


def _non_negative(text: str, what: str) -> float:
    """A gain [1/s] >= 0 (0: no feedback), named by its option when refused (it was named 'gain' or 'stanley
    gain', as the Python keyword)."""
    value = parse_value(text, "number", what)
    if not 0 <= value < float("inf"):
        raise WmrkitError(f"{what}: expected a gain >= 0 [1/s], got {text}")
    return value


#: The options of each controller (``track``): any other controller would ignore them, so they are refused there.
CONTROLLER_OPTIONS = {"--gain": ("p", "pi", "point"), "--gate": ("p", "pi"),
                      "--lookahead": ("pure-pursuit",), "--stanley-gain": ("stanley",)}


def _check_controller_options(args: argparse.Namespace) -> None:
    for option, controllers in CONTROLLER_OPTIONS.items():
        if getattr(args, option[2:].replace("-", "_")) is not None and args.controller not in controllers:
            raise WmrkitError(f"{option} applies to --controller {' or '.join(controllers)}, not "
                              f"{args.controller} (it would be ignored)")


def check_animation_path(path: str | None, suffixes: tuple[str, ...] = (".gif",)) -> None:
    """Refuse, before the work it shows, an ``--animate`` file whose extension is not one of `suffixes` (a
    ``.png`` was written as a single still frame, exit 0; a ``.mp4`` refused after the answer was printed)."""
    if path is not None and Path(path).suffix.lower() not in suffixes:
        raise WmrkitError(f"--animate {path}: the animation is written as {' or '.join(suffixes)}")


#: The keywords of :func:`wmrkit.control.track.track` its errors start with, and the options of ``track``.
TRACK_KEYWORDS = {"initial_pose: ": "--from: initial pose ", "period: expected": "--period: expected",
                  "delay: ": "--delay: "}  # '--delay: ... needs a sample period (--period)' is --delay's error, as
# '--feedback needs --dynamics' is --feedback's


def run_track(args: argparse.Namespace) -> int:
    """Simulate, then print a summary (or the time series as JSON); warnings on stderr (and in the JSON)."""
    from ..control.laws import SamplingWarning
    from ..control.track import track

    check_plot_path(args.plot)
    check_animation_path(args.animate)
    robot = load_robot(args.robot)
    if args.dynamics:  # what the description lacks for the dynamics, named in its file
        dynamic_model(robot, args.robot, say=False)  # the run builds it again and says its linkages
    reference, size, described = _reference(args, robot)
    start = None
    if args.start:
        start = [parse_value(args.start[0], "length", "--from X"), parse_value(args.start[1], "length", "--from Y"),
                 parse_value(args.start[2], "angle", "--from THETA")]
    _check_controller_options(args)
    gain = 1.0 if args.gain is None else _non_negative(args.gain, "--gain")
    lookahead, ahead_words = _lookahead(args, robot, reference)
    stanley_gain = 1.0 if args.stanley_gain is None else _non_negative(args.stanley_gain, "--stanley-gain")
    period = None if args.period is None else _positive(args.period, "--period", "time")
    duration = None if args.duration is None else _positive(args.duration, "--duration", "time")
    gate = None if args.gate is None else _positive(args.gate, "--gate", "length")
    weights = noise = None
    if (args.slip_model != "none" or args.feedback != "pose" or args.ramp) and not args.dynamics:
        option = "slip-model" if args.slip_model != "none" else "feedback" if args.feedback != "pose" else "ramp"
        raise WmrkitError(f"--{option} needs --dynamics (it acts on the dynamic plant with tyres)")
    if args.feedback in ("wls", "fk2"):
        from ..slip.settings import odometry_settings

        settings = odometry_settings(args.robot)
        weights, noise = settings.weights(), settings.kalman_noise()
    failed: WmrkitError | None = None
    with warnings.catch_warnings(record=True) as caught:  # every one said below (after: one passed on is not caught)
        warnings.simplefilter("always", UserWarning)  # wmrkit's classes (a model built twice says it once)
        try:
            with renaming(TRACK_KEYWORDS):
                run = track(robot, reference, controller=args.controller, gain=gain, gate=gate, initial_pose=start,
                            lookahead=lookahead, stanley_gain=stanley_gain, period=period, delay=args.delay,
                            duration=duration, policy=args.steering, dynamics=args.dynamics,
                            slip_model=args.slip_model, feedback=args.feedback, weights=weights, noise=noise,
                            ramp=args.ramp, progress=sys.stderr.isatty() and not args.json)
        except WmrkitError as err:
            failed = err
    foretold = [str(w.message) for w in caught if issubclass(w.category, SamplingWarning)] if failed else []
    say_caught(caught, skip=(SamplingWarning,) if foretold else ())  # the others said before the error
    if failed is not None:  # the sampling warning that foretold it, in the one line of the error
        if not foretold:
            raise failed
        message = f"{failed} ({'; '.join(foretold)})"
        try:
            joined = type(failed)(message)
        except TypeError:  # a class that takes more (UnstableStepError: the steps and the door): said as it is
            joined = WmrkitError(message)
        raise joined from None
    for tight in tight_turns(run.feasibility):  # and where the law asks the car to back up, at the other stop
        back = run.t[run.twist[:, 0] < -1e-9]
        warn(f"{tight_words(tight, 'the tracked point')}: it cannot follow this reference (its steering is held at "
             "its stops)" + (
                 f"; the law backs it up where the reference runs beside it (t = {back[0]:.4g} to {back[-1]:.4g} s; "
                 "backing up, a car turns the other way at the same steering, so its steering swings to the other "
                 "stop)" if len(back) else ""))
    for line in range_warnings(robot, run.range_violations()):
        warn(line)
    for v in run.held_off_axle():  # no twist_miss through the dynamics
        moved = (f"so the kinematic loop moved the robot with the least-squares twist of its wheels, up to "
                 f"{v['twist_miss'][0]:.3g} m/s and {v['twist_miss'][1]:.3g} rad/s off the commanded one"
                 if "twist_miss" in v else "and through the dynamics their tyres slip sideways")
        linkage = coupling_words(robot.couplings, v["coupling"])
        warn(f"{linkage} held them up to {math.degrees(v['axle_miss']):.3g} deg off the "
             f"axles the commanded twist needs for {v['duration']:.3g} s (t = {v['from']:.4g} to {v['to']:.4g} s): "
             f"that twist is not realisable without the wheels scrubbing, {moved}; the tracking errors are the result")
    for c, ok in zip(robot.couplings, run.commands.in_gear.all(axis=0).tolist(), strict=True):
        if not ok:  # the kinematic plants hold a gear of steering joints only; the dynamics hold every gear
            warn(f"the commands turn {c.joints_words()} out of its ratios (ratios "
                 f"{', '.join(f'{k:g}' for k in c.ratios)}); " + (
                     "the dynamics hold the gear, so its servos fight and the robot cannot follow them"
                     if args.dynamics else "the kinematic loop holds the ratios of steering joints only, not these "
                     "(it drives each on its own), so the real robot cannot drive this run (--dynamics holds the "
                     "gear)"))
    slipping = [] if args.dynamics else run.slip_violations()  # the dynamics' tyres do slip, and show it
    if slipping:
        warn(f"wheel{'s' if len(slipping) > 1 else ''} {', '.join(repr(v['wheel']) for v in slipping)} must slip "
             f"sideways to move as commanded (t = {min(v['from'] for v in slipping):.4g} to "
             f"{max(v['to'] for v in slipping):.4g} s): the kinematic loop moved the robot as commanded, so its errors "
             "do not show the scrubbing (--dynamics simulates it with tyres)")
    warn_infeasible(run.feasibility, reference.duration if run.t[-1] > reference.duration else None,
                    instant=not args.dynamics, turns=False)
    if args.plot or args.animate:
        from ..control.plots import animate_run, plot_run

        if args.plot:
            plot_run(run, args.plot)
            written("plot", args.plot)
        if args.animate:
            animate_run(run, args.animate)
            written("animation", args.animate)
    if args.json:
        looked = {"lookahead": lookahead} if args.controller == "pure-pursuit" else {}
        print_json({**run.to_dict(), "reference_name": reference.name, "reference_size": size, **looked})
    else:
        reach = max(float(np.abs(reference.pose[:, :2]).max()), float(np.abs(run.tracked[:, :2]).max()))
        s = {k: tidy(v, reach) for k, v in run.summary().items()}  # errors of positions of this reach: round-off 0
        print(f"robot {robot.name}, reference {described}, controller {args.controller}{ahead_words}, "
              f"{'continuous' if run.period is None else f'period {run.period:g} s, delay {args.delay}'}"
              f"{', through the dynamics' if args.dynamics else ''}"
              f"{f', {args.slip_model.upper()} commands' if args.slip_model != 'none' else ''}"
              f"{f', {args.feedback} feedback' if args.feedback != 'pose' else ''}")
        print(f"tracking error [m]: rms {s['rms_error']:.4g}, max {s['max_error']:.4g}, final {s['final_error']:.4g}"
              f"{PATH_FOLLOWER_NOTE if args.controller in ('pure-pursuit', 'stanley') else ''}")
        print(f"cross-track error [m]: rms {s['rms_cross_track']:.4g}, max {s['max_cross_track']:.4g}")
    return 0


#: How every warning of a wheel held at a steering range's end ends.
CANNOT_FOLLOW = "the robot cannot follow this reference there (its wheels scrub; the tracking errors are the result)"


def range_warnings(robot, violations: list[dict]) -> list[str]:
    """The warnings of a run's :meth:`~wmrkit.control.tracking_run.TrackingRun.range_violations`: one per wheel
    steered on its own, and one per linkage or steering gear, naming each wheel it held at its end and those it held
    with it (the catalog car's corner said four lines, two of them the same event, naming the linkage by its channel
    name)."""
    from ..control.tracking_run import steers_together

    def asked(v: dict) -> str:
        lo, hi = (math.degrees(a) for a in robot.wheel(v["wheel"]).steer_range)
        return (f"'{v['wheel']}' was asked to steer beyond its range [{lo:g}, {hi:g}] deg for {v['duration']:.3g} s "
                f"(t = {v['from']:.4g} to {v['to']:.4g} s), held at its end")

    def at(v: dict) -> str:
        lo, hi = (f"{math.degrees(a):.4g}" for a in v["headings"])
        return f"'{v['wheel']}' at {lo if lo == hi else f'{lo} to {hi}'} deg"

    holders = {j.removesuffix(".steer"): c.channel_name for c in robot.couplings if steers_together(c)
               for j in c.joints if j.endswith(".steer")}
    out = [f"wheel {asked(v)}: {CANNOT_FOLLOW}" for v in violations if v["wheel"] not in holders]
    for channel in dict.fromkeys(holders[v["wheel"]] for v in violations if v["wheel"] in holders):
        vs = [v for v in violations if holders.get(v["wheel"]) == channel]
        held = [v for v in vs if "held_by" in v]
        parts = []
        for v in (v for v in vs if "held_by" not in v):  # a wheel at its own end, and those held with it then
            with_it = [at(h) for h in held if (h["from"], h["to"]) == (v["from"], v["to"])]
            parts.append(asked(v) + (f", and {', '.join(with_it)} with it (within its range)" if with_it else ""))
        paired = {(v["from"], v["to"]) for v in vs if "held_by" not in v}
        parts += [f"{at(h)} (within its range) for {h['duration']:.3g} s (t = {h['from']:.4g} to {h['to']:.4g} s)"
                  for h in held if (h["from"], h["to"]) not in paired]
        out.append(f"{coupling_words(robot.couplings, channel)} held them at a steering limit: {'; '.join(parts)}: "
                   f"{CANNOT_FOLLOW}")
    return out


#: Said after a remedy that re-orients a wheel alone, in a kinematic run (its plant steers the wheels instantly).
INSTANT_NOTE = (" (this kinematic run turns the wheels instantly, without the stop; --dynamics drives "
                "the steering servos)")


def verdict_line(verdict: Feasibility, point: str = "the tracked point") -> str:
    """One line: Table 8.1's column for `point`, the framework, and whether the reference can be followed."""
    r = verdict.requirement
    return f"Table 8.1 (column '{r.column}' for {point}, {r.framework} framework): {_feasible(verdict)}"


def _feasible(verdict: Feasibility) -> str:
    """``feasible: yes`` or ``feasible: NO (n violation(s))``."""
    return "feasible: yes" if verdict.feasible else f"feasible: NO ({len(verdict.violations)} violation(s))"


def tight_turns(verdict: Feasibility | None) -> list:
    """The :class:`~wmrkit.control.feasibility.TightTurn` violations of `verdict` (None: none)."""
    from ..control.feasibility import TightTurn

    return [v for v in verdict.violations if isinstance(v, TightTurn)] if verdict else []


def tight_words(v, whose: str) -> str:
    """The words of a tight turn `v` (``TightTurn``), `whose`: the point judged, for ``track`` and ``feasibility``."""
    return f"the reference {v.words()}, tighter than the robot can drive: {v.remedy.replace('the point', whose, 1)}"


def warn_infeasible(verdict: Feasibility | None, end: float | None = None, *, instant: bool = False,
                    turns: bool = True) -> None:
    """Warn where Table 8.1 says the robot cannot follow the reference it tracked (`verdict`: a run's
    ``feasibility``), a line per remedy and set of times, in feasibility's words; `end` [s]: where the reference
    ended before the run did (it then holds its last pose at rest: the stop is judged as any jump); `instant`: the
    run's plant turned the wheels instantly (the kinematic loop), so where the remedy re-orients a wheel alone the
    run did not stop, and the line says so (it read as contradicting the 1e-10 m errors the run printed); `turns`:
    a line per stretch tighter than the steering stops allow too (``track`` says them itself)."""
    broken: dict[tuple[str, tuple[float, ...]], list[str]] = {}
    tight = tight_turns(verdict)
    table = [v for v in verdict.violations if v not in tight] if verdict else []  # the tight turns: said apart
    for kind, remedy in dict.fromkeys((v.kind, v.remedy) for v in table):
        times = tuple(v.t for v in table if (v.kind, v.remedy) == (kind, remedy))
        broken.setdefault((remedy, times), []).append(kind)
    for (remedy, times), kinds in broken.items():
        more = f" and {len(times) - 5} more times" if len(times) > 5 else ""
        stop = (f" ({'' if len(times) == 1 else f't = {end:.4g} s: '}the reference's end: the run went on past it, "
                "where the reference stops, holding its last pose)" if end in times else "")
        warn(f"the robot cannot follow this reference with zero error (Table 8.1, column "
             f"'{verdict.requirement.column}' for the tracked point, {verdict.requirement.framework} framework): "
             f"{' and '.join(kinds)} at t = {', '.join(f'{t:.4g}' for t in times[:5])} s{more}{stop}: {remedy}"
             + (INSTANT_NOTE if instant and remedy.startswith("stop and re-orient the orientable wheel") else ""))
    for v in tight if turns else ():
        warn(f"{tight_words(v, 'the tracked point')}: the robot cannot follow this reference")


def run_feasibility(args: argparse.Namespace) -> int:
    """Print the Table 8.1 requirement and every violation with its remedy; exit 1 when there is one (the answer is
    no)."""
    from ..control.feasibility import feasibility
    from ..control.tracking_run import steers_together

    check_plot_path(args.plot)
    robot = load_robot(args.robot)
    reference, size, described = _reference(args, robot)
    point = None if args.point is None else (parse_value(args.point[0], "length", "--point X"),
                                              parse_value(args.point[1], "length", "--point Y"))
    with renaming({"point: ": "--point: "}):
        result = feasibility(robot, reference, args.framework, point=point)
    if result.requirement.note:  # a skid steer, judged as a differential drive
        warn(result.requirement.note)
    fewer = None  # whether the linkages command fewer steering angles than the wheels' steerability d
    coupled = result.requirement.type == 4 and not any(w.type == "fixed" for w in robot.wheels)  # judged with them
    for c in () if coupled else robot.couplings:  # Table 8.1 classifies the wheels' geometry only
        if c.kind == "gear" and not steers_together(c):
            warn(f"{coupling_words(robot.couplings, c.channel_name)} is not considered: Table 8.1 judges the wheels "
                 "alone; check the reference's "
                 "twists with 'wmrkit ik' (a gear may forbid them)")
        elif steers_together(c):
            if c.kind == "linkage" and fewer is None:
                from ..analysis.classification import classify

                k = classify(robot)
                fewer = k.commanded_steerability < k.steerability
            if c.kind == "gear" or fewer:
                warn(f"{coupling_words(robot.couplings, c.channel_name)} is not considered: Table 8.1 judges the "
                     "wheels alone, each steered on its "
                     "own, and it steers them together, so it may forbid the reference's twists; 'wmrkit track' "
                     "says where it holds the wheels off the axles the commanded twist needs")
    if args.plot:
        from ..control.plots import plot_feasibility

        plot_feasibility(result, reference, args.plot, robot=robot.name)
        written("plot", args.plot)
    if args.json:
        print_json({"robot": robot.name, "reference_name": reference.name, "reference_size": size,
                    **result.to_dict()})
        return 0 if result.feasible else 1  # an answer that is no (docs/limits.md, Exit codes)
    r = result.requirement
    print(f"robot {robot.name}: Table 8.1 column '{r.column}', {r.references} pose references; "
          f"{r.framework} framework needs continuous: {', '.join(r.signals)}")
    print(f"reference {described}")
    turns = tight_turns(result)
    if turns:  # Table 8.1's own verdict, apart from the steering stops'
        table = len(result.violations) - len(turns)
        print(f"Table 8.1 (continuity): {'yes' if not table else f'NO ({table} violation(s))'}; steering stops: NO")
    print(_feasible(result))
    for v in result.violations:
        if v in turns:
            print(f"  t = {v.t:8.3f} s  {v.kind}: the reference {v.words()}: {v.remedy}")
        else:
            print(f"  t = {v.t:8.3f} s  {v.kind}, jump {_jump(v.signal, v.size)}: {v.remedy}")
    return 0 if result.feasible else 1


#: The unit of a Table 8.1 violation's size, per signal (``control.feasibility.KINDS``); angles also in degrees.
JUMP_UNITS = {"position": "m", "theta": "rad", "velocity": "m/s", "omega": "rad/s", "acceleration": "m/s^2",
              "omega_rate": "rad/s^2", "chi": "rad", "chi_rate": "rad/s", "kappa": "1/m", "kappa_rate": "1/(m s)"}


def _jump(signal: str, size: float) -> str:
    """A violation's size with its unit: ``1.57 rad (90 deg)``, ``0.5 m/s``."""
    unit = JUMP_UNITS[signal]
    return f"{size:.3g} {unit}" + (f" ({math.degrees(size):.3g} deg)" if unit == "rad" else "")
