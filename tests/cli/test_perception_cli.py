"""``--perception``, ``--sensor-noise`` and ``--sensor-rate`` on ``anyplan run`` and ``bench``."""

from __future__ import annotations

import json

import pytest

from anyplan.cli.main import main


@pytest.mark.parametrize(("argv", "words"), [
    (["--perception", "radar"], "--perception: unknown perception mode 'radar'"),
    (["--perception", "tracked", "--sensor-noise", "-0.1"], "--sensor-noise: sensor noise must be >= 0"),
    (["--sensor-rate", "0"], "--sensor-rate: sensor rate must be > 0"),
    (["--sensor-association", "guess"], "--sensor-association: unknown association 'guess'"),
    (["--detection-prob", "0"], "--detection-prob: detection probability must be > 0"),
    (["--clutter-rate", "1"], "--clutter-rate: false detections need association: anonymous"),
    (["--sensor-association", "anonymous", "--clutter-rate", "-1"],
     "--clutter-rate: clutter rate must be >= 0"),
    (["--sensor-occlusion", "people"], "--sensor-occlusion: unknown occlusion 'people'"),
])
@pytest.mark.parametrize("command", ["run", "bench"])
def test_bad_perception_options_exit_2_with_one_line(tmp_path, capsys, argv, words, command):
    base = (["run", "paper-1", "--planner", "straight", "--out", str(tmp_path / "r")]
            if command == "run" else
            ["bench", "--suite", "paper-1", "--runs", "1", "--jobs", "1", "--db",
             str(tmp_path / "x.db"), "--no-progress"])
    assert main(base + argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


def test_run_records_the_perception_mode(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "paper-1", "--planner", "straight", "--out", str(out), "--no-plot",
                 "--perception", "tracked", "--sensor-noise", "0.2", "--sensor-rate", "5",
                 "--time-limit", "3"]) == 1  # exit code 1: a 3 s run times out; result.json is written
    p = json.loads((out / "result.json").read_text())["extra"]["perception"]
    assert p["mode"] == "tracked" and p["noise_m"] == 0.2 and p["rate_hz"] == 5.0
    assert p["frames"] == 15 and p["noise_seed"][0] == 0


def test_run_records_anonymous_detections_and_clutter(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "paper-1", "--planner", "straight", "--out", str(out), "--no-plot",
                 "--perception", "tracked", "--sensor-association", "anonymous",
                 "--detection-prob", "0.8", "--clutter-rate", "0.5", "--time-limit", "3"]) == 1
    extra = json.loads((out / "result.json").read_text())["extra"]
    p = extra["perception"]
    assert (p["association"], p["detection_prob"], p["clutter_rate"]) == ("anonymous", 0.8, 0.5)
    assert p["clutter_seed"][0] == 0 and p["false_detections"] > 0 and p["missed"] > 0
    assert extra["tracking"]["started"] >= 1


@pytest.mark.parametrize(("item", "words"), [
    ("q_c=0.01", "--tracker: unknown tracker setting 'q_c'; did you mean 'q_cv'?"),
    ("q_cv=-1", "--tracker: TrackerConfig.q_cv: must be in (0, 10000]"),
    ("sigma_m=1e300", "--tracker: TrackerConfig.sigma_m: must be in [0, 10] m"),
    ("turn_confidence=2", "--tracker: UncertaintyModel.turn_confidence: must be in [0, 1]"),
    ("k_sigma=two", "--tracker: k_sigma: expected a number, got 'two'"),
    ("k_sigma", "--tracker: expected KEY=VALUE, got 'k_sigma'"),
])
def test_bad_tracker_settings_exit_2_with_one_line(tmp_path, capsys, item, words):
    argv = ["run", "paper-1", "--planner", "straight", "--out", str(tmp_path / "r"),
            "--perception", "tracked", "--tracker", item]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err
    assert not (tmp_path / "r").exists()  # refused before any work


def test_run_records_the_tracker_settings_it_used(tmp_path):
    out = tmp_path / "r"
    assert main(["run", "paper-1", "--planner", "straight", "--out", str(out), "--no-plot",
                 "--perception", "tracked", "--sensor-noise", "0.2", "--time-limit", "1",
                 "--tracker", "q_cv=0.01", "--tracker", "k_sigma=1.5"]) == 1
    t = json.loads((out / "result.json").read_text())["extra"]["perception"]["tracker"]
    # the given ones, the sensor's noise as the tracker's, the defaults elsewhere
    assert t["q_cv"] == 0.01 and t["k_sigma"] == 1.5 and t["sigma_m"] == 0.2
    assert t["q_ct"] == 0.05 and t["cap_m"] == 1.0
    # and the settings given, as anyplan bench records them
    given = json.loads((out / "result.json").read_text())["extra"]["settings"]
    assert given == "tracker.k_sigma = 1.5;tracker.q_cv = 0.01;"


@pytest.mark.parametrize("perception", [[], ["--perception", "twist"]])
@pytest.mark.parametrize("command", ["run", "bench"])
def test_tracker_settings_without_tracked_perception_exit_2(tmp_path, capsys, perception, command):
    # paper-1 has no sensing block (oracle): nothing would read the settings
    base = (["run", "paper-1", "--planner", "straight", "--out", str(tmp_path / "r")]
            if command == "run" else
            ["bench", "--suite", "paper-1", "--planners", "straight", "--runs", "1", "--jobs",
             "1", "--db", str(tmp_path / "x.db"), "--no-progress"])
    assert main([*base, "--tracker", "q_cv=0.01", *perception]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "tracker settings apply to tracked perception only" in err
    assert not (tmp_path / "x.db").exists() and not (tmp_path / "r").exists()


def test_bench_keeps_runs_with_other_tracker_settings_apart(tmp_path, capsys):
    db = tmp_path / "x.db"

    def bench(*tracker: str) -> int:
        argv = ["bench", "--suite", "paper-1", "--planners", "straight", "--runs", "1", "--jobs",
                "1", "--db", str(db), "--no-progress", "--perception", "tracked",
                "--time-limit", "1"]
        return main(argv + [a for t in tracker for a in ("--tracker", t)])

    assert bench("q_cv=0.01", "k_sigma=1.5") == 0
    assert bench("k_sigma=1.5", "q_cv=0.01") == 2  # the same settings: stored already
    assert "already holds 1 of these 1 runs" in capsys.readouterr().err
    assert bench("q_cv=0.02") == 0  # other settings: another planner row, its own run
    from anyplan.experiments.db import ResultsDB

    with ResultsDB(db, readonly=True) as d:
        runs = sorted(d.runs(), key=lambda r: r["settings"])
        assert [r["settings"] for r in runs] == ["tracker.k_sigma = 1.5;tracker.q_cv = 0.01;",
                                                 "tracker.q_cv = 0.02;"]
        used = [d.result(r["id"])["extra"]["perception"]["tracker"] for r in runs]
    assert [(u["q_cv"], u["k_sigma"]) for u in used] == [(0.01, 1.5), (0.02, 2.0)]
