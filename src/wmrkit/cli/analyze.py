"""``wmrkit analyze``: what the robot is (type, m, d), how well it transmits errors, where it breaks down (ch. 5-6)."""

from __future__ import annotations

import argparse

from ..analysis.conditioning import ill_conditioned_pairs
from ..analysis.summary import analyze, check_resolution
from ..errors import WmrkitError
from ..limits import check_length
from ._common import (
    add_json_flag,
    add_robot_argument,
    add_steer_option,
    parse_value,
    print_json,
    steered_robot,
    warn,
)
from ._shown import written


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``analyze``."""
    p = commands.add_parser(
        "analyze", help="vehicle type, mobility, actuation/sensing, condition number, singularities (ch. 5-6)")
    add_robot_argument(p)
    add_steer_option(p)
    p.add_argument("--length", metavar="D", help="characteristic length of the condition number, e.g. 0.3 or "
                   "'300 mm' (default: the natural length, which minimises it)")
    p.add_argument("--report", metavar="DIR", help="write an HTML report with pictures to DIR/index.html")
    p.add_argument("--resolution", type=int, default=90, metavar="N",
                   help="grid points per turn of a steering angle for maps and singular sets (default 90)")
    add_json_flag(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Print the analysis; write the report with --report."""
    robot = steered_robot(args.robot, args.steer)
    check_resolution(args.resolution, "--resolution")
    result = analyze(robot, length=_length(args.length), resolution=args.resolution)
    for message in ill_conditioned_pairs(robot):  # said, not refused: the verdicts stand as computed
        warn(f"{args.robot}: {message}")
    if args.report:
        from ..analysis.report import write_report

        written("report", write_report(result, args.report, resolution=args.resolution))
    print_json(result.to_dict()) if args.json else print(result.format_text())
    return 0


def _length(text: str | None) -> float | None:
    if text is None:
        return None
    value = parse_value(text, "length", "--length")
    check_length(value, WmrkitError, "--length")
    return value
