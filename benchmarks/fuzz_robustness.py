"""Many generated bad (and good) inputs, each run once, with counts of what went wrong.

    PYTHONPATH=src python benchmarks/fuzz_robustness.py --cases 300 [--pairs 5]

For every class of broken scenario document (tests/fuzz/harness.py, BROKEN_CLASSES) the command
line must refuse with exit code 2 and one bounded line naming the file; valid documents must
give a sound result (or a clean refusal); option values outside their ranges must be refused and
inside them must run; damaged database files (random truncations and scribbles) must be refused
and left unchanged; two benches racing on one database must store every run once. Prints one
row per class: cases, ok, tracebacks, hangs, other failures, damaged or duplicated records.
Hypothesis generates the cases (no shrinking, no example database); a class whose strategy has
fewer distinct values than --cases runs fewer (the count says how many).
"""

from __future__ import annotations

import argparse
import hashlib
import os
import random
import sqlite3
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "src"))

import yaml  # noqa: E402
from hypothesis import HealthCheck, Phase, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tests.fuzz.harness import (  # noqa: E402
    BROKEN_CLASSES,
    broken_documents,
    refusal_problem,
    run_cli,
    sound_problem,
    valid_documents,
)


def _settings(n: int) -> settings:
    return settings(max_examples=n, deadline=None, database=None, phases=[Phase.generate],
                    suppress_health_check=list(HealthCheck))


def _tally(counts: Counter, problem: str | None) -> None:
    counts["cases"] += 1
    if problem is None:
        counts["ok"] += 1
    elif problem.startswith("traceback"):
        counts["tracebacks"] += 1
        counts.setdefault("first", problem)  # type: ignore[arg-type]
    elif problem == "hang":
        counts["hangs"] += 1
    else:
        counts["other"] += 1
        counts.setdefault("first", problem)  # type: ignore[arg-type]


def broken_class(kind: str, n: int, command: str) -> Counter:
    counts: Counter = Counter()

    @_settings(n)
    @given(case=broken_documents(kind))
    def run(case):
        _, blob, field = case
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "doc.yaml"
            path.write_bytes(blob)
            argv = (["run", str(path), "--planner", "straight", "--no-plot", "--out", str(Path(d) / "o")]
                    if command == "run" else ["plan", str(path), "--planner", "visgraph"])
            o = run_cli(argv, timeout_s=60)
            problem = refusal_problem(o, must_name=str(path))
            if problem is None and field is not None and field not in o.err:
                problem = f"field {field} not named: {o.err[:120]!r}"
            _tally(counts, problem)

    run()
    return counts


def valid_class(n: int) -> Counter:
    counts: Counter = Counter()

    @_settings(n)
    @given(doc=valid_documents())
    def run(doc):
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "doc.yaml"
            path.write_text(yaml.safe_dump(doc, allow_unicode=True))
            out = Path(d) / "o"
            o = run_cli(["run", str(path), "--planner", "straight", "--no-plot", "--out", str(out)],
                        timeout_s=120)
            _tally(counts, sound_problem(o, out / "result.json", doc["time_limit"]))

    run()
    return counts


TINY = {"name": "tiny", "time_limit": 3.0, "arena": {"width": 4.0, "height": 3.0},
        "robot": {"start": [0.5, 1.5, 0.0], "goal": [1.5, 1.5], "radius": 0.2, "v_max": 1.0,
                  "omega_max": 1.0, "a_max": 2.0, "alpha_max": 2.0}}


def options_class(n: int) -> Counter:
    sys.path.insert(0, str(ROOT / "tests" / "fuzz"))
    from tests.fuzz.test_fuzz_options import NUMBERISH, dt_ok, seed_ok, time_limit_ok

    counts: Counter = Counter()
    d0 = Path(tempfile.mkdtemp())
    tiny = d0 / "tiny.yaml"
    tiny.write_text(yaml.safe_dump(TINY))
    oracle = {"--seed": seed_ok, "--dt": dt_ok, "--time-limit": time_limit_ok}

    @_settings(n)
    @given(value=NUMBERISH, option=st.sampled_from(sorted(oracle)))
    def run(value, option):
        ok = oracle[option](value)
        if ok and option == "--time-limit":
            value = str(min(float(value), 20.0))
        with tempfile.TemporaryDirectory() as d:
            out = Path(d) / "o"
            o = run_cli(["run", str(tiny), "--planner", "straight", "--no-plot", "--out", str(out),
                         f"{option}={value}"], timeout_s=120)
            limit = float(value) if ok and option == "--time-limit" else TINY["time_limit"]
            _tally(counts, sound_problem(o, out / "result.json", limit) if ok else refusal_problem(o))

    run()
    return counts


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def database_class(n: int, seed: int = 0) -> Counter:
    """Random truncations and scribbles of a real database, refused by bench and report."""
    counts: Counter = Counter()
    rnd = random.Random(seed)
    d = Path(tempfile.mkdtemp())
    tiny = d / "tiny.yaml"
    tiny.write_text(yaml.safe_dump(TINY))
    good = d / "good.db"
    bench = ["bench", "--suite", str(tiny), "--planners", "straight", "--runs", "2", "--jobs", "1",
             "--no-progress", "--db"]
    assert run_cli([*bench, str(good)]).rc == 0
    data = good.read_bytes()
    for i in range(n):
        f = d / f"bad{i}.db"
        kind = rnd.choice(["truncate", "scribble", "header"])
        if kind == "truncate":
            f.write_bytes(data[: rnd.randrange(0, len(data) - 1)])
        elif kind == "scribble":
            b = bytearray(data)
            start = rnd.randrange(100, len(b))
            for j in range(start, min(len(b), start + rnd.randrange(1, 20000)), rnd.randrange(1, 50)):
                b[j] = rnd.randrange(256)
            f.write_bytes(bytes(b))
        else:
            b = bytearray(data)
            for j in rnd.sample(range(16, 100), 5):
                b[j] = rnd.randrange(256)
            f.write_bytes(bytes(b))
        before = _digest(f)
        cmd = rnd.choice(["bench", "report"])
        argv = ([*bench, str(f), "--resume"] if cmd == "bench"
                else ["report", str(f), "--out", str(d / "rep")])
        o = run_cli(argv, timeout_s=120)
        problem = refusal_problem(o) if o.rc != 0 else None  # a scribble SQLite survives is fine
        if o.rc == 0 and cmd == "bench":
            problem = _duplicates(f)
        if _digest(f) != before and not (o.rc == 0 and cmd == "bench"):
            counts["damaged"] += 1
            problem = problem or "file changed"
        _tally(counts, problem)
        f.unlink()
    return counts


def _duplicates(db: Path) -> str | None:
    c = sqlite3.connect(db)
    try:
        n, k = c.execute("SELECT count(*), count(DISTINCT experimentid || '/' || plannerid || '/' || "
                         "run_index || '/' || seed) FROM runs").fetchone()
    finally:
        c.close()
    return None if n == k else f"{n - k} duplicated runs"


def concurrency_class(pairs: int) -> Counter:
    counts: Counter = Counter()
    d = Path(tempfile.mkdtemp())
    tiny = d / "tiny.yaml"
    tiny.write_text(yaml.safe_dump(dict(TINY, robot=dict(TINY["robot"], goal=[3.5, 1.5]))))
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    for i in range(pairs):
        db = d / f"par{i}.db"
        argv = [sys.executable, "-m", "anyplan", "bench", "--suite", str(tiny), "--planners", "straight",
                "--runs", "5", "--jobs", "1", "--no-progress", "--db", str(db)]
        extra = [["--resume"], ["--resume"]] if i % 2 else [[], []]
        if i % 2:  # a partial bench first; then two --resume benches race for the rest
            first = [a if a != "5" else "1" for a in argv]
            subprocess.run(first, env=env, capture_output=True, check=True)
        procs = [subprocess.Popen(argv + e, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  text=True) for e in extra]
        outs = [p.communicate(timeout=600) for p in procs]
        problem = None
        if any(p.returncode not in (0, 2) for p in procs) or any("Traceback" in e for _, e in outs):
            problem = "traceback: " + " | ".join(e[-200:] for _, e in outs)
        dup = _duplicates(db)
        c = sqlite3.connect(db)
        n = c.execute("SELECT count(*) FROM runs").fetchone()[0]
        c.close()
        if dup:
            counts["duplicated"] += 1
        if n != 5:
            problem = problem or f"{n} runs stored, expected 5"
        _tally(counts, problem or dup)
    return counts


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=300, help="cases per class (default 300)")
    ap.add_argument("--pairs", type=int, default=5, help="racing bench pairs (default 5)")
    ap.add_argument("--only", default=None, help="comma-separated classes to run")
    args = ap.parse_args()
    rows = []
    t0 = time.perf_counter()
    jobs = [(f"broken:{k}", lambda k=k: broken_class(k, args.cases, "run")) for k in BROKEN_CLASSES]
    jobs += [("broken:any (plan)", lambda: broken_class(None, args.cases, "plan")),  # type: ignore[arg-type]
             ("valid documents", lambda: valid_class(args.cases)),
             ("option values", lambda: options_class(args.cases)),
             ("damaged databases", lambda: database_class(args.cases)),
             ("racing benches", lambda: concurrency_class(args.pairs))]
    only = set(args.only.split(",")) if args.only else None
    for name, job in jobs:
        if only and name not in only:
            continue
        t = time.perf_counter()
        c = job()
        rows.append((name, c, time.perf_counter() - t))
        first = f"  first: {str(c['first'])[:150]}" if "first" in c else ""
        print(f"{name:22s} cases {c['cases']:4d}  ok {c['ok']:4d}  tracebacks {c['tracebacks']}  "
              f"hangs {c['hangs']}  other {c['other']}  damaged {c['damaged']}  duplicated {c['duplicated']}"
              f"  ({time.perf_counter() - t:.0f} s){first}", flush=True)
    tot = Counter()
    for _, c, _ in rows:
        for k in ("cases", "ok", "tracebacks", "hangs", "other", "damaged", "duplicated"):
            tot[k] += c[k]
    print(f"{'total':22s} cases {tot['cases']:4d}  ok {tot['ok']:4d}  tracebacks {tot['tracebacks']}  "
          f"hangs {tot['hangs']}  other {tot['other']}  damaged {tot['damaged']}  duplicated "
          f"{tot['duplicated']}  ({time.perf_counter() - t0:.0f} s, machine shared: timings are noisy)")
    return 0 if tot["cases"] == tot["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
