"""The bench runner and the results database: completeness, seeds, resume after interruption."""

from __future__ import annotations

import json

import pytest

from anyplan.experiments.db import ResultsDB
from anyplan.experiments.runner import (
    BenchError,
    BenchInterrupted,
    PlannerSpec,
    derive_seed,
    execute_task,
    parse_planners,
    plan_tasks,
    run_bench,
)
from anyplan.world.scenario import load_scenario


def _keys(db_path):
    with ResultsDB(db_path) as db:
        return [(r["scenario"], r["planner"], r["run_index"], r["seed"]) for r in db.runs()]


def test_derive_seed_is_deterministic_and_distinct():
    seeds = [derive_seed(7, i) for i in range(50)]
    assert seeds == [derive_seed(7, i) for i in range(50)]
    assert len(set(seeds)) == 50
    assert derive_seed(8, 0) != derive_seed(7, 0)


def test_tiny_bench_stores_every_run_with_its_seed(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    db_path = tmp_path / "r.db"
    s = run_bench([sc], [PlannerSpec("straight"), PlannerSpec("half-speed")], 2, db_path,
                  master_seed=3, progress=False)
    assert (s.finished, s.skipped, s.errors) == (4, 0, 0)
    with ResultsDB(db_path) as db:
        runs = db.runs()
        assert sorted((r["planner"], r["run_index"]) for r in runs) == [
            ("half-speed", 0), ("half-speed", 1), ("straight", 0), ("straight", 1)]
        for r in runs:
            assert r["seed"] == derive_seed(3, r["run_index"])
            assert r["scenario_hash"] == sc.content_hash()
            assert r["anyplan_version"]
            assert r["outcome"] == "reached" and r["solved"] == 1 and r["status"] == 6
            res = db.run_result(r["id"])
            # The whole result.json is kept, and agrees with the run's columns.
            assert res.seed == r["seed"] and res.planner == r["planner"]
            assert res.path_length_m == pytest.approx(r["path_length"])
            assert len(res.trajectory) > 10
        # Half speed takes about twice as long over the same 5 m.
        ttg = {r["planner"]: r["time_to_goal"] for r in runs if r["run_index"] == 0}
        assert ttg["half-speed"] > 1.6 * ttg["straight"]
        (exp,) = db.experiments()
        assert exp["seed"] == "3" and exp["moving_obstacles"] == 1 and exp["runcount"] == 2
        assert json.loads(exp["setup"])["name"] == "tiny"


def test_refuses_to_duplicate_runs_without_resume(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    db_path = tmp_path / "r.db"
    run_bench([sc], [PlannerSpec("straight")], 1, db_path, progress=False)
    with pytest.raises(BenchError, match="--resume"):
        run_bench([sc], [PlannerSpec("straight")], 2, db_path, progress=False)
    s = run_bench([sc], [PlannerSpec("straight")], 2, db_path, resume=True, progress=False)
    assert (s.skipped, s.finished) == (1, 1)
    assert sorted(k[2] for k in _keys(db_path)) == [0, 1]


def test_resume_after_keyboard_interrupt_runs_only_the_missing(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    db_path = tmp_path / "r.db"
    flag = tmp_path / "flag"
    planners = [PlannerSpec("straight"), PlannerSpec("interrupt-once", {"flag_file": str(flag)})]
    with pytest.raises(KeyboardInterrupt):
        run_bench([sc], planners, 2, db_path, progress=False)
    # Tasks run run-major: straight#0 finished and was committed before the interruption.
    assert _keys(db_path) == [("tiny", "straight", 0, derive_seed(0, 0))]
    s = run_bench([sc], planners, 2, db_path, resume=True, progress=False)
    assert (s.skipped, s.finished, s.errors) == (1, 3, 0)
    keys = _keys(db_path)
    assert len(keys) == len(set(keys)) == 4


def test_resume_after_a_killed_worker(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    db_path = tmp_path / "r.db"
    flag = tmp_path / "flag"
    planners = [PlannerSpec("straight"), PlannerSpec("die-once", {"flag_file": str(flag)})]
    with pytest.raises(BenchInterrupted, match="worker process died"):
        run_bench([sc], planners, 2, db_path, jobs=2, progress=False)
    first = _keys(db_path)
    assert len(first) < 4 and sum(k[1] == "die-once" for k in first) < 2
    s = run_bench([sc], planners, 2, db_path, resume=True, jobs=1, progress=False)
    assert s.skipped == len(first) and s.finished == 4 - len(first)
    keys = _keys(db_path)
    assert len(keys) == len(set(keys)) == 4


def test_planner_exception_is_a_stored_crash_not_a_failed_bench(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    db_path = tmp_path / "r.db"
    s = run_bench([sc], [PlannerSpec("raising")], 1, db_path, progress=False)
    assert s.errors == 1
    with ResultsDB(db_path) as db:
        (r,) = db.runs()
        assert r["status"] == 7 and r["outcome"] == "error" and "planner bug" in r["error"]
        assert db.query("SELECT description FROM enums WHERE name='status' AND value=7")[0][
            "description"] == "Crash"


def test_execute_task_registers_plugin_planners_in_fresh_workers(tiny_file):
    from anyplan.agents.base import AGENTS

    sc = load_scenario(tiny_file)
    (task,) = plan_tasks([sc], [PlannerSpec("half-speed")], 1, 0)
    assert task.planner_entry == "anyplan_bench_test_agents:HalfSpeedAgent"
    # A worker that never heard of the name registers it from the entry.
    entries = AGENTS._entries
    saved = entries.pop("half-speed")
    try:
        out = execute_task(task)
    finally:
        entries["half-speed"] = saved
    assert out["error"] is None and out["result"]["status"] == "reached"


def test_unknown_planner_is_a_clear_error(tiny_file):
    from anyplan.errors import UnknownNameError

    with pytest.raises(UnknownNameError, match="unknown planner 'strait'"):
        plan_tasks([load_scenario(tiny_file)], [PlannerSpec("strait")], 1, 0)


def test_a_registered_object_that_is_not_an_agent_class_is_refused_before_any_run(tmp_path, tiny_file):
    from anyplan.agents.base import AGENTS

    AGENTS.register("not-an-agent", "json:JSONDecoder", origin="plugin from x 1")
    try:
        for config in ({}, {"strict": True}):  # with a config or without, as make_agent refuses it
            with pytest.raises(BenchError, match=r"^planner 'not-an-agent' \(plugin from x 1\) is not "
                                                 r"an anyplan.agents.Agent subclass"):
                run_bench([load_scenario(tiny_file)], [PlannerSpec("not-an-agent", config)], 1,
                          tmp_path / "r.db", progress=False)
        assert not (tmp_path / "r.db").exists()  # refused before the database is opened
    finally:
        AGENTS._entries.pop("not-an-agent")
        AGENTS._origins.pop("not-an-agent")


def test_plan_tasks_looks_each_planner_up_once_and_still_checks_every_planner_before_any_config(
        tiny_file, monkeypatch):
    from anyplan.errors import UnknownNameError
    from anyplan.experiments import runner

    calls: list[str] = []
    lookup = runner._planner_entry

    def counted(name: str) -> str | None:
        calls.append(name)
        return lookup(name)

    monkeypatch.setattr(runner, "_planner_entry", counted)
    sc = load_scenario(tiny_file)
    tasks = plan_tasks([sc], [PlannerSpec("straight", {"heading_gain": "1.5"}), PlannerSpec("half-speed")],
                       2, 0)
    assert calls == ["straight", "half-speed"]
    assert [(t.planner, t.planner_config, t.planner_entry) for t in tasks[:2]] == [
        ("straight", {"heading_gain": 1.5}, lookup("straight")),
        ("half-speed", {}, "anyplan_bench_test_agents:HalfSpeedAgent")]
    # an unknown planner listed after a bad config is still the error told
    calls.clear()
    with pytest.raises(UnknownNameError, match="unknown planner 'strait'"):
        plan_tasks([sc], [PlannerSpec("straight", {"heading_gain": "x"}), PlannerSpec("strait")], 1, 0)
    assert calls == ["straight", "strait"]


def test_a_library_config_is_checked_as_bench_config_is(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    with pytest.raises(BenchError, match=r"^config straight: heading_gain='x': planner 'straight' "
                                         "expects float"):
        plan_tasks([sc], [PlannerSpec("straight", {"heading_gain": "x"})], 1, 0)
    with pytest.raises(BenchError, match=r"^config straight: unknown setting of planner 'straight' 'nope'"):
        run_bench([sc], [PlannerSpec("straight", {"nope": 1})], 1, tmp_path / "r.db", progress=False)
    assert not (tmp_path / "r.db").exists()  # refused before the database is opened
    # a value the check converts runs converted and is recorded so; any other is kept as given
    run_bench([sc], [PlannerSpec("straight", {"heading_gain": "1.5", "align_tolerance": 3})], 1,
              tmp_path / "r.db", progress=False)
    with ResultsDB(tmp_path / "r.db", readonly=True) as db:
        (r,) = db.runs()
    assert r["settings"] == "align_tolerance = 3;heading_gain = 1.5;" and r["error"] is None


@pytest.mark.parametrize(("blob", "why"), [
    ('{"heading_gain": ' + "9" * 5000 + "}", "a number with too many digits"),  # int(): ValueError
    ("[" * 100_000, "nested too deeply"),  # RecursionError
])
def test_a_config_json_python_cannot_hold_is_a_bench_error(blob, why):
    with pytest.raises(BenchError) as info:
        parse_planners("straight", [f"straight={blob}"])
    assert str(info.value) == f"config straight: cannot read the JSON ({why})"
