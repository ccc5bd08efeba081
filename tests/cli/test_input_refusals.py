"""Bad input of ``run``, ``plan`` and ``bench`` refused before any work, with exit code 2 and one
line naming the flag: ``--config`` values of the wrong type, empty arguments, sensor and other
options that nothing reads, and a bench too large for its stated limit."""

from __future__ import annotations

import pytest
import yaml

from anyplan.cli.main import main
from anyplan.experiments.db import ResultsDB
from anyplan.experiments.suites import SuiteError, resolve_suite
from tests.conftest import small_scenario_dict


@pytest.fixture
def scenario(tmp_path):
    """An oracle scenario file (no sensing block)."""
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(small_scenario_dict(name="s")))
    return f


def _code(argv: list[str]) -> int:
    """The exit code of ``anyplan ARGV`` (argparse's refusals exit through SystemExit)."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code or 0)


def _one_line(capsys, *words: str) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


def _bench(scenario, tmp_path, *argv: str) -> list[str]:
    return ["bench", "--suite", str(scenario), "--planners", "straight", "--runs", "1", "--jobs",
            "1", "--time-limit", "1", "--no-progress", "--db", str(tmp_path / "b.db"), *argv]


@pytest.mark.parametrize(("config", "words"), [
    ('{"heading_gain": "x"}', "--config straight: heading_gain='x': planner 'straight' expects float"),
    ('{"heading_gain": [1, 2]}', "--config straight: heading_gain=[1, 2]: planner 'straight' expects"),
    ('{"align_tolerance": true}', "--config straight: align_tolerance=True"),
    ('{"nope": 1}', "--config straight: unknown setting of planner 'straight' 'nope'"),
])
def test_bench_config_values_are_checked_as_set_checks_them(tmp_path, scenario, capsys, config, words):
    assert main(_bench(scenario, tmp_path, "--config", f"straight={config}")) == 2
    _one_line(capsys, words)
    assert not (tmp_path / "b.db").exists()  # refused before any run


def test_a_bad_bench_config_is_refused_before_the_suite_is_read(tmp_path, capsys):
    argv = _bench(tmp_path / "missing.yaml", tmp_path, "--config", 'straight={"nope": 1}')
    assert main(argv) == 2
    _one_line(capsys, "--config straight: unknown setting")


def test_a_good_bench_config_is_recorded_as_given_or_converted_as_set_converts(tmp_path, scenario,
                                                                               capsys):
    assert main(_bench(scenario, tmp_path, "--config", 'straight={"align_tolerance": 3}')) == 0
    capsys.readouterr()
    assert main(_bench(scenario, tmp_path, "--config", 'straight={"heading_gain": "1.5"}')) == 0
    assert "1 runs in" in capsys.readouterr().out  # the bench's tables find its converted run
    with ResultsDB(tmp_path / "b.db", readonly=True) as db:
        runs = db.runs()
    # an int stays an int (the settings string of earlier runs), the string became a number
    assert [r["settings"] for r in runs] == ["align_tolerance = 3;", "heading_gain = 1.5;"]
    assert [r["outcome"] for r in runs] != ["error", "error"] and all(r["error"] is None for r in runs)


_HUGE = "9" * 400  # an int beyond the float range (float() raises OverflowError)


_UNCONVERTIBLE = [
    (f"heading_gain={_HUGE}", "--set heading_gain=999"),
    (f"heading_gain=-{_HUGE}", "--set heading_gain=-999"),
    ("heading_gain=" + "9" * 5000, "--set heading_gain: cannot read '999"),  # not even an int
    ("heading_gain=2020-13-45", "--set heading_gain: cannot read '2020-13-45' as a YAML value"),
]


@pytest.mark.parametrize(("command", "item", "words"), [
    *(("run", *case) for case in _UNCONVERTIBLE), *(("bench", *case) for case in _UNCONVERTIBLE),
    ("bench", f"straight:heading_gain={_HUGE}", "--set heading_gain=999"),  # PLANNER:KEY=VALUE
])
def test_a_set_value_python_cannot_convert_is_refused_by_name(tmp_path, scenario, capsys, command,
                                                              item, words):
    out = tmp_path / "r"
    argv = (["run", str(scenario), "--planner", "straight", "--out", str(out), "--no-plot"]
            if command == "run" else _bench(scenario, tmp_path))
    assert main([*argv, "--set", item]) == 2  # a traceback before (OverflowError, ValueError)
    err = _one_line(capsys, words)
    assert "9" * 400 not in err and ("number too large" in err or "cannot read" in err)
    assert not out.exists() and not (tmp_path / "b.db").exists()


@pytest.mark.parametrize(("planner", "key"), [("seq-bitstar", "batches_per_plan"),
                                            ("dovs", "dw_samples")])
def test_an_int_setting_beyond_the_float_range_is_refused_by_name(tmp_path, scenario, capsys, planner,
                                                                  key):
    # an int field of a settings dataclass (anyplan.config.validate): an OverflowError before
    out = tmp_path / "r"
    argv = ["run", str(scenario), "--planner", planner, "--out", str(out), "--no-plot"]
    assert main([*argv, "--set", f"{key}={_HUGE}"]) == 2
    _one_line(capsys, f"--set: planner '{planner}' rejects its settings: ", f"{key}: must be a finite "
              "number, got 999")
    assert not out.exists()


def test_a_bench_config_int_beyond_the_float_range_is_refused_by_name(tmp_path, scenario, capsys):
    assert main(_bench(scenario, tmp_path, "--config", f'straight={{"heading_gain": {_HUGE}}}')) == 2
    _one_line(capsys, "--config straight: heading_gain=999", "number too large")
    assert not (tmp_path / "b.db").exists()


@pytest.mark.parametrize(("argv", "flag"), [
    (["--planners", ""], "--planners"),
    (["--planners", " "], "--planners"),
    (["--suite", ""], "--suite"),
    (["--out", ""], "--out"),
    (["--scheduler", ""], "--scheduler"),
    (["--db", ""], "--db"),
])
def test_bench_refuses_empty_arguments(tmp_path, scenario, capsys, monkeypatch, argv, flag):
    monkeypatch.chdir(tmp_path)  # holds a scenario file: "" must not read this folder as the suite
    assert _code(_bench(scenario, tmp_path, *argv)) == 2
    _one_line(capsys, f"argument {flag}: empty")
    assert not (tmp_path / "b.db").exists()


def test_an_empty_suite_is_refused_by_the_library(tmp_path, scenario, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SuiteError, match="suite: empty"):
        resolve_suite("")


@pytest.mark.parametrize(("argv", "flag"), [
    (["run", "", "--planner", "straight"], "scenario"),
    (["plan", ""], "scenario"),
    (["run", "S", "--planner", "straight", "--out", ""], "--out"),
    (["run", "S", "--planner", "straight", "--animate", ""], "--animate"),
    (["run", "S", "--planner", "straight", "--mcap", ""], "--mcap"),
    (["plan", "S", "--json", ""], "--json"),
    (["plan", "S", "--plot", ""], "--plot"),
])
def test_run_and_plan_refuse_empty_arguments(tmp_path, scenario, capsys, monkeypatch, argv, flag):
    monkeypatch.chdir(tmp_path)
    argv = [str(scenario) if a == "S" else a for a in argv]
    assert _code(argv) == 2
    _one_line(capsys, f"argument {flag}: empty")
    assert not (tmp_path / "runs").exists()  # no run written to the default folder


_SENSOR_FLAGS = [["--sensor-noise", "0.3"], ["--sensor-rate", "5"], ["--sensor-association", "anonymous"],
                 ["--detection-prob", "0.9"], ["--sensor-association", "anonymous", "--clutter-rate", "3"],
                 ["--sensor-occlusion", "all"]]


@pytest.mark.parametrize("sensor", _SENSOR_FLAGS)
@pytest.mark.parametrize("perception", [[], ["--perception", "twist"], ["--perception", "oracle"]])
@pytest.mark.parametrize("command", ["run", "bench"])
def test_sensor_options_without_tracked_perception_are_refused(tmp_path, scenario, capsys, command,
                                                               perception, sensor):
    out = tmp_path / "r"
    argv = (["run", str(scenario), "--planner", "straight", "--out", str(out), "--time-limit", "1"]
            if command == "run" else _bench(scenario, tmp_path))
    assert main([*argv, *perception, *sensor]) == 2
    mode = perception[1] if perception else "oracle"
    _one_line(capsys, f"{command}: {sensor[0]}: s's perception is '{mode}'",
              "sensor settings apply to tracked perception only")
    assert not out.exists() and not (tmp_path / "b.db").exists()


def test_a_tracked_scenario_run_as_oracle_takes_no_sensor_options(tmp_path, capsys):
    f = tmp_path / "t.yaml"
    f.write_text(yaml.safe_dump(small_scenario_dict(name="t", sensing={"mode": "tracked", "noise_m": 0.2})))
    argv = ["run", str(f), "--planner", "straight", "--no-plot", "--time-limit", "1"]
    assert main([*argv, "--out", str(tmp_path / "a"), "--perception", "oracle"]) == 1  # a time-out
    assert main([*argv, "--out", str(tmp_path / "b"), "--sensor-noise", "0.1"]) == 1  # tracked
    assert main([*argv, "--out", str(tmp_path / "c"), "--perception", "oracle",
                 "--sensor-noise", "0.1"]) == 2
    _one_line(capsys, "run: --sensor-noise: t's perception is 'oracle'")


@pytest.mark.parametrize(("extra", "words"), [
    (["--speed", "8"], "run: --speed applies to --animate only"),
    (["--no-plot", "--speed", "8"], "run: --speed applies to --animate only"),
    (["--no-plot", "--format", "svg"], "run: --format applies to the picture, which --no-plot turns off"),
    (["--no-plot", "--format", "png"], "run: --format applies to the picture, which --no-plot turns off"),
])
def test_run_options_that_nothing_reads_are_refused(tmp_path, scenario, capsys, extra, words):
    out = tmp_path / "r"
    argv = ["run", str(scenario), "--planner", "straight", "--out", str(out), "--time-limit", "1"]
    assert main([*argv, *extra]) == 2
    _one_line(capsys, words)
    assert not out.exists()  # refused before the run


def test_run_speed_and_format_where_they_apply(tmp_path, scenario, capsys):
    argv = ["run", str(scenario), "--planner", "straight", "--time-limit", "1"]
    assert main([*argv, "--out", str(tmp_path / "a"), "--format", "svg"]) == 1  # a time-out
    assert (tmp_path / "a" / "run.svg").exists() and not (tmp_path / "a" / "run.png").exists()
    assert main([*argv, "--out", str(tmp_path / "b")]) == 1  # the default: a PNG
    assert (tmp_path / "b" / "run.png").exists()
    assert main([*argv, "--out", str(tmp_path / "c"), "--no-plot", "--animate", str(tmp_path / "c.gif"),
                 "--speed", "8"]) == 1
    assert (tmp_path / "c.gif").exists() and not list((tmp_path / "c").glob("run.*"))


@pytest.mark.parametrize(("extra", "words"), [
    (["--planner", "visgraph", "--time", "0.5"],
     "plan: --time applies to --planner bitstar only (visgraph is exact, not anytime)"),
    (["--planner", "visgraph", "--time", "1"], "plan: --time applies to --planner bitstar only"),
    (["--format", "svg"], "plan: --format applies to --plot only"),
    (["--planner", "visgraph", "--format", "png"], "plan: --format applies to --plot only"),
])
def test_plan_options_that_nothing_reads_are_refused(tmp_path, scenario, capsys, extra, words):
    out = tmp_path / "p.json"
    assert main(["plan", str(scenario), "--json", str(out), *extra]) == 2
    _one_line(capsys, words)
    assert not out.exists()  # refused before planning


@pytest.mark.parametrize(("planner", "extra"), [("bitstar", ["--time", "0.05"]), ("bitstar", []),
                                                ("visgraph", [])])
def test_plan_time_and_format_where_they_apply(tmp_path, scenario, planner, extra):
    import json

    out, pic = tmp_path / "p.json", tmp_path / "p"
    argv = ["plan", str(scenario), "--planner", planner, "--json", str(out), "--plot", str(pic),
            "--format", "svg"]
    assert main([*argv, *extra]) == 0
    assert (tmp_path / "p.svg").exists()
    if planner == "bitstar":  # the budget given, else the default
        assert json.loads(out.read_text())["time_budget_s"] == (float(extra[1]) if extra else 1.0)


@pytest.mark.parametrize("suite", ["S", "paper", "paper-1,paper-2", "folder"])
@pytest.mark.parametrize("flag", ["--random-count", "--random-seed"])
def test_random_options_with_a_suite_that_is_not_generated_are_refused(tmp_path, scenario, capsys, suite,
                                                                       flag):
    (tmp_path / "folder").mkdir()
    (tmp_path / "folder" / "s.yaml").write_text(scenario.read_text())
    suite = {"S": str(scenario), "folder": str(tmp_path / "folder")}.get(suite, suite)
    argv = ["bench", "--suite", suite, "--planners", "straight", "--runs", "1", "--jobs", "1",
            "--time-limit", "1", "--no-progress", "--db", str(tmp_path / "b.db"), flag, "2"]
    assert main(argv) == 2
    _one_line(capsys, f"bench: {flag} applies to the generated suites only (--suite random or gaps)")
    assert not (tmp_path / "b.db").exists()


@pytest.mark.parametrize("suite", ["S", "paper"])
def test_bench_planning_random_count_with_a_suite_that_is_not_generated_is_refused(tmp_path, scenario, capsys,
                                                                                     suite):
    db = tmp_path / "b.db"
    argv = ["bench-planning", "--suite", str(scenario) if suite == "S" else suite, "--runs", "1",
            "--budget", "0.01", "--ompl", "none", "--no-progress", "--db", str(db), "--random-count", "2"]
    assert main(argv) == 2
    _one_line(capsys, "bench-planning: --random-count applies to the generated suites only "
                      "(--suite planning, random or gaps)")
    assert not db.exists()


class _Built(Exception):
    """What a generated suite was asked for."""


@pytest.mark.parametrize("suite", ["random", "gaps"])
@pytest.mark.parametrize(("extra", "asked"), [
    ([], (0, 1)), (["--random-count", "3", "--random-seed", "5"], (5, 3)), (["--seed", "7"], (7, 1))])
def test_random_options_reach_a_generated_suite(tmp_path, monkeypatch, suite, extra, asked):
    import anyplan.experiments.gaps as gaps
    import anyplan.experiments.suites as suites

    def random_suite(seed, per_count):
        raise _Built(seed, per_count)

    def gap_suite(seed, n):
        raise _Built(seed, n // 20)

    monkeypatch.setattr(suites, "random_suite", random_suite)
    monkeypatch.setattr(gaps, "gap_suite", gap_suite)
    argv = ["bench", "--suite", suite, "--planners", "straight", "--runs", "1", "--jobs", "1",
            "--no-progress", "--db", str(tmp_path / "b.db"), *extra]
    with pytest.raises(_Built) as built:
        main(argv)
    assert built.value.args == asked


@pytest.mark.parametrize(("extra", "asked"), [
    ([], (0, 4)), (["--random-count", "3", "--seed", "2"], (2, 12))])
def test_bench_planning_random_count_reaches_the_planning_suite(tmp_path, monkeypatch, extra, asked):
    import anyplan.experiments.planning_problems as problems

    def planning_suite(seed, count):
        raise _Built(seed, count)

    monkeypatch.setattr(problems, "planning_suite", planning_suite)
    with pytest.raises(_Built) as built:
        main(["bench-planning", "--runs", "1", "--ompl", "none", "--no-progress",
              "--db", str(tmp_path / "b.db"), *extra])
    assert built.value.args == asked


@pytest.mark.parametrize(("suite", "count", "runs", "planners", "scenarios"), [
    ("random", 1000, 1000, "straight,bitstar", 6000),
    ("gaps", 1000, 11, "straight", 20000),
])
def test_the_bench_limit_is_checked_before_a_named_suite_is_built(tmp_path, capsys, monkeypatch, suite,
                                                                   count, runs, planners, scenarios):
    import anyplan.experiments.gaps as gaps
    import anyplan.experiments.suites as suites

    def never(*args, **kwargs):
        raise AssertionError("the suite was built")

    monkeypatch.setattr(suites, "random_suite", never)
    monkeypatch.setattr(gaps, "gap_suite", never)
    n = len(planners.split(","))
    argv = ["bench", "--suite", suite, "--random-count", str(count), "--runs", str(runs),
            "--planners", planners, "--jobs", "1", "--no-progress", "--db", str(tmp_path / "b.db")]
    assert main(argv) == 2
    _one_line(capsys, f"bench: {runs} runs x {scenarios} scenarios x {n} planners = "
                      f"{runs * scenarios * n} runs, more than the limit of 200000")
    from anyplan.experiments.suites import suite_size

    assert suite_size(suite, count) == scenarios


def test_suite_sizes_are_the_sizes_of_the_suites():
    from anyplan.experiments.suites import suite_size

    for name in ("paper", "random"):
        assert suite_size(name, 2) == len(resolve_suite(name, per_count=2))
    assert suite_size("gaps", 3) == 60 and suite_size("some-folder", 3) is None


def test_bench_help_tells_the_gaps_suite_and_what_random_count_scales(capsys):
    with pytest.raises(SystemExit):
        main(["bench", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "'gaps'" in text and "--suite gaps: 20 x K gap worlds" in text
    assert "--suite random or gaps: generator seed" in text
