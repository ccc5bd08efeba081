"""The BARN table: our runs on BARN worlds beside the challenge's DWA baseline.

One row per planner configuration for the worlds the visibility graph finds feasible for the
robot's disc and one for the others, with outcome counts, time to the goal, time over the
challenge's optimal time (reference path length / 2 m/s) and the challenge's score
``success * optimal / clip(time, 2 optimal, 8 optimal)``. The DWA baseline
(:data:`DWA_BASELINE`) is quoted from the BARN Challenge's README (Gazebo, real footprint), so
it is context, not a like-for-like comparison.

Columns: ``docs/experiments.md``, "The BARN table".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from anyplan.experiments.barn import INDEX_FILE, load_index
from anyplan.experiments.tables import Stat

__all__ = ["DWA_BASELINE", "BarnRow", "summarize_barn", "format_barn", "suite_index",
           "bench_barn_report", "challenge_score"]

#: The challenge's DWA baseline (BARN Challenge repository README, Daffan/the-barn-challenge:
#: 50 worlds x 10 runs in Gazebo).
DWA_BASELINE: dict[str, Any] = {
    "success": 0.88, "collision": 0.048, "timeout": 0.072, "mean_time_s": 33.47, "score": 0.1693,
    "source": "BARN Challenge README (github.com/Daffan/the-barn-challenge), DWA, "
              "50 worlds x 10 runs in Gazebo"}


def challenge_score(reached: bool, time_s: float | None, optimal_s: float) -> float:
    """The challenge's score of one run: ``success * optimal / clip(time, 2 opt, 8 opt)``."""
    if not reached or time_s is None or not math.isfinite(time_s):
        return 0.0
    return optimal_s / min(max(time_s, 2.0 * optimal_s), 8.0 * optimal_s)


@dataclass(frozen=True)
class BarnRow:
    """One planner configuration on one group of worlds (``feasible`` or ``other``)."""

    planner: str
    settings: str
    group: str
    worlds: int
    runs: int
    reached: int
    collisions: int
    robot_caused: int | None
    timeouts: int
    errors: int
    time: Stat
    time_over_optimal: Stat
    mean_time_over_mean_optimal: float
    score: float

    @property
    def title(self) -> str:
        """Planner name, with its settings if not the defaults."""
        return self.planner + (f" [{self.settings}]" if self.settings else "")


def _robot_caused(r: Mapping[str, Any]) -> bool | None:
    v = r.get("robot_caused", r.get("collision_robot_caused"))
    return None if v is None else bool(v)


def summarize_barn(runs: Sequence[Mapping[str, Any]],
                   index: Mapping[str, Mapping[str, Any]]) -> list[BarnRow]:
    """Rows (docs/experiments.md, "The BARN table") of the ``runs`` (rows of :meth:`ResultsDB.runs`) on the
    scenarios of ``index`` (:func:`~anyplan.experiments.barn.load_index`); other runs ignored."""
    groups: dict[tuple[str, str, str], list[Mapping[str, Any]]] = {}
    for r in runs:
        e = index.get(str(r.get("scenario")))
        if e is None or r.get("outcome") is None:
            continue
        g = "feasible" if e.get("feasibility", "feasible") == "feasible" else "other"
        groups.setdefault((str(r["planner"]), str(r.get("settings") or ""), g), []).append(r)
    rows = []
    for (name, settings, g), rs in groups.items():
        opt = {id(r): float(index[str(r["scenario"])]["optimal_time_s"]) for r in rs}
        ok = [r for r in rs if r["outcome"] == "reached" and r.get("time_to_goal") is not None]
        caused = [_robot_caused(r) for r in rs if r["outcome"] == "collision"]
        known = all(c is not None for c in caused) and any(
            ("robot_caused" in r or "collision_robot_caused" in r) for r in rs)
        mt = Stat.of(r["time_to_goal"] for r in ok)
        mo = Stat.of(opt[id(r)] for r in ok)
        rows.append(BarnRow(
            planner=name, settings=settings, group=g,
            worlds=len({r["scenario"] for r in rs}), runs=len(rs), reached=len(ok),
            collisions=sum(r["outcome"] == "collision" for r in rs),
            robot_caused=sum(bool(c) for c in caused) if known else None,
            timeouts=sum(r["outcome"] == "timeout" for r in rs),
            errors=sum(r["outcome"] == "error" for r in rs),
            time=mt, time_over_optimal=Stat.of(r["time_to_goal"] / opt[id(r)] for r in ok),
            mean_time_over_mean_optimal=mt.mean / mo.mean if ok else math.nan,
            score=sum(challenge_score(r["outcome"] == "reached", r.get("time_to_goal"), opt[id(r)])
                      for r in rs) / len(rs)))
    order = {"seq-bitstar": 0, "st-bitstar": 1, "bitstar": 2, "dovs": 3}
    rows.sort(key=lambda t: (t.group != "feasible", order.get(t.planner, 9), t.planner, t.settings))
    return rows


HEADERS = ["planner", "worlds", "runs", "success", "collisions", "robot-caused", "timeouts",
           "errors", "time [s]", "time / optimal", "mean t / mean opt", "score"]


def _cells(r: BarnRow) -> list[str]:
    rc = "n/a" if r.robot_caused is None else str(r.robot_caused)
    ratio = "-" if math.isnan(r.mean_time_over_mean_optimal) else f"{r.mean_time_over_mean_optimal:.3f}"
    return [r.title, str(r.worlds), str(r.runs), f"{r.reached}/{r.runs} ({r.reached / r.runs:.3f})",
            str(r.collisions), rc, str(r.timeouts), str(r.errors), r.time.fmt(2),
            r.time_over_optimal.fmt(3), ratio, f"{r.score:.4f}"]


def _dwa_cells() -> list[str]:
    b = DWA_BASELINE
    return ["DWA (challenge baseline)", "50", "500", f"{b['success']:.2f}", f"{b['collision']:.3f}",
            "n/a", f"{b['timeout']:.3f}", "-", f"{b['mean_time_s']:.2f}", "-", "-",
            f"{b['score']:.4f}"]


def _grid(rows: Sequence[Sequence[str]], markdown: bool) -> str:
    if markdown:
        out = ["| " + " | ".join(HEADERS) + " |", "|" + "---|" * len(HEADERS)]
        return "\n".join(out + ["| " + " | ".join(r) + " |" for r in rows])
    w = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(HEADERS)]
    line = "  ".join(h.rjust(w[i]) for i, h in enumerate(HEADERS))
    return "\n".join([line, "-" * len(line)]
                     + ["  ".join(c.rjust(w[i]) for i, c in enumerate(r)) for r in rows])


def format_barn(rows: Sequence[BarnRow], markdown: bool = False) -> str:
    """The BARN tables (feasible worlds with the DWA baseline, then the other worlds), or ''."""
    if not rows:
        return ""
    parts = []
    feas = [r for r in rows if r.group == "feasible"]
    other = [r for r in rows if r.group != "feasible"]
    head = "**{}**" if markdown else "{}"
    if feas:
        parts.append(head.format("BARN, worlds feasible for the robot's disc (visibility graph)")
                     + ("\n\n" if markdown else "\n")
                     + _grid([*(_cells(r) for r in feas), _dwa_cells()], markdown))
    if other:
        parts.append(head.format("BARN, worlds infeasible or uncertain for the disc")
                     + ("\n\n" if markdown else "\n") + _grid([_cells(r) for r in other], markdown))
    parts.append("(success: goal within 1 m in 100 s without collision; time over reached runs; "
                 "optimal = the challenge's reference path length / 2 m/s; score = the challenge's "
                 "success * optimal / clip(time, 2 opt, 8 opt), mean over runs, at most 0.5. "
                 f"DWA: {DWA_BASELINE['source']}; a different simulator, footprint and sensing.)")
    return "\n\n".join(parts)


def suite_index(suite: str) -> dict[str, dict[str, Any]] | None:
    """The BARN index of a ``--suite`` folder written by ``anyplan import-barn``, or None."""
    p = Path(suite)
    if not (p.is_dir() and (p / INDEX_FILE).is_file()):
        return None
    return load_index(p)


def bench_barn_report(suite: str, runs: Sequence[Mapping[str, Any]]) -> tuple[str, str] | None:
    """(text, Markdown) BARN tables of ``runs`` if ``suite`` is a folder from ``import-barn``."""
    index = suite_index(suite)
    rows = summarize_barn(runs, index) if index else []
    if not rows:
        return None
    return format_barn(rows), "# BARN\n\n" + format_barn(rows, markdown=True) + "\n"
