"""Figures and a self-contained HTML report from a results database (and nothing else).

* ``figure4.png``: the paper's Figure 4 as a grid, rows = planners, columns = scenarios
  (paper-1..3 when present): each panel is one representative run (the first successful run,
  else the first run) with its executed path, the obstacles and the virtual obstacles, drawn by
  :func:`anyplan.viz.run.draw_run`.
* ``boxplots.png``: path length, path generation time, time to goal and minimum clearance per
  planner and number of moving obstacles.
* ``cost_time.png``: best cost against planning time from the ``progress`` table, for anytime
  planners that report it (``source = 'planner'``) and OMPL planners imported into the database
  (``source`` NULL, e.g. ``geometric_BITstar``, dashed): median over runs with the inter-quartile
  band. Without such rows, the lengths of the executed plans against simulated time.
* ``tables.md``, ``tables.csv`` and ``report.html`` (images embedded as base64).
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from anyplan.experiments.db import ResultsDB  # noqa: E402
from anyplan.experiments.tables import (  # noqa: E402
    HEADERS,
    PAPER_TABLES,
    PlannerTable,
    _cells,
    paper_runs,
    summarize,
    write_tables,
)
from anyplan.world.scenario import Scenario, scenario_from_dict  # noqa: E402

__all__ = ["build_report", "figure4", "boxplots", "cost_time_figure", "draw_run_panel"]

PLANNER_COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"]


def draw_run_panel(ax: Any, scenario: Scenario, result: dict[str, Any]) -> None:
    """One run on ``ax``: :func:`anyplan.viz.run.draw_run` without colour bar and title (a minimal
    drawing if that module is unavailable)."""
    try:
        from anyplan.viz.run import draw_run
    except ImportError:
        from anyplan.viz._fallback import draw_run

    draw_run(ax, scenario, result, colorbar=False, title=False)
    # Obstacles may leave the arena: keep the panel on the arena and clip labels outside it.
    x0, y0, x1, y1 = scenario.bounds
    ax.set_xlim(x0 - 0.3, x1 + 0.3)
    ax.set_ylim(y0 - 0.3, y1 + 0.3)
    for artist in [*ax.texts, *ax.patches, *ax.lines, *ax.collections]:
        artist.set_clip_on(True)


def _scenarios(db: ResultsDB) -> dict[int, Scenario]:
    out = {}
    for e in db.experiments():
        try:
            out[int(e["id"])] = scenario_from_dict(json.loads(e["setup"]), f"<db experiment {e['id']}>")
        except (TypeError, ValueError, KeyError):
            continue  # an imported OMPL experiment: its setup is not a scenario
    return out


def _our_runs(db: ResultsDB) -> list[dict[str, Any]]:
    return [r for r in db.runs() if r.get("outcome") is not None]


def _planner_order(runs: Sequence[dict[str, Any]]) -> list[str]:
    order = {"seq-bitstar": 0, "bitstar": 1, "dovs": 2}
    return sorted({r["planner"] for r in runs}, key=lambda n: (order.get(n, 9), n))


def figure4(db: ResultsDB, path: str | Path, max_columns: int = 3) -> Path | None:
    """The Figure 4 grid (see the module docstring); None if the database has no runs."""
    runs = _our_runs(db)
    scen = _scenarios(db)
    runs = [r for r in runs if r["experimentid"] in scen]
    if not runs:
        return None
    planners = _planner_order(runs)
    exps: dict[str, int] = {}
    for r in sorted(runs, key=lambda r: (r["n_moving"] or 0, r["scenario"], r["experimentid"])):
        exps.setdefault(r["scenario"], r["experimentid"])
    names = [n for n in ("paper-1", "paper-2", "paper-3") if n in exps] or list(exps)
    names = names[:max_columns]
    nr, nc = len(planners), len(names)
    sc0 = scen[exps[names[0]]]
    aspect = sc0.height / sc0.width
    fig, axes = plt.subplots(nr, nc, figsize=(5.2 * nc, 5.2 * nc * aspect / nc * nr + 0.6 * nr + 0.4),
                             squeeze=False)
    for i, planner in enumerate(planners):
        for j, name in enumerate(names):
            ax = axes[i][j]
            cand = [r for r in runs if r["planner"] == planner and r["scenario"] == name]
            if not cand:
                ax.set_axis_off()
                ax.set_title(f"{planner} / {name}: no run", fontsize=9)
                continue
            cand.sort(key=lambda r: (r["outcome"] != "reached", r["run_index"] or 0, r["id"]))
            best = cand[0]
            res = db.result(int(best["id"]))
            sc = scen[best["experimentid"]]
            if res is None:
                ax.set_axis_off()
                continue
            draw_run_panel(ax, sc, res)
            ok = sum(r["outcome"] == "reached" for r in cand)
            outcome = res.get("status", "?")
            if outcome == "collision":
                outcome = f"collided with {res.get('collision_with')}"
            ax.set_title(f"{planner} on {name} (run {best['run_index']}): {outcome}\n"
                         f"L = {res.get('path_length_m', float('nan')):.2f} m, "
                         f"{len(res.get('virtual_obstacles') or [])} virtual obstacles; "
                         f"{ok}/{len(cand)} runs reached the goal", fontsize=8.5)
            if j > 0:
                ax.set_ylabel("")
            if i < nr - 1:
                ax.set_xlabel("")
    fig.suptitle("Executed paths per planner (rows) and scenario (columns), as the paper's Figure 4",
                 fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


BOX_METRICS = [("path_length", "path length [m] (successful runs)", True),
               ("planning_time_mean", "path generation time [s] (mean per run)", False),
               ("time_to_goal", "time to goal [s] (successful runs)", True),
               ("min_clearance", "minimum clearance [m]", False)]


def boxplots(db: ResultsDB, path: str | Path) -> Path | None:
    """Box plots of the metrics per planner, grouped by the number of moving obstacles."""
    runs = _our_runs(db)
    if not runs:
        return None
    planners = _planner_order(runs)
    ns = sorted({int(r["n_moving"]) for r in runs if r["n_moving"] is not None})
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    width = 0.8 / max(len(planners), 1)
    for ax, (col, label, only_ok) in zip(axes.ravel(), BOX_METRICS, strict=True):
        drawn = False
        for k, planner in enumerate(planners):
            data, pos = [], []
            for g, n in enumerate(ns):
                vals = [r[col] for r in runs if r["planner"] == planner and r["n_moving"] == n
                        and r[col] is not None and (not only_ok or r["outcome"] == "reached")]
                vals = [v for v in vals if math.isfinite(v)]
                if vals:
                    data.append(vals)
                    pos.append(g + (k - (len(planners) - 1) / 2) * width)
            if data:
                color = PLANNER_COLORS[k % len(PLANNER_COLORS)]
                ax.boxplot(data, positions=pos, widths=width * 0.85, patch_artist=True,
                           boxprops={"facecolor": color, "alpha": 0.45, "edgecolor": color},
                           medianprops={"color": "black"}, whiskerprops={"color": color},
                           capprops={"color": color}, flierprops={"markeredgecolor": color})
                # Every run as a dot (boxes of identical values collapse to a line).
                jitter = np.random.default_rng(k).uniform(-0.25, 0.25, size=sum(len(d) for d in data))
                xs = np.concatenate([np.full(len(d), x) for d, x in zip(data, pos, strict=True)])
                ax.scatter(xs + jitter * width, np.concatenate(data), s=9, color=color, alpha=0.7,
                           zorder=3, lw=0)
                drawn = True
            ax.plot([], [], "s", color=PLANNER_COLORS[k % len(PLANNER_COLORS)], alpha=0.6, label=planner)
        ax.set_xticks(range(len(ns)))
        ax.set_xticklabels([str(n) for n in ns])
        ax.set_xlim(-0.6, len(ns) - 0.4)
        ax.set_xlabel("moving obstacles")
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
        if not drawn:
            ax.text(0.5, 0.5, "no data", transform=ax.transAxes, ha="center", va="center", color="gray")
    axes[0][0].legend(fontsize=8)
    fig.suptitle("Metrics per planner and number of moving obstacles", fontsize=11)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _step_median(curves: list[tuple[np.ndarray, np.ndarray]], grid: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    vals = np.full((len(curves), grid.size), np.nan)
    for i, (t, c) in enumerate(curves):
        idx = np.searchsorted(t, grid, side="right") - 1
        ok = idx >= 0
        vals[i, ok] = c[idx[ok]]
    with np.errstate(all="ignore"):
        # A point counts once at least half of the runs have a solution (as OMPL's plots do).
        have = np.sum(np.isfinite(vals), axis=0) * 2 >= len(curves)
        med = np.where(have, np.nanmedian(np.where(np.isfinite(vals), vals, np.inf), axis=0), np.nan)
        lo = np.where(have, np.nanpercentile(np.where(np.isfinite(vals), vals, np.inf), 25, axis=0), np.nan)
        hi = np.where(have, np.nanpercentile(np.where(np.isfinite(vals), vals, np.inf), 75, axis=0), np.nan)
    return med, np.where(np.isfinite(lo), lo, np.nan), np.where(np.isfinite(hi), hi, np.nan)


def cost_time_figure(db: ResultsDB, path: str | Path) -> Path | None:
    """Cost against time (see the module docstring); None if there is no progress data."""
    rows = db.query("SELECT p.runid, p.time, p.best_cost, p.source, c.name AS planner, r.experimentid, "
                    "e.name AS scenario FROM progress p JOIN runs r ON r.id = p.runid "
                    "JOIN plannerConfigs c ON c.id = r.plannerid JOIN experiments e ON e.id = r.experimentid "
                    "WHERE p.best_cost IS NOT NULL ORDER BY p.runid, p.time")
    anytime = [r for r in rows if r["source"] in (None, "planner")]
    use = anytime if anytime else [r for r in rows if r["source"] == "plans"]
    if not use:
        return None
    by: dict[tuple[str, str], dict[int, list[tuple[float, float]]]] = {}
    for r in use:
        by.setdefault((r["scenario"], r["planner"]), {}).setdefault(r["runid"], []).append(
            (float(r["time"]), float(r["best_cost"])))
    scenarios = sorted({k[0] for k in by})[:4]
    fig, axes = plt.subplots(1, len(scenarios), figsize=(5.4 * len(scenarios), 4.2), squeeze=False)
    planners = sorted({k[1] for k in by})
    for ax, scn in zip(axes[0], scenarios, strict=False):
        for k, planner in enumerate(planners):
            runs = by.get((scn, planner))
            if not runs:
                continue
            color = PLANNER_COLORS[k % len(PLANNER_COLORS)]
            ompl = planner.startswith("geometric_") or planner.startswith("control_")
            curves = [(np.array([p[0] for p in v]), np.array([p[1] for p in v])) for v in runs.values()]
            if anytime:
                # Anytime costs only improve: keep the running minimum.
                curves = [(t, np.minimum.accumulate(c)) for t, c in curves]
            tmax = max(float(t[-1]) for t, _ in curves)
            tmin = min(float(t[0]) for t, _ in curves)
            for t, c in curves[:30]:
                ax.step(t, c, where="post", color=color, alpha=0.25 if anytime else 0.5, lw=0.8,
                        marker="" if anytime and len(t) > 20 else "o", ms=3)
            if anytime and tmax > tmin:
                grid = np.geomspace(tmin, tmax, 200) if tmin > 0.0 else np.linspace(tmin, tmax, 200)
                med, lo, hi = _step_median(curves, grid)
                ax.plot(grid, med, color=color, lw=2, ls="--" if ompl else "-",
                        label=f"{planner} (median of {len(curves)})")
                ax.fill_between(grid, lo, hi, color=color, alpha=0.15, lw=0)
            else:
                ax.plot([], [], color=color, lw=2, label=f"{planner} ({len(curves)} runs)")
        ax.set_title(scn, fontsize=10)
        if not anytime:  # a single plan at t = 0 would give a degenerate axis
            t_hi = max((t for (s_, _), runs in by.items() if s_ == scn for v in runs.values() for t, _ in v),
                       default=0.0)
            ax.set_xlim(-0.02 * max(t_hi, 1.0), 1.05 * max(t_hi, 1.0))
        times = [t for (s_, _), runs in by.items() if s_ == scn for v in runs.values() for t, _ in v]
        if anytime and times and min(times) > 0.0:  # anytime curves change most early on
            ax.set_xscale("log")
        ax.set_xlabel("planning time [s]" if anytime else "simulated time [s]")
        ax.set_ylabel("best cost [m]" if anytime else "plan length [m]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Best cost against planning time (OMPL planners dashed)" if anytime else
                 "Length of each new plan over the run (no anytime progress recorded)", fontsize=11)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _html_table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _paper_html(tables: Sequence[PlannerTable]) -> str:
    parts = []
    for t in tables:
        paper = PAPER_TABLES.get(t.planner)
        if not paper:
            continue
        mine = {r.n_moving: r for r in t.rows}
        rows = []
        for n in sorted(set(mine) | set(paper["rows"])):
            p = paper["rows"].get(n, "n/a")
            pc = ["crashed"] * 3 if p is None else ["-"] * 3 if p == "n/a" else [f"{x:g}" for x in p]
            r = mine.get(n)
            oc = ([r.path_length.fmt(3), r.generation_time.fmt(4), r.time_to_goal.fmt(2),
                   f"{r.successes}/{r.runs}"] if r else ["-"] * 4)
            rows.append([str(n), oc[0], pc[0], oc[1], pc[1], oc[2], pc[2], oc[3]])
        parts.append(f"<h3>{html.escape(t.title)} against {html.escape(paper['title'])}</h3>" + _html_table(
            ["moving obstacles", "path length [m] ours", "paper", "generation time [s] ours", "paper",
             "time to goal [s] ours", "paper", "successes ours"], rows))
    return "".join(parts)


def build_report(db_path: str | Path, out: str | Path) -> list[Path]:
    """Write the figures, tables and ``report.html`` of ``db_path`` into ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with ResultsDB(db_path, readonly=True) as db:
        runs = db.runs()
        tables = summarize(runs)
        ptables = summarize(paper_runs(runs))
        written = write_tables(tables, out, ptables)
        figs = [("Figure 4: executed paths", figure4(db, out / "figure4.png")),
                ("Metrics", boxplots(db, out / "boxplots.png")),
                ("Cost against time", cost_time_figure(db, out / "cost_time.png"))]
        exps = db.experiments()
    written += [p for _, p in figs if p is not None]
    n_ours = sum(r.get("outcome") is not None for r in runs)
    parts = ["<!doctype html><html><head><meta charset='utf-8'><title>anyplan benchmark report</title>",
             "<style>body{font-family:sans-serif;max-width:1200px;margin:2em auto;padding:0 1em}"
             "table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #bbb;"
             "padding:3px 8px;text-align:right}th{background:#eee}img{max-width:100%}"
             "code{background:#f4f4f4}</style></head><body>",
             "<h1>anyplan benchmark report</h1>",
             f"<p>Database <code>{html.escape(str(db_path))}</code>: {len(exps)} experiments "
             f"(scenarios), {n_ours} anyplan runs"
             + (f", {len(runs) - n_ours} imported runs" if len(runs) > n_ours else "") + ". "
             "Path length and time to goal are over the successful runs; path generation time is "
             "each run's mean planning-call time. Crashes are collisions with an obstacle; errors are "
             "planner exceptions.</p>",
             "<h2>Tables</h2>"]
    for t in tables:
        parts.append(f"<h3>{html.escape(t.title)}</h3>" + _html_table(HEADERS, [_cells(r) for r in t.rows]))
    parts.append(_paper_html(ptables))
    parts.append("<h2>Scenarios</h2>" + _html_table(
        ["experiment", "scenario", "moving obstacles", "hash", "master seed", "runs", "version"],
        [[str(e["id"]), str(e["name"]), str(e.get("moving_obstacles", "")), str(e.get("scenario_hash", "")),
          str(e["seed"]), str(e["runcount"]), str(e["version"])] for e in exps]))
    for title, p in figs:
        if p is None:
            continue
        b64 = base64.b64encode(p.read_bytes()).decode()
        parts.append(f"<h2>{html.escape(title)}</h2><img alt='{html.escape(title)}' "
                     f"src='data:image/png;base64,{b64}'>")
    parts.append("</body></html>")
    page = out / "report.html"
    page.write_text("\n".join(parts))
    written.append(page)
    return written
