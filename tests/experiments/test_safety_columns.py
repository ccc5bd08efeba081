"""The robot-caused collision, time-bound and fallback columns of the results database and tables."""

from __future__ import annotations

import pytest

from anyplan.experiments.db import run_row
from anyplan.experiments.tables import format_csv, format_text, summarize


def _result(status, caused=None, ttg=None, bound=30.0, fallbacks=0):
    return {"status": status, "reached_goal": status == "reached", "collision": status == "collision",
            "collision_robot_caused": caused, "time_to_goal_s": ttg, "time_lower_bound_s": bound,
            "time_over_lower_bound": None if ttg is None else ttg / bound, "path_length_m": 12.0,
            "planning_times_s": [0.01], "trajectory": [[0.0], [40.0]],
            "extra": {"fallbacks": [{"t": 1.0, "kind": "hold", "predicted_clearance_m": 0.4}] * fallbacks}}


def test_run_row_carries_the_new_columns():
    row = run_row(_result("collision", caused=True, fallbacks=2), run_index=0, seed=0, scenario_hash="h")
    assert row["robot_caused"] == 1 and row["fallbacks"] == 2 and row["time_lower_bound"] == 30.0
    row = run_row(_result("reached", ttg=31.5), run_index=0, seed=0, scenario_hash="h")
    assert row["robot_caused"] is None and row["time_over_lower_bound"] == pytest.approx(1.05)


def test_tables_count_robot_caused_collisions_and_time_over_bound():
    runs = []
    for res in (_result("collision", caused=True), _result("collision", caused=False),
                _result("reached", ttg=31.5), _result("reached", ttg=30.9)):
        row = run_row(res, run_index=0, seed=0, scenario_hash="h")
        row.update(planner="p", settings="", n_moving=2)
        runs.append(row)
    (t,) = summarize(runs)
    (r,) = t.rows
    assert (r.crashes, r.robot_caused, r.successes) == (2, 1, 2)
    assert r.time_over_bound.mean == pytest.approx((1.05 + 1.03) / 2)
    text = format_text([t])
    assert "robot-caused collisions" in text and "time / lower bound" in text
    assert "robot_caused_collisions" in format_csv([t]).splitlines()[0]
