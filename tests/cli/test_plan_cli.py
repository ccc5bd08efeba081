"""``anyplan plan``: outputs, exit codes and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from anyplan.cli.main import main
from anyplan.geometry import ObstacleSet, Polygon

PEERS_YAML = Path(__file__).resolve().parents[2] / "benchmarks" / "scenarios" / "peers.yaml"


@pytest.mark.parametrize("planner", ["bitstar", "visgraph"])
def test_plan_writes_json_and_plot(tmp_path, capsys, planner):
    out, png = tmp_path / "plan.json", tmp_path / "plan.png"
    budget = ["--time", "0.05"] if planner == "bitstar" else []  # visgraph is exact: no budget
    rc = main(["plan", str(PEERS_YAML), "--planner", planner, *budget, "--seed", "3",
               "--json", str(out), "--plot", str(png)])
    assert rc == 0
    doc = json.loads(out.read_text())
    for key in ("status", "cost", "path", "first_solution_time_s", "solve_time_s", "history",
                "lower_bound"):
        assert key in doc
    assert doc["status"] == "exact"
    # the budget recorded is the one given; visgraph has none (and refuses --time)
    assert doc["time_budget_s"] == (0.05 if planner == "bitstar" else None)
    path = np.array(doc["path"])
    rects = [(3.0, 0.0, 5.0, 7.0), (7.0, 4.0, 9.0, 11.0), (10.5, 2.0, 12.5, 8.0)]
    obs = ObstacleSet([Polygon([[a, b], [c, b], [c, d], [a, d]]) for a, b, c, d in rects],
                      bounds=(0.0, 0.0, 15.0, 11.0))
    assert obs.path_free(path, 0.25)
    assert doc["lower_bound"] <= doc["cost"]
    assert doc["cost"] == pytest.approx(float(np.sum(np.hypot(*np.diff(path, axis=0).T))))
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    assert "exact" in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "needle"), [
    (["plan", "paper-1", "--time", "0"], "--time must be > 0"),
    (["plan", "paper-9"], "unknown scenario 'paper-9'"),
    (["plan", "paper-1", "--json", "/no/such/dir/x.json"], "does not exist"),
])
def test_plan_bad_input_is_one_line_exit_2(capsys, argv, needle):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


def test_plan_unknown_planner_exits_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["plan", "paper-1", "--planner", "rrt"])
    assert exc.value.code == 2
    assert "invalid choice" in capsys.readouterr().err
