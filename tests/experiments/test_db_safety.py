"""The results database is safe: files that are not anyplan databases are refused and left
byte-for-byte unchanged, ``report`` changes nothing, one writer at a time, and the schema itself
makes a run impossible to store twice (also with two benches in parallel)."""

from __future__ import annotations

import hashlib
import os
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from anyplan.experiments.db import DatabaseFileError, ResultsDB, run_row
from tests.fuzz.harness import refusal_problem, run_cli

TINY = {"name": "tiny", "time_limit": 3.0, "arena": {"width": 4.0, "height": 3.0},
        "robot": {"start": [0.5, 1.5, 0.0], "goal": [3.5, 1.5], "radius": 0.2, "v_max": 1.0,
                  "omega_max": 1.0, "a_max": 2.0, "alpha_max": 2.0}}
ROOT = Path(__file__).resolve().parents[2]


def _digest(p: Path) -> tuple[str, int]:
    return hashlib.sha256(p.read_bytes()).hexdigest(), p.stat().st_mtime_ns


@pytest.fixture
def tiny(tmp_path):
    p = tmp_path / "tiny.yaml"
    p.write_text(yaml.safe_dump(TINY))
    return p


def _bench(tiny: Path, db: Path, *extra: str) -> list[str]:
    return ["bench", "--suite", str(tiny), "--planners", "straight", "--runs", "2", "--jobs", "1",
            "--no-progress", "--db", str(db), *extra]


@pytest.fixture
def good_db(tmp_path, tiny):
    db = tmp_path / "good.db"
    assert run_cli(_bench(tiny, db)).rc == 0
    return db


def _foreign(path: Path) -> Path:
    c = sqlite3.connect(path)
    c.execute("CREATE TABLE runs (id INTEGER PRIMARY KEY, who TEXT)")
    c.execute("INSERT INTO runs (who) VALUES ('someone else')")
    c.commit()
    c.close()
    return path


def _damaged_files(tmp: Path, good: Path) -> dict[str, Path]:
    data = good.read_bytes()
    files = {
        "empty": tmp / "empty.db", "text": tmp / "text.db", "foreign": _foreign(tmp / "foreign.db"),
        "truncated": tmp / "truncated.db", "corrupt": tmp / "corrupt.db", "folder": tmp / "folder.db",
    }
    files["empty"].write_bytes(b"")
    files["text"].write_text("id,name\n1,two\n")
    files["truncated"].write_bytes(data[: len(data) // 3])
    bad = bytearray(data)
    for i in range(4096, len(bad), 97):  # scribble over every page but the first
        bad[i] = (bad[i] + 101) % 256
    files["corrupt"].write_bytes(bytes(bad))
    files["folder"].mkdir()
    return files


@pytest.mark.parametrize("command", ["bench", "report", "bench-resume"])
def test_files_that_are_not_anyplan_databases_are_refused_and_unchanged(tmp_path, tiny, good_db, command):
    for kind, f in _damaged_files(tmp_path, good_db).items():
        before = None if f.is_dir() else _digest(f)
        if command == "report":
            argv = ["report", str(f), "--out", str(tmp_path / f"rep-{kind}")]
        else:
            argv = _bench(tiny, f, *(["--resume"] if command == "bench-resume" else []))
        o = run_cli(argv)
        assert refusal_problem(o) is None, (command, kind, refusal_problem(o))
        assert str(f.name) in o.err, (kind, o.err)
        if before is not None:
            assert _digest(f) == before, f"{command} changed the {kind} file"
        assert not Path(str(f) + "-journal").exists()


def test_report_is_read_only(tmp_path, good_db):
    before = _digest(good_db)
    good_db.chmod(0o444)
    try:
        o = run_cli(["report", str(good_db), "--out", str(tmp_path / "rep")])
        assert o.rc == 0, o.err
        assert (tmp_path / "rep" / "report.html").is_file()
    finally:
        good_db.chmod(0o644)
    assert _digest(good_db) == before


def test_bench_refuses_a_read_only_database(tmp_path, tiny, good_db):
    before = _digest(good_db)
    good_db.chmod(0o444)
    try:
        o = run_cli(_bench(tiny, good_db, "--resume"))
    finally:
        good_db.chmod(0o644)
    assert refusal_problem(o) is None and "read-only" in o.err
    assert _digest(good_db) == before


def test_schema_makes_duplicate_runs_impossible(tmp_path):
    db = ResultsDB(tmp_path / "u.db")
    try:
        pid = db.planner_id("straight", "")
        eid = db.conn.execute("INSERT INTO experiments (name) VALUES ('e')").lastrowid
        row = run_row(None, run_index=0, seed=7, scenario_hash="h", error="x")
        a = db.add_run(eid, pid, row, None)
        assert db.add_run(eid, pid, row, None) == a  # the second copy is not stored
        with pytest.raises(sqlite3.IntegrityError, match="UNIQUE"):
            db.conn.execute("INSERT INTO runs (experimentid, plannerid, run_index, seed) VALUES (?, ?, 0, 7)",
                            (eid, pid))
        assert db.conn.execute("SELECT count(*) FROM runs").fetchone()[0] == 1
    finally:
        db.close()


def test_one_writer_at_a_time(tmp_path):
    path = tmp_path / "w.db"
    first = ResultsDB(path)
    try:
        t0 = time.monotonic()
        with pytest.raises(DatabaseFileError, match="in use by another anyplan process"):
            ResultsDB(path, lock_timeout_s=0.3)
        assert time.monotonic() - t0 < 5.0
        reader = ResultsDB(path, readonly=True)  # readers need no lock
        assert reader.runs() == []
        reader.close()
    finally:
        first.close()
    ResultsDB(path, lock_timeout_s=0.0).close()  # free again


def test_an_old_database_with_duplicates_is_refused_unchanged(tmp_path, good_db):
    c = sqlite3.connect(good_db)
    c.execute("DROP INDEX runs_unique_key")
    c.execute("INSERT INTO runs (experimentid, plannerid, run_index, seed, outcome) "
              "SELECT experimentid, plannerid, run_index, seed, outcome FROM runs LIMIT 1")
    c.commit()
    c.close()
    before = _digest(good_db)
    with pytest.raises(DatabaseFileError, match="stored twice"):
        ResultsDB(good_db)
    assert _digest(good_db) == before


def _spawn(argv: list[str]) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.Popen([sys.executable, "-m", "anyplan", *argv], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


@pytest.mark.parametrize("resume", [False, True])
def test_two_benches_on_one_database_store_each_run_once(tmp_path, tiny, resume):
    db = tmp_path / "par.db"
    extra = ["--runs", "4"]
    if resume:  # a first, partial bench; then two --resume benches race for the rest
        assert run_cli(_bench(tiny, db, "--runs", "1")).rc == 0
        extra.append("--resume")
    procs = [_spawn(_bench(tiny, db, *extra)) for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    codes = sorted(p.returncode for p in procs)
    # One finishes the work; the other either waited and found nothing left (exit 0 with
    # --resume, 2 without it: the runs are stored) or was refused after waiting (exit 2).
    assert codes[0] == 0 and codes[1] in (0, 2), (codes, [o[1][-300:] for o in outs])
    for p, (_, err) in zip(procs, outs, strict=True):
        if p.returncode == 2:
            assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    c = sqlite3.connect(db)
    n, distinct = c.execute("SELECT count(*), count(DISTINCT experimentid || '/' || plannerid || '/' || "
                            "run_index || '/' || seed) FROM runs").fetchone()
    c.close()
    assert n == distinct == 4
