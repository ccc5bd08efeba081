"""Anytime planning benchmark: best cost against planning time, ours beside OMPL's.

Among a scenario's static obstacles only, our BIT* (:func:`anyplan.planning.plan`, named
``anyplan_BITstar``) and OMPL's planners (Sucan, Moll & Kavraki, "The Open Motion Planning
Library", IEEE RAM 2012; optional ``ompl`` wheel, named ``geometric_<Planner>``) plan for
``budget_s`` seconds each. Runs are stored as OMPL's benchmark logs are (:mod:`anyplan.experiments.db`:
``runs`` and cost-over-time in ``progress``), one at a time in this process, OMPL with the same
exact geometry as ours. These experiments have ``suite = 'planning'``.

Fairness, seeding and what is stored: ``docs/experiments.md``, "Planning benchmark: protocol".
"""

from __future__ import annotations

import json
import math
import platform
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from anyplan import __version__
from anyplan.experiments.db import ResultsDB
from anyplan.experiments.progress import ProgressBar
from anyplan.experiments.runner import BenchError, derive_seed
from anyplan.world.scenario import Scenario

__all__ = ["OURS", "run_planning_bench", "ompl_available", "PlanningBenchSummary"]

OURS = "anyplan_BITstar"
OMPL_DEFAULT = ("BITstar", "InformedRRTstar", "RRTstar")


def ompl_available() -> bool:
    """True if the ``ompl`` wheel imports."""
    try:
        import ompl.geometric  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass
class PlanningBenchSummary:
    """Counts of a planning bench."""

    planned: int = 0
    skipped: int = 0
    finished: int = 0
    solved: dict[str, int] = field(default_factory=dict)


def _ours(scenario: Scenario, seed: int, budget_s: float) -> tuple[list[tuple[float, float]], float, float]:
    from anyplan.planning import plan

    r = scenario.robot
    res = plan(scenario.obstacle_set(), r.start[:2], r.goal, r.radius, planner="bitstar",
               time_budget_s=budget_s, rng=seed)
    hist = [(float(t), float(c)) for t, c in res.history if math.isfinite(c)]
    return hist, float(res.cost), float(res.solve_time_s)


class _OMPL:
    """One OMPL SimpleSetup per scenario with exact validity checking."""

    def __init__(self, scenario: Scenario) -> None:
        from ompl import base as ob
        from ompl import geometric as og

        self.ob, self.og = ob, og
        obs = scenario.obstacle_set()
        rad = scenario.robot.radius
        space = ob.RealVectorStateSpace(2)
        b = ob.RealVectorBounds(2)
        x0, y0, x1, y1 = scenario.bounds
        b.setLow(0, x0)
        b.setHigh(0, x1)
        b.setLow(1, y0)
        b.setHigh(1, y1)
        space.setBounds(b)
        self.space = space
        ss = og.SimpleSetup(space)
        si = ss.getSpaceInformation()
        ss.setStateValidityChecker(lambda s: bool(obs.point_free((s[0], s[1]), rad)))

        class ExactMotion(ob.MotionValidator):
            def checkMotion(self, s1, s2) -> bool:  # noqa: ANN001, N802 - OMPL's name
                return bool(obs.segment_free((s1[0], s1[1]), (s2[0], s2[1]), rad))

        self._mv = ExactMotion(si)  # keep a reference: OMPL holds it without owning it
        si.setMotionValidator(self._mv)
        self.si, self.ss = si, ss
        start, goal = space.allocState(), space.allocState()
        start[0], start[1] = scenario.robot.start[:2]
        goal[0], goal[1] = scenario.robot.goal
        ss.setStartAndGoalStates(start, goal)
        ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))

    def run(self, name: str, budget_s: float) -> tuple[list[tuple[float, float]], float, float]:
        ss = self.ss
        ss.clear()
        ss.setPlanner(getattr(self.og, name)(self.si))
        ss.setup()
        hist: list[tuple[float, float]] = []
        spent = 0.0
        for target in np.geomspace(min(0.005, budget_s), budget_s, 12):
            if target <= spent:
                continue
            t0 = time.perf_counter()
            ss.solve(float(target - spent))
            spent += time.perf_counter() - t0
            if ss.haveExactSolutionPath():
                c = float(ss.getSolutionPath().length())
                if not hist or c < hist[-1][1] - 1e-12:
                    hist.append((spent, c))
        return hist, (hist[-1][1] if hist else math.inf), spent


def _experiment(db: ResultsDB, sc: Scenario, seed: int, budget_s: float, runs: int) -> int:
    h = sc.content_hash()
    row = db.conn.execute(
        "SELECT id FROM experiments WHERE name = ? AND scenario_hash = ? AND seed = ? AND suite = 'planning' "
        "AND abs(timelimit - ?) < 1e-9", (sc.name, h, str(seed), budget_s)).fetchone()
    if row is not None:
        return int(row[0])
    cur = db.conn.execute(
        "INSERT INTO experiments (name, totaltime, timelimit, memorylimit, runcount, version, hostname, "
        "cpuinfo, date, seed, setup, scenario_hash, moving_obstacles, suite, sim_dt) "
        "VALUES (?, 0.0, ?, 0.0, ?, ?, ?, ?, ?, ?, ?, ?, NULL, 'planning', NULL)",
        (sc.name, budget_s, runs, f"anyplan {__version__}", platform.node(),
         f"{platform.processor() or platform.machine()}; python {platform.python_version()}",
         datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S"), str(seed),
         json.dumps(sc.static_only().to_dict()), h))
    db.conn.commit()
    assert cur.lastrowid is not None  # set by the INSERT
    return cur.lastrowid


def run_planning_bench(scenarios: Sequence[Scenario], db_path: str | Path, *, runs: int = 10,
                       budget_s: float = 1.0, ompl: Sequence[str] | None = OMPL_DEFAULT,
                       master_seed: int = 0, resume: bool = False, progress: bool = True,
                       stream: TextIO | None = None) -> PlanningBenchSummary:
    """Run the anytime planning benchmark into ``db_path`` (``docs/experiments.md``, "Planning
    benchmark: protocol").

    Args:
        scenarios: Scenarios; only their static obstacles, robot radius, start and goal are used.
        db_path: Results database.
        runs: Runs per (scenario, planner).
        budget_s: Planning time per run [s].
        ompl: OMPL geometric planner class names; empty or None for ours only.
        master_seed: Seeds our runs (``derive_seed``) and OMPL's generator (once).
        resume: Skip runs already stored; without it, stored runs are refused.
        progress: Show a progress bar.
        stream: Where the progress bar goes (default stderr).

    Raises:
        BenchError: bad input, OMPL requested but not installed, or runs already stored.
    """
    stream = stream if stream is not None else sys.stderr
    if runs < 1:
        raise BenchError.about("runs", f" must be >= 1, got {runs}")
    if not budget_s > 0.0:
        raise BenchError.about("budget_s", f" must be > 0 s, got {budget_s}")
    names = list(ompl or [])
    if names:
        if not ompl_available():
            raise BenchError.about("", "OMPL planners need the ompl wheel: pip install "
                                   "'anyplan[bench]' (or pass {ompl} none)", "ompl")
        from ompl import geometric as og
        from ompl import util as ou

        unknown = [n for n in names if not hasattr(og, n)]
        if unknown:
            raise BenchError.about("ompl", f": unknown OMPL planner(s) {', '.join(unknown)}")
        ou.setLogLevel(ou.LOG_ERROR)
        ou.RNG.setSeed(int(master_seed) % (2**31 - 1) + 1)
    planners = [OURS] + [f"geometric_{n}" for n in names]
    summary = PlanningBenchSummary(planned=len(scenarios) * len(planners) * runs)
    with ResultsDB(db_path) as db:
        pid = {p: db.planner_id(p, f"time_budget_s = {budget_s:g};") for p in planners}
        eid = {sc.content_hash(): _experiment(db, sc, master_seed, budget_s, runs) for sc in scenarios}
        done = db.done_keys()
        todo = []
        for i in range(runs):
            seed = derive_seed(master_seed, i)
            for sc in scenarios:
                for p in planners:
                    if (eid[sc.content_hash()], pid[p], i, seed) in done:
                        summary.skipped += 1
                    else:
                        todo.append((sc, p, i, seed))
        if summary.skipped and not resume:
            raise BenchError(f"{db_path} already holds {summary.skipped} of these {summary.planned} "
                             "planning runs; pass --resume or use another --db")
        bar = ProgressBar(len(todo), stream=stream, enabled=progress)
        setups: dict[str, _OMPL] = {}
        for sc, p, i, seed in todo:
            if p == OURS:
                hist, cost, spent = _ours(sc, seed, budget_s)
            else:
                h = sc.content_hash()
                if h not in setups:
                    setups[h] = _OMPL(sc)
                hist, cost, spent = setups[h].run(p.removeprefix("geometric_"), budget_s)
            solved = math.isfinite(cost)
            row: dict[str, Any] = {
                "status": 6 if solved else 4, "solved": int(solved), "approximate_solution": 0,
                "correct_solution": int(solved), "time": spent,
                "best_cost": cost if solved else None, "solution_length": cost if solved else None,
                "run_index": i, "seed": seed, "scenario_hash": sc.content_hash(),
                "anyplan_version": __version__, "planning_time_first": hist[0][0] if hist else None,
                "planning_time_total": spent, "wall_time": spent,
            }
            result = {"extra": {"progress": [list(x) for x in hist]}, "planner": p, "seed": seed,
                      "scenario": sc.name, "budget_s": budget_s}
            db.add_run(eid[sc.content_hash()], pid[p], row, result)
            summary.finished += 1
            summary.solved[p] = summary.solved.get(p, 0) + int(solved)
            bar.update(1)
        bar.close()
    return summary


def planning_table(db: ResultsDB, fractions: Sequence[float] = (0.1, 0.5, 1.0)) -> str:
    """Median best cost [m] at fractions of each experiment's budget and median time to the first
    solution [s], per scenario and planner, over the stored planning runs (text table)."""
    rows = db.query("SELECT r.id, r.solved, e.name AS scenario, e.timelimit AS budget, p.name AS planner "
                    "FROM runs r JOIN experiments e ON e.id = r.experimentid JOIN plannerConfigs p "
                    "ON p.id = r.plannerid WHERE e.suite = 'planning' ORDER BY e.name, p.id, r.id")
    groups: dict[tuple[str, str, float], list[int]] = {}
    for r in rows:
        groups.setdefault((r["scenario"], r["planner"], float(r["budget"])), []).append(int(r["id"]))
    head = ["scenario", "planner", "runs", "solved", "first solution [s]"] + \
        [f"cost @{f:g}xbudget [m]" for f in fractions]
    out = []
    for (scn, planner, budget), ids in groups.items():
        firsts: list[float] = []
        at: dict[float, list[float]] = {f: [] for f in fractions}
        solved = 0
        for rid in ids:
            prog = db.progress(rid)
            pts = [(p["time"], p["best_cost"]) for p in prog if p["best_cost"] is not None]
            if pts:
                solved += 1
                firsts.append(pts[0][0])
            for f in fractions:
                c = [cost for t, cost in pts if t <= f * budget + 1e-9]
                at[f].append(min(c) if c else math.inf)
        med = [float(np.median(at[f])) if at[f] else math.inf for f in fractions]
        out.append([scn, planner, str(len(ids)), str(solved),
                    f"{np.median(firsts):.4f}" if firsts else "-"] +
                   [f"{m:.3f}" if math.isfinite(m) else "inf" for m in med])
    if not out:
        return "(no planning runs)"
    w = [max(len(h), *(len(r[i]) for r in out)) for i, h in enumerate(head)]
    lines = ["  ".join(h.rjust(w[i]) for i, h in enumerate(head))]
    lines.append("-" * len(lines[0]))
    lines += ["  ".join(c.rjust(w[i]) for i, c in enumerate(r)) for r in out]
    return "\n".join(lines)
