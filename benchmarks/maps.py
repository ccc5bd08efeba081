"""Benchmark: planning on occupancy-grid maps and among many moving obstacles (issue 11).

Maps are generated floor plans written as ROS map_server maps (PGM + YAML, 0.05 m cells,
:mod:`anyplan.experiments.floorplans`): offices (a corridor, rooms with doors, furniture) and
warehouses (racks and aisles), "rough" = SLAM-like ragged walls (each free cell next to a wall
occupied with probability 0.3) and isolated speckles. They are loaded through ``static_map:``
like any user map, so the loader, the cell merging and the grid index are all in the loop.

Sections (every time is wall-clock on a shared machine; compare within one run):

1. **Static maps.** Per map: occupied cells, merged rectangles, load time (read + merge +
   index); the visibility-graph optimum bracket (``lower`` <= optimum <= ``feasible``, arcs
   of pi/8) and its time; BIT* over seeds: time to the first solution (median, max), cost /
   the lower bound at 50, 200 and 1000 ms (median, max; so >= the ratio to the optimum),
   whether every returned path passes the exact check, and the process's peak RSS. The same
   BIT* first-solution time on the static ``paper-3`` problem is printed for
   context, and the peer is the same BIT* on the same map with the grid index switched off
   (every box scanned; first 3 seeds), with point-clearance and segment-check times with and
   without the index (ratio linear / indexed).
2. **Walkers in the office corridor.** ``seq-bitstar`` (and ``st-bitstar`` when that agent is
   registered) drive across the 30 m x 20 m office with walkers pacing the corridor: goal
   reached, collisions, robot-caused collisions (robot speed towards the obstacle > 0.05 m/s at
   first contact; any contact with a map cell or a wall while moving counts as robot-caused),
   the first plan's time (from rest at the start) and the replanning time per call while
   driving (median, p90; wall clock, as the agents measure it; "no replanning" when the first
   motion needed none, as with announced walkers; st-bitstar's improvement calls, made while
   the robot drives a safe motion, are counted in it and their share given apart), and the
   whole runs' CPU and wall time (their ratio shows how loaded the machine was). The built-in
   ``paper-3`` scenario runs first as the peer.
3. **Many moving obstacles.** The same for 25, 50 and 100 pacing obstacles in a 40 m x 30 m hall
   (:mod:`anyplan.experiments.many`).
4. **Long routes.** ``st-bitstar`` along corridors 30, 150 and 600 m long with pillars and a
   walker every 40 m (``anyplan.experiments.many.long_route``) and across a 100 m x 60 m
   warehouse map with 6 walkers, walkers tracked: the same figures, and the largest call; a
   call's cost should not grow with the route's length.

Targets (issue 11): office 30 x 20 m: BIT* first solution <= 10 ms, <= 1.02 x the optimum at
200 ms, a valid path every time; seq-bitstar across it with walkers without collision,
replanning <= 20 ms median; 100 moving obstacles: replanning <= 30 ms median.

Usage::

    python benchmarks/maps.py --quick          # 30 x 20 office only, 5 seeds, 1 run per crowd
    python benchmarks/maps.py                  # all maps, 10 seeds, 3 runs per crowd
    python benchmarks/maps.py --json out.json --out maps/   # keep the results and the maps
    python benchmarks/maps.py --quick --no-static --deterministic   # A/B two commits
    python benchmarks/maps.py --quick --no-static --perception tracked   # walkers detected, not known
    python benchmarks/maps.py --quick --no-static --set st-bitstar:announced_horizon_s=null
"""

from __future__ import annotations

import argparse
import gc
import hashlib
import json
import math
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.agents import AGENTS, make_agent
from anyplan.agents.settings import SettingsError
from anyplan.agents.stats import improvement_calls
from anyplan.cli.agent_options import add_agent_options, bench_configs
from anyplan.geometry import ObstacleSet
from anyplan.planning import BITStar, Problem
from anyplan.planning.visgraph import shortest_path
from anyplan.simulation import simulate
from anyplan.world import load_scenario
from anyplan.world.scenario import Scenario

BUDGETS_S = (0.05, 0.2, 1.0)
#: The planners of sections 2-3.
PLANNERS = ["seq-bitstar"] + (["st-bitstar"] if "st-bitstar" in AGENTS else [])
ARC_STEP = math.pi / 8


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _maps(quick: bool) -> list[tuple[str, Any]]:
    from anyplan.experiments.floorplans import office, roughen, warehouse

    out = [("office-30x20-rough", lambda: roughen(office(30, 20, rng=1), 0.3, 50, rng=1))]
    if not quick:
        out += [("office-30x20-clean", lambda: office(30, 20, rng=1)),
                ("office-60x40-rough", lambda: roughen(office(60, 40, rng=2), 0.3, 150, rng=2)),
                ("warehouse-60x40-rough",
                 lambda: roughen(warehouse(60, 40, rng=3), 0.3, 150, rng=3)),
                ("warehouse-100x60-rough",
                 lambda: roughen(warehouse(100, 60, rng=4), 0.3, 300, rng=4))]
    return out


def _first_solution(prob: Problem, seed: int, cap_s: float = 2.0) -> tuple[BITStar, float]:
    gc.collect()
    b = BITStar(prob, rng=seed)
    t0 = time.perf_counter()
    while not math.isfinite(b.best_cost) and time.perf_counter() - t0 < cap_s:
        b.solve(0.0005)
    return b, b.result().first_solution_time_s or math.inf


def _bitstar_runs(prob: Problem, seeds: int, lower: float) -> dict[str, Any]:
    firsts, ratios, valid = [], {b: [] for b in BUDGETS_S}, True
    for s in range(seeds):
        b, t_first = _first_solution(prob, 1000 + s)
        firsts.append(t_first)
        spent = b.result().solve_time_s
        for budget in BUDGETS_S:
            if budget > spent:
                b.solve(budget - spent)
                spent = b.result().solve_time_s
            res = b.result()
            ratios[budget].append(res.cost / lower if math.isfinite(res.cost) else math.inf)
            if len(res.path) and not prob.obstacles.path_free(res.path, prob.radius):
                valid = False
    return {"first_ms": [1e3 * t for t in firsts],
            "ratio": {str(k): v for k, v in ratios.items()}, "valid": valid}


def _query_speed(obs: ObstacleSet, rng: np.random.Generator) -> dict[str, float]:
    x0, y0, x1, y1 = obs.bounds
    pts = rng.uniform([x0, y0], [x1, y1], size=(2000, 2))
    a = rng.uniform([x0, y0], [x1, y1], size=(500, 2))
    b = a + rng.normal(0.0, 2.0, size=a.shape)
    linear = ObstacleSet(obs.shapes, bounds=obs.bounds, boxes=obs.boxes, index=False)
    out = {}
    for name, o in (("indexed", obs), ("linear", linear)):
        o.clearances(pts[:10])
        o.segments_free(a[:10], b[:10], 0.3)
        t = time.perf_counter()
        c = o.clearances(pts)
        out[f"point_us_{name}"] = 1e6 * (time.perf_counter() - t) / len(pts)
        t = time.perf_counter()
        f = o.segments_free(a, b, 0.3)
        out[f"segment_us_{name}"] = 1e6 * (time.perf_counter() - t) / len(a)
        out[f"_c_{name}"], out[f"_f_{name}"] = c, f
    assert np.array_equal(out.pop("_f_indexed"), out.pop("_f_linear"))
    assert np.allclose(out.pop("_c_indexed"), out.pop("_c_linear"), atol=1e-12, rtol=0)
    return out


def static_section(maps_dir: Path, quick: bool, seeds: int) -> list[dict[str, Any]]:
    from anyplan.experiments.floorplans import map_scenario

    rows = []
    peer = load_scenario("paper-3").static_only()
    r = peer.robot
    peer_prob = Problem.create(peer.obstacle_set(), r.start[:2], r.goal, r.radius)
    peer_first = [1e3 * _first_solution(peer_prob, 1000 + s)[1] for s in range(seeds)]
    print(f"peer: BIT* first solution on paper-3 (static): median "
          f"{statistics.median(peer_first):.2f} ms over {seeds} seeds")
    for name, make in _maps(quick):
        plan = make()
        path = map_scenario(plan, maps_dir, name)
        t = time.perf_counter()
        sc = load_scenario(path)
        obs = sc.obstacle_set()
        t_load = time.perf_counter() - t
        rb = sc.robot
        prob = Problem.create(obs, rb.start[:2], rb.goal, rb.radius)
        t = time.perf_counter()
        lo = shortest_path(prob, variant="lower", arc_step=ARC_STEP)
        hi = shortest_path(prob, variant="feasible", arc_step=ARC_STEP)
        t_vg = time.perf_counter() - t
        runs = _bitstar_runs(prob, seeds, lo.cost)
        lin = ObstacleSet(obs.shapes, bounds=obs.bounds, boxes=obs.boxes, index=False)
        lin_prob = Problem.create(lin, rb.start[:2], rb.goal, rb.radius)
        lin_first = [1e3 * _first_solution(lin_prob, 1000 + s, cap_s=5.0)[1]
                     for s in range(min(seeds, 3))]
        q = _query_speed(obs, np.random.default_rng(0))
        row = {"map": name, "size_m": plan.size_m, "cells": int(sc.static_map.n_blocked),
               "rects": len(obs.boxes), "load_s": t_load, "vg_lower": lo.cost,
               "vg_feasible": hi.cost, "vg_nodes": hi.n_nodes, "vg_s": t_vg,
               "peer_first_ms": statistics.median(peer_first), "linear_first_ms": lin_first,
               "rss_mb": _rss_mb(), **runs, **q}
        rows.append(row)
        f = row["first_ms"]
        rat = {k: (statistics.median(v), max(v)) for k, v in row["ratio"].items()}
        print(f"\n{name}: {plan.size_m[0]:g} x {plan.size_m[1]:g} m, {row['cells']} occupied "
              f"cells -> {row['rects']} rectangles; load+merge+index {t_load * 1e3:.0f} ms")
        print(f"  visibility graph: {lo.cost:.4f} <= optimum <= {hi.cost:.4f} m "
              f"({hi.n_nodes} nodes, {t_vg:.1f} s)")
        print(f"  BIT* first solution: median {statistics.median(f):.1f} ms, max {max(f):.1f} ms "
              f"(paper-3: {row['peer_first_ms']:.2f} ms; the same map without the index, seeds "
              f"0-{len(lin_first) - 1}: median {statistics.median(lin_first):.1f} ms, "
              f"{statistics.median(lin_first) / statistics.median(f[:len(lin_first)]):.1f} x)")
        for k, (m, mx) in rat.items():
            print(f"  BIT* cost / lower bound at {float(k) * 1e3:.0f} ms: median {m:.4f}, max {mx:.4f}")
        print(f"  every path valid (exact check): {runs['valid']}; peak RSS {row['rss_mb']:.0f} MB")
        print(f"  point clearance {q['point_us_indexed']:.2f} us indexed vs "
              f"{q['point_us_linear']:.1f} us linear ({q['point_us_linear'] / q['point_us_indexed']:.0f} x); "
              f"segment check {q['segment_us_indexed']:.2f} vs {q['segment_us_linear']:.1f} us "
              f"({q['segment_us_linear'] / q['segment_us_indexed']:.0f} x)")
    return rows


def _drive(sc: Scenario, planners: list[str], runs: int, label: str,
           configs: dict[str, dict[str, Any]], perception: str | None = None) -> list[dict[str, Any]]:
    if perception is not None:
        from anyplan.simulation.perception import override_sensing

        sc = override_sensing(sc, perception)
    rows = []
    for planner in planners:
        times, first, reached, coll, caused, ttg, cpu, wall = [], [], 0, 0, 0, [], 0.0, 0.0
        own: list[float] = []  # replanning calls other than improvement calls
        digest = hashlib.sha1()
        kw = configs.get(planner, {})
        for s in range(runs):
            gc.collect()
            c0, w0 = time.process_time(), time.perf_counter()
            res = simulate(sc, make_agent(planner, **kw), seed=s)
            digest.update(np.round(res.trajectory_array[:, 1:3], 9).tobytes())
            cpu += time.process_time() - c0
            wall += time.perf_counter() - w0
            first += res.planning_times_s[:1]
            times += res.planning_times_s[1:]
            improving = improvement_calls(res.extra, len(res.planning_times_s))
            own += [t for t, imp in zip(res.planning_times_s[1:], improving[1:], strict=True)
                    if not imp]  # st-bitstar's improvement calls apart
            reached += bool(res.reached_goal)
            coll += bool(res.collision)
            caused += bool(res.collision_robot_caused)  # the simulator's classification
            if res.time_to_goal_s is not None:
                ttg.append(res.time_to_goal_s)
        ms = sorted(1e3 * t for t in times) or [math.nan]
        row = {"scenario": label, "planner": planner, "runs": runs, "reached": reached,
               "collisions": coll, "robot_caused": caused,
               "perception": perception or "scenario",
               "first_plan_ms_median": statistics.median(1e3 * t for t in first) if first else None,
               "replan_ms_median": statistics.median(ms),
               "replan_ms_p90": ms[min(len(ms) - 1, int(0.9 * len(ms)))], "replan_ms_max": ms[-1],
               "replans": len(times),
               "replan_own_ms_median": statistics.median(1e3 * t for t in own) if own else None,
               "replans_own": len(own),
               "time_to_goal_s": statistics.median(ttg) if ttg else None, "rss_mb": _rss_mb(),
               "run_cpu_s": cpu, "run_wall_s": wall, "trajectory_digest": digest.hexdigest()[:10]}
        rows.append(row)
        replan = (f"replanning median {row['replan_ms_median']:.1f} ms, p90 "
                  f"{row['replan_ms_p90']:.1f} ms, max {ms[-1]:.1f} ms over {len(times)} calls"
                  if times else
                  "no replanning")
        if len(own) != len(times):
            om = row["replan_own_ms_median"]
            replan += (f" (without improvement calls: median {om:.1f} ms over {len(own)} calls)"
                       if om is not None else " (all of them improvement calls)")
        fp = row["first_plan_ms_median"]
        print(f"  {label:26s} {planner:12s} reached {reached}/{runs}, collisions {coll} "
              f"(robot-caused {caused}), first plan {fp if fp is not None else math.nan:.1f} ms, "
              f"{replan}, time to goal "
              f"{row['time_to_goal_s'] if ttg else float('nan'):.1f} s; whole runs: CPU {cpu:.1f} s "
              f"in {wall:.1f} s wall; trajectories {row['trajectory_digest']}")
    return rows


def dynamic_section(maps_dir: Path, quick: bool, configs: dict[str, dict[str, Any]],
                    perception: str | None = None) -> list[dict[str, Any]]:
    """Sections 2-3; ``configs``: each planner's settings (``--set``, ``--deterministic``)."""
    from anyplan.experiments.floorplans import map_scenario, office, roughen
    from anyplan.experiments.many import many_obstacles

    planners = PLANNERS
    runs = 1 if quick else 3
    print("\nwalkers in the office corridor, and many moving obstacles (the first plan, from rest "
          "at the start, apart from the replanning calls while driving; walkers perceived "
          f"{perception or 'as each scenario says (oracle)'})")
    plan = roughen(office(30, 20, rng=1), 0.3, 50, rng=1)
    # peer: the paper's scenario in the same run (README: 15.3 ms median on an unloaded machine)
    rows = _drive(load_scenario("paper-3"), planners, 1, "peer: paper-3", configs)
    for n in (2, 4):
        path = map_scenario(plan, maps_dir, f"office-walkers-{n}", n_walkers=n, rng=n)
        rows += _drive(load_scenario(path), planners, runs, f"office-30x20 + {n} walkers", configs,
                       perception)
    for n in (25, 50, 100):
        rows += _drive(many_obstacles(n, rng=n), planners, runs, f"hall 40x30 + {n} movers", configs)
    return rows


def long_section(maps_dir: Path, configs: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """Section 4: st-bitstar along corridors 30, 150 and 600 m long and across a 100 m x 60 m
    warehouse map (walkers tracked)."""
    from anyplan.experiments.floorplans import map_scenario, roughen, warehouse
    from anyplan.experiments.many import long_route

    print("\nlong routes: a corridor 12 m wide with pillars and a walker every 40 m, and a "
          "100 m x 60 m warehouse map with 6 walkers, walkers tracked (8 m range); st-bitstar "
          "(a call's cost should not grow with the route; peak RSS is the process's so far)")
    rows = []
    for length in (30.0, 150.0, 600.0):
        rows += _drive(long_route(length, rng=1), ["st-bitstar"], 1, f"corridor {length:g} m", configs)
    plan = roughen(warehouse(100.0, 60.0, rng=1), 0.3, 50, rng=1)
    path = map_scenario(plan, maps_dir, "warehouse-walkers-6", n_walkers=6, rng=6, time_limit=480.0)
    rows += _drive(load_scenario(path), ["st-bitstar"], 1, "warehouse 100x60 + 6 walkers", configs,
                   "tracked")
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="the 30 x 20 office only, 5 seeds")
    ap.add_argument("--seeds", type=int, default=None, help="BIT* seeds per map (10; quick 5)")
    ap.add_argument("--out", default=None, help="keep the generated maps in this directory")
    ap.add_argument("--json", default=None, help="write every figure to this file")
    ap.add_argument("--no-dynamic", action="store_true", help="skip sections 2, 3 and 4")
    ap.add_argument("--no-static", action="store_true", help="skip section 1")
    ap.add_argument("--perception", choices=("oracle", "twist", "tracked"), default=None,
                    help="how the robot perceives the office's walkers (default: the scenario's "
                         "oracle, their whole motion; with tracked the agents replan as they go)")
    # sections 2-3: --set [PLANNER:]KEY=VALUE and --deterministic, as anyplan bench's (with
    # --deterministic runs depend only on the code: compare two commits by the printed digests)
    add_agent_options(ap, bench=True)
    args = ap.parse_args(argv)
    try:
        configs = bench_configs(args, PLANNERS, source="the planners this benchmark drives")
    except SettingsError as exc:  # a bad --set: one line, exit 2
        ap.error(str(exc))
    seeds = args.seeds or (5 if args.quick else 10)
    with tempfile.TemporaryDirectory() as tmp:
        maps_dir = Path(args.out or tmp)
        # compile (or load) every kernel once before anything is timed
        from anyplan.agents.warmup import warm_up_kernels

        warm_up_kernels()
        out: dict[str, Any] = {}
        if not args.no_static:
            out["static"] = static_section(maps_dir, args.quick, seeds)
        if not args.no_dynamic:
            out["dynamic"] = dynamic_section(maps_dir, args.quick, configs, args.perception)
            out["long"] = long_section(maps_dir, configs)
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
