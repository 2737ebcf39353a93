"""``wmrkit kinematics``: the no-slip kinematic models of a robot (thesis ch. 4) at one steering configuration."""

from __future__ import annotations

import argparse

from ..errors import WmrkitError
from ..kinematics.summary import format_kinematics_summary, kinematics_summary
from ._common import (
    add_json_flag,
    add_robot_argument,
    add_steer_option,
    print_json,
    steered_robot,
    warn,
)
from ._shown import written

CODEGEN_LANGUAGES = ("c", "python")


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``kinematics``."""
    p = commands.add_parser(
        "kinematics", help="mobility, assignable sets, direct/inverse models, actuation and sensing (ch. 4)")
    add_robot_argument(p)
    add_steer_option(p)
    add_json_flag(p)
    p.add_argument("--all", action="store_true", help="list every assignable set (default: the first 12 of each)")
    p.add_argument("--symbolic", action="store_true", help="also print the closed-form models (sympy)")
    p.add_argument("--codegen", nargs=2, metavar=("LANG", "DIR"),
                   help="also write the models as code, LANG 'c' or 'python', into DIR")
    p.set_defaults(run=run)


def headings_note(robot) -> str | None:
    """What `robot`'s steered axles miss when its headings look rounded from consistent ones, as ``analyze`` says it
    (:meth:`wmrkit.analysis.icr.ICRSet.heading_note`); None otherwise or without steering."""
    if not robot.steer_names:
        return None
    from ..analysis.icr import icr

    return icr(robot, geared=True).heading_note()


def run(args: argparse.Namespace) -> int:
    """Print the chapter-4 summary; --symbolic and --codegen add closed forms and generated files."""
    if args.codegen and args.codegen[0] not in CODEGEN_LANGUAGES:  # before the work, not after it
        raise WmrkitError(f"--codegen: language must be one of {', '.join(CODEGEN_LANGUAGES)}, got '{args.codegen[0]}'")
    robot = steered_robot(args.robot, args.steer)
    summary = kinematics_summary(robot)
    summary["headings_note"] = headings_note(robot)
    if args.symbolic:
        from ..kinematics.symbolic import format_symbolic

        summary["symbolic"] = format_symbolic(robot)
        if summary["gears"]:
            from ..kinematics.symbolic import unheld_gears

            for message in unheld_gears(robot):
                warn(message)
    if args.codegen:
        lang, directory = args.codegen
        from ..kinematics.codegen import write_code

        summary["generated"] = [str(p) for p in write_code(robot, lang, directory)]
        for path in summary["generated"]:
            written("code", path)
    if args.json:
        print_json(summary)
        return 0
    print(format_kinematics_summary(summary, limit=None if args.all else 12, couplings=robot.couplings))
    if args.symbolic:
        print(summary["symbolic"])
    return 0
