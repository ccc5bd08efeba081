"""The BARN table: grouping by feasibility, time over the optimal time, score, baseline, CLI."""

from __future__ import annotations

import json
import math

import pytest

from anyplan.cli.main import main
from anyplan.experiments.barn_tables import (
    DWA_BASELINE,
    challenge_score,
    format_barn,
    summarize_barn,
)

INDEX = {"barn-000": {"optimal_time_s": 5.0, "feasibility": "feasible"},
         "barn-001": {"optimal_time_s": 6.0, "feasibility": "feasible"},
         "barn-002": {"optimal_time_s": 6.0, "feasibility": "infeasible"}}


def _run(scenario, outcome, time=None, planner="seq-bitstar", **kw):
    return {"scenario": scenario, "planner": planner, "settings": "", "outcome": outcome,
            "time_to_goal": time, **kw}


def test_challenge_score_clips_time_between_2_and_8_optimal():
    assert challenge_score(True, 3.0, 5.0) == 0.5  # faster than 2 x optimal counts as 2 x
    assert challenge_score(True, 20.0, 5.0) == 0.25
    assert challenge_score(True, 90.0, 5.0) == 0.125  # slower than 8 x counts as 8 x
    assert challenge_score(False, 20.0, 5.0) == 0.0 and challenge_score(True, None, 5.0) == 0.0


def test_rows_split_feasible_worlds_from_the_others():
    runs = [_run("barn-000", "reached", 7.5), _run("barn-001", "reached", 12.0),
            _run("barn-001", "collision"), _run("barn-002", "timeout"),
            _run("elsewhere", "reached", 1.0), _run("barn-000", "reached", 5.0, planner="bitstar")]
    rows = summarize_barn(runs, INDEX)
    assert [(r.planner, r.group) for r in rows] == [
        ("seq-bitstar", "feasible"), ("bitstar", "feasible"), ("seq-bitstar", "other")]
    f = rows[0]
    assert (f.worlds, f.runs, f.reached, f.collisions, f.timeouts) == (2, 3, 2, 1, 0)
    assert f.robot_caused is None  # the rows carry no robot-caused field
    assert f.time.mean == pytest.approx(9.75)
    assert f.time_over_optimal.mean == pytest.approx((7.5 / 5 + 12 / 6) / 2)
    assert f.mean_time_over_mean_optimal == pytest.approx(9.75 / 5.5)
    assert f.score == pytest.approx((5 / 10 + 6 / 12 + 0) / 3)
    o = rows[2]
    assert (o.worlds, o.runs, o.reached, o.timeouts) == (1, 1, 0, 1)
    assert math.isnan(o.mean_time_over_mean_optimal) and o.score == 0.0
    text = format_barn(rows)
    assert "infeasible or uncertain" in text and f"{DWA_BASELINE['mean_time_s']:.2f}" in text
    assert "2/3 (0.667)" in text


def test_robot_caused_collisions_are_counted_when_present():
    runs = [_run("barn-000", "collision", robot_caused=1), _run("barn-000", "collision", robot_caused=0),
            _run("barn-001", "reached", 6.0, robot_caused=None)]
    (row,) = summarize_barn(runs, INDEX)
    assert row.collisions == 2 and row.robot_caused == 1


def test_bench_on_an_imported_folder_prints_and_writes_the_barn_table(tmp_path, capsys):
    from tests.experiments.test_barn import WORLD

    src = tmp_path / "worlds.json"
    src.write_text(json.dumps([{**WORLD, "cylinders": [*WORLD["cylinders"], [-2.25, 6.0, 0.075]]}]))
    suite = tmp_path / "barn"
    assert main(["import-barn", "--source", str(src), "--out", str(suite)]) == 0
    # 'straight' drives into the cylinder in front of the start: a quick, failed run.
    assert main(["bench", "--suite", str(suite), "--planners", "straight", "--runs", "1",
                 "--jobs", "1", "--db", str(tmp_path / "r.db"), "--out", str(tmp_path / "out"),
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "BARN, worlds feasible for the robot's disc" in out and "DWA (challenge baseline)" in out
    md = (tmp_path / "out" / "barn.md").read_text()
    assert "| straight | 1 | 1 | 0/1 (0.000) | 1 |" in md
