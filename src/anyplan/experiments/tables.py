"""Tables like the paper's Tables 2 and 3, computed from the results database.

One table per planner configuration, one row per number of moving obstacles, with the paper's
columns (path length, path generation time, time to goal; mean ± sample std) plus the outcome
counts (successes, collisions, robot-caused collisions, timeouts, errors) and the time over the
run's lower bound, with the success rate's 95 % Wilson interval. Planner configurations run on
the same scenarios and seeds are compared pair by pair (:func:`compare_planners`: the difference
in success and in robot-caused collisions, Newcombe's interval, McNemar's exact p). The paper's
own numbers (Roy, Harchowdhury & Vachhani, Tables 2-3) are in :data:`PAPER_TABLES`.

What each column averages over: ``docs/experiments.md``, "The paper's tables: columns".
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.experiments.significance import PairedComparison, compare_outcomes, wilson_interval

__all__ = ["PAPER_TABLES", "PAPER_SCENARIOS", "Stat", "TableRow", "PlannerTable", "PlannerPair",
           "COMPARISON_HEADERS", "summarize", "compare_planners", "pair_cells", "paper_runs",
           "format_text", "format_markdown", "format_csv", "format_comparisons",
           "format_paper_comparison", "write_tables"]

#: The paper's figures per planner registry name and number of moving obstacles:
#: (path length [m], path generation time [s], time to goal [s]), or None for "crashed".
PAPER_TABLES: dict[str, dict[str, Any]] = {
    "dovs": {"title": "DOVS (paper Table 2)",
             "rows": {1: (18.762, 0.25188, 50.1), 2: (18.4852, 0.207315, 56.006), 3: None}},
    "seq-bitstar": {"title": "Sequential BIT* (paper Table 3)",
                    "rows": {1: (12.076, 0.1841, 40.766), 2: (12.003, 0.1716, 40.218),
                             3: (12.115, 0.1835, 40.655)}},
}

#: The scenarios the paper's figures are compared with (our reconstructions of its scenes).
PAPER_SCENARIOS = ("paper-1", "paper-2", "paper-3")


def paper_runs(runs: Sequence[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The runs on the built-in paper scenarios: the only ones compared with the paper's tables."""
    return [r for r in runs if r.get("scenario") in PAPER_SCENARIOS]


@dataclass(frozen=True)
class Stat:
    """Mean and sample standard deviation of ``n`` values (NaN when n == 0; std NaN when n < 2)."""

    mean: float
    std: float
    n: int

    @staticmethod
    def of(values: Iterable[float | None]) -> Stat:
        """Statistics of the finite values in ``values``."""
        v = np.array([x for x in values if x is not None and math.isfinite(x)], dtype=float)
        if v.size == 0:
            return Stat(math.nan, math.nan, 0)
        return Stat(float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else math.nan, int(v.size))

    def fmt(self, digits: int = 3) -> str:
        """``mean ± std`` (``-`` when empty)."""
        if self.n == 0:
            return "-"
        if not math.isfinite(self.std):
            return f"{self.mean:.{digits}f}"
        return f"{self.mean:.{digits}f} ± {self.std:.{digits}f}"


@dataclass(frozen=True)
class TableRow:
    """One row: the runs of one planner on scenarios with ``n_moving`` moving obstacles."""

    n_moving: int
    runs: int
    successes: int
    crashes: int
    timeouts: int
    errors: int
    path_length: Stat
    generation_time: Stat
    time_to_goal: Stat
    robot_caused: int = 0
    time_over_bound: Stat = Stat(math.nan, math.nan, 0)
    #: Smallest robot-to-moving-obstacle surface distance [m] over the runs, and the mean time
    #: [s] within 0.2 m of one (discomfort).
    min_distance_to_moving: float = math.nan
    discomfort_time: Stat = Stat(math.nan, math.nan, 0)


@dataclass
class PlannerTable:
    """The table of one planner configuration."""

    planner: str
    settings: str
    rows: list[TableRow] = field(default_factory=list)

    @property
    def title(self) -> str:
        """Planner name, with its settings if not the defaults."""
        return self.planner + (f" [{self.settings}]" if self.settings else "")


#: The tables' order: the paper's planners first, then by name and settings.
_ORDER = {"seq-bitstar": 0, "bitstar": 1, "dovs": 2}


def _configs(runs: Sequence[Mapping[str, Any]]
             ) -> list[tuple[tuple[str, str], list[Mapping[str, Any]]]]:
    """The rows of each planner configuration ``(planner, settings)``, in the tables' order;
    rows without ``outcome`` or ``n_moving`` (e.g. imported OMPL runs) are left out."""
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    for r in runs:
        if r.get("outcome") is None or r.get("n_moving") is None:
            continue
        groups.setdefault((str(r["planner"]), str(r.get("settings") or "")), []).append(r)
    return sorted(groups.items(), key=lambda g: (_ORDER.get(g[0][0], 9), g[0][0], g[0][1]))


def _reached(r: Mapping[str, Any]) -> bool:
    return bool(r["outcome"] == "reached")


def _robot_caused(r: Mapping[str, Any]) -> bool:
    """A collision in which the robot drove into what it hit (``robot_caused``)."""
    return r["outcome"] == "collision" and bool(r.get("robot_caused"))


def summarize(runs: Sequence[Mapping[str, Any]]) -> list[PlannerTable]:
    """Tables from run rows as returned by :meth:`ResultsDB.runs`.

    Rows without ``outcome`` or ``n_moving`` (e.g. imported OMPL runs) are ignored.
    """
    tables = []
    for (name, settings), rows in _configs(runs):
        by_n: dict[int, list[Mapping[str, Any]]] = {}
        for r in rows:
            by_n.setdefault(int(r["n_moving"]), []).append(r)
        t = PlannerTable(name, settings)
        for n in sorted(by_n):
            rs = by_n[n]
            ok = [r for r in rs if _reached(r)]
            t.rows.append(TableRow(
                n_moving=n, runs=len(rs), successes=len(ok),
                crashes=sum(r["outcome"] == "collision" for r in rs),
                timeouts=sum(r["outcome"] == "timeout" for r in rs),
                errors=sum(r["outcome"] == "error" for r in rs),
                path_length=Stat.of(r["path_length"] for r in ok),
                generation_time=Stat.of(r.get("planning_time_mean") for r in rs
                                        if (r.get("planning_calls") or 0) > 0),
                time_to_goal=Stat.of(r["time_to_goal"] for r in ok),
                robot_caused=sum(_robot_caused(r) for r in rs),
                time_over_bound=Stat.of(r.get("time_over_lower_bound") for r in ok),
                min_distance_to_moving=min((r["min_distance_to_moving"] for r in rs
                                            if r.get("min_distance_to_moving") is not None),
                                           default=math.nan),
                discomfort_time=Stat.of(r.get("discomfort_time") for r in rs)))
        tables.append(t)
    return tables


def _run_key(r: Mapping[str, Any]) -> tuple[Any, ...]:
    """What makes two planners' runs a pair: the same scenario (content), run index and seed."""
    return (r.get("scenario_hash") or r.get("scenario"), r.get("run_index"), r.get("seed"))


@dataclass(frozen=True)
class PlannerPair:
    """Two planner configurations over the runs they share (same scenario, run index, seed).

    Attributes:
        a, b: The configurations' titles (:attr:`PlannerTable.title`).
        reached: Paired comparison of reaching the goal (A's rate - B's).
        robot_caused: Paired comparison of ending in a robot-caused collision.
    """

    a: str
    b: str
    reached: PairedComparison
    robot_caused: PairedComparison


def compare_planners(runs: Sequence[Mapping[str, Any]], level: float = 0.95) -> list[PlannerPair]:
    """Every pair of planner configurations in ``runs`` (rows as for :func:`summarize`) that
    share at least one run, in the order of :func:`summarize`'s tables. Errors count as not
    reached; a run key stored twice for one configuration keeps its last row."""
    configs = [(PlannerTable(name, settings).title, {_run_key(r): r for r in rows})
               for (name, settings), rows in _configs(runs)]

    def paired(ra: Mapping[Any, Mapping[str, Any]], rb: Mapping[Any, Mapping[str, Any]],
               outcome: Any) -> PairedComparison:
        return compare_outcomes({k: outcome(r) for k, r in ra.items()},
                                {k: outcome(r) for k, r in rb.items()}, level)

    pairs = []
    for i, (ta, ra) in enumerate(configs):
        for tb, rb in configs[i + 1:]:
            if any(k in rb for k in ra):
                pairs.append(PlannerPair(ta, tb, paired(ra, rb, _reached),
                                         paired(ra, rb, _robot_caused)))
    return pairs


COMPARISON_HEADERS = ["A", "B", "paired runs", "reached A / B", "A - B reached [95 % CI] (McNemar p)",
                      "robot-caused A / B", "A - B robot-caused [95 % CI] (McNemar p)"]


def pair_cells(p: PlannerPair) -> list[str]:
    """The cells of one pair's row, under :data:`COMPARISON_HEADERS`."""
    r, c = p.reached, p.robot_caused
    return [p.a, p.b, str(r.n), f"{r.both + r.only_a} / {r.both + r.only_b}", r.fmt(),
            f"{c.both + c.only_a} / {c.both + c.only_b}", c.fmt()]


def format_comparisons(pairs: Sequence[PlannerPair], markdown: bool = False) -> str:
    """The paired comparisons as a table (empty without pairs). An interval that excludes 0 is
    a difference the runs show at its level; one that holds 0 does not show one."""
    if not pairs:
        return ""
    rows = [pair_cells(p) for p in pairs]
    return _md(COMPARISON_HEADERS, rows) if markdown else _grid(COMPARISON_HEADERS, rows)


HEADERS = ["moving obstacles", "path length [m]", "path generation time [s]", "time to goal [s]",
           "time / lower bound", "successes", "success 95 % CI", "collisions",
           "robot-caused collisions", "timeouts", "errors", "min distance to moving [m]",
           "discomfort time [s]"]


def _cells(row: TableRow) -> list[str]:
    return [str(row.n_moving), row.path_length.fmt(3), row.generation_time.fmt(4),
            row.time_to_goal.fmt(2), row.time_over_bound.fmt(3), f"{row.successes}/{row.runs}",
            "{:.2f}-{:.2f}".format(*wilson_interval(row.successes, row.runs)), str(row.crashes),
            str(row.robot_caused), str(row.timeouts), str(row.errors),
            "-" if not math.isfinite(row.min_distance_to_moving) else f"{row.min_distance_to_moving:.3f}",
            row.discomfort_time.fmt(2)]


def _grid(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    w = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)]
    line = "  ".join(h.rjust(w[i]) for i, h in enumerate(headers))
    out = [line, "-" * len(line)]
    out += ["  ".join(c.rjust(w[i]) for i, c in enumerate(r)) for r in rows]
    return "\n".join(out)


def format_text(tables: Sequence[PlannerTable]) -> str:
    """Plain-text tables for a terminal."""
    parts = []
    for t in tables:
        parts.append(f"{t.title}\n" + _grid(HEADERS, [_cells(r) for r in t.rows]))
    return "\n\n".join(parts) if parts else "(no runs)"


def _md(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    out = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def format_markdown(tables: Sequence[PlannerTable],
                    paper_tables: Sequence[PlannerTable] | None = None,
                    pairs: Sequence[PlannerPair] = ()) -> str:
    """Markdown tables (one per planner), the paired comparisons ``pairs``
    (:func:`compare_planners`), then ``paper_tables`` (tables of the runs on the paper
    scenarios, see :func:`paper_runs`) beside the paper's figures."""
    parts = []
    for t in tables:
        parts.append(f"### {t.title}\n\n" + _md(HEADERS, [_cells(r) for r in t.rows]))
    if pairs:
        parts.append("### Paired comparisons\n\n" + format_comparisons(pairs, markdown=True))
    cmp = format_paper_comparison(paper_tables or [], markdown=True)
    if cmp:
        parts.append("### Ours against the paper\n\n" + cmp)
    return "\n\n".join(parts) + "\n"


def format_csv(tables: Sequence[PlannerTable]) -> str:
    """CSV: one line per (planner, number of moving obstacles), means and stds in own columns."""
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["planner", "settings", "moving_obstacles", "runs", "successes", "crashes", "timeouts",
                "errors", "path_length_mean_m", "path_length_std_m", "generation_time_mean_s",
                "generation_time_std_s", "time_to_goal_mean_s", "time_to_goal_std_s",
                "robot_caused_collisions", "time_over_lower_bound_mean", "time_over_lower_bound_std",
                "min_distance_to_moving_m", "discomfort_time_mean_s", "success_ci95_low",
                "success_ci95_high", "robot_caused_ci95_low", "robot_caused_ci95_high"])

    def num(x: float) -> str:
        return "" if not math.isfinite(x) else f"{x:.6g}"

    for t in tables:
        for r in t.rows:
            w.writerow([t.planner, t.settings, r.n_moving, r.runs, r.successes, r.crashes, r.timeouts,
                        r.errors, num(r.path_length.mean), num(r.path_length.std),
                        num(r.generation_time.mean), num(r.generation_time.std),
                        num(r.time_to_goal.mean), num(r.time_to_goal.std), r.robot_caused,
                        num(r.time_over_bound.mean), num(r.time_over_bound.std),
                        num(r.min_distance_to_moving), num(r.discomfort_time.mean),
                        *map(num, wilson_interval(r.successes, r.runs)),
                        *map(num, wilson_interval(r.robot_caused, r.runs))])
    return buf.getvalue()


def format_paper_comparison(tables: Sequence[PlannerTable], markdown: bool = False) -> str:
    """The paper's Tables 2-3 beside ``tables``, for the planners the paper reports (empty if
    none). Pass tables of the runs on the paper scenarios only (:func:`paper_runs`)."""
    headers = ["moving obstacles", "path length [m] ours", "paper", "generation time [s] ours",
               "paper", "time to goal [s] ours", "paper", "successes ours"]
    parts = []
    for t in tables:
        paper = PAPER_TABLES.get(t.planner)
        if paper is None:
            continue
        mine = {r.n_moving: r for r in t.rows}
        rows = []
        for n in sorted(set(mine) | set(paper["rows"])):
            r = mine.get(n)
            p = paper["rows"].get(n, "n/a")
            if p is None:
                pc = ["crashed"] * 3
            elif p == "n/a":
                pc = ["-"] * 3
            else:
                pc = [f"{p[0]:g}", f"{p[1]:g}", f"{p[2]:g}"]
            ours = ([r.path_length.fmt(3), r.generation_time.fmt(4), r.time_to_goal.fmt(2),
                     f"{r.successes}/{r.runs}"] if r else ["-", "-", "-", "-"])
            rows.append([str(n), ours[0], pc[0], ours[1], pc[1], ours[2], pc[2], ours[3]])
        title = f"{t.title} against {paper['title']}"
        parts.append((f"**{title}**\n\n" + _md(headers, rows)) if markdown
                     else f"{title}\n" + _grid(headers, rows))
    return "\n\n".join(parts)


def write_tables(tables: Sequence[PlannerTable], out: str | Path,
                 paper_tables: Sequence[PlannerTable] | None = None,
                 pairs: Sequence[PlannerPair] = ()) -> list[Path]:
    """Write ``tables.md`` (with the paired comparisons ``pairs``) and ``tables.csv`` into
    folder ``out``; returns the paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    md, cs = out / "tables.md", out / "tables.csv"
    md.write_text("# Benchmark tables\n\n" + format_markdown(tables, paper_tables, pairs))
    cs.write_text(format_csv(tables))
    return [md, cs]
