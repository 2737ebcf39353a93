"""``wmrkit robots`` and ``wmrkit show``: the catalog and one robot's summary and drawing."""

from __future__ import annotations

import argparse
import math

from .. import catalog
from ..description import described_type
from ..robot import Robot
from ._common import add_json_flag, add_robot_argument, check_plot_path, load_robot, print_json, wheel_column_width
from ._shown import written


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``robots`` and ``show``."""
    p = commands.add_parser("robots", help="list the built-in robots")
    add_json_flag(p)
    p.set_defaults(run=run_robots)

    p = commands.add_parser("show", help="summary of a robot; --plot draws it from above")
    add_robot_argument(p)
    p.add_argument("--plot", metavar="FILE", help="draw the robot to FILE (.png, .svg or .pdf)")
    add_json_flag(p)
    p.set_defaults(run=run_show)


def run_robots(args: argparse.Namespace) -> int:
    """List the catalog."""
    rows = [(name, catalog.load(name)) for name in catalog.names()]
    if args.json:
        print_json([{"name": n, "wheels": len(r.wheels), "notes": r.notes} for n, r in rows])
    else:
        width = max(len(n) for n, _ in rows)
        for name, robot in rows:
            print(f"{name:<{width}}  {len(robot.wheels)} wheels  {robot.notes}")
    return 0


def run_show(args: argparse.Namespace) -> int:
    """Print a robot's summary; draw it with --plot."""
    robot = load_robot(args.robot)
    check_plot_path(args.plot)
    if args.plot:
        from ..plotting.robot import save_robot_figure

        save_robot_figure(robot, args.plot)
        written("drawing", args.plot)
    if args.json:
        print_json(summary(robot))
    else:
        print(format_summary(robot))
    return 0


def summary(robot: Robot) -> dict:
    """Machine-readable summary: ``robot`` (its name, as every command's answer; the description's ``name`` too),
    the description, and derived names."""
    return {
        "robot": robot.name,
        **robot.to_dict(),
        "velocity_names": list(robot.velocity_names),
        "steer_names": list(robot.steer_names),
        "actuated_joints": list(robot.actuated),
        "sensed_joints": list(robot.sensed),
    }


def format_summary(robot: Robot) -> str:
    """Human-readable summary: one line per wheel in the robot frame (x forward, y left)."""
    lines = [f"robot {robot.name}: {len(robot.wheels)} wheels" + (f"  ({robot.notes})" if robot.notes else "")]
    width = wheel_column_width(robot)
    header = f"  {'wheel':<{width}}{'type':<14}{'x [m]':>10}{'y [m]':>10}{'heading':>10}{'r [m]':>10}"
    lines.append(header + "  joints (A actuated, S sensed)")
    for w in robot.wheels:
        x, y = w.position
        joints = ", ".join(
            j + ("[" + "A" * (j in w.actuated) + "S" * (j in w.sensed) + "]" if j in w.actuated + w.sensed else "")
            for j in w.kind.joints
        )
        extra = {"castor": f"  d={_g(w.d)} m delta={_g(math.degrees(w.delta))} deg",
                 "double_castor": f"  d={_g(w.d)} m b={_g(w.b)} m", "double": f"  b={_g(w.b)} m",
                 "swedish": f"  gamma={_g(math.degrees(w.gamma))} deg r_r={_g(w.r_r)} m"}.get(w.type, "")
        row = (f"  {w.name:<{width}}{described_type(w):<14}{_g(_zero(x)):>10}{_g(_zero(y)):>10}"
               f"{_g(_zero(math.degrees(w.heading))) + '°':>10}{_g(w.r):>10}")
        lines.append(f"{row}  {joints}{extra}")
    lines.append("  heading: the wheel's rolling direction, 0° = straight ahead (+x), counter-clockwise positive")
    lines.append(f"  velocity vector q_dot ({len(robot.velocity_names)}): {', '.join(robot.velocity_names)}")
    if robot.steer_names:
        lines.append(f"  steered wheels: {', '.join(robot.steer_names)}")
    for c in robot.couplings:
        law = f"; law {c.law}" if c.law is not None else ""  # a linkage's, stated
        ratios = ", ".join(_g(k) for k in c.ratios)
        lines.append(f"  coupling: {c.kind} of {', '.join(c.joints)} (ratios {ratios}{law})")
    return "\n".join(lines)


def _g(x: float) -> str:
    """A number to 5 significant digits, without trailing zeros (0.0475 stays 0.0475)."""
    return f"{x:.5g}"


def _zero(x: float) -> float:
    return 0.0 if abs(x) < 1e-9 else x
