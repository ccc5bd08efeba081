"""benchmarks/compare_rows.py: the paired comparison of two benchmark row files."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "compare_rows.py"


@pytest.fixture(scope="module")
def compare_rows():
    spec = importlib.util.spec_from_file_location("compare_rows", PATH)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _rows(planner, outcomes, seed=0):
    return [{"suite": "dynabarn", "mode": "tracked", "planner": planner, "scenario": f"w{i}",
             "seed": seed, "status": s.rstrip("*"), "robot_caused": s.endswith("*")}
            for i, s in enumerate(outcomes)]


def test_pairs_two_files_and_lists_the_runs_that_differ(tmp_path, compare_rows, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(_rows("st-bitstar", ["reached"] * 9 + ["collision*"])))
    b.write_text(json.dumps(_rows("st-bitstar", ["collision"] * 8 + ["reached", "collision*"])
                            + _rows("st-bitstar", ["reached"], seed=1)))
    assert compare_rows.main([str(a), str(b), "--labels", "new,old", "--runs"]) == 0
    out = capsys.readouterr().out
    # 10 paired runs (the seed-1 run of b pairs with nothing): 9 against 1 reached, 8 one way
    assert "| dynabarn tracked st-bitstar | 10 | reached | 9 | 1 | +80.0 % [" in out
    assert "(p = 0.0078)" in out  # McNemar: 8 discordant pairs, all one way: 2 / 2**8
    assert "| robot-caused | 1 | 1 | +0.0 % [" in out
    assert "8 runs differ" in out and "w0 seed 0: new reached, old collision" in out


def test_robot_caused_seen_in_time_leaves_out_obstacles_that_appeared_late(tmp_path, compare_rows, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    rows = _rows("st-bitstar", ["collision*", "collision*", "reached"])
    rows[0]["appeared_within_stop"] = True  # a person whose recorded track began on the robot
    rows[1]["appeared_within_stop"] = False
    a.write_text(json.dumps(rows))
    b.write_text(json.dumps(_rows("st-bitstar", ["reached"] * 3)))
    assert compare_rows.main([str(a), str(b)]) == 0
    out = capsys.readouterr().out
    assert "| robot-caused | 2 | 0 |" in out and "| robot-caused, seen in time | 1 | 0 |" in out


def test_one_planner_per_file_pairs_across_names(tmp_path, compare_rows, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(_rows("st-bitstar", ["reached", "reached"])))
    b.write_text(json.dumps(_rows("seq-bitstar", ["reached", "timeout"])))
    assert compare_rows.main([str(a), str(b)]) == 0
    assert "st-bitstar / seq-bitstar | 2 | reached | 2 | 1 |" in capsys.readouterr().out


def test_modes_pair_two_perception_modes(tmp_path, compare_rows, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(_rows("st-bitstar", ["reached", "collision"])))
    twist = [dict(r, mode="twist") for r in _rows("st-bitstar", ["reached", "reached"])]
    b.write_text(json.dumps(twist + _rows("st-bitstar", ["timeout", "timeout"])))
    assert compare_rows.main([str(a), str(b), "--modes", "tracked,twist"]) == 0
    out = capsys.readouterr().out
    assert "| dynabarn tracked / twist st-bitstar | 2 | reached | 1 | 2 | -50.0 % [" in out
    assert compare_rows.main([str(a), str(b), "--modes", "tracked"]) == 2
    assert "--modes" in capsys.readouterr().err


@pytest.mark.parametrize(("content", "message"), [
    (None, "cannot read"), ("{", "not JSON"), ('{"a": 1}', "not a --rows file"),
    (json.dumps(_rows("st-bitstar", ["reached"], seed=5)), "share no run")])
def test_bad_files_are_one_line_and_exit_2(tmp_path, compare_rows, capsys, content, message):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    if content is not None:
        a.write_text(content)
    b.write_text(json.dumps(_rows("st-bitstar", ["reached"])))
    assert compare_rows.main([str(a), str(b)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and str(a) in err
