"""Paired comparison of two runs of ``benchmarks/unknown.py`` (their ``--rows`` files).

Two settings or trees run on the same worlds and seeds give paired outcomes. For each suite and
perception mode (and planner, when both files hold it; with one planner in each file, those two
are paired) this prints, over the runs both files hold (same scenario and seed): how many each
reached, collided and collided robot-caused, the differences (A - B) with Newcombe's 95 %
interval, and McNemar's exact p (``anyplan.experiments.significance``). An interval that holds 0
does not show a difference; the closed loop of the DynaBARN runs is chaotic, so a total moving by
a few runs says nothing until the interval says it does. ``--runs`` lists every run whose
outcome differs. ``--modes MA,MB`` pairs file A's runs in perception mode MA with file B's in
MB (e.g. ``tracked,twist``: what tracking costs against exact twists, world by world).

Usage::

    python benchmarks/compare_rows.py A.json B.json [--labels A,B] [--runs] [--modes MA,MB]
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from anyplan.experiments.significance import compare_outcomes

sys.path.insert(0, str(Path(__file__).resolve().parent))
from unknown import robot_caused, seen_in_time  # the rows' own predicates

Row = dict[str, Any]


class BadInput(Exception):
    """A file that cannot be compared: one line, exit code 2."""


OUTCOMES: dict[str, Callable[[Row], bool]] = {
    "reached": lambda r: r["status"] == "reached",
    "collided": lambda r: r["status"] == "collision",
    "robot-caused": robot_caused,
    "robot-caused, seen in time": seen_in_time,  # unknown.py's column
}


def _load(path: str) -> list[Row]:
    try:
        rows = json.loads(Path(path).read_text())
    except OSError as exc:
        raise BadInput(f"{path}: cannot read ({exc.strerror})") from None
    except json.JSONDecodeError as exc:
        raise BadInput(f"{path}: not JSON ({exc.msg}, line {exc.lineno})") from None
    need = ("suite", "mode", "planner", "scenario", "seed", "status")
    if not isinstance(rows, list) or not all(isinstance(r, dict) and all(k in r for k in need)
                                             for r in rows):
        raise BadInput(f"{path}: not a --rows file of benchmarks/unknown.py "
                       f"(a list of runs with {', '.join(need)})")
    return rows


def _groups(a: list[Row], b: list[Row],
            modes: tuple[str, str] | None = None) -> list[tuple[str, dict[Any, Row], dict[Any, Row]]]:
    if modes is not None:  # one mode of each file, compared as if they were one
        a = [dict(r, mode=f"{modes[0]} / {modes[1]}") for r in a if r["mode"] == modes[0]]
        b = [dict(r, mode=f"{modes[0]} / {modes[1]}") for r in b if r["mode"] == modes[1]]
    pa, pb = sorted({r["planner"] for r in a}), sorted({r["planner"] for r in b})
    pairs = [(p, p) for p in pa if p in pb] or ([(pa[0], pb[0])] if len(pa) == len(pb) == 1 else [])
    out = []
    for qa, qb in pairs:
        for suite, mode in sorted({(r["suite"], r["mode"]) for r in a if r["planner"] == qa}):
            ra = {(r["scenario"], r["seed"]): r for r in a
                  if (r["planner"], r["suite"], r["mode"]) == (qa, suite, mode)}
            rb = {(r["scenario"], r["seed"]): r for r in b
                  if (r["planner"], r["suite"], r["mode"]) == (qb, suite, mode)}
            if any(k in rb for k in ra):
                name = qa if qa == qb else f"{qa} / {qb}"
                out.append((f"{suite} {mode} {name}", ra, rb))
    return out


def _tag(r: Row) -> str:
    if r["status"] == "collision":
        return "collision (robot-caused)" if robot_caused(r) else "collision"
    return str(r["status"])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--labels", default="A,B", help="names of the two files in the output")
    ap.add_argument("--runs", action="store_true", help="list the runs whose outcomes differ")
    ap.add_argument("--modes", default=None, metavar="MA,MB",
                    help="pair A's runs in perception mode MA with B's in mode MB")
    args = ap.parse_args(argv)
    la, _, lb = args.labels.partition(",")
    try:
        modes = None
        if args.modes is not None:
            ma, comma, mb = args.modes.partition(",")
            if not (comma and ma and mb):
                raise BadInput(f"--modes: two perception modes, MA,MB (got {args.modes!r})")
            modes = (ma, mb)
        groups = _groups(_load(args.a), _load(args.b), modes)
        if not groups:
            raise BadInput(f"{args.a} and {args.b} share no run (same suite, mode, planner, "
                           "scenario and seed)")
    except BadInput as exc:
        sys.stderr.write(f"compare_rows: {exc}\n")
        return 2
    print(f"| runs | paired | outcome | {la} | {lb} | {la} - {lb} [95 % CI] (McNemar p) |")
    print("|---|---|---|---|---|---|")
    for name, ra, rb in groups:
        for outcome, f in OUTCOMES.items():
            c = compare_outcomes({k: f(r) for k, r in ra.items()}, {k: f(r) for k, r in rb.items()})
            print(f"| {name} | {c.n} | {outcome} | {c.both + c.only_a} | {c.both + c.only_b} | "
                  f"{c.fmt()} |")
    if args.runs:
        for name, ra, rb in groups:
            diff = [(k, _tag(ra[k]), _tag(rb[k])) for k in sorted(ra, key=str) if k in rb
                    and _tag(ra[k]) != _tag(rb[k])]
            print(f"\n{name}: {len(diff)} runs differ")
            for (scenario, seed), ta, tb in diff:
                print(f"  {scenario} seed {seed}: {la} {ta}, {lb} {tb}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
