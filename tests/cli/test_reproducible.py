"""Reproducible command lines: --deterministic and --set give the same result.json for the same
seed (apart from the fields it lists as wall-clock), checked against the agent's settings."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from anyplan.agents.sequential import SequentialBITStarAgent
from anyplan.agents.settings import SettingsError, agent_settings, build_agent_config, parse_set_options
from anyplan.cli.main import main
from anyplan.simulation.simulator import without_wall_clock

ROOT = Path(__file__).resolve().parents[2]


def _run(tmp_path, name, *extra):
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), MPLBACKEND="Agg")
    out = tmp_path / name
    p = subprocess.run([sys.executable, "-m", "anyplan", "run", "paper-3", "--planner", "seq-bitstar",
                        "--seed", "7", "--out", str(out), "--no-plot", *extra],
                       env=env, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr
    return json.loads((out / "result.json").read_text())


def test_the_same_deterministic_command_twice_gives_the_same_result(tmp_path):
    a = _run(tmp_path, "a", "--deterministic")
    b = _run(tmp_path, "b", "--deterministic")
    assert "wall_time_s" in a["wall_clock_fields"] and "planning_times_s" in a["wall_clock_fields"]
    assert a["wall_time_s"] != b["wall_time_s"]  # the clock did differ between the two processes
    ra, rb = without_wall_clock(a), without_wall_clock(b)
    assert "wall_time_s" not in ra and "plan_time_s" not in ra["extra"]
    assert ra == rb
    assert a["virtual_obstacles"] and a["plans"]  # the loop did plan around obstacles
    assert a["replans"] == len(a["planning_times_s"]) - 1  # every planning but the first is a replanning
    # --set gives the same settings by hand (and --set overrides --deterministic's).
    c = _run(tmp_path, "c", "--set", "planning_delay=0.1", "--set", "batches_per_plan=2",
             "--set", "max_time_s=10")
    assert without_wall_clock(c) == ra
    # the settings given are recorded, as anyplan bench records them
    assert a["extra"]["settings"] == c["extra"]["settings"]
    assert all(f"{k} = " in a["extra"]["settings"]
               for k in ("planning_delay", "batches_per_plan", "max_time_s"))


def test_values_are_yaml_scalars_checked_against_the_settings():
    opts = parse_set_options(["planning_delay=0.1", "batches_per_plan=2", "warm_start=true",
                              "prediction_dt=null", "wait_delays_s=[1, 2.5]", "first_budget_s=1e-3"])
    cfg = build_agent_config(SequentialBITStarAgent, "seq-bitstar", opts)
    assert cfg == {"planning_delay": 0.1, "batches_per_plan": 2, "warm_start": True, "prediction_dt": None,
                   "wait_delays_s": (1.0, 2.5), "first_budget_s": 1e-3}
    assert isinstance(cfg["batches_per_plan"], int)
    settings = parse_set_options(["planning_delay=measured"])
    config = build_agent_config(SequentialBITStarAgent, "seq-bitstar", settings)
    assert config == {"planning_delay": "measured"}
    assert "gains" not in agent_settings(SequentialBITStarAgent)  # objects are not command-line settings


@pytest.mark.parametrize(("items", "words"), [
    (["batches_per_plan=2.5"], "expects int or None"),
    (["warm_start=3"], "expects bool"),
    (["batches_per_plan=0"], "rejects its settings: batches_per_plan: must be >= 1"),
    (["planning_delay=soon"], "rejects its settings: planning_delay"),
    (["batch_per_plan=2"], "did you mean 'batches_per_plan'"),
    (["margin"], "expected KEY=VALUE"),
    (["margin=1", "margin=2"], "given twice"),
])
def test_bad_settings_are_refused(items, words):
    with pytest.raises(SettingsError, match=words.replace("(", r"\(")):
        build_agent_config(SequentialBITStarAgent, "seq-bitstar", parse_set_options(items))


def test_bench_routes_settings_to_the_planners_that_have_them(tmp_path, capsys):
    argv = ["bench", "--suite", "paper-1", "--planners", "straight,dovs", "--runs", "1", "--jobs", "1",
            "--db", str(tmp_path / "x.db"), "--no-progress", "--time-limit", "1"]
    assert main([*argv, "--set", "nothing_has_this=1"]) == 2
    assert "no planner in --planners" in capsys.readouterr().err
    assert main([*argv, "--set", "seq-bitstar:margin=1"]) == 2
    assert "'seq-bitstar' is not in --planners" in capsys.readouterr().err
    assert main([*argv, "--set", "d_safe=0.2", "--set", "straight:heading_gain=3"]) == 0
    import sqlite3

    con = sqlite3.connect(tmp_path / "x.db")
    settings = dict(con.execute("SELECT name, settings FROM plannerConfigs").fetchall())
    con.close()
    assert settings == {"straight": "heading_gain = 3.0;", "dovs": "d_safe = 0.2;"}


@pytest.mark.parametrize("planner", ["st-bitstar", "dovs"])
def test_other_planners_deterministic_settings_repeat(planner):
    from anyplan.agents.base import AGENTS, make_agent
    from anyplan.simulation import SimConfig, simulate
    from anyplan.world import load_scenario

    if planner not in AGENTS:
        pytest.skip(f"{planner} is not registered")
    cfg = build_agent_config(AGENTS.get(planner), planner, {}, deterministic=True)
    sc = load_scenario("paper-3")
    runs = [simulate(sc, make_agent(planner, **cfg), seed=4, config=SimConfig(time_limit=25.0))
            for _ in range(2)]
    assert runs[0].reproducible_dict() == runs[1].reproducible_dict()
    assert len(runs[0].trajectory) > 100


@pytest.mark.parametrize("planner", ["seq-bitstar", "st-bitstar"])
def test_deterministic_settings_give_the_same_run_on_a_slower_machine(planner):
    # Running twice on the same machine cannot show a deterministic run that still reads the
    # wall clock. The second run here is on a "slower machine": every replanning takes 0.15 s
    # more of wall clock. A fixed planning delay (0.1 s) must start every motion 0.1 s after
    # its call on both; a measured one would start the second 0.25 s after (1.5 x 0.15 s on
    # the 0.05 s grid). paper-1 with a 2 m sensing range, so that the robot replans.
    import dataclasses
    import time

    from anyplan.agents.base import AGENTS, make_agent
    from anyplan.simulation import SimConfig, simulate
    from anyplan.world import load_scenario

    slow_s = 0.15
    cfg = build_agent_config(AGENTS.get(planner), planner, {}, deterministic=True)
    sc = load_scenario("paper-1")
    sc = dataclasses.replace(sc, robot=dataclasses.replace(sc.robot, sensing_range=2.0))

    def slower(agent):
        reset = agent.reset

        def slow_reset(scenario, rng):
            reset(scenario, rng)
            inner = agent.loop.replan

            def replan(*args, **kwargs):
                time.sleep(slow_s)
                return inner(*args, **kwargs)

            agent.loop.replan = replan

        agent.reset = slow_reset
        return agent

    config = SimConfig(time_limit=6.0)
    fast = simulate(sc, make_agent(planner, **cfg), seed=4, config=config)
    slow = simulate(sc, slower(make_agent(planner, **cfg)), seed=4, config=config)
    assert fast.replans >= 1  # a delay after a first measured call exists
    assert min(slow.planning_times_s) >= slow_s  # every replanning was slower
    assert [p["t_start"] - p["t"] for p in slow.plans] == [p["t_start"] - p["t"] for p in fast.plans]
    assert slow.trajectory == fast.trajectory
    assert slow.extra["statuses"] == fast.extra["statuses"]
    assert slow.reproducible_dict() == fast.reproducible_dict()


def test_a_benchmark_with_fixed_planners_names_them_in_a_bad_set(capsys):
    # benchmarks/maps.py has no --planners: a --set no planner takes says which planners it
    # drives, in one line, exit 2 (before anything is compiled or run)
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "maps.py"
    spec = importlib.util.spec_from_file_location("maps_bench", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    with pytest.raises(SystemExit) as exc:
        mod.main(["--quick", "--set", "nothing_has_this=1"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "no planner in the planners this benchmark drives (seq-bitstar, st-bitstar)" in err
    assert "--planners" not in err
