"""Defaults that point at what matters: run's planner, bench's planners, bench-planning without
OMPL on problems where planners differ, and ``moving_obstacles`` as another name for
``dynamic_obstacles``."""

from __future__ import annotations

import math

import pytest
import yaml

from anyplan.agents.base import AGENTS
from anyplan.cli.main import build_parser, main
from anyplan.experiments import planning_bench
from anyplan.experiments.db import ResultsDB
from anyplan.experiments.planning_problems import cluttered_world, planning_suite
from anyplan.planning import Problem, lower_bound
from tests.conftest import small_scenario_dict


def test_run_plans_with_st_bitstar_unless_told_and_it_reaches_safely(tmp_path, capsys):
    # st-bitstar beat seq-bitstar on every suite of issue 10 (docs/spacetime.md, "Targets"), so
    # `anyplan run` uses it; paper-3 (three walkers) is the README's first command.
    import json

    assert main(["run", "paper-3", "--deterministic", "--no-plot", "--out", str(tmp_path)]) == 0
    res = json.loads((tmp_path / "result.json").read_text())
    assert res["planner"] == "st-bitstar"
    assert res["status"] == "reached" and not res["collision"]
    # the printed summary counts what result.json holds, in English ("1 call", "0 replans"),
    # and says how many of the replannings were improvement calls
    n, r = len(res["planning_times_s"]), res["replans"]
    k = res["extra"]["reasons"].count("improve")
    assert k >= 1  # paper-3: the first plan waits for the walkers; the next calls improve on it
    line = next(s for s in capsys.readouterr().out.splitlines() if s.strip().startswith("planning"))
    assert f"{n} call{'' if n == 1 else 's'}," in line
    assert line.endswith(f"{r} replan{'' if r == 1 else 's'} ({k} of them improving the motion "
                         "in use)")


def test_bench_defaults_to_the_paper_comparison():
    args = build_parser().parse_args(["bench"])
    from anyplan.cli.cmd_bench import default_bench_planners

    assert args.planners is None  # resolved at run time, from what is registered
    expected = "seq-bitstar,dovs" + (",st-bitstar" if "st-bitstar" in AGENTS else "")
    assert default_bench_planners() == expected
    assert "straight" not in default_bench_planners()


def test_planning_suite_has_no_straight_line_problem():
    suite = planning_suite(0, count=2)
    assert [sc.name for sc in suite] == ["peers", "cluttered-s0-0", "cluttered-s0-1"]
    for sc in suite:
        r = sc.robot
        assert not sc.obstacle_set().segment_free(r.start[:2], r.goal, r.radius), sc.name
        assert not sc.moving_obstacles
    assert cluttered_world(0, 1).content_hash() == suite[2].content_hash()  # seeded


def test_bench_planning_runs_without_ompl_and_finds_detours(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(planning_bench, "ompl_available", lambda: False)
    db = tmp_path / "p.db"
    assert main(["bench-planning", "--runs", "1", "--budget", "0.05", "--db", str(db), "--no-progress"]) == 0
    assert "ompl wheel is not installed" in capsys.readouterr().err
    suite = {sc.name: sc for sc in planning_suite(0, count=4)}
    with ResultsDB(db) as d:
        runs = d.runs()
    assert {r["planner"] for r in runs} == {planning_bench.OURS}
    assert len(runs) == len(suite) == 5
    by_hash = {sc.content_hash(): sc for sc in suite.values()}
    for r in runs:
        sc = by_hash[r["scenario_hash"]]
        straight = math.dist(sc.robot.start[:2], sc.robot.goal)
        problem = Problem.create(sc.obstacle_set(), sc.robot.start[:2], sc.robot.goal, sc.robot.radius)
        bound = lower_bound(problem)
        # A real detour: the optimum is longer than the straight line, and BIT* respects it.
        assert bound > straight + 1e-3
        if r["solved"]:
            assert r["best_cost"] >= bound - 1e-6


def test_moving_obstacles_is_another_name_for_dynamic_obstacles(tmp_path, capsys):
    d = small_scenario_dict()
    alias = dict(d)
    alias["moving_obstacles"] = alias.pop("dynamic_obstacles")
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump(alias))
    g = tmp_path / "d.yaml"
    g.write_text(yaml.safe_dump(d))
    code_a = main(["run", str(f), "--planner", "straight", "--out", str(tmp_path / "a"), "--no-plot"])
    code_d = main(["run", str(g), "--planner", "straight", "--out", str(tmp_path / "d"), "--no-plot"])
    assert code_a == code_d
    import json

    ra = json.loads((tmp_path / "a" / "result.json").read_text())
    rd = json.loads((tmp_path / "d" / "result.json").read_text())
    assert ra["scenario_hash"] == rd["scenario_hash"] and ra["trajectory"] == rd["trajectory"]
    both = dict(d, moving_obstacles=d["dynamic_obstacles"])
    h = tmp_path / "both.yaml"
    h.write_text(yaml.safe_dump(both))
    capsys.readouterr()
    assert main(["run", str(h), "--planner", "straight", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "both.yaml: moving_obstacles: give the moving obstacles once" in err


@pytest.mark.parametrize("key", ["moving_obstacle", "dynamic_obstacle"])
def test_misspelt_moving_obstacles_get_a_moving_hint(tmp_path, capsys, key):
    d = small_scenario_dict()
    d[key] = d.pop("dynamic_obstacles")
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(d))
    assert main(["run", str(f), "--planner", "straight"]) == 2
    assert "did you mean '" + key + "s'" in capsys.readouterr().err
