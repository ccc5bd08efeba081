"""``anyplan bench`` and ``anyplan report`` end to end on a tiny scenario (2 planners x 2 seeds)."""

from __future__ import annotations

import base64
import csv
import re
import sqlite3
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parents[1] / "experiments"))

import anyplan_bench_test_agents as agents

from anyplan.cli.main import main
from anyplan.experiments.tables import PlannerTable, Stat, TableRow, format_paper_comparison

agents.register_all()


@pytest.fixture
def tiny(tmp_path):
    p = tmp_path / "tiny.yaml"
    p.write_text(yaml.safe_dump(agents.TINY))
    return p


def _available(name):
    from anyplan.agents import AGENTS

    try:
        AGENTS.get(name)
    except ImportError:
        return False
    return True


@pytest.mark.parametrize("other", ["half-speed", pytest.param("dovs", marks=pytest.mark.skipif(
    not _available("dovs"), reason="the dovs agent is not importable"))])
def test_bench_then_report(tmp_path, tiny, capsys, other):
    db, out = tmp_path / "results.db", tmp_path / "out"
    code = main(["bench", "--suite", str(tiny), "--planners", f"straight,{other}", "--runs", "2",
                 "--jobs", "1", "--db", str(db), "--out", str(out), "--seed", "4"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    assert "4/4" in cap.err and "ETA" in cap.err  # the progress bar, on stderr
    assert "path length [m]" in cap.out and other in cap.out
    # One row per number of moving obstacles, 2 successes of 2 runs; time over the lower bound
    # >= 1; the success rate's Wilson interval (0.34-1.00 for 2 of 2); no collision, none
    # robot-caused, no timeout, no error; then the minimum distance to the moving obstacles and
    # the discomfort time.
    assert re.search(r"^\s+1\s+4\.8\d\d ± 0\.000.*\s1\.\d\d\d ± \d\.\d\d\d\s+2/2\s+0\.34-1\.00"
                     r"\s+0\s+0\s+0\s+0"
                     r"\s+-?\d+\.\d{3}\s+\d\.\d\d( ± \d\.\d\d)?$",
                     cap.out, re.M), cap.out
    # the two planners ran the same scenario and seeds: one paired comparison, both reached
    # every run (no difference: 0 with an interval around it, McNemar's p = 1)
    pair = f"(straight\\s+{re.escape(other)}|{re.escape(other)}\\s+straight)"
    assert re.search(r"^" + pair + r"\s+2\s+2 / 2\s+\+0\.0 % \[-\d+\.\d, "
                     r"\+\d+\.\d\] \(p = 1\)", cap.out, re.M), cap.out
    md = (out / "tables.md").read_text()
    assert "| moving obstacles | path length [m]" in md and "### Paired comparisons" in md
    rows = list(csv.DictReader((out / "tables.csv").read_text().splitlines()))
    assert {r["planner"] for r in rows} == {"straight", other}
    assert all(r["runs"] == "2" and r["successes"] == "2" for r in rows)
    conn = sqlite3.connect(db)
    assert conn.execute("SELECT count(*) FROM runs").fetchone()[0] == 4
    assert conn.execute("SELECT count(*) FROM results").fetchone()[0] == 4
    conn.close()

    rep = tmp_path / "rep"
    assert main(["report", str(db), "--out", str(rep)]) == 0
    for name in ("figure4.png", "boxplots.png", "report.html", "tables.md", "tables.csv"):
        assert (rep / name).is_file(), name
    # Cost over time needs plans or anytime progress; only the half-speed test agent reports them.
    has_progress = other == "half-speed"
    assert (rep / "cost_time.png").is_file() == has_progress
    page = (rep / "report.html").read_text()
    imgs = re.findall(r"src='data:image/png;base64,([^']+)'", page)
    assert len(imgs) == 2 + has_progress
    assert all(base64.b64decode(b)[:8] == b"\x89PNG\r\n\x1a\n" for b in imgs)
    assert other in page and "<table class='sortable'>" in page and "Paired comparisons" in page


def test_bench_resume_flag_and_refusal(tmp_path, tiny, capsys):
    db = tmp_path / "r.db"
    args = ["bench", "--suite", str(tiny), "--planners", "straight", "--runs", "1", "--jobs", "1",
            "--db", str(db), "--no-progress"]
    assert main(args) == 0
    assert main(args) == 2
    assert "--resume" in capsys.readouterr().err
    assert main([*args[:6], "2", *args[7:], "--resume"]) == 0
    assert "1 runs now, 1 already stored" in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "message"), [
    (["--planners", "strait"], "unknown planner 'strait'"),
    (["--runs", "0"], "--runs must be >= 1"),
    (["--jobs", "0"], "--jobs must be >= 1"),
    (["--suite", "nope.yaml"], "nope.yaml: no such file"),
    (["--resume", "--db", "missing.db"], "does not exist"),
    (["--planners", "straight", "--config", 'straight={"nope": 1}'],
     "--config straight: unknown setting of planner 'straight' 'nope'"),
    (["--planners", "straight", "--config", "straight=[1"], "--config straight: not JSON"),
    (["--planners", "straight", "--config", f'straight={{"heading_gain": {"9" * 5000}}}'],
     "--config straight: cannot read the JSON (a number with too many digits)"),  # was a ValueError
    (["--planners", "straight", "--config", "dovs={}"], "'dovs' is not in --planners"),
])
def test_bench_bad_input_is_one_line(tmp_path, tiny, capsys, argv, message, monkeypatch):
    monkeypatch.chdir(tmp_path)
    base = ["bench", "--suite", str(tiny), "--runs", "1", "--jobs", "1", "--no-progress"]
    assert main(base + argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_report_on_a_missing_database(tmp_path, capsys):
    assert main(["report", str(tmp_path / "none.db"), "--out", str(tmp_path / "o")]) == 2
    assert "no such database" in capsys.readouterr().err


def test_paper_figures_are_printed_beside_ours():
    s = Stat(12.5, 0.4, 30)
    t = PlannerTable("seq-bitstar", "", [TableRow(1, 30, 30, 0, 0, 0, s, Stat(0.2, 0.01, 30), s)])
    d = PlannerTable("dovs", "", [TableRow(3, 30, 10, 20, 0, 0, s, s, s)])
    text = format_paper_comparison([t, d])
    assert "12.076" in text and "0.1841" in text and "40.766" in text   # Table 3
    assert "18.762" in text and "0.25188" in text and "crashed" in text  # Table 2
    assert "12.500 ± 0.400" in text


def test_planner_config_is_used_and_recorded(tmp_path):
    turned = yaml.safe_load(yaml.safe_dump(agents.TINY))
    turned["robot"]["start"][2] = 1.5  # facing away from the goal: align_tolerance matters
    tiny = tmp_path / "turned.yaml"
    tiny.write_text(yaml.safe_dump(turned))
    db = tmp_path / "c.db"
    args = ["bench", "--suite", str(tiny), "--planners", "straight", "--runs", "1", "--jobs", "1",
            "--db", str(db), "--no-progress"]
    assert main([*args, "--config", 'straight={"align_tolerance": 3.2}']) == 0
    assert main(args) == 0  # the default config is another planner configuration: no overlap
    conn = sqlite3.connect(db)
    rows = conn.execute("SELECT p.settings, r.time_to_goal FROM runs r JOIN plannerConfigs p "
                        "ON p.id = r.plannerid ORDER BY p.id").fetchall()
    conn.close()
    assert [r[0] for r in rows] == ["align_tolerance = 3.2;", ""]
    # Driving off without first turning to the goal takes a different time.
    assert rows[0][1] != rows[1][1]
