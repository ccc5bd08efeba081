"""Plugins: the example package of examples/plugin, installed, works from the command line like a
built-in planner (run, bench with worker processes, report, --set); a broken plugin is one line."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

from anyplan.agents import plugins
from anyplan.registry import LoadError, Registry

ROOT = Path(__file__).resolve().parents[2]
PLUGIN = ROOT / "examples" / "plugin"


def _pip_install_target(target: Path) -> None:
    base = [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target), str(PLUGIN)]
    # Without build isolation where the build back-end is at hand (fast, offline); else pip's default.
    for cmd in (base[:4] + ["--no-build-isolation"] + base[4:], base):
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode == 0:
            return
    raise AssertionError(f"pip could not install {PLUGIN}:\n{proc.stderr[-2000:]}")


@pytest.fixture(scope="module")
def plugin_env(tmp_path_factory):
    """An environment in which the example plugin is installed (and a broken plugin declared)."""
    target = tmp_path_factory.mktemp("site")
    _pip_install_target(target)
    assert (target / "anyplan_patient" / "agent.py").is_file()
    # A second, broken plugin: its entry point names a module that does not exist.
    dist = target / "anyplan_broken-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: anyplan-broken\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[anyplan.agents]\nbroken = anyplan_broken_nowhere:Agent\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(target), str(ROOT / "src")])
    env["MPLBACKEND"] = "Agg"
    return env


def _anyplan(env, *argv, cwd):
    return subprocess.run([sys.executable, "-m", "anyplan", *argv], env=env, cwd=cwd,
                          capture_output=True, text=True, timeout=600)


def test_installed_plugin_is_listed_and_runs(plugin_env, tmp_path):
    p = _anyplan(plugin_env, "planners", cwd=tmp_path)
    assert "patient-straight   plugin from anyplan-patient 0.1.0" in p.stdout
    assert "seq-bitstar" in p.stdout  # the built-ins are still there
    assert p.returncode == 1 and "broken" in p.stdout and "BROKEN" in p.stdout

    p = _anyplan(plugin_env, "run", "paper-1", "--planner", "patient-straight", "--set", "gap_m=0.4",
                 "--out", "r", "--no-plot", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    res = json.loads((tmp_path / "r" / "result.json").read_text())
    assert res["planner"] == "patient-straight" and res["reached_goal"] and not res["collision"]
    assert res["extra"]["waiting_steps"] > 0  # it did wait for the obstacle: the plugin's own logic ran


def test_installed_plugin_benches_in_worker_processes_and_reports(plugin_env, tmp_path):
    p = _anyplan(plugin_env, "bench", "--suite", "paper-1", "--planners", "patient-straight,straight",
                 "--runs", "2", "--jobs", "2", "--db", "b.db", "--no-progress",
                 "--set", "patient-straight:horizon_s=3", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    con = sqlite3.connect(tmp_path / "b.db")
    rows = con.execute("SELECT p.name, p.settings, r.outcome FROM runs r JOIN plannerConfigs p "
                       "ON r.plannerid = p.id").fetchall()
    con.close()
    mine = [r for r in rows if r[0] == "patient-straight"]
    assert len(mine) == 2 and all(r[2] == "reached" for r in mine)
    assert all("horizon_s = 3" in r[1] for r in mine)  # the --set value is recorded
    assert len([r for r in rows if r[0] == "straight"]) == 2
    p = _anyplan(plugin_env, "report", "b.db", "--out", "rep", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "patient-straight" in (tmp_path / "rep" / "report.html").read_text()


def test_broken_plugin_is_one_line_naming_it_and_its_package(plugin_env, tmp_path):
    p = _anyplan(plugin_env, "run", "paper-1", "--planner", "broken", cwd=tmp_path)
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and "Traceback" not in p.stderr
    assert "planner 'broken'" in p.stderr and "anyplan-broken" in p.stderr
    assert "ModuleNotFoundError" in p.stderr


def test_discovery_skips_taken_names_and_bad_values(monkeypatch, caplog):
    eps = [EntryPoint("straight", "somewhere:Agent", plugins.ENTRY_POINT_GROUP),
           EntryPoint("mine", "no_colon_here", plugins.ENTRY_POINT_GROUP),
           EntryPoint("other", "json:JSONDecoder", plugins.ENTRY_POINT_GROUP)]
    monkeypatch.setattr(plugins, "_entry_points", lambda: eps)
    reg: Registry = Registry("planner")
    reg.register("straight", "anyplan.agents.straight:StraightAgent")
    reg.set_discovery(plugins.discover_plugins)
    assert reg.names() == ["straight", "other"]
    assert reg.origin("straight") == "built-in" and reg.origin("other") == "plugin"
    assert "name is taken" in caplog.text and "expected 'module:Class'" in caplog.text
    import json as json_mod

    assert reg.get("other") is json_mod.JSONDecoder
    reg.register("gone", "json:NoSuchThing", origin="plugin from x 1")
    with pytest.raises(LoadError,
                       match=r"planner 'gone' \(plugin from x 1: json:NoSuchThing\).*AttributeError"):
        reg.get("gone")


def test_a_plugin_claiming_a_built_in_name_is_warned_about_on_the_command_line(tmp_path):
    # the warning is logged while the parser is built (plugin discovery), before the options
    # are read: the command line must have set up logging by then, or it is lost
    dist = tmp_path / "site" / "shadow_pkg-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: shadow-pkg\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[anyplan.agents]\nstraight = shadow_nowhere:Agent\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path / "site"), str(ROOT / "src")]))
    p = _anyplan(env, "planners", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "shadow-pkg" in p.stderr and "straight" in p.stderr and "the name is taken" in p.stderr
