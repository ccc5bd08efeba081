"""CPU time per planning call of st-bitstar, and its decisions, for two source trees back-to-back.

Runs st-bitstar deterministically (its ``deterministic_settings``: ``planning_delay=0.1,
batches_per_plan=2, max_time_s=10``, no search budget) on
paper-1..3 (``--seeds`` seeds), the first ``--random`` scenarios of ``random_suite(0)``,
``gap_suite(0, n=--gaps)``, ``--dynabarn`` of DynaBARN's medium and hard worlds (20-59, evenly
spread; tracks announced, as in ``benchmarks/spacetime.py``, or perceived as ``--dynabarn-mode``
says) and ``--crowds`` windows of each recorded crowd and of the dense overlay (``tracked``,
as ``benchmarks/unknown.py`` builds them), and records for every run its
status, time to goal, executed trajectory and planned paths (a fingerprint), and the CPU time
(``time.process_time``) of every planning call (``_replan``). With ``--trees A,B`` each repetition
runs one worker process per tree, alternating, so that the load of the shared machine falls on
both alike; it then tells whether the decisions (trajectory, paths, outcome) are identical
(``--mode deterministic``; and, apart, whether the whole results are, statistics included) and
prints per suite the median and p95 per-call CPU times and their ratios B / A. ``--mode bench``
runs the benchmark's settings instead (BIT* on a time budget), for timing only.

Usage::

    python benchmarks/spacetime_calls.py --trees /path/to/before,/path/to/after --reps 3
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import time
from typing import Any

import numpy as np


def _scenarios(args: argparse.Namespace) -> list[tuple[str, Any, list[int]]]:
    from anyplan.experiments.gaps import gap_suite
    from anyplan.experiments.generate import random_suite
    from anyplan.world import load_scenario

    seeds = list(range(args.seeds))
    out = [("paper", load_scenario(f"paper-{n}"), seeds) for n in (1, 2, 3)]
    out += [("random", sc, [0]) for sc in random_suite(0)[: args.random]]
    out += [("gaps", sc, [0]) for sc in gap_suite(0, n=args.gaps)]
    if args.dynabarn > 0:
        from anyplan.experiments.dynabarn import load_worlds, world_to_scenario
        from anyplan.world.scenario import scenario_from_dict

        worlds = load_worlds(args.worlds_file)
        for i in np.linspace(20, 59, args.dynabarn).round().astype(int):
            d = world_to_scenario(worlds[int(i)])
            sc = d if not isinstance(d, dict) else scenario_from_dict(d, f"<dynabarn {i}>")
            if args.dynabarn_mode != "oracle":
                from anyplan.simulation.perception import override_sensing

                sc = override_sensing(sc, args.dynabarn_mode)
            out.append(("dynabarn", sc, [0]))
    if args.crowds > 0:
        out += _crowds(args.crowds)
    return out


def _crowds(n: int) -> list[tuple[str, Any, list[int]]]:
    """The first ``n`` windows of ETH hotel and UCY zara01 (``crowds``) and of zara01 overlaid
    ten times (``dense``), ``tracked``: ``benchmarks/unknown.py``'s crowd windows."""
    import unknown  # benchmarks/unknown.py, beside this script (as benchmarks/contacts.py)

    from anyplan.simulation.perception import override_sensing
    from anyplan.world.scenario import scenario_from_dict

    return [("dense" if tag == "crowds-dense" else "crowds",
             override_sensing(scenario_from_dict(d, d["name"]), "tracked"), [0])
            for tag, d in unknown._crowds(n)]


def _digest(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


def worker(args: argparse.Namespace) -> dict[str, Any]:
    """Every run in this process; per-call CPU times and fingerprints."""
    from anyplan.agents import make_agent
    from anyplan.agents.spacetime import SpaceTimeBITStarAgent
    from anyplan.simulation import simulate

    calls: list[float] = []
    inner = SpaceTimeBITStarAgent._replan

    def timed(self: Any, *a: Any, **k: Any) -> Any:
        c0 = time.process_time()
        try:
            return inner(self, *a, **k)
        finally:
            calls.append(time.process_time() - c0)

    SpaceTimeBITStarAgent._replan = timed  # type: ignore[method-assign]

    def agent() -> Any:
        if args.mode == "bench":  # benchmarks/spacetime.py's settings: BIT* on a time budget
            return make_agent("st-bitstar", planning_delay=0.1)
        from anyplan.agents import AGENTS

        return make_agent("st-bitstar", **AGENTS.get("st-bitstar").deterministic_settings)

    scen = _scenarios(args)
    simulate(scen[0][1], agent(), seed=0)  # warm-up: compiled kernels loaded, caches filled
    runs = []
    for suite, sc, seeds in scen:
        for seed in seeds:
            calls.clear()
            res = simulate(sc, agent(), seed=seed)
            d = res.reproducible_dict()
            core = {"status": str(res.status), "time_to_goal_s": res.time_to_goal_s,
                    "trajectory": res.trajectory,
                    "paths": [p.get("path") for p in res.plans]}
            runs.append({"suite": suite, "scenario": sc.name, "seed": seed,
                         "status": str(res.status), "time_to_goal_s": res.time_to_goal_s,
                         "core": _digest(core), "full": _digest(d), "cpu_s": list(calls)})
    return {"runs": runs}


def _stats(x: list[float]) -> tuple[float, float]:
    a = np.asarray(x) * 1e3
    return (float(np.median(a)), float(np.percentile(a, 95))) if len(a) else (np.nan, np.nan)


def driver(args: argparse.Namespace) -> int:
    trees = [os.path.abspath(t) for t in args.trees.split(",")]
    results: dict[str, list[dict[str, Any]]] = {t: [] for t in trees}
    flags = ["--seeds", str(args.seeds), "--random", str(args.random), "--gaps", str(args.gaps),
             "--dynabarn", str(args.dynabarn), "--worlds-file", args.worlds_file, "--mode", args.mode,
             "--dynabarn-mode", args.dynabarn_mode, "--crowds", str(args.crowds)]
    for rep in range(args.reps):
        for t in trees:
            env = dict(os.environ, PYTHONPATH=os.path.join(t, "src"))
            w0 = time.perf_counter()
            out = subprocess.run([sys.executable, os.path.abspath(__file__), "--worker", *flags],
                                 env=env, check=True, capture_output=True, text=True).stdout
            results[t].append(json.loads(out.strip().splitlines()[-1]))
            print(f"rep {rep} {t}: {time.perf_counter() - w0:.0f} s", flush=True)
    base = trees[0]
    ref = results[base][0]["runs"]
    ok, same_records = True, True
    for t in trees if args.mode == "deterministic" else ():
        for rep in results[t]:
            for r0, r1 in zip(ref, rep["runs"], strict=True):
                if r0["full"] != r1["full"]:
                    same_records = False  # e.g. a new statistic: reported, not a failure
                if r0["core"] != r1["core"]:
                    ok = False
                    print(f"DIFFERENT: {t} {r1['scenario']} seed {r1['seed']}: "
                          f"{r0['status']} {r0['time_to_goal_s']} -> {r1['status']} "
                          f"{r1['time_to_goal_s']}")
    print(f"decisions identical across trees and repetitions: {ok} ({len(ref)} runs, {args.mode})")
    if args.mode == "deterministic":
        print(f"whole results identical (statistics included): {same_records}")
    for r in ref:
        print(f"  {r['suite']:6s} {r['scenario']:16s} seed {r['seed']}: {r['status']} "
              f"{r['time_to_goal_s']} core {r['core']} calls {len(r['cpu_s'])}")
    print("\nCPU ms per planning call (all repetitions pooled; each tree's calls)")
    print("| suite | calls | " + " | ".join(f"{os.path.basename(t)} med / p95" for t in trees)
          + " | ratio med | ratio p95 |")
    print("|---|---|" + "---|" * len(trees) + "---|---|")
    for suite in ("paper", "random", "gaps", "dynabarn", "crowds", "dense", "all"):
        per = []
        for t in trees:
            x = [c for rep in results[t] for r in rep["runs"]
                 if suite in ("all", r["suite"]) for c in r["cpu_s"]]
            per.append((len(x), *_stats(x)))
        if not per[0][0]:
            continue
        cells = " | ".join(f"{m:.1f} / {p:.1f}" for _, m, p in per)
        rm, rp = per[-1][1] / per[0][1], per[-1][2] / per[0][2]
        print(f"| {suite} | {per[0][0]} | {cells} | {rm:.2f} | {rp:.2f} |")
    # per repetition ratios (load drifts between repetitions)
    for i in range(args.reps):
        xs = [[c for r in results[t][i]["runs"] for c in r["cpu_s"]] for t in trees]
        m = [_stats(x) for x in xs]
        print(f"rep {i}: all suites ratio med {m[-1][0] / m[0][0]:.2f}, p95 {m[-1][1] / m[0][1]:.2f}")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f)
    return 0 if ok else 1


def main(argv: list[str] | None = None) -> int:
    from anyplan.world.sensing import MODES

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trees", default=None, help="comma-separated source trees (before,after)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--random", type=int, default=6)
    ap.add_argument("--gaps", type=int, default=6)
    ap.add_argument("--dynabarn", type=int, default=0, help="DynaBARN worlds of 20-59 (default 0)")
    ap.add_argument("--worlds-file", default="/work/shared/benchmarks/dynabarn/worlds.json")
    ap.add_argument("--dynabarn-mode", choices=MODES, default="oracle",
                    help="perception of the DynaBARN worlds (default oracle: tracks announced)")
    ap.add_argument("--crowds", type=int, default=0,
                    help="windows of each recorded crowd and of the dense overlay (default 0)")
    ap.add_argument("--mode", choices=("deterministic", "bench"), default="deterministic",
                    help="deterministic (batch budget: decisions compared) or bench (the "
                    "benchmark's time budget: decisions may differ with the load; timing only)")
    ap.add_argument("--out", default=None)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(args)))
        return 0
    if not args.trees:
        ap.error("--trees is required")
    return driver(args)


if __name__ == "__main__":
    sys.exit(main())
