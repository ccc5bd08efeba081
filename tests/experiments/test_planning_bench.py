"""The anytime planning benchmark: cost-over-time rows are sound and bounded by the optimum."""

from __future__ import annotations

import pytest

from anyplan.experiments.db import ResultsDB
from anyplan.experiments.planning_bench import OURS, planning_table, run_planning_bench
from anyplan.experiments.runner import BenchError
from anyplan.planning import Problem, lower_bound
from anyplan.world.scenario import scenario_from_dict

WALL = {
    "name": "wall", "arena": {"width": 6.0, "height": 3.0},
    "robot": {"start": [0.5, 1.2, 0.0], "goal": [5.5, 1.2], "radius": 0.2, "v_max": 0.5,
              "omega_max": 0.8, "a_max": 0.5, "alpha_max": 1.0},
    "static_obstacles": [{"name": "W", "type": "rectangle", "center": [3.0, 1.0], "size": [0.4, 2.0]}],
}


def _check(db, scenario, planner, runs):
    bound = lower_bound(Problem.create(scenario.obstacle_set(), scenario.robot.start[:2],
                                       scenario.robot.goal, scenario.robot.radius))
    rows = [r for r in db.runs() if r["planner"] == planner]
    assert len(rows) == runs
    for r in rows:
        prog = db.progress(r["id"])
        assert prog and all(p["source"] == "planner" for p in prog)
        costs = [p["best_cost"] for p in prog]
        times = [p["time"] for p in prog]
        assert times == sorted(times) and all(t > 0 for t in times)
        assert all(b <= a + 1e-12 for a, b in zip(costs, costs[1:], strict=False))  # anytime: never worse
        assert costs[-1] == pytest.approx(r["best_cost"]) and r["solved"] == 1
        assert min(costs) >= bound - 1e-6 and bound > 5.0  # the wall forces a detour
        assert r["outcome"] is None  # not an execution run: kept out of the paper tables


def test_ours_only(tmp_path):
    sc = scenario_from_dict(WALL)
    db_path = tmp_path / "p.db"
    s = run_planning_bench([sc], db_path, runs=2, budget_s=0.05, ompl=None, progress=False)
    assert (s.finished, s.solved[OURS]) == (2, 2)
    with ResultsDB(db_path) as db:
        _check(db, sc, OURS, 2)
        assert "anyplan_BITstar" in planning_table(db)
    with pytest.raises(BenchError, match="--resume"):
        run_planning_bench([sc], db_path, runs=2, budget_s=0.05, ompl=None, progress=False)
    s = run_planning_bench([sc], db_path, runs=3, budget_s=0.05, ompl=None, resume=True, progress=False)
    assert (s.skipped, s.finished) == (2, 1)


def test_with_ompl_bitstar(tmp_path):
    pytest.importorskip("ompl.geometric")
    sc = scenario_from_dict(WALL)
    db_path = tmp_path / "p.db"
    run_planning_bench([sc], db_path, runs=2, budget_s=0.05, ompl=["BITstar"], progress=False)
    with ResultsDB(db_path) as db:
        _check(db, sc, OURS, 2)
        _check(db, sc, "geometric_BITstar", 2)
        from anyplan.viz.report import cost_time_figure

        assert cost_time_figure(db, tmp_path / "ct.png").is_file()


def test_bad_input(tmp_path):
    sc = scenario_from_dict(WALL)
    with pytest.raises(BenchError, match="budget_s must be > 0"):
        run_planning_bench([sc], tmp_path / "p.db", budget_s=0.0, ompl=None)
    assert not (tmp_path / "p.db").exists()
