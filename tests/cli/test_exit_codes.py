"""``anyplan run`` exit codes: 0 at the goal, 1 after a collision or a timeout (with result.json and
the picture written), 2 on bad input; and the codes are in --help."""

from __future__ import annotations

import json

import pytest
import yaml

from anyplan.cli.main import main
from tests.conftest import small_scenario_dict


def _scenario(tmp_path, **over):
    d = small_scenario_dict(**over)
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(d))
    return p


def test_goal_reached_exits_0(tmp_path):
    p = _scenario(tmp_path, static_obstacles=[], dynamic_obstacles=[])
    assert main(["run", str(p), "--planner", "straight", "--out", str(tmp_path / "o"), "--no-plot"]) == 0
    assert json.loads((tmp_path / "o" / "result.json").read_text())["status"] == "reached"


def test_timeout_exits_1_and_still_writes_result_and_picture(tmp_path):
    p = _scenario(tmp_path, static_obstacles=[], dynamic_obstacles=[])
    out = tmp_path / "o"
    assert main(["run", str(p), "--planner", "straight", "--time-limit", "2", "--out", str(out)]) == 1
    assert json.loads((out / "result.json").read_text())["status"] == "timeout"
    assert (out / "run.png").read_bytes()[:4] == b"\x89PNG"


def test_bad_setting_exits_2(tmp_path, capsys):
    assert main(["run", "paper-1", "--planner", "straight", "--set", "heading_gian=3",
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "did you mean 'heading_gain'" in err
    assert not (tmp_path / "o").exists()  # refused before any work


def test_help_documents_the_exit_codes(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = capsys.readouterr().out
    assert "exit codes:" in out and "1  the run collided or timed out" in out
