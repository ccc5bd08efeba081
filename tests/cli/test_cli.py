"""The command line: the result.json contract, pictures, and one-line errors with exit code 2."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from anyplan.cli.main import main

FIELDS = {
    "scenario": str, "planner": str, "seed": int, "reached_goal": bool, "collision": bool,
    "path_length_m": float, "planning_times_s": list, "replans": int, "min_clearance_m": float,
    "trajectory": list,
}


def test_run_writes_the_result_contract_and_picture(tmp_path, capsys):
    out = tmp_path / "r"
    # exit code 1: the straight robot collides; result.json and run.png are written all the same
    assert main(["run", "paper-1", "--planner", "straight", "--seed", "4", "--out", str(out)]) == 1
    res = json.loads((out / "result.json").read_text())
    for k, typ in FIELDS.items():
        assert isinstance(res[k], typ), k
    assert "time_to_goal_s" in res and res["time_to_goal_s"] is None  # it collides
    assert res["seed"] == 4 and res["planner"] == "straight" and res["scenario"] == "paper-1"
    assert all(len(row) == 6 for row in res["trajectory"])
    png = (out / "run.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    assert "collision" in capsys.readouterr().out


def test_scenarios_lists_builtins(capsys):
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    assert "paper-1" in out and "paper-3" in out


@pytest.mark.parametrize(("argv", "words"), [
    (["run", "paper-9"], "unknown scenario 'paper-9'"),
    (["run", "paper-1", "--planner", "strait"], "did you mean 'straight'"),
    (["run", "missing.yaml"], "missing.yaml: no such file"),
    (["run", "paper-1", "--dt", "0.5"], "dt must be in"),
    (["run", "paper-1", "--seed", "x"], "invalid int value"),
    (["run", "paper-1", "--actuation-noise", "0.1"], "expected SIGMA_V,SIGMA_OMEGA"),
    (["run", "paper-1", "--actuation-noise", "0.1,-0.1"], "spreads must be in [0, 10], got -0.1"),
    (["run", "paper-1", "--actuation-noise", "0.1,nan"], "finite"),
    (["run", "paper-1", "--localization-noise", "0.05"], "expected SIGMA_XY,SIGMA_THETA"),
    (["run", "paper-1", "--localization-noise", "0.05,-0.01"], "spreads must be in [0, 10], got -0.01"),
    (["bench", "--localization-noise", "a,b"], "a spread in m or rad"),
    (["run", "paper-1", "--set", "pose_margin_m=-0.1"], "pose_margin_m: must be >= 0"),
    (["frobnicate"], "invalid choice"),
])
def test_bad_input_exits_2_with_one_line(argv, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as ei:
        sys.exit(main(argv))
    assert ei.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("anyplan: error:")
    assert words in err


def test_bad_scenario_file_names_file_and_field(tmp_path, capsys):
    f = tmp_path / "s.yaml"
    f.write_text("name: s\narena: {width: 10, height: 8}\nrobot: {start: [1, 1, 0], goal: [9, 7], "
                 "radius: -0.3, v_max: 1, omega_max: 1, a_max: 1, alpha_max: 1}\n")
    assert main(["run", str(f), "--planner", "straight"]) == 2
    err = capsys.readouterr().err
    assert f"{f}: robot.radius: must be > 0" in err and err.count("\n") == 1


def test_python_dash_m_entry_point(tmp_path):
    p = subprocess.run([sys.executable, "-m", "anyplan", "run", "nope"], capture_output=True,
                       text=True, cwd=tmp_path, timeout=120)
    assert p.returncode == 2
    assert "Traceback" not in p.stderr and "unknown scenario 'nope'" in p.stderr


def test_a_reader_gone_early_ends_the_command_quietly(tmp_path):
    # `anyplan planners --settings | head -1`, with the reader gone before the first line
    r, w = os.pipe()
    os.close(r)
    try:
        p = subprocess.run([sys.executable, "-m", "anyplan", "planners", "--settings"], stdout=w,
                           stderr=subprocess.PIPE, text=True, cwd=tmp_path, timeout=120)
    finally:
        os.close(w)
    assert p.returncode == 141 and p.stderr == ""  # as a command killed by SIGPIPE: no traceback


def test_core_layers_do_not_import_matplotlib():
    code = ("import sys, anyplan.geometry, anyplan.world, anyplan.agents, anyplan.simulation, "
            "anyplan.agents.straight; print('matplotlib' in sys.modules)")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.stdout.strip() == "False", p.stderr


def test_bench_keeps_runs_with_another_execution_error_apart(tmp_path, capsys):
    from anyplan.experiments.db import ResultsDB

    db = tmp_path / "x.db"

    def bench(*noise: str) -> int:
        return main(["bench", "--suite", "paper-1", "--planners", "straight", "--runs", "1",
                     "--jobs", "1", "--db", str(db), "--no-progress", "--time-limit", "2", *noise])

    assert bench() == 0
    assert bench("--actuation-noise", "0.02,0.01") == 0  # another row, its own run
    assert bench("--actuation-noise", "0.020,0.010") == 2  # the same: stored already
    assert "already holds 1 of these 1 runs" in capsys.readouterr().err
    with ResultsDB(db, readonly=True) as d:
        runs = sorted(d.runs(), key=lambda r: r["settings"])
        assert [r["settings"] for r in runs] == [
            "", "actuation.sigma_v = 0.02;actuation.sigma_omega = 0.01;"]
        extra = [d.result(r["id"])["extra"] for r in runs]
    assert "actuation" not in extra[0]
    assert extra[1]["actuation"]["sigma_v_mps"] == 0.02


def test_run_summary_tells_how_far_the_robot_strayed_from_its_references(tmp_path, capsys):
    def tracking_lines(*extra: str) -> list[str]:
        assert main(["run", "paper-1", "--out", str(tmp_path / "r"), "--no-plot", "--deterministic",
                     *extra]) == 0
        out = capsys.readouterr().out
        return [ln for ln in out.splitlines() if ln.strip().startswith("tracking")]

    assert tracking_lines() == []  # an exact robot: nothing to tell
    (line,) = tracking_lines("--actuation-noise", "0.05,0.05")
    extra = json.loads((tmp_path / "r" / "result.json").read_text())["extra"]
    n = len(extra["reanchored_s"])
    assert n > 0 and f"{extra['tracking_max_m']:.3f} m from the reference at most" in line
    assert f"off it {n} time" in line


def test_run_records_its_execution_error_with_its_settings(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "paper-1", "--planner", "straight", "--out", str(out), "--no-plot",
                 "--time-limit", "2", "--actuation-noise", "0.02,0.01", "--seed", "4"]) == 1
    extra = json.loads((out / "result.json").read_text())["extra"]
    assert extra["settings"] == "actuation.sigma_v = 0.02;actuation.sigma_omega = 0.01;"
    assert extra["actuation"]["seed"][0] == 4


def test_a_localization_error_gets_its_own_row_and_its_summary_line(tmp_path, capsys):
    from anyplan.experiments.db import ResultsDB

    db = tmp_path / "x.db"
    argv = ["bench", "--suite", "paper-1", "--planners", "straight", "--runs", "1", "--jobs", "1",
            "--db", str(db), "--no-progress", "--time-limit", "2"]
    assert main(argv) == 0
    assert main([*argv, "--localization-noise", "0.05,0.01"]) == 0  # another row
    with ResultsDB(db, readonly=True) as d:
        runs = sorted(d.runs(), key=lambda r: r["settings"])
        assert [r["settings"] for r in runs] == [
            "", "localization.sigma_xy = 0.05;localization.sigma_theta = 0.01;"]
        loc = d.result(runs[1]["id"])["extra"]["localization"]
    assert (loc["sigma_xy_m"], loc["sigma_theta_rad"]) == (0.05, 0.01)
    capsys.readouterr()
    assert main(["run", "paper-1", "--planner", "straight", "--out", str(tmp_path / "r"),
                 "--no-plot", "--time-limit", "2", "--localization-noise", "0.05,0.01"]) == 1
    lines = [ln.strip() for ln in capsys.readouterr().out.splitlines()]
    extra = json.loads((tmp_path / "r" / "result.json").read_text())["extra"]
    worst = extra["localization"]["max_position_error_m"]
    assert (f"localization   believed position off by {worst:.3f} m at most "
            "(spreads 0.05 m, 0.01 rad)") in lines
    assert main(["run", "paper-1", "--out", str(tmp_path / "m"), "--no-plot", "--deterministic",
                 "--localization-noise", "0.02,0.01", "--set", "pose_margin_m=0.05"]) == 0
    (line,) = [ln for ln in capsys.readouterr().out.splitlines() if ln.strip().startswith("localization")]
    assert line.endswith("; 0.050 m more clearance kept for it")
