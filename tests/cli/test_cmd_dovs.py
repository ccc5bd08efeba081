"""``anyplan dovs-plot``: writes the picture; bad input is one line and exit code 2."""

from __future__ import annotations

import pytest

from anyplan.cli.main import main


def test_dovs_plot_writes_a_png(tmp_path, capsys) -> None:
    out = tmp_path / "v.png"
    assert main(["dovs-plot", "paper-1", "--time", "3", "--out", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "chosen v =" in capsys.readouterr().out


def test_dovs_plot_at_time_zero(tmp_path) -> None:
    out = tmp_path / "a" / "b.png"
    assert main(["dovs-plot", "paper-2", "--time", "0", "--out", str(out),
                 "--set", "time_horizon_s=5"]) == 0
    assert out.exists()


@pytest.mark.parametrize(("argv", "needle"), [
    (["dovs-plot", "paper-1", "--time", "-1"], "--time"),
    (["dovs-plot", "paper-1", "--time", "nan"], "--time"),
    (["dovs-plot", "paper-1", "--time", "1e6"], "time limit"),
    (["dovs-plot", "paper-1", "--time", "1", "--out", "x.gif"], ".png, .svg or .pdf"),
    (["dovs-plot", "paper-1", "--time", "1", "--set", "bogus=1"], "bogus"),
    (["dovs-plot", "paper-1", "--time", "1", "--set", "d_safe=-1"], "DOVSConfig.d_safe"),
    (["dovs-plot", "paper-1", "--time", "1", "--set", "time_horizon_s=" + "9" * 400],
     "DOVSConfig.time_horizon_s: must be a finite number, got 999"),  # an OverflowError before
    (["dovs-plot", "paper-1", "--time", "1", "--set", "dw_samples=" + "9" * 400],
     "DOVSConfig.dw_samples: must be a finite number, got 999"),
    (["dovs-plot", "no-such-scenario", "--time", "1"], "no-such-scenario"),
])
def test_dovs_plot_bad_input(argv, needle, capsys, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1 and "Traceback" not in err


def test_dovs_plot_offers_only_the_keys_a_value_can_set(capsys, tmp_path, monkeypatch) -> None:
    # the robot's limits are the scenario's: no command-line value can be a RobotLimits
    monkeypatch.chdir(tmp_path)
    assert main(["dovs-plot", "paper-1", "--time", "1", "--set", "limits=1"]) == 2
    err = capsys.readouterr().err
    assert "expected KEY=VALUE with KEY one of" in err and "limits" not in err.split("one of")[1]
