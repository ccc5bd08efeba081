"""The bench tables' success interval and the paired comparison of planner configurations."""

from __future__ import annotations

import csv
import io

import pytest

from anyplan.experiments.significance import wilson_interval
from anyplan.experiments.tables import (
    compare_planners,
    format_comparisons,
    format_csv,
    format_markdown,
    format_text,
    summarize,
)


def _row(planner, scenario, seed, outcome, caused=False, settings=""):
    return {"planner": planner, "settings": settings, "scenario": scenario, "scenario_hash": "h" + scenario,
            "run_index": seed, "seed": seed, "n_moving": 3, "outcome": outcome,
            "robot_caused": 1 if caused else None, "path_length": 12.0, "time_to_goal": 30.0,
            "planning_time_mean": 0.01, "planning_calls": 1}


def _runs():
    # A reaches 8 of 10 worlds, B 3 of them; on two worlds B drives into an obstacle; a world
    # only A ran (w10) and one only B ran (w11) pair with nothing.
    a = [_row("A", f"w{i}", 0, "reached" if i < 8 else "collision") for i in range(10)]
    b = [_row("B", f"w{i}", 0, "reached" if i < 3 else "collision", caused=i in (5, 6)) for i in range(10)]
    return a + [_row("A", "w10", 0, "reached")] + b + [_row("B", "w11", 0, "collision", caused=True)]


def test_pairs_count_the_shared_runs_and_their_discordance():
    (p,) = compare_planners(_runs())
    assert (p.a, p.b) == ("A", "B")
    r, c = p.reached, p.robot_caused
    assert (r.n, r.both, r.only_a, r.only_b, r.neither) == (10, 3, 5, 0, 2)
    assert r.difference == pytest.approx(0.5) and r.p_value == pytest.approx(2 / 2**5)
    assert r.interval[0] > 0.0  # five worlds one way, none the other
    assert (c.both, c.only_a, c.only_b, c.neither) == (0, 0, 2, 8)
    assert c.difference == pytest.approx(-0.2) and c.p_value == 1.0 / 2.0


def test_runs_of_other_seeds_or_scenarios_do_not_pair():
    runs = [_row("A", "w0", 0, "reached"), _row("B", "w0", 1, "reached"), _row("B", "w1", 0, "reached")]
    assert compare_planners(runs) == []
    assert format_comparisons([]) == ""


def test_settings_make_another_configuration():
    runs = [_row("A", "w0", 0, "reached"), _row("A", "w0", 0, "collision", settings="x = 1;")]
    (p,) = compare_planners(runs)
    assert (p.a, p.b) == ("A", "A [x = 1;]")
    assert (p.reached.only_a, p.reached.only_b) == (1, 0)


def test_tables_show_the_success_interval_and_the_pairs():
    runs = _runs()
    tables = summarize(runs)
    text = format_text(tables)
    lo, hi = wilson_interval(9, 11)
    assert "success 95 % CI" in text and f"{lo:.2f}-{hi:.2f}" in text
    md = format_markdown(tables, None, compare_planners(runs))
    assert "### Paired comparisons" in md and "+50.0 %" in md
    rows = list(csv.DictReader(io.StringIO(format_csv(tables))))
    a = next(r for r in rows if r["planner"] == "A")
    assert float(a["success_ci95_low"]) == pytest.approx(lo, rel=1e-5)
    b = next(r for r in rows if r["planner"] == "B")
    assert float(b["robot_caused_ci95_high"]) == pytest.approx(wilson_interval(3, 11)[1], rel=1e-5)
