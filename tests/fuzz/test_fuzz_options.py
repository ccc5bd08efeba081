"""Fuzzing the command-line options: a value outside its stated range (docs/scenarios.md,
"Limits") is refused with exit code 2 and one bounded line before any work; a value inside it
gives a sound result. Output paths that cannot be written are refused before the simulation.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzz.harness import refusal_problem, run_cli, sound_problem

TINY = {"name": "tiny", "time_limit": 3.0, "arena": {"width": 4.0, "height": 3.0},
        "robot": {"start": [0.5, 1.5, 0.0], "goal": [1.5, 1.5], "radius": 0.2, "v_max": 1.0,
                  "omega_max": 1.0, "a_max": 2.0, "alpha_max": 2.0},
        "static_obstacles": [{"type": "circle", "center": [3.0, 0.6], "radius": 0.3}]}
FUZZ = settings(max_examples=25, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def _float(text: str) -> float | None:
    try:
        x = float(text)
    except (ValueError, OverflowError):
        return None
    return x if math.isfinite(x) else None


def _int(text: str) -> int | None:
    try:
        return int(text, 10)
    except ValueError:
        return None


# Independent statements of the documented ranges (not the implementation's code).
def seed_ok(v: str) -> bool:
    n = _int(v)
    return n is not None and 0 <= n <= 2**63 - 1


def dt_ok(v: str) -> bool:
    x = _float(v)
    return x is not None and 0.001 <= x <= 0.05


def time_limit_ok(v: str) -> bool:
    x = _float(v)
    return x is not None and 0.0 < x <= 3600.0


NUMBERISH = st.one_of(
    st.integers(-2**70, 2**70).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["inf", "-inf", "nan", "", " ", "1e-9", "1e308", "-1", "0", "0x10", "1_0", "\u0663",
                     "1\n2", "x" * 5000, "0.05", "0.001", "3600", "3600.0001", "9223372036854775807",
                     "9223372036854775808", "-0"]),
    st.text(max_size=12),
)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    p = tmp_path_factory.mktemp("opt") / "tiny.yaml"
    p.write_text(yaml.safe_dump(TINY))
    return p


def _check(argv: list[str], ok: bool, out: Path | None, time_limit: float | None = None) -> None:
    o = run_cli(argv)
    if ok:
        assert out is not None
        problem = sound_problem(o, out / "result.json", time_limit)
    else:
        problem = refusal_problem(o)
    assert problem is None, f"{argv[:8]} (valid: {ok}): {problem}"


@FUZZ
@given(value=NUMBERISH, option=st.sampled_from(["--seed", "--dt", "--time-limit"]))
def test_run_numeric_options(tiny, value, option):
    ok = {"--seed": seed_ok, "--dt": dt_ok, "--time-limit": time_limit_ok}[option](value)
    if ok and option == "--time-limit":
        value = str(min(float(value), 20.0))  # keep valid runs short
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "o"
        limit = float(value) if ok and option == "--time-limit" else TINY["time_limit"]
        _check(["run", str(tiny), "--planner", "straight", "--no-plot", "--out", str(out),
                f"{option}={value}"], ok, out, limit)


@FUZZ
@given(value=NUMBERISH, option=st.sampled_from(["--seed", "--dt", "--time-limit", "--runs"]))
def test_bench_numeric_options(tiny, value, option):
    if option == "--runs":
        n = _int(value)
        ok = n is not None and 1 <= n <= 10_000
        if ok and n > 2:
            value = "2"
    else:
        ok = {"--seed": seed_ok, "--dt": dt_ok, "--time-limit": time_limit_ok}[option](value)
        if ok and option == "--time-limit":
            value = str(min(float(value), 20.0))
    with tempfile.TemporaryDirectory() as d:
        db = Path(d) / "r.db"
        argv = ["bench", "--suite", str(tiny), "--planners", "straight", "--jobs", "1",
                "--no-progress", "--db", str(db), f"{option}={value}"]
        if option != "--runs":
            argv += ["--runs", "1"]
        o = run_cli(argv)
        if ok:
            assert o.rc == 0 and o.exc is None and not o.hang, (argv, o.err[-300:], o.exc)
        else:
            assert refusal_problem(o) is None, (argv, refusal_problem(o))
            assert not db.exists(), "a refused bench created its database"


@FUZZ
@given(value=NUMBERISH)
def test_plan_seed_and_time(tiny, value):
    x = _float(value)
    o = run_cli(["plan", str(tiny), "--planner", "bitstar", f"--seed={value}", "--time", "0.02"])
    if seed_ok(value):
        assert o.rc in (0, 1) and o.exc is None, o.exc or o.err
    else:
        assert refusal_problem(o) is None
    o = run_cli(["plan", str(tiny), "--planner", "bitstar", f"--time={value}"])
    if x is not None and 0.0 < x <= 0.05:
        assert o.rc in (0, 1) and o.exc is None, o.exc or o.err
    elif x is None or not 0.0 < x <= 3600.0:
        assert refusal_problem(o) is None


def test_absurd_bench_sizes_are_refused_at_once(tiny, tmp_path):
    for extra in (["--runs", "1000000000"], ["--jobs", "100000"], ["--runs", "0"],
                  ["--random-count", "99999999"]):
        o = run_cli(["bench", "--suite", str(tiny), "--planners", "straight", "--no-progress",
                     "--db", str(tmp_path / "x.db"), *extra], timeout_s=20)
        assert refusal_problem(o) is None, (extra, refusal_problem(o))
        assert not (tmp_path / "x.db").exists()


# ------------------------------------------------------------------------------ output paths
def _targets(tmp: Path) -> dict[str, Path]:
    """Unwritable targets."""
    (tmp / "folder.json").mkdir()
    (tmp / "folder.png").mkdir()
    (tmp / "folder.gif").mkdir()
    (tmp / "plain").write_text("x")
    return {
        "a folder": tmp / "folder.json",
        "a folder (png)": tmp / "folder.png",
        "under a file": tmp / "plain" / "x.png",
        "name too long": tmp / ("n" * 300 + ".png"),
        "in /proc": Path("/proc/anyplan-x.png"),
    }


@pytest.mark.parametrize("command", ["plan-json", "plan-plot", "run-animate", "dovs-out", "run-out"])
def test_unwritable_outputs_are_refused_before_work(tmp_path, tiny, command):
    for what, target in _targets(tmp_path).items():
        t = str(target)
        if command == "plan-json":
            argv = ["plan", str(tiny), "--json", t.replace(".png", ".json")]
        elif command == "plan-plot":
            argv = ["plan", str(tiny), "--plot", t.replace(".json", ".png")]
        elif command == "run-animate":
            argv = ["run", str(tiny), "--planner", "straight", "--no-plot", "--out", str(tmp_path / "o"),
                    "--animate", t.replace(".png", ".gif").replace(".json", ".gif")]
        elif command == "dovs-out":
            argv = ["dovs-plot", str(tiny), "--time", "1", "--out", t.replace(".json", ".png")]
        else:
            argv = ["run", str(tiny), "--planner", "straight", "--out",
                    t.replace(".png", "").replace(".json", "")]
        o = run_cli(argv, timeout_s=30)
        if command == "run-out" and what in ("a folder", "a folder (png)"):
            continue  # an existing folder is a fine --out
        assert refusal_problem(o) is None, (command, what, refusal_problem(o))
        opt = {"plan-json": "--json", "plan-plot": "--plot", "run-animate": "--animate",
               "dovs-out": "--out", "run-out": "--out"}[command]
        assert opt in o.err, (command, what, o.err)  # the line names the option
        assert "simulat" not in o.out  # refused before any work: nothing printed


def test_unknown_plot_extension_is_refused(tmp_path, tiny):
    o = run_cli(["plan", str(tiny), "--plot", str(tmp_path / "p.foo")])
    assert refusal_problem(o) is None and "unknown file type '.foo'" in o.err


@settings(max_examples=25, deadline=None, database=None)
@given(name=st.one_of(st.sampled_from(["../../escaped", "..", ".", "/abs/path", "a/../../b", "~root",
                                       "x\ny", "\\..\\..\\w"]), st.text(min_size=1, max_size=30)))
def test_default_output_stays_under_runs(name):
    doc = dict(TINY, name=name)
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "s.yaml"
        p.write_text(yaml.safe_dump(doc))
        import os

        cwd = os.getcwd()
        os.chdir(d)
        try:
            o = run_cli(["run", str(p), "--planner", "straight", "--no-plot"])
        finally:
            os.chdir(cwd)
        if o.rc == 2:  # a refused name (e.g. too long) is fine
            assert refusal_problem(o) is None
            return
        assert o.rc in (0, 1), o.exc or o.err
        written = list(Path(d).rglob("result.json"))
        assert len(written) == 1
        rel = written[0].resolve().relative_to(Path(d).resolve())
        assert rel.parts[0] == "runs" and len(rel.parts) == 3, rel
        assert json.loads(written[0].read_text())["scenario"] == name
