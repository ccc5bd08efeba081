"""``anyplan plan``: plan start -> goal among a scenario's static obstacles."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from anyplan.cli import checks
from anyplan.cli.pictures import picture_path
from anyplan.errors import UsageError
from anyplan.planning.api import PLANNERS

DEFAULT_TIME_S = 1.0
#: The planners that take --time (anytime); the others are exact and plan once.
TIMED = ("bitstar",)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``plan`` sub-command."""
    p = sub.add_parser("plan", help="plan a path among a scenario's static obstacles",
                       description="Plan start -> goal for the scenario's robot (a disc) among its "
                       "static obstacles; prints a summary and optionally writes JSON and a plot.")
    p.add_argument("scenario", type=checks.nonempty("a built-in scenario name or a YAML file"),
                   help="built-in scenario name (see 'anyplan scenarios') or YAML file")
    p.add_argument("--planner", default="bitstar", choices=PLANNERS,
                   help="planner (default bitstar)")
    p.add_argument("--time", type=float, default=None,
                   help=f"--planner bitstar: its time budget [s] (default {DEFAULT_TIME_S:g}; visgraph "
                        "is exact and takes none)")
    p.add_argument("--seed", type=checks.seed, default=0, help="random seed >= 0 (default 0)")
    p.add_argument("--json", default=None, metavar="FILE", type=checks.nonempty("a file"),
                   help="write the result as JSON")
    p.add_argument("--plot", default=None, metavar="FILE", type=checks.nonempty("a file"),
                   help="write a picture (tree, samples, informed ellipse, path): .png, .svg or .pdf")
    p.add_argument("--format", default=None, choices=("png", "svg", "pdf"),
                   help="with --plot: the picture format (default: the suffix of --plot FILE)")
    p.set_defaults(func=cmd_plan)


def _refuse_unused(args: argparse.Namespace) -> None:
    """Refuse an option that nothing would read: ``--time`` for visgraph (exact, not anytime: it
    plans once, whatever the budget), ``--format`` without ``--plot``."""
    if args.time is not None and args.planner not in TIMED:
        raise UsageError(f"plan: --time applies to --planner {' or '.join(TIMED)} only ({args.planner} "
                         "is exact, not anytime)")
    if args.format is not None and args.plot is None:
        raise UsageError("plan: --format applies to --plot only")


def cmd_plan(args: argparse.Namespace) -> int:
    """Run one planning query; exit code 0 if a path was found, 1 otherwise."""
    from anyplan.planning import Problem, make_planner, timed
    from anyplan.planning.visgraph import lower_bound
    from anyplan.world.scenario import load_scenario

    _refuse_unused(args)
    budget: float | None = None  # an exact planner has none (and refused --time above)
    if args.planner in TIMED:
        budget = DEFAULT_TIME_S if args.time is None else args.time
        if not (math.isfinite(budget) and budget > 0.0):
            raise UsageError(f"plan: --time must be > 0 seconds, got {budget}")
        if budget > checks.MAX_PLAN_TIME_S:
            raise UsageError(f"plan: --time must be <= {checks.MAX_PLAN_TIME_S:g} s (the stated limit), "
                             f"got {budget:g}")
    if args.json is not None:
        checks.writable_file(args.json, "plan: --json", make_parent=False)
    plot = picture_path(args.plot, args.format, "plan", "--plot") if args.plot else None
    if plot is not None:
        checks.writable_file(plot, "plan: --plot", checks.PLOT_SUFFIXES, make_parent=False)
    scenario = load_scenario(args.scenario)
    r = scenario.robot
    problem = Problem.create(scenario.obstacle_set(), r.start[:2], r.goal, r.radius)
    planner = make_planner(args.planner, problem, rng=args.seed)
    planner.solve(timed(budget) if budget is not None else 0.0)  # visgraph: the ptc is not consulted
    result = planner.result()
    if result.lower_bound is None and problem.start_valid() and problem.goal_valid():
        bound = lower_bound(problem)
        result.lower_bound = bound if math.isfinite(bound) else None
    out = {k: v for k, v in result.to_dict().items() if k not in ("planner", "stats")}
    if args.json:
        doc = {**out, "planner": result.planner, "scenario": scenario.name, "seed": args.seed,
               "time_budget_s": budget, "stats": result.stats}
        Path(args.json).write_text(json.dumps(doc, indent=1))
    if plot is not None:
        from anyplan.viz.planner import save_planner_figure

        data = planner.planner_data() if hasattr(planner, "planner_data") else None
        save_planner_figure(problem, result, plot, data)
    lb = result.lower_bound
    ratio = f" ({result.cost / lb:.4f} x lower bound {lb:.3f} m)" if lb and result.solved else ""
    first = ("-" if result.first_solution_time_s is None
             else f"{1e3 * result.first_solution_time_s:.2f} ms")
    print(f"{scenario.name} / {result.planner} / seed {args.seed}: {result.status.value}")
    print(f"  cost            {result.cost:.4f} m{ratio}")
    print(f"  first solution  {first}; solve time {result.solve_time_s:.3f} s")
    print(f"  waypoints       {len(result.path)}")
    return 0 if result.solved else 1

