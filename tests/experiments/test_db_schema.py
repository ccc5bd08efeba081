"""The results database follows OMPL's benchmark layout, so OMPL's own tools work on it."""

from __future__ import annotations

import sqlite3

import pytest

from anyplan.experiments.db import STATUS, ResultsDB, progress_rows, run_row, settings_string
from anyplan.experiments.runner import PlannerSpec, run_bench
from anyplan.world.scenario import load_scenario

# What ompl_benchmark_statistics.py creates and Planner Arena reads (OMPL's benchmark database).
OMPL_COLUMNS = {
    "experiments": ["id", "name", "totaltime", "timelimit", "memorylimit", "runcount", "version",
                    "hostname", "cpuinfo", "date", "seed", "setup"],
    "plannerConfigs": ["id", "name", "settings"],
    "enums": ["name", "value", "description"],
    "runs": ["id", "experimentid", "plannerid", "status", "solved", "time", "best_cost"],
    "progress": ["runid", "time", "best_cost"],
}

OMPL_LOG = """OMPL version 2.0.1
Experiment ompl-synthetic
Running on testhost
Starting at 2026-11-22 01:00:00
<<<|
a synthetic OMPL benchmark log
|>>>
<<<|
cpu
|>>>
42 is the random seed
1 seconds per run
4096 MB per run
2 runs per planner
0.5 seconds spent to collect the data
1 enum types
{enum}
1 planners
geometric_BITstar
1 common properties
samples_per_batch = 100
4 properties for each run
best cost REAL
solved BOOLEAN
status ENUM
time REAL
2 runs
23.5; 1; 6; 1.0;{sp}
23.1; 1; 6; 1.0;{sp}
3 progress properties for each run
time REAL
best cost REAL
iterations INTEGER
2 runs
0.1,25.0,10,;0.5,23.5,50,;
0.1,24.0,12,;0.5,23.1,52,;
.
""".format(enum="status|Unknown status|Invalid start|Invalid goal|Unrecognized goal type|Timeout|"
           "Approximate solution|Exact solution|Crash|Abort|Infeasible", sp=" ")


@pytest.fixture
def bench_db(tmp_path, tiny_file):
    db_path = tmp_path / "r.db"
    run_bench([load_scenario(tiny_file)], [PlannerSpec("straight")], 1, db_path, progress=False)
    return db_path


def test_tables_and_columns_of_ompl_layout(bench_db):
    conn = sqlite3.connect(bench_db)
    for table, cols in OMPL_COLUMNS.items():
        have = [r[1] for r in conn.execute(f"PRAGMA table_info({table})")]
        assert set(cols) <= set(have), (table, set(cols) - set(have))
    views = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='view'")}
    assert {"bestPlannerConfigs", "bestPlannerConfigsPerExperiment"} <= views
    # Planner Arena needs a non-empty version and the status enum.
    (version,) = conn.execute("SELECT version FROM experiments").fetchone()
    assert version.startswith("anyplan ")
    enums = dict(conn.execute("SELECT value, description FROM enums WHERE name='status'").fetchall())
    assert enums[6] == "Exact solution" and enums[4] == "Timeout" and enums[10] == "Collision"
    solved, t, status = conn.execute("SELECT solved, time, status FROM runs").fetchone()
    assert solved == 1 and status == 6 and t >= 0.0
    assert conn.execute("SELECT avg_solved FROM bestPlannerConfigs").fetchone()[0] == 1.0
    conn.close()


def test_ompl_statistics_script_appends_into_our_database(bench_db, tmp_path):
    stats = pytest.importorskip("ompl._benchmark_statistics")
    log = tmp_path / "ompl.log"
    log.write_text(OMPL_LOG)
    stats.readBenchmarkLog(str(bench_db), [str(log)], False)
    stats.computeViews(str(bench_db), False)
    with ResultsDB(bench_db) as db:  # reopening keeps OMPL's rows and our schema
        runs = db.runs()
        assert sorted(r["planner"] for r in runs) == ["geometric_BITstar", "geometric_BITstar", "straight"]
        ompl = [r for r in runs if r["planner"] == "geometric_BITstar"]
        assert {r["best_cost"] for r in ompl} == {23.5, 23.1}
        prog = db.progress(ompl[0]["id"])
        assert [(p["time"], p["best_cost"], p["source"]) for p in prog] == [(0.1, 25.0, None),
                                                                             (0.5, 23.5, None)]
        assert len(db.query("SELECT * FROM bestPlannerConfigs")) == 2
        # The report's cost-against-time figure draws the OMPL planner from its progress rows.
        from anyplan.viz.report import cost_time_figure

        assert cost_time_figure(db, tmp_path / "ct.png").is_file()


def test_status_enum_keeps_ompl_values():
    assert [STATUS[i] for i in range(8)] == [
        "Unknown status", "Invalid start", "Invalid goal", "Unrecognized goal type", "Timeout",
        "Approximate solution", "Exact solution", "Crash"]


def test_run_row_and_progress_from_a_result():
    res = {"status": "collision", "reached_goal": False, "collision": True, "path_length_m": 3.0,
           "time_to_goal_s": None, "planning_times_s": [0.1, 0.3, 0.2], "replans": 2,
           "min_clearance_m": -0.01, "trajectory": [[0.0] * 6, [4.5] + [0.0] * 5],
           "virtual_obstacles": [{"center": [1, 1], "side": 0.5, "created_at_s": 1.0}],
           "plans": [{"t": 0.0, "path": [[0, 0], [3, 4]]}, {"t": 2.0, "path": [[1, 0], [1, 2]]}],
           "collision_with": "D1", "collision_time_s": 4.5}
    row = run_row(res, run_index=0, seed=5, scenario_hash="h")
    assert row["status"] == 10 and row["solved"] == 0 and row["best_cost"] is None
    assert row["planning_time_mean"] == pytest.approx(0.2) and row["planning_time_first"] == 0.1
    assert row["time"] == pytest.approx(0.6) and row["virtual_obstacles"] == 1 and row["replans"] == 2
    assert row["sim_time"] == 4.5 and row["collided"] == 1
    # Without an anytime history, progress = plan lengths against simulated time.
    assert progress_rows(res) == [(0.0, 5.0, 0, "plans"), (2.0, 2.0, 1, "plans")]
    res["extra"] = {"progress": [[0.01, 9.0], [0.05, 7.5]]}
    assert progress_rows(res) == [(0.01, 9.0, None, "planner"), (0.05, 7.5, None, "planner")]


def test_settings_string_is_ompl_style_and_stable():
    assert settings_string({}) == ""
    assert settings_string({"b": 1, "a": 0.5}) == "a = 0.5;b = 1;"
