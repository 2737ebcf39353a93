"""``wmrkit robots`` and ``wmrkit show``: the catalog and one robot's summary and drawing."""

from __future__ import annotations

import argparse
import math

from .. import catalog
from ..robot import Robot
from ._common import add_json_flag, add_robot_argument, load_robot, print_json


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
    if args.plot:
        from ..plotting.robot import save_robot_figure

        save_robot_figure(robot, args.plot)
    if args.json:
        print_json(summary(robot))
    else:
        print(format_summary(robot))
        if args.plot:
            print(f"drawing written to {args.plot}")
    return 0


def summary(robot: Robot) -> dict:
    """Machine-readable summary: the description plus derived names."""
    return {
        **robot.to_dict(),
        "velocity_names": list(robot.velocity_names),
        "steer_names": list(robot.steer_names),
        "actuated_joints": list(robot.actuated),
        "sensed_joints": list(robot.sensed),
    }


def format_summary(robot: Robot) -> str:
    """Human-readable summary: one line per wheel in the robot frame (x forward, y left)."""
    lines = [f"robot {robot.name}: {len(robot.wheels)} wheels" + (f"  ({robot.notes})" if robot.notes else "")]
    header = f"  {'wheel':<14}{'type':<14}{'x [m]':>8}{'y [m]':>8}{'beta':>9}{'r [m]':>8}"
    lines.append(header + "  joints (A actuated, S sensed)")
    for w in robot.wheels:
        x, y = w.position
        joints = ", ".join(
            j + ("[" + "A" * (j in w.actuated) + "S" * (j in w.sensed) + "]" if j in w.actuated + w.sensed else "")
            for j in w.kind.joints
        )
        extra = {"castor": f"  d={w.d:g}", "double_castor": f"  d={w.d:g} b={w.b:g}", "double": f"  b={w.b:g}",
                 "swedish": f"  gamma={math.degrees(w.gamma):g}deg r_r={w.r_r:g}"}.get(w.type, "")
        row = f"  {w.name:<14}{w.type:<14}{x:>8.3f}{y:>8.3f}{math.degrees(w.beta):>7.1f}°{w.r:>8.3f}"
        lines.append(f"{row}  {joints}{extra}")
    lines.append(f"  velocity vector q_dot ({len(robot.velocity_names)}): {', '.join(robot.velocity_names)}")
    if robot.steer_names:
        lines.append(f"  steering configuration beta: {', '.join(robot.steer_names)}")
    return "\n".join(lines)
