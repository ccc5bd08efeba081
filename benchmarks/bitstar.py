"""Benchmark: our BIT* against OMPL's BITstar, InformedRRTstar and RRTstar (issue 3).

Problems: the paper scenarios without their moving obstacles, the peers' problem
(``benchmarks/scenarios/peers.yaml``: 15 x 11 m, two walls from the border and a block; point
robot and a 0.25 m disc; exact point-robot optimum 22.233237 m), and random cluttered 15 x 11 m
worlds (P3-DX radius 0.3 m), half of them with long walls that force detours. The reference is
the visibility-graph lower bound (:func:`anyplan.planning.visgraph.lower_bound`, inscribed
rounded corners), so every ratio below is >= the true ratio to the optimum (the feasible
visibility-graph path is within 0.05 % of the bound on these problems).

The cyclic garbage collector is paused during every ``solve`` (our planner does it itself;
the benchmark does it around OMPL's calls) and a collection runs before every run, so that a
collection triggered by earlier runs does not land in someone's budget.

OMPL (the optional ``ompl`` wheel) gets the same exact checks as our planner: a Python
``StateValidityChecker`` and an exact segment ``MotionValidator`` (one call per edge), both calling
:class:`~anyplan.geometry.collision.ObstacleSet`'s compiled kernels. Each OMPL run uses two
planner instances: one stopped at its first solution (cost threshold 1e9) for the time to the
first solution, and one resumed to 10, 50, 100 and 500 ms of wall time (cumulative ``solve``
calls), then to 1.01 x the bound (cost threshold) or the cap. If OMPL is already within 1.01 x at
a budget, its time to 1.01 x is reported as that budget (an upper estimate).

For each problem and planner the table gives medians over the seeds of: the time to the first
solution [ms], the cost ratio to the bound at 10/50/100/500 ms (inf without a solution), and the
time to reach 1.01 x the bound [ms] (inf if not within the cap). Ratios "ours / OMPL BITstar"
come from the same run. Timings are wall-clock on a shared machine: compare within one run.

Usage::

    python benchmarks/bitstar.py                      # full: all problems, 20 seeds (~25 min)
    python benchmarks/bitstar.py --quick              # peers + 3 random worlds, 5 seeds
    python benchmarks/bitstar.py --seeds 10 --problems peers,peers-point,random-00 --no-ompl
    python benchmarks/bitstar.py --json out.json      # also write every run
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from anyplan.geometry import Circle, ObstacleSet, Polygon, rectangle, regular_polygon
from anyplan.planning import BITStar, Problem, any_of, target_cost, timed
from anyplan.planning.visgraph import lower_bound, shortest_path
from anyplan.world import load_scenario

BUDGETS_S = (0.01, 0.05, 0.1, 0.5)
TARGET = 1.01
HERE = Path(__file__).resolve().parent


# ----------------------------------------------------------------------------------------------
# Problems
# ----------------------------------------------------------------------------------------------
def _box(x0: float, y0: float, x1: float, y1: float) -> Polygon:
    return Polygon([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def peers(radius: float) -> Problem:
    rects = [(3.0, 0.0, 5.0, 7.0), (7.0, 4.0, 9.0, 11.0), (10.5, 2.0, 12.5, 8.0)]
    obs = ObstacleSet([_box(*r) for r in rects], bounds=(0.0, 0.0, 15.0, 11.0))
    return Problem.create(obs, (1.0, 1.0), (14.0, 10.0), radius)


def scenario_problem(name: str) -> Problem:
    sc = load_scenario(name).static_only()
    return Problem.create(sc.obstacle_set(), sc.robot.start[:2], sc.robot.goal, sc.robot.radius)


def random_world(seed: int, walls: bool, radius: float = 0.3) -> Problem:
    """A cluttered 15 x 11 m world; with ``walls``, two or three long walls force detours."""
    rng = np.random.default_rng(1000 + seed)
    W, H = 15.0, 11.0
    for _attempt in range(200):
        shapes: list = []
        if walls:
            xs = np.sort(rng.choice(np.linspace(3.5, 11.5, 9), size=int(rng.integers(2, 4)),
                                    replace=False))
            for k, x in enumerate(xs):
                length = rng.uniform(6.0, 8.5)
                t = rng.uniform(0.3, 0.5)
                mode = rng.integers(0, 3)  # 0 from the bottom, 1 from the top, 2 free-standing
                if mode == 2 or (k % 2 == 1 and mode == 0):
                    y0 = rng.uniform(1.2, H - length - 1.2) if H - length > 2.4 else 1.2
                    shapes.append(_box(x, y0, x + t, min(y0 + length, H - 1.2)))
                elif mode == 0:
                    shapes.append(_box(x, 0.0, x + t, length))
                else:
                    shapes.append(_box(x, H - length, x + t, H))
        n_clutter = int(rng.integers(15, 25) if walls else rng.integers(25, 40))
        for _ in range(n_clutter):
            c = rng.uniform([2.0, 0.5], [W - 2.0, H - 0.5])
            kind = rng.integers(0, 3)
            if kind == 0:
                shapes.append(rectangle(c, rng.uniform(0.3, 1.4, size=2), rng.uniform(0, np.pi)))
            elif kind == 1:
                shapes.append(Circle(c, rng.uniform(0.2, 0.7)))
            else:
                shapes.append(regular_polygon(c, rng.uniform(0.3, 0.8), int(rng.integers(3, 7)),
                                              phase=rng.uniform(0, np.pi)))
        obs = ObstacleSet(shapes, bounds=(0.0, 0.0, W, H))
        start = (1.0, rng.uniform(1.0, H - 1.0))
        goal = (W - 1.0, rng.uniform(1.0, H - 1.0))
        p = Problem.create(obs, start, goal, radius)
        if p.start_valid() and p.goal_valid() and math.isfinite(lower_bound(p)):
            return p
    raise RuntimeError(f"no valid random world for seed {seed}")


def all_problems() -> dict[str, Callable[[], Problem]]:
    probs: dict[str, Callable[[], Problem]] = {
        "paper-1": lambda: scenario_problem("paper-1"),
        "paper-2": lambda: scenario_problem("paper-2"),
        "paper-3": lambda: scenario_problem("paper-3"),
        "peers": lambda: peers(0.25),
        "peers-point": lambda: peers(0.0),
    }
    for i in range(12):
        walls = i % 2 == 1
        probs[f"random-{i:02d}{'-walls' if walls else ''}"] = (
            lambda i=i, walls=walls: random_world(i, walls))
    return probs


# ----------------------------------------------------------------------------------------------
# Runs
# ----------------------------------------------------------------------------------------------
@dataclass
class Run:
    planner: str
    seed: int
    t_first_s: float = math.inf
    costs: list[float] = field(default_factory=lambda: [math.inf] * len(BUDGETS_S))
    t_target_s: float = math.inf
    valid: bool = True


def run_ours(problem: Problem, seed: int, opt: float, cap_s: float, **cfg) -> Run:
    planner = BITStar(problem, rng=seed, **cfg)
    gc.collect()  # every run starts from a collected heap (OMPL's runs too)
    planner.solve(timed(BUDGETS_S[-1]))
    if planner.best_cost > TARGET * opt:
        planner.solve(any_of(timed(cap_s - planner.result().solve_time_s),
                             target_cost(TARGET * opt)))
    res = planner.result()
    run = Run("anyplan BIT*", seed)
    if res.first_solution_time_s is not None:
        run.t_first_s = res.first_solution_time_s
    run.costs = [res.cost_at(b) for b in BUDGETS_S]
    hits = [t for t, c in res.history if c <= TARGET * opt]
    run.t_target_s = hits[0] if hits else math.inf
    run.valid = (not res.solved) or problem.path_valid(res.path)
    return run


class OMPLRunner:
    """OMPL planners on one problem with the same exact validity checks as ours."""

    def __init__(self, problem: Problem) -> None:
        from ompl import base as ob
        from ompl import geometric as og

        self.ob, self.og = ob, og
        self.problem = problem
        obs, r = problem.obstacles, problem.check_radius
        xmin, ymin, xmax, ymax = problem.bounds

        class ExactMotionValidator(ob.MotionValidator):
            def __init__(self, si) -> None:  # noqa: ANN001
                super().__init__(si)

            def checkMotion(self, s1, s2) -> bool:  # noqa: ANN001, N802 - OMPL's name
                return obs.segment_free((s1[0], s1[1]), (s2[0], s2[1]), r)

        self._mv_cls = ExactMotionValidator
        self._valid = lambda s: obs.point_free((s[0], s[1]), r)
        self._bounds = (xmin, ymin, xmax, ymax)

    def _setup(self, name: str):  # noqa: ANN202
        ob, og = self.ob, self.og
        space = ob.RealVectorStateSpace(2)
        b = ob.RealVectorBounds(2)
        b.setLow(0, self._bounds[0])
        b.setHigh(0, self._bounds[2])
        b.setLow(1, self._bounds[1])
        b.setHigh(1, self._bounds[3])
        space.setBounds(b)
        ss = og.SimpleSetup(space)
        si = ss.getSpaceInformation()
        ss.setStateValidityChecker(self._valid)
        mv = self._mv_cls(si)
        si.setMotionValidator(mv)
        s, g = space.allocState(), space.allocState()
        s[0], s[1] = (float(v) for v in self.problem.start)
        g[0], g[1] = (float(v) for v in self.problem.goal)
        ss.setStartAndGoalStates(s, g)
        objective = ob.PathLengthOptimizationObjective(si)
        ss.setOptimizationObjective(objective)
        planner = getattr(og, name)(si)
        ss.setPlanner(planner)
        ss.setup()
        return ss, objective, (space, si, mv, planner, s, g)  # keep everything alive

    def run(self, name: str, opt: float, cap_s: float, seed: int) -> Run:
        """One run. The first-solution time comes from a separate instance stopped by a cost
        threshold of 1e9; a solution satisfying a threshold ranks first in OMPL's solution
        list whatever later ones cost, so the budget runs resume without a threshold."""
        ob = self.ob
        run = Run(f"OMPL {name}", seed)
        ss, objective, _keep = self._setup(name)
        objective.setCostThreshold(ob.Cost(1e9))
        gc.collect()
        gc.disable()
        t0 = time.perf_counter()
        ss.solve(BUDGETS_S[-1])
        t_first = time.perf_counter() - t0
        gc.enable()
        if ss.getProblemDefinition().hasExactSolution():
            run.t_first_s = t_first

        ss, objective, _keep = self._setup(name)
        pdef = ss.getProblemDefinition()
        gc.collect()

        def best() -> float:
            return ss.getSolutionPath().length() if pdef.hasExactSolution() else math.inf

        elapsed = 0.0

        def solve(budget: float) -> None:
            nonlocal elapsed
            gc.disable()  # as our planner does during solve (same treatment)
            t1 = time.perf_counter()
            ss.solve(max(budget, 1e-4))
            elapsed += time.perf_counter() - t1
            gc.enable()

        for k, budget in enumerate(BUDGETS_S):
            if elapsed < budget:
                solve(budget - elapsed)
            run.costs[k] = best()
        if best() <= TARGET * opt:
            # Reached by the last budget; the time is only known to lie in this bracket.
            hit = [b for b, c in zip(BUDGETS_S, run.costs, strict=True) if c <= TARGET * opt]
            run.t_target_s = hit[0]
        elif elapsed < cap_s:
            objective.setCostThreshold(ob.Cost(TARGET * opt))  # returns once it is met
            solve(cap_s - elapsed)
            if best() <= TARGET * opt:
                run.t_target_s = elapsed
        if pdef.hasExactSolution():
            path = ss.getSolutionPath()
            pts = np.array([[path.getState(i)[0], path.getState(i)[1]]
                            for i in range(path.getStateCount())])
            run.valid = self.problem.path_valid(pts)
        return run


# ----------------------------------------------------------------------------------------------
# Statistics and table
# ----------------------------------------------------------------------------------------------
def median(xs: list[float]) -> float:
    return float(statistics.median(xs)) if xs else math.nan


def summarize(runs: list[Run], opt: float) -> dict[str, float]:
    return {
        "solved": sum(math.isfinite(r.t_first_s) for r in runs) / max(len(runs), 1),
        "t_first_ms": 1e3 * median([r.t_first_s for r in runs]),
        **{f"r@{int(b * 1e3)}ms": median([r.costs[k] / opt for r in runs])
           for k, b in enumerate(BUDGETS_S)},
        "t_1.01_ms": 1e3 * median([r.t_target_s for r in runs]),
        "invalid": sum(not r.valid for r in runs),
    }


COLS = ["solved", "t_first_ms", "r@10ms", "r@50ms", "r@100ms", "r@500ms", "t_1.01_ms"]


def fmt(key: str, v: float) -> str:
    if key == "solved":
        return f"{100 * v:5.0f}%"
    if not math.isfinite(v):
        return "    inf" if v > 0 else "    nan"
    if key.startswith("r@"):
        return f"{v:7.4f}"
    return f"{v:7.1f}" if v >= 10 else f"{v:7.2f}"


def print_table(summary: dict[str, dict[str, dict[str, float]]], planners: list[str]) -> None:
    head = f"{'problem':22s} {'planner':24s} " + " ".join(f"{c:>7s}" for c in COLS)
    print(head)
    print("-" * len(head))
    ref = "OMPL BITstar"
    for prob, rows in summary.items():
        for pl in planners:
            if pl not in rows:
                continue
            s = rows[pl]
            bad = f"  INVALID x{s['invalid']}" if s["invalid"] else ""
            print(f"{prob:22s} {pl:24s} " + " ".join(fmt(c, s[c]) for c in COLS) + bad)
        if ref in rows and "anyplan BIT*" in rows:
            a, o = rows["anyplan BIT*"], rows[ref]
            cells = []
            for c in COLS:
                if c == "solved":
                    cells.append("       ")
                    continue
                x, y = a[c], o[c]
                if math.isfinite(x) and math.isfinite(y) and y > 0:
                    cells.append(f"{x / y:7.3f}")
                elif math.isfinite(x) and not math.isfinite(y):
                    cells.append("  ours<")
                else:
                    cells.append("      -")
            print(f"{prob:22s} {'ours / OMPL BITstar':24s} " + " ".join(cells))
        print()


def startup_check() -> tuple[float, float]:
    """Seconds from launching a fresh interpreter until its first ``plan()`` starts searching.

    The child gets the launch time (wall clock) and reports when its first ``BITStar`` is
    ready to search (after imports and loading the cached compiled code), and when its
    ``plan()`` with a 10 ms budget has returned. Best of three launches, after one launch that
    makes sure the on-disk cache is filled. Returns (start, returned) in seconds.
    """
    code = ("import sys, time\n"
            "t_launch = float(sys.argv[1])\n"
            "from anyplan.planning import plan, bitstar\n"
            "from anyplan.geometry import ObstacleSet, square\n"
            "bitstar.warm_up()\n"
            "t_ready = time.time() - t_launch\n"
            "obs = ObstacleSet([square((5.0, 5.0), 2.0)], bounds=(0.0, 0.0, 10.0, 10.0))\n"
            "r = plan(obs, (1.0, 5.0), (9.0, 5.0), 0.3, time_budget_s=0.01, rng=0)\n"
            "assert r.status\n"
            "print(t_ready, time.time() - t_launch)\n")
    subprocess.run([sys.executable, "-c", code, str(time.time())], check=True,
                   capture_output=True)
    best = (math.inf, math.inf)
    for _ in range(3):
        out = subprocess.run([sys.executable, "-c", code, str(time.time())], check=True,
                             capture_output=True, text=True).stdout.split()
        ready, done = float(out[0]), float(out[1])
        best = min(best, (ready, done))
    return best


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=20, help="seeds per problem (default 20)")
    ap.add_argument("--problems", default="all",
                    help="comma-separated problem names, or 'all' (default)")
    ap.add_argument("--cap", type=float, default=1.0,
                    help="longest run [s] when chasing 1.01 x (default 1.0)")
    ap.add_argument("--ompl", default="BITstar,InformedRRTstar,RRTstar",
                    help="OMPL planners (comma-separated; default BITstar,InformedRRTstar,RRTstar)")
    ap.add_argument("--no-ompl", action="store_true", help="skip OMPL")
    ap.add_argument("--quick", action="store_true",
                    help="peers, peers-point, random-00, random-01-walls, random-03-walls; 5 seeds")
    ap.add_argument("--json", default=None, help="write all runs and summaries to this file")
    ap.add_argument("--config", default="{}", help="BIT* options as a JSON object")
    ap.add_argument("--no-startup", action="store_true", help="skip the second-process check")
    args = ap.parse_args(argv)

    probs = all_problems()
    if args.quick:
        names = ["peers", "peers-point", "random-00", "random-01-walls", "random-03-walls"]
        args.seeds = min(args.seeds, 5)
    elif args.problems == "all":
        names = list(probs)
    else:
        names = [n.strip() for n in args.problems.split(",") if n.strip()]
        unknown = [n for n in names if n not in probs]
        if unknown:
            ap.error(f"unknown problem(s) {unknown}; known: {', '.join(probs)}")
    cfg = json.loads(args.config)
    ompl_names: list[str] = []
    if not args.no_ompl:
        try:
            from ompl import util as ou

            ou.setLogLevel(ou.LOG_ERROR)
            ou.RNG.setSeed(12345)
            ompl_names = [n.strip() for n in args.ompl.split(",") if n.strip()]
        except ImportError:
            print("ompl is not installed: running our BIT* only", file=sys.stderr)
    planners = ["anyplan BIT*"] + [f"OMPL {n}" for n in ompl_names]

    summary: dict[str, dict[str, dict[str, float]]] = {}
    raw: dict[str, dict] = {}
    t_all = time.perf_counter()
    for name in names:
        problem = probs[name]()
        lb = shortest_path(problem, variant="lower")
        fe = shortest_path(problem, variant="feasible")
        opt = lb.cost
        runs: dict[str, list[Run]] = {p: [] for p in planners}
        ompl = OMPLRunner(problem) if ompl_names else None
        for seed in range(args.seeds):
            runs["anyplan BIT*"].append(run_ours(problem, seed, opt, args.cap, **cfg))
            for n in ompl_names:
                runs[f"OMPL {n}"].append(ompl.run(n, opt, args.cap, seed))
        summary[name] = {p: summarize(rs, opt) for p, rs in runs.items()}
        raw[name] = {"lower_bound": opt, "feasible_optimum": fe.cost,
                     "n_obstacles": len(problem.obstacles), "radius": problem.radius,
                     "runs": {p: [r.__dict__ for r in rs] for p, rs in runs.items()}}
        print(f"# {name}: {len(problem.obstacles)} obstacles, r = {problem.radius} m, lower bound "
              f"{opt:.4f} m, feasible visgraph {fe.cost:.4f} m ({time.perf_counter() - t_all:.0f} s)",
              file=sys.stderr, flush=True)

    print(f"\nMedians over {args.seeds} seeds; ratios are cost / visibility-graph lower bound; "
          f"times in ms; cap {args.cap} s.\n")
    print_table(summary, planners)

    # Aggregate: median over problems of the per-problem medians.
    print("Median over problems of the per-problem medians:")
    agg = {p: {c: median([summary[n][p][c] for n in names]) for c in COLS} for p in planners}
    for p in planners:
        print(f"  {p:24s} " + " ".join(fmt(c, agg[p][c]) for c in COLS))
    nontrivial = [n for n in names if raw[n]["lower_bound"] > 1.0001 * float(
        np.hypot(*(probs[n]().goal - probs[n]().start)))]
    ours = "anyplan BIT*"
    print("\nTargets (our BIT*, medians per problem; straight-line problems excluded):")
    t_first = max(summary[n][ours]["t_first_ms"] for n in names)
    print(f"  first solution <= 5 ms median:  worst problem {t_first:.2f} ms "
          f"-> {'met' if t_first <= 5 else 'MISSED'}")
    if nontrivial:
        w100 = max(summary[n][ours]["r@100ms"] for n in nontrivial)
        w500 = max(summary[n][ours]["r@500ms"] for n in nontrivial)
        print(f"  <= 1.03 x at 100 ms:            worst problem {w100:.4f} "
              f"-> {'met' if w100 <= 1.03 else 'MISSED'}")
        print(f"  <= 1.01 x within 500 ms:        worst problem {w500:.4f} "
              f"-> {'met' if w500 <= 1.01 else 'MISSED'}  "
              f"(problems at <= 1.01: {sum(summary[n][ours]['r@500ms'] <= 1.01 for n in nontrivial)}"
              f"/{len(nontrivial)})")
        if "OMPL BITstar" in planners:
            ahead = []
            for c in ["r@10ms", "r@50ms", "r@100ms", "r@500ms"]:
                wins = sum(summary[n][ours][c] <= summary[n]["OMPL BITstar"][c] for n in nontrivial)
                ahead.append(f"{c} {wins}/{len(nontrivial)}")
            print(f"  ahead of OMPL BITstar (problems where our median is <=): {', '.join(ahead)}")
    if not args.no_startup:
        ready, done = startup_check()
        print(f"  second process: launch -> planning starts {ready:.2f} s "
              f"-> {'met' if ready <= 1.0 else 'MISSED'} (<= 1 s); first plan() (10 ms budget) "
              f"returned at {done:.2f} s")
    if args.json:
        Path(args.json).write_text(json.dumps({"summary": summary, "runs": raw, "args": vars(args)},
                                              indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
