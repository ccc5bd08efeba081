"""Space-time planning benchmark (issue 10): st-bitstar, seq-bitstar, dovs and STRRT*, one run.

Suites (obstacle motion known to the planners: announced tracks, the paper's assumption):

* ``paper``: paper-1..3, ``--seeds`` seeds each;
* ``random``: ``--random`` generated scenarios per number of moving obstacles 1-6
  (:func:`anyplan.experiments.generate.random_suite`, seed 0), one seed each;
* ``dynabarn``: DynaBARN's medium and hard worlds (20-59), tracks announced, one seed each;
* ``gaps``: ``--gaps`` gap worlds (:mod:`anyplan.experiments.gaps`, seed 0) and issue 10's case.

For each (suite, planner): success, collisions, robot-caused collisions (at first contact the
robot's velocity has a component > 0.05 m/s towards the obstacle), time to goal over the time
lower bound (the result's ``time_lower_bound_s`` when present, otherwise the same bound computed
here: from rest under v_max and a_max along the visibility-graph shortest path to the edge of the
goal tolerance), path length, and planning time per call (median and p95 over all calls; the
number of calls, the same without st-bitstar's improvement calls (each on its own budget, made
while the robot already drives a safe motion), and the median of the first plans from rest),
and the least distance between the robot's disc and a moving obstacle's disc over each run
(median and minimum over the runs).

st-bitstar and seq-bitstar run with a **fixed planning delay** of ``--delay`` seconds (0.1 by
default): the new motion starts that long after the replanning decision whatever the computation
took, so runs are reproducible for a seed; planning times are still measured (wall clock, on a
shared machine: noisy). DOVS plans every control step (no delay).

STRRT* (OMPL 1.7, optional, ``--strrt-site`` or an ``anyplan[strrt]`` install) solves each
scenario offline with 1 s and 5 s budgets (``--strrt-budgets``) for a holonomic robot with no
acceleration limit (exact moving-disc validator); it is skipped cleanly when unavailable. Its
time is the first time its path is within the goal tolerance, against the same lower bound.

Usage::

    python benchmarks/spacetime.py --quick            # a few minutes
    python benchmarks/spacetime.py --jobs 2 --out benchmarks/results/spacetime.json
    python benchmarks/spacetime.py --planners st-bitstar --strrt-budgets none --set announced_horizon_s=null
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

PLANNERS = ("st-bitstar", "seq-bitstar", "dovs")
_CACHE: dict[str, Any] = {}


def _scenarios(suite: str, args: argparse.Namespace) -> list[Any]:
    if suite == "paper":
        from anyplan.world import load_scenario

        return [load_scenario(f"paper-{n}") for n in (1, 2, 3)]
    if suite == "random":
        from anyplan.experiments.generate import random_suite

        return random_suite(0, per_count=args.random)
    if suite == "gaps":
        from anyplan.experiments.gaps import gap_suite, issue_gap_scenario

        return [issue_gap_scenario()] + gap_suite(0, args.gaps)
    if suite == "dynabarn":
        from anyplan.experiments.dynabarn import load_worlds, parse_worlds, world_to_scenario

        worlds = load_worlds(args.worlds_file)
        from anyplan.world.scenario import scenario_from_dict

        out = []
        for i in parse_worlds(args.dynabarn):
            d = world_to_scenario(worlds[i])
            out.append(d if not isinstance(d, dict) else scenario_from_dict(d, f"<dynabarn {i}>"))
        return out
    raise SystemExit(f"unknown suite {suite!r}")


def _scenario(suite: str, index: int, args: argparse.Namespace) -> Any:
    key = f"{suite}:{index}"
    if key not in _CACHE:
        for i, sc in enumerate(_scenarios(suite, args)):
            _CACHE[f"{suite}:{i}"] = sc
    return _CACHE[key]


def lower_bound(sc: Any) -> float:
    """Least time [s] from rest to the edge of the goal tolerance under v_max and a_max along the
    visibility-graph shortest path among the static obstacles (no stop at the edge)."""
    from anyplan.planning import plan

    r = sc.robot
    res = plan(sc.obstacle_set(), r.start[:2], r.goal, r.radius, planner="visgraph")
    d = max(float(res.cost) - r.goal_tolerance, 0.0)
    d_acc = r.v_max ** 2 / (2.0 * r.a_max)
    if d >= d_acc:
        return r.v_max / r.a_max + (d - d_acc) / r.v_max
    return math.sqrt(2.0 * d / r.a_max)


def run_one(job: tuple[str, int, str, int, dict[str, Any]]) -> dict[str, Any]:
    """One simulated run (top level so that worker processes can call it)."""
    from anyplan.agents import make_agent
    from anyplan.agents.stats import improvement_calls
    from anyplan.simulation import simulate

    suite, index, planner, seed, opts = job
    args = argparse.Namespace(**opts)
    sc = _scenario(suite, index, args)
    kw = args.agent_configs.get(planner, {})  # --delay, then --set and --deterministic
    t0 = time.perf_counter()
    res = simulate(sc, make_agent(planner, **kw), seed=seed)
    d = res.to_dict()
    lb = d.get("time_lower_bound_s") or lower_bound(sc)
    improving = improvement_calls(res.extra, len(res.planning_times_s))
    return {"suite": suite, "scenario": sc.name, "planner": planner, "seed": seed,
            "status": res.status, "collision": res.collision,
            "robot_caused": bool(res.collision_robot_caused),
            "time_to_goal": res.time_to_goal_s, "lower_bound": lb, "length": res.path_length_m,
            "plan_times": list(res.planning_times_s), "improving": improving,
            "min_dist": d.get("min_distance_to_moving_m"),
            "fallbacks": len(res.extra.get("fallbacks", [])), "wall": time.perf_counter() - t0}


def run_strrt(job: tuple[str, int, float, dict[str, Any]]) -> dict[str, Any]:
    from anyplan.experiments.strrt import solve_strrt

    suite, index, budget, opts = job
    args = argparse.Namespace(**opts)
    sc = _scenario(suite, index, args)
    out = solve_strrt(sc, budget, seed=0, site=args.strrt_site)
    out.pop("path", None)
    return {"suite": suite, "scenario": sc.name, "planner": f"strrt*-{budget:g}s", "budget": budget,
            "lower_bound": lower_bound(sc), **out}


def _fmt(x: float | None, nd: int = 2) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{nd}f}"


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    if rows and "budget" in rows[0]:
        ok = [r for r in rows if r.get("solved")]
        ratio = [r["goal_edge_s"] / r["lower_bound"] for r in ok]
        return {"runs": len(rows), "success": len(ok) / len(rows), "collision": 0.0,
                "robot_caused": 0, "ratio_med": float(np.median(ratio)) if ratio else math.nan,
                "len": float(np.mean([r["path_length_m"] for r in ok])) if ok else math.nan,
                "pt_med": float(np.median([r["solve_time_s"] for r in rows])) * 1e3,
                "pt_p95": math.nan, "pt_first_med": math.nan, "calls": 0, "fallbacks": 0,
                "pt_own_med": math.nan, "pt_own_p95": math.nan, "calls_own": 0,
                "dist_med": math.nan, "dist_min": math.nan}
    pt = np.array([t for r in rows for t in r["plan_times"]]) * 1e3
    # without st-bitstar's improvement calls (made while the robot has a safe motion already)
    pt_own = np.array([t for r in rows for t, imp in zip(r["plan_times"], r["improving"],
                                                         strict=True) if not imp]) * 1e3
    ok = [r for r in rows if r["status"] == "reached"]
    ratio = [r["time_to_goal"] / r["lower_bound"] for r in ok]
    # robot's disc to the nearest moving obstacle's disc [m] (negative: overlap), per run
    dist = [r["min_dist"] for r in rows if r.get("min_dist") is not None]
    return {"runs": len(rows), "success": len(ok) / len(rows),
            "dist_med": float(np.median(dist)) if dist else math.nan,
            "dist_min": float(np.min(dist)) if dist else math.nan,
            "collision": sum(r["collision"] for r in rows) / len(rows),
            "robot_caused": int(sum(r["robot_caused"] for r in rows)),
            "ratio_med": float(np.median(ratio)) if ratio else math.nan,
            "len": float(np.mean([r["length"] for r in ok])) if ok else math.nan,
            "pt_med": float(np.median(pt)) if len(pt) else math.nan,
            "pt_p95": float(np.percentile(pt, 95)) if len(pt) else math.nan,
            "pt_first_med": float(np.median([r["plan_times"][0] for r in rows if r["plan_times"]]))
            * 1e3 if any(r["plan_times"] for r in rows) else math.nan,
            "calls": int(len(pt)),
            "pt_own_med": float(np.median(pt_own)) if len(pt_own) else math.nan,
            "pt_own_p95": float(np.percentile(pt_own, 95)) if len(pt_own) else math.nan,
            "calls_own": int(len(pt_own)),
            "fallbacks": int(sum(r["fallbacks"] for r in rows))}


def main(argv: list[str] | None = None) -> int:
    from anyplan.agents import AGENTS
    from anyplan.agents.settings import SettingsError
    from anyplan.cli.agent_options import add_agent_options, bench_configs

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="paper x 2 seeds, 1 random per count, 6 gap worlds, 6 DynaBARN worlds, "
                    "STRRT* at 1 s on paper only")
    ap.add_argument("--suites", default="paper,random,dynabarn,gaps")
    ap.add_argument("--planners", default=",".join(PLANNERS))
    ap.add_argument("--seeds", type=int, default=5, help="seeds per paper scenario (default 5)")
    ap.add_argument("--random", type=int, default=6, help="random scenarios per count 1-6 (default 6)")
    ap.add_argument("--gaps", type=int, default=40, help="gap worlds besides the issue's (default 40)")
    ap.add_argument("--dynabarn", default="20-59", help="DynaBARN worlds (default medium+hard 20-59)")
    ap.add_argument("--worlds-file", default="/work/shared/benchmarks/dynabarn/worlds.json")
    ap.add_argument("--delay", type=float, default=0.1, help="fixed planning delay [s] (default 0.1)")
    ap.add_argument("--strrt-budgets", default="1,5", help="STRRT* budgets [s]; 'none' to skip")
    ap.add_argument("--strrt-suites", default="paper,gaps", help="suites STRRT* runs on")
    ap.add_argument("--strrt-site", default=None,
                    help="directory with the ompl 1.7 wheel (pip install --target), if not installed")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default=None, help="write every run and the summary as JSON")
    add_agent_options(ap, bench=True)  # --set [PLANNER:]KEY=VALUE, --deterministic (anyplan bench's)
    args = ap.parse_args(argv)
    if args.quick:
        args.seeds, args.random, args.gaps, args.dynabarn = 2, 1, 6, "20,25,30,40,45,50"
        args.strrt_budgets, args.strrt_suites = "1", "paper"
    suites = [s.strip() for s in args.suites.split(",") if s.strip()]
    planners = [p.strip() for p in args.planners.split(",") if p.strip()]
    try:
        configs = bench_configs(args, [p for p in planners if p in AGENTS],
                                base={p: {"planning_delay": args.delay} for p in planners
                                      if p != "dovs"})
    except SettingsError as exc:  # a bad --set: one line, exit 2
        ap.error(str(exc))
    opts = {k: getattr(args, k) for k in ("random", "gaps", "dynabarn", "worlds_file", "delay",
                                          "strrt_site")}
    opts["agent_configs"] = configs
    jobs = []
    sizes = {}
    for suite in suites:
        n = len(_scenarios(suite, args))
        sizes[suite] = n
        seeds = range(args.seeds) if suite == "paper" else range(1)
        jobs += [(suite, i, p, s, opts) for p in planners for i in range(n) for s in seeds]
    budgets = [] if args.strrt_budgets.strip().lower() == "none" else \
        [float(b) for b in args.strrt_budgets.split(",") if b.strip()]
    strrt_jobs = []
    if budgets:
        from anyplan.experiments.strrt import strrt_available

        if strrt_available(args.strrt_site):
            strrt_suites = [s.strip() for s in args.strrt_suites.split(",")]
            strrt_jobs = [(s, i, b, opts) for s in suites if s in strrt_suites
                          for i in range(sizes[s]) for b in budgets]
        else:
            print("STRRT*: skipped (no ompl 1.7 with STRRTstar; pip install 'anyplan[strrt]' or "
                  "--strrt-site DIR)", flush=True)
    print(f"{len(jobs)} runs, {len(strrt_jobs)} STRRT* problems, {args.jobs} process(es); fixed "
          f"planning delay {args.delay} s", flush=True)
    t0 = time.perf_counter()
    rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        for k, r in enumerate(ex.map(run_one, jobs), 1):
            rows.append(r)
            if k % 10 == 0 or k == len(jobs):
                print(f"  {k}/{len(jobs)} runs ({time.perf_counter() - t0:.0f} s)", flush=True)
    for j in strrt_jobs:  # one subprocess each, sequential: they are timed
        rows.append(run_strrt(j))
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault((r["suite"], r["planner"]), []).append(r)
    summary = {f"{s}/{p}": summarise(g) for (s, p), g in groups.items()}
    print("\n| suite | planner | runs | success | collisions | robot-caused | time / bound (median) "
          "| path m | plan ms median | plan ms p95 | calls | without improvement calls: median / p95 "
          "(calls) | first plan ms median | fallbacks | distance to moving m, median / min |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (s, p), _ in sorted(groups.items()):
        m = summary[f"{s}/{p}"]
        print(f"| {s} | {p} | {m['runs']} | {100 * m['success']:.1f} % | {100 * m['collision']:.1f} % "
              f"| {m['robot_caused']} | {_fmt(m['ratio_med'], 3)} | {_fmt(m['len'])} "
              f"| {_fmt(m['pt_med'], 1)} | {_fmt(m['pt_p95'], 1)} | {m['calls']} "
              f"| {_fmt(m['pt_own_med'], 1)} / {_fmt(m['pt_own_p95'], 1)} ({m['calls_own']}) "
              f"| {_fmt(m['pt_first_med'], 1)} | {m['fallbacks']} "
              f"| {_fmt(m['dist_med'], 3)} / {_fmt(m['dist_min'], 3)} |")
    for s in suites:  # ratios against seq-bitstar in this same run
        a, b = summary.get(f"{s}/st-bitstar"), summary.get(f"{s}/seq-bitstar")
        if a and b and b["pt_med"] > 0:
            print(f"{s}: st-bitstar / seq-bitstar planning time median {a['pt_med'] / b['pt_med']:.2f}x, "
                  f"p95 {a['pt_p95'] / b['pt_p95']:.2f}x; success {100 * a['success']:.1f} % vs "
                  f"{100 * b['success']:.1f} %")
    print(f"total {time.perf_counter() - t0:.0f} s (timings on a shared machine are noisy)")
    if args.out:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        with open(args.out, "w") as f:
            json.dump({"args": vars(args), "summary": summary, "runs": rows}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
