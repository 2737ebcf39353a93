"""``wmrkit park``: the thesis's parallel-parking planner (§9.3) on a problem file or a built-in problem."""

from __future__ import annotations

import argparse

from ._common import add_json_flag, print_json


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``park``."""
    p = commands.add_parser("park", help="plan a parallel parking manoeuvre (thesis 9.3)")
    p.add_argument("problem", metavar="FILE", help="problem file (.yaml/.json: vehicle and space) or a built-in "
                   "name: thesis-9.1, thesis-9.2")
    p.add_argument("--plot", metavar="FILE", help="draw the plan (.png, .svg or .pdf)")
    p.add_argument("--animate", metavar="FILE", help="animate the executed plan (.gif or .html)")
    p.add_argument("--frames", type=int, default=200, metavar="N", help="at most N animation frames (default 200)")
    p.add_argument("--controller", choices=("p", "pi"), default=None,
                   help="execute closed loop with the thesis's law (8.2)/(8.3) for --animate (default: open loop)")
    p.add_argument("--check", action="store_true", help="check every pose with exact polygons (needs shapely)")
    add_json_flag(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Plan, print (text or JSON), draw and animate on request."""
    from ..parking.problem import load_problem
    from ..parking.solve import describe, solve

    solution = solve(load_problem(args.problem), check=args.check)
    print_json(solution.to_dict()) if args.json else print(describe(solution))
    if args.plot or args.animate:
        from ..parking import plot

        execution = None
        if args.animate:
            from ..parking.execute import execute_plan  # refuses an infeasible plan (exit 2, the reason)

            execution = execute_plan(solution.plan, solution.problem.robot, controller=args.controller)
            plot.animate_plan(solution.plan, args.animate, execution, max_frames=max(2, args.frames))
        if args.plot:
            plot.save_plan_figure(solution.plan, args.plot, execution)
    return 0
