"""``wmrkit park``: the thesis's parallel-parking planner (§9.3) on a problem file or a built-in problem."""

from __future__ import annotations

import argparse

from ..errors import WmrkitError
from ._common import add_json_flag, check_plot_path, print_json, warn
from ._shown import written
from .control import check_animation_path, verdict_line, warn_infeasible


def add_parsers(commands: argparse._SubParsersAction) -> None:
    """Register ``park``."""
    p = commands.add_parser("park", help="plan a parallel parking manoeuvre (thesis 9.3)")
    p.add_argument("problem", metavar="FILE", help="problem file (.yaml/.json: vehicle and space) or a built-in "
                   "name: thesis-9.1, thesis-9.2")
    p.add_argument("--plot", metavar="FILE", help="draw the plan (.png, .svg or .pdf)")
    p.add_argument("--animate", metavar="FILE", help="animate the executed plan (.gif or .html)")
    p.add_argument("--frames", type=int, metavar="N", help="at most N animation frames (default 200)")
    p.add_argument("--controller", choices=("p", "pi"), default=None,
                   help="execute closed loop with the thesis's law (8.2)/(8.3) for --animate and --check (default: "
                   "open loop)")
    p.add_argument("--check", action="store_true", help="check every pose of the plan with exact polygons (needs "
                   "shapely); with --controller or --animate, the executed path's too")
    add_json_flag(p)
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Plan, execute and check on request, print (text or JSON), draw and animate on request."""
    from ..parking.problem import load_problem
    from ..parking.solve import check_dict, describe, describe_check, solve

    # options of the executed plan without --animate or --check were ignored (exit 0): refused, as track's
    if args.frames is not None and not args.animate:
        raise WmrkitError("--frames applies to --animate (it would be ignored)")
    if args.controller is not None and not (args.animate or args.check):
        raise WmrkitError(f"--controller {args.controller} drives the plan for --animate or --check (it would be "
                          "ignored)")
    frames = 200 if args.frames is None else args.frames
    if args.animate:
        from ..parking.plot import MAX_FRAMES  # (matplotlib: imported only to animate)

        if not 2 <= frames <= MAX_FRAMES:  # below 2 was raised to 2 silently; thousands took minutes
            raise WmrkitError(f"--frames: expected 2 to {MAX_FRAMES} animation frames, got {frames}")
    check_plot_path(args.plot)  # before the answer is printed
    check_animation_path(args.animate, (".gif", ".html"))
    solution = solve(load_problem(args.problem), check=args.check)
    for line in solution.plan.warnings:  # on stderr, as every command's (they were 'warning: ...' lines on stdout)
        warn(line)
    execution = executed = None
    if solution.plan.feasible and (args.animate or (args.check and args.controller)):
        from ..parking.execute import execute_plan

        execution = execute_plan(solution.plan, solution.problem.robot, controller=args.controller)
        if args.check:
            from ..parking.verify import check_poses, densify

            vehicle, space = solution.problem.vehicle, solution.problem.space
            executed = check_poses(vehicle, space, densify(vehicle, execution.pose))
    verdict = None
    if solution.plan.feasible:  # Table 8.1 on the timed plan, at the point the closed loop tracks, as track judges
        from ..parking.execute import plan_feasibility

        try:
            verdict = plan_feasibility(solution.plan, solution.problem.robot)
        except WmrkitError as err:  # a plan too long to time is still the answer: judged, it was an error, exit 2
            warn(f"Table 8.1 not judged: {err}")
        else:
            warn_infeasible(verdict)
    if args.animate and execution is None:  # an impossible slot is an answer (exit 1), not bad input
        warn(f"no plan, so no animation: {args.animate} not written")
    if args.json:
        out = solution.to_dict()
        if executed is not None:
            out["executed_check"] = {"mode": execution.mode, **check_dict(executed)}
        out["feasibility"] = None if verdict is None else verdict.to_dict()
        robot = solution.problem.robot  # None: a vehicle given by its parameters
        print_json({"robot": None if robot is None else robot.name, **out})  # warnings: the plan's, the command's
    else:
        print(describe(solution))
        if verdict is not None:
            print(verdict_line(verdict, "the steering axle's midpoint"))
        if executed is not None:
            law = execution.mode.upper()
            mode = "open loop" if execution.mode == "open-loop" else f"closed loop with the {law} law"
            print(describe_check(executed, f"executed path, {mode}", solution.problem.vehicle))
    if args.animate or args.plot:
        from ..parking import plot

        if args.animate and execution is not None:
            plot.animate_plan(solution.plan, args.animate, execution, max_frames=frames)
            written("animation", args.animate)
        if args.plot:
            robot = solution.problem.robot
            name = solution.problem.name + ("" if robot is None else f" (robot {robot.name})")
            plot.save_plan_figure(solution.plan, args.plot, execution, name=name)
            written("plot", args.plot)
    return 0 if parked(solution, executed) else 1


def parked(solution, executed=None) -> bool:
    """Whether the answer is yes: a plan, and every check asked for collision-free and ending inside the slot. The
    command exits 1 otherwise (its answer printed all the same; 2 is kept for bad input), so that a script's
    ``wmrkit park ... && next`` does not go on as if the car had parked."""
    checks = [c for c in (solution.check, executed) if c is not None]
    return bool(solution.plan.feasible and all(c.collision_free and c.inside for c in checks))
