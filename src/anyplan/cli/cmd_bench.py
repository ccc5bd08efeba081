"""``anyplan bench`` (run a benchmark into a results database) and ``anyplan report``."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from anyplan.cli import checks
from anyplan.cli.agent_options import add_agent_options
from anyplan.errors import UsageError

DESCRIPTION = """\
Run every (scenario, planner, run) in parallel processes (or on a Dask cluster) and store each
finished run at once in an SQLite database laid out like OMPL's benchmark database. Prints
tables like the paper's Tables 2-3 (one per planner, one row per number of moving obstacles)
and the paper's own figures beside ours. Ctrl-C loses no finished run; --resume runs only the
missing ones."""


#: What ``--suite`` expects, for the message about an empty one.
_SUITE_WHAT = "a suite name, a folder or a comma-separated list of scenarios"


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``bench`` and ``report`` sub-commands."""
    p = sub.add_parser("bench", help="benchmark planners on a suite of scenarios",
                       description=DESCRIPTION)
    p.add_argument("--suite", default="paper", type=checks.nonempty(_SUITE_WHAT),
                   help="'paper' (paper-1..3), 'random' (generated), 'gaps' (a wall with a gap "
                        "and walkers), a folder of scenario YAML files, or a comma-separated "
                        "list of files/built-in names (default paper)")
    p.add_argument("--planners", default=None, type=checks.nonempty("planner names"),
                   help="comma-separated planner names (default: the paper's comparison, "
                        f"{default_bench_planners()}; 'anyplan planners' lists them all)")
    p.add_argument("--config", action="append", default=[], metavar="NAME=JSON",
                   help="keyword config of one planner as a JSON object, e.g. "
                        "'bitstar={\"time_budget_s\": 0.2}' (repeatable; checked as --set checks its "
                        "values; recorded in plannerConfigs)")
    p.add_argument("--runs", type=int, default=30,
                   help=f"runs per (scenario, planner), at most {checks.MAX_RUNS} (default 30)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                   help="worker processes (default: the number of CPUs; 1 = no subprocess)")
    p.add_argument("--db", default="results.db", type=checks.nonempty("a database file"),
                   help="SQLite results database (default results.db)")
    p.add_argument("--out", default=None, type=checks.nonempty("a folder"),
                   help="folder for tables.md and tables.csv")
    p.add_argument("--resume", action="store_true",
                   help="run only the runs missing from --db (after an interruption)")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   type=checks.nonempty("a scheduler address"),
                   help="run on this Dask scheduler (needs the 'dask' extra) instead of --jobs")
    p.add_argument("--seed", type=checks.seed, default=0,
                   help="master seed; run i uses a seed derived from (seed, i) (default 0)")
    p.add_argument("--random-count", type=checks.count(1000), default=None, metavar="K",
                   help="--suite random: K scenarios per number of moving obstacles 1-6; "
                        "--suite gaps: 20 x K gap worlds (default 1)")
    p.add_argument("--random-seed", type=checks.seed, default=None,
                   help="--suite random or gaps: generator seed (default: --seed)")
    p.add_argument("--dt", type=checks.sim_step, default=0.05,
                   help="simulation step [s], in [0.001, 0.05] (default 0.05)")
    p.add_argument("--time-limit", type=checks.time_limit, default=None,
                   help="simulated time limit [s] (default: each scenario's)")
    p.add_argument("--actuation-noise", type=checks.actuation_noise, default=(0.0, 0.0),
                   metavar="SV,SW", help="the robot drives its commands with a correlated error of "
                   "these spreads [m/s, rad/s] at full speed (as anyplan run; default 0,0: exactly)")
    p.add_argument("--localization-noise", type=checks.localization_noise, default=(0.0, 0.0),
                   metavar="SXY,STH", help="the robot believes its pose off by an error of these "
                   "spreads [m per axis, rad] (as anyplan run; default 0,0: exactly)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    from anyplan.cli.perception_opts import add_perception_options, add_tracker_option

    add_perception_options(p)
    add_tracker_option(p)
    add_agent_options(p, bench=True)
    p.set_defaults(func=_database_errors(cmd_bench))

    q = sub.add_parser("bench-planning", help="anytime planning benchmark: our BIT* beside OMPL",
                       description="Plan among each scenario's static obstacles with our BIT* and "
                       "OMPL's planners (optional ompl wheel) for --budget seconds per run, and store "
                       "best cost against planning time in the results database (progress table); "
                       "'anyplan report' draws it. Runs one at a time (wall-clock costs).")
    q.add_argument("--suite", default="planning", type=checks.nonempty(_SUITE_WHAT),
                   help="as for 'anyplan bench', or 'planning' (the default): the peers problem and "
                        "random cluttered worlds where the straight line is blocked")
    q.add_argument("--runs", type=checks.count(checks.MAX_RUNS), default=10,
                   help="runs per (scenario, planner) (default 10)")
    q.add_argument("--budget", type=checks.positive_seconds, default=1.0,
                   help="planning time per run [s] (default 1)")
    q.add_argument("--ompl", default="auto",
                   help="OMPL geometric planners, comma-separated, or 'none'; default 'auto': "
                        "BITstar,InformedRRTstar,RRTstar when the ompl wheel is installed, else none")
    q.add_argument("--db", default="results.db", type=checks.nonempty("a database file"),
                   help="SQLite results database (default results.db)")
    q.add_argument("--seed", type=checks.seed, default=0, help="master seed (default 0)")
    q.add_argument("--random-count", type=checks.count(1000), default=None,
                   help="--suite random or gaps: see 'anyplan bench'; --suite planning: 4 x this "
                        "many cluttered worlds (default 1)")
    q.add_argument("--resume", action="store_true", help="run only the runs missing from --db")
    q.add_argument("--no-progress", action="store_true", help="no progress bar")
    q.set_defaults(func=_database_errors(cmd_bench_planning))

    r = sub.add_parser("report", help="figures, tables and an HTML report from a results database",
                       description="Read only the results database and write DIR/report.html "
                       "(one self-contained, interactive page: navigation, sortable tables, plots, "
                       "drill-down from each number to its runs and a playback of each run), the "
                       "paper's Figure 4 grid, box plots, cost against time, and the tables as "
                       "Markdown and CSV.")
    r.add_argument("db", help="results database written by 'anyplan bench'")
    r.add_argument("--out", default="report", help="output folder (default report)")
    r.add_argument("--format", default="png", choices=("png", "svg", "pdf"),
                   help="format of the figures (default png; report.html embeds them as PNG)")
    r.set_defaults(func=_database_errors(cmd_report))


def _database_errors(fn):  # noqa: ANN001, ANN202
    """A database that turns out damaged while it is read or written (past the checks made when
    it is opened: SQLite's quick_check cannot see every corruption) ends the command with exit
    code 2 and one line, not a traceback."""
    import functools

    @functools.wraps(fn)
    def wrapper(args: argparse.Namespace) -> int:
        import json
        import sqlite3
        import zlib

        try:
            return fn(args)
        except (sqlite3.DatabaseError, zlib.error, UnicodeDecodeError, json.JSONDecodeError) as exc:
            from anyplan.errors import one_line

            raise _usage(f"{args.command}: {one_line(args.db, 160)}: the database is damaged or "
                         f"unreadable ({one_line(exc, 100)})") from None

    return wrapper


def default_bench_planners() -> str:
    """``seq-bitstar,dovs``, and ``st-bitstar`` where it is registered."""
    from anyplan.agents.base import AGENTS

    names = ["seq-bitstar", "dovs", "st-bitstar"]
    return ",".join(n for n in names if n in AGENTS)


def _usage(msg: str) -> Exception:
    return UsageError(msg)


def cmd_bench(args: argparse.Namespace) -> int:
    """Run the bench, then print and write the tables."""
    from anyplan.experiments.db import ResultsDB, agent_settings_string
    from anyplan.experiments.runner import (
        BenchInterrupted,
        PlannerSpec,
        check_planner_config,
        parse_planners,
        run_bench,
    )
    from anyplan.experiments.suites import GENERATED, resolve_suite, suite_size
    from anyplan.experiments.tables import (
        compare_planners,
        format_comparisons,
        format_paper_comparison,
        format_text,
        paper_runs,
        summarize,
        write_tables,
    )

    per_count = _random_count("bench", args, GENERATED)
    if args.runs < 1:
        raise _usage(f"bench: --runs must be >= 1, got {args.runs}")
    if args.runs > checks.MAX_RUNS:
        raise _usage(f"bench: --runs must be <= {checks.MAX_RUNS} (the stated limit), got {args.runs}")
    if args.jobs < 1:
        raise _usage(f"bench: --jobs must be >= 1, got {args.jobs}")
    if args.jobs > checks.MAX_JOBS:
        raise _usage(f"bench: --jobs must be <= {checks.MAX_JOBS} (the stated limit), got {args.jobs}")
    # --config is checked here, before the suite is made; its checked values are what --set adds to
    planners = [check_planner_config(p) for p in parse_planners(
        default_bench_planners() if args.planners is None else args.planners, args.config)]
    if args.set_options or args.deterministic:
        from anyplan.cli.agent_options import bench_configs

        cfgs = bench_configs(args, [p.name for p in planners], {p.name: dict(p.config) for p in planners})
        planners = [PlannerSpec(p.name, cfgs[p.name]) for p in planners]
    known = suite_size(args.suite, per_count)
    if known is not None:  # a named suite: refused before it is generated
        _check_task_count(args.runs, known, len(planners))
    scenarios = resolve_suite(args.suite, random_seed=args.seed if args.random_seed is None
                              else args.random_seed, per_count=per_count)
    from anyplan.cli.perception_opts import apply_perception, tracker_settings

    scenarios = apply_perception("bench", scenarios, args)
    tracker = tracker_settings("bench", args, scenarios)
    _check_task_count(args.runs, len(scenarios), len(planners))
    from anyplan.simulation.simulator import SimConfig

    try:
        cfg = SimConfig(dt=args.dt, time_limit=args.time_limit, tracker=tracker,
                        actuation_sigma_v=args.actuation_noise[0],
                        actuation_sigma_omega=args.actuation_noise[1],
                        localization_sigma_xy=args.localization_noise[0],
                        localization_sigma_theta=args.localization_noise[1])
        for sc in scenarios:
            cfg.steps(sc.time_limit)
    except ValueError as exc:
        raise _usage(f"bench: {checks.flag_message(exc, checks.SIM_FLAGS)}") from None
    db_path = Path(args.db)
    if db_path.parent and not db_path.parent.exists():
        raise _usage(f"bench: --db {db_path}: folder {db_path.parent} does not exist")
    if args.resume and not db_path.exists():
        raise _usage(f"bench: --resume: {db_path} does not exist")
    if args.out:
        checks.writable_folder(args.out, "bench: --out")
    try:
        summary = run_bench(scenarios, planners, args.runs, db_path, master_seed=args.seed,
                            jobs=args.jobs, resume=args.resume, scheduler=args.scheduler,
                            suite=args.suite, progress=not args.no_progress, sim=cfg)
    except BenchInterrupted as exc:
        sys.stderr.write(f"anyplan: bench stopped: {exc}\n")
        return 1
    hashes = {sc.content_hash() for sc in scenarios}
    configs = {(p.name, agent_settings_string(p.config, cfg)) for p in planners}
    with ResultsDB(db_path, readonly=True) as db:
        runs = [r for r in db.runs()
                if r["scenario_hash"] in hashes and str(r["experiment_seed"]) == str(args.seed)
                and (r["planner"], r["settings"] or "") in configs]
    tables = summarize(runs)
    print(f"{summary.finished} runs now, {summary.skipped} already stored; "
          f"{len(runs)} runs in {db_path} for this bench ({summary.wall_time_s:.1f} s)\n")
    print(format_text(tables))
    pairs = compare_planners(runs)
    if pairs:
        print("\npaired comparisons (the runs both configurations made):\n" + format_comparisons(pairs))
    ptables = summarize(paper_runs(runs))
    cmp = format_paper_comparison(ptables)
    if cmp:
        print("\n" + cmp)
    from anyplan.experiments.barn_tables import bench_barn_report

    barn = bench_barn_report(args.suite, runs)  # a folder written by 'anyplan import-barn'
    if barn:
        print("\n" + barn[0])
    if args.out:
        try:
            paths = write_tables(tables, args.out, ptables, pairs)
            if barn:
                paths.append(Path(args.out) / "barn.md")
                paths[-1].write_text(barn[1])
        except OSError as exc:
            raise _usage(f"bench: --out {args.out}: cannot write ({exc.strerror})") from None
        print("\nwrote " + ", ".join(str(p) for p in paths))
    return 0


def _random_count(command: str, args: argparse.Namespace, generated: Sequence[str]) -> int:
    """``--random-count`` (default 1), after refusing it and ``--random-seed`` (where the command
    has it) with a suite not among ``generated``: nothing would read them."""
    for flag, value in (("--random-count", args.random_count),
                        ("--random-seed", getattr(args, "random_seed", None))):
        if value is not None and args.suite not in generated:
            raise _usage(f"{command}: {flag} applies to the generated suites only (--suite "
                         f"{', '.join(generated[:-1])} or {generated[-1]})")
    return 1 if args.random_count is None else int(args.random_count)


def _check_task_count(runs: int, scenarios: int, planners: int) -> None:
    """Refuse a bench of more than :data:`~anyplan.cli.checks.MAX_TASKS` runs in all."""
    n_tasks = runs * scenarios * planners
    if n_tasks > checks.MAX_TASKS:
        raise _usage(f"bench: {runs} runs x {scenarios} scenarios x {planners} planners = "
                     f"{n_tasks} runs, more than the limit of {checks.MAX_TASKS}")


def cmd_bench_planning(args: argparse.Namespace) -> int:
    """Run the anytime planning benchmark and print its table."""
    from anyplan.experiments.db import ResultsDB
    from anyplan.experiments.planning_bench import (
        OMPL_DEFAULT,
        ompl_available,
        planning_table,
        run_planning_bench,
    )
    from anyplan.experiments.suites import GENERATED, resolve_suite

    per_count = _random_count("bench-planning", args, ("planning", *GENERATED))
    if args.suite == "planning":
        from anyplan.experiments.planning_problems import planning_suite

        scenarios = planning_suite(args.seed, count=4 * per_count)
    else:
        scenarios = resolve_suite(args.suite, random_seed=args.seed, per_count=per_count)
    choice = args.ompl.strip().lower()
    if choice == "auto":
        ompl = list(OMPL_DEFAULT) if ompl_available() else []
        if not ompl:
            sys.stderr.write("anyplan: the ompl wheel is not installed: our BIT* alone "
                             "(pip install 'anyplan[bench]' adds OMPL's planners)\n")
    else:
        ompl = [] if choice == "none" else [n.strip() for n in args.ompl.split(",") if n.strip()]
    db_path = Path(args.db)
    if args.resume and not db_path.exists():
        raise _usage(f"bench-planning: --resume: {db_path} does not exist")
    s = run_planning_bench(scenarios, db_path, runs=args.runs, budget_s=args.budget, ompl=ompl,
                           master_seed=args.seed, resume=args.resume, progress=not args.no_progress)
    print(f"{s.finished} planning runs now, {s.skipped} already stored in {db_path}\n")
    with ResultsDB(db_path, readonly=True) as db:
        print(planning_table(db))
    print("\n(OMPL's first-solution time is the first of its sampled budgets with a solution: an "
          "upper estimate.)")
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    """Write the figures and the HTML report of a results database."""
    from anyplan.experiments.db import check_database

    db = Path(args.db)
    check_database(db, "report")  # an anyplan database, opened read-only below
    checks.writable_folder(args.out, "report: --out")
    from anyplan.viz.report import build_report

    try:
        paths = build_report(db, args.out, fmt=args.format)
    except OSError as exc:
        raise _usage(f"report: --out {args.out}: cannot write ({exc.strerror})") from None
    for p in paths:
        print(f"wrote {p}")
    return 0
