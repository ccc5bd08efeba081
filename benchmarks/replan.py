"""Benchmark of Sequential BIT* executed online (issue 5).

For each scenario (paper-1..3 and random scenarios with 1-6 moving obstacles from
``anyplan.experiments.generate``) and each configuration, it runs the ``seq-bitstar`` agent in
the simulator over several seeds and reports:

* path generation time per replanning: median and 95th percentile of the wall-clock time of one
  whole Sequential BIT* replanning (all BIT* searches, smoothing, velocity profiles and
  collision predictions of the loop), and of its BIT* part alone;
* BIT* plans per replanning (the paper needed about three);
* time to goal and path length (means over the runs that reached the goal);
* success, collision and timeout rates, robot-caused collisions (at first contact the robot
  moved towards the obstacle at more than 0.05 m/s) and safety fallbacks per run;
* time to goal over the run's time lower bound (static shortest path at the robot's limits).

The configurations compared in the same run: ``warm`` (the default: the BIT* search continues
after each virtual obstacle is added) against ``cold`` (a new search for each iteration, as
separate runs in the paper), and ``dovs`` as the paper's baseline. The paper's figures are
printed beside ours; ratios are ours / paper and cold / warm from this same run.

Usage::

    python benchmarks/replan.py [--seeds 10] [--random 12] [--gap 0] [--configs warm,cold,dovs] [--jobs 2]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

PAPER = {  # the paper's Tables 2 and 3: (path length m, path generation time s, time to goal s)
    "seq-bitstar": {1: (12.076, 0.1841, 40.766), 2: (12.003, 0.1716, 40.218), 3: (12.115, 0.1835, 40.655)},
    "dovs": {1: (18.762, 0.25188, 50.1), 2: (18.4852, 0.207315, 56.006), 3: None},
}


def _agent(config: str) -> Any:
    """``warm``, ``cold`` or ``dovs``, optionally with options: ``cold:iteration_budget_s=0.002``
    (``True``/``False`` and ``()`` are read as such: ``cold:safety=False;wait_delays_s=()``)."""
    from anyplan.agents import make_agent

    name, _, opts = config.partition(":")
    kw: dict[str, Any] = {}
    for item in filter(None, opts.split(";")):
        k, _, v = item.partition("=")
        if v in ("True", "False"):
            kw[k] = v == "True"
        elif v == "()":
            kw[k] = ()
        else:
            kw[k] = float(v) if v.replace(".", "", 1).replace("e-", "", 1).isdigit() else v
    if name == "warm":
        return make_agent("seq-bitstar", warm_start=True, **kw)
    if name == "cold":
        return make_agent("seq-bitstar", warm_start=False, **kw)
    if name == "dovs":
        return make_agent("dovs", **kw)
    raise SystemExit(f"unknown config {config!r}")


def _scenario(key: str) -> Any:
    from anyplan.experiments.generate import random_scenario
    from anyplan.world import load_scenario

    if key.startswith("paper-") or key == "gap-walker":
        return load_scenario(key)
    _, seed, n = key.split(":")
    return random_scenario(np.random.default_rng(int(seed)), n_moving=int(n))


def _warm_up() -> None:
    """Load the compiled kernels in a worker before anything is timed (a robot's planner is a
    long-lived process: loading numba's cached machine code is a start-up cost, not a
    replanning cost)."""
    from anyplan.simulation import simulate
    from anyplan.world import load_scenario

    simulate(load_scenario("paper-1"), _agent("cold"), seed=0)
    simulate(load_scenario("paper-1"), _agent("dovs"), seed=0)


def run_one(job: tuple[str, str, int]) -> dict[str, Any]:
    """One simulated run; returns its metrics (top level so that worker processes can call it)."""
    from anyplan.simulation import simulate

    key, config, seed = job
    sc = _scenario(key)
    t = time.perf_counter()
    res = simulate(sc, _agent(config), seed=seed)
    ex = res.extra
    return {
        "key": key, "config": config, "seed": seed, "n_moving": len(sc.moving_obstacles),
        "status": res.status, "time_to_goal": res.time_to_goal_s, "length": res.path_length_m,
        "plan_times": list(res.planning_times_s), "bitstar_times": list(ex.get("plan_time_s", [])),
        "iterations": list(ex.get("iterations", [])), "replans": res.replans,
        "virtual": len(res.virtual_obstacles), "clearance": res.min_clearance_m,
        "robot_caused": res.collision_robot_caused, "fallbacks": len(ex.get("fallbacks", [])),
        "over_bound": res.time_over_lower_bound,
        "wall": time.perf_counter() - t,
    }


def _fmt(x: float | None, nd: int = 2) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{nd}f}"


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Aggregate the runs of one (scenario group, configuration)."""
    pt = np.array([t for r in rows for t in r["plan_times"]]) * 1e3
    bt = np.array([t for r in rows for t in r["bitstar_times"]]) * 1e3
    it = [i for r in rows for i in r["iterations"]]
    ok = [r for r in rows if r["status"] == "reached"]
    return {
        "runs": len(rows),
        "success": len(ok) / len(rows),
        "collision": sum(r["status"] == "collision" for r in rows) / len(rows),
        "timeout": sum(r["status"] == "timeout" for r in rows) / len(rows),
        "n_collisions": sum(r["status"] == "collision" for r in rows),
        "n_robot_caused": sum(bool(r.get("robot_caused")) for r in rows if r["status"] == "collision"),
        "fallbacks": float(np.mean([r.get("fallbacks", 0) for r in rows])),
        "over_bound": float(np.median([r["over_bound"] for r in ok if r.get("over_bound")]))
        if any(r.get("over_bound") for r in ok) else math.nan,
        "pt_med": float(np.median(pt)) if len(pt) else math.nan,
        "pt_p95": float(np.percentile(pt, 95)) if len(pt) else math.nan,
        "bt_med": float(np.median(bt)) if len(bt) else math.nan,
        "iters": float(np.mean(it)) if it else math.nan,
        "ttg": float(np.mean([r["time_to_goal"] for r in ok])) if ok else math.nan,
        "len": float(np.mean([r["length"] for r in ok])) if ok else math.nan,
        "clear": float(min(r["clearance"] for r in rows)),
        "replans": float(np.mean([r["replans"] for r in rows])),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=10, help="seeds per paper scenario (default 10)")
    ap.add_argument("--random", type=int, default=12,
                    help="random scenarios per number of moving obstacles 1..6 (default 12)")
    ap.add_argument("--gap", type=int, default=0,
                    help="seeds on the built-in gap-walker scenario (issue 10; default 0)")
    ap.add_argument("--configs", default="warm,cold,dovs",
                    help="comma list of warm, cold, dovs, each optionally with agent options "
                    "after a colon, separated by semicolons (e.g. 'cold:iteration_budget_s=0.002')")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1), help="processes")
    args = ap.parse_args(argv)
    configs = [c.strip() for c in args.configs.split(",") if c.strip()]
    jobs: list[tuple[str, str, int]] = []
    for c in configs:
        for n in (1, 2, 3):
            jobs += [(f"paper-{n}", c, s) for s in range(args.seeds)]
        for n in range(1, 7):
            jobs += [(f"random:{9000 + 100 * n + i}:{n}", c, i) for i in range(args.random)]
        jobs += [("gap-walker", c, s) for s in range(args.gap)]
    t0 = time.perf_counter()
    rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(max_workers=args.jobs, initializer=_warm_up) as pool:
        for k, row in enumerate(pool.map(run_one, jobs, chunksize=2)):
            rows.append(row)
            if (k + 1) % 20 == 0 or k + 1 == len(jobs):
                print(f"  {k + 1}/{len(jobs)} runs, {time.perf_counter() - t0:.0f} s", file=sys.stderr)

    print(f"\nSequential BIT* online: {len(rows)} runs in {time.perf_counter() - t0:.0f} s "
          f"({args.jobs} processes; times are wall-clock on this machine)\n")
    head = ("| scenarios | config | runs | success | collisions | robot-caused collisions | timeout "
            "| gen. time median / p95 [ms] "
            "| BIT* part median [ms] | plans per replan | replans per run | fallbacks per run "
            "| time to goal [s] | time / lower bound (median) | path [m] | min clearance [m] |")
    print(head)
    print("|" + "---|" * 16)
    groups = [(f"paper-{n}", lambda r, n=n: r["key"] == f"paper-{n}") for n in (1, 2, 3)]
    groups += [(f"random, {n} moving", lambda r, n=n: r["key"].startswith("random") and r["n_moving"] == n)
               for n in range(1, 7)]
    groups += [("random, all", lambda r: r["key"].startswith("random"))]
    groups += [("gap-walker", lambda r: r["key"] == "gap-walker")]
    summary: dict[tuple[str, str], dict[str, Any]] = {}
    for name, pred in groups:
        for c in configs:
            sel = [r for r in rows if r["config"] == c and pred(r)]
            if not sel:
                continue
            s = summarise(sel)
            summary[(name, c)] = s
            print(f"| {name} | {c} | {s['runs']} | {s['success']:.0%} | {s['n_collisions']} | "
                  f"{s['n_robot_caused']} | "
                  f"{s['timeout']:.0%} | {_fmt(s['pt_med'], 1)} / {_fmt(s['pt_p95'], 1)} | "
                  f"{_fmt(s['bt_med'], 1)} | {_fmt(s['iters'], 1)} | {_fmt(s['replans'], 1)} | "
                  f"{_fmt(s['fallbacks'], 1)} | {_fmt(s['ttg'])} | {_fmt(s['over_bound'], 3)} | "
                  f"{_fmt(s['len'])} | {_fmt(s['clear'])} |")

    print("\nBeside the paper (Tables 2-3; ours: means over the runs that reached the goal; "
          "generation time: median per replanning, ours in ms against the paper's in ms)\n")
    print("| scenario | method | path [m] ours / paper | generation time [ms] ours / paper (ratio) "
          "| time to goal [s] ours / paper (ratio) |")
    print("|---|---|---|---|---|")
    for n in (1, 2, 3):
        for c, method in [(c, "seq-bitstar") for c in configs if not c.startswith("dovs")] + [
                ("dovs", "dovs")]:
            s = summary.get((f"paper-{n}", c))
            if s is None:
                continue
            p = PAPER[method][n]
            if p is None:
                print(f"| paper-{n} | {method} | {_fmt(s['len'])} / crashed | {_fmt(s['pt_med'], 1)} / - "
                      f"| {_fmt(s['ttg'])} / crashed (ours: {s['success']:.0%} reached) |")
                continue
            print(f"| paper-{n} | {method} ({c}) | {_fmt(s['len'])} / {p[0]:.3f} | {_fmt(s['pt_med'], 1)} / "
                  f"{1e3 * p[1]:.1f} ({s['pt_med'] / (1e3 * p[1]):.3f}) | {_fmt(s['ttg'])} / {p[2]:.1f} "
                  f"({s['ttg'] / p[2]:.3f}) |")
    if "warm" in configs and "cold" in configs:
        print("\nContinued search (warm) against a new search per iteration (cold), same run:\n")
        print("| scenarios | gen. time median warm / cold [ms] | ratio cold / warm "
              "| BIT* part warm / cold [ms] |")
        print("|---|---|---|---|")
        for name, _ in groups:
            w, c = summary.get((name, "warm")), summary.get((name, "cold"))
            if w and c:
                print(f"| {name} | {_fmt(w['pt_med'], 1)} / {_fmt(c['pt_med'], 1)} | "
                      f"{c['pt_med'] / w['pt_med']:.2f} | {_fmt(w['bt_med'], 1)} / {_fmt(c['bt_med'], 1)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
