"""Figures and a self-contained, interactive HTML report from a results database (and nothing else).

Figures are made at print size (:mod:`anyplan.viz.style`) as PNG, SVG or PDF: ``figure4`` (the
paper's Figure 4 as a grid of representative runs), ``boxplots`` (path length, generation time,
time to goal and clearance per planner and number of moving obstacles), ``cost_time`` (best cost
against planning time, ours and OMPL's), then ``tables.md``, ``tables.csv`` and ``report.html``
(:mod:`anyplan.viz.report_html`).

What each figure draws: ``docs/experiments.md``, "Report: the figures".
"""

from __future__ import annotations

import io
import json
import math
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullFormatter

from anyplan.experiments.db import ResultsDB
from anyplan.experiments.tables import compare_planners, paper_runs, summarize, write_tables
from anyplan.viz.run import PATH_CMAP, draw_run, run_legend_handles
from anyplan.viz.style import (
    COLUMN_WIDTH_IN,
    TEXT_WIDTH_IN,
    LabelPlacer,
    figure_path,
    new_figure,
    paper_style,
    save_figure,
    tight,
)
from anyplan.world.scenario import Scenario, scenario_from_dict
from anyplan.world.sensing import without_unread_settings

__all__ = ["build_report", "figure4", "boxplots", "cost_time_figure", "draw_run_panel"]

PLANNER_COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"]


def draw_run_panel(ax: Any, scenario: Scenario, result: dict[str, Any], *, t_max: float | None = None
                   ) -> LabelPlacer:
    """One run on ``ax``: :func:`anyplan.viz.run.draw_run` without colour bar and title, on the
    arena (obstacles may leave it; what lies outside is clipped). Returns its label placer."""
    x0, y0, x1, y1 = scenario.bounds
    ax.set_xlim(x0 - 0.3, x1 + 0.3)
    ax.set_ylim(y0 - 0.3, y1 + 0.3)
    placer = draw_run(ax, scenario, result, colorbar=False, title=False, t_max=t_max)
    for artist in [*ax.patches, *ax.lines, *ax.collections]:
        artist.set_clip_on(True)
    return placer


def _scenarios(db: ResultsDB) -> dict[int, Scenario]:
    out = {}
    for e in db.experiments():
        try:
            data = json.loads(e["setup"])
            if isinstance(data, dict) and "sensing" in data:  # stored before oracle and twist
                data["sensing"] = without_unread_settings(data["sensing"])  # refused tracked keys
            out[int(e["id"])] = scenario_from_dict(data, f"<db experiment {e['id']}>")
        except (TypeError, ValueError, KeyError):
            continue  # an imported OMPL experiment: its setup is not a scenario
    return out


def _our_runs(db: ResultsDB) -> list[dict[str, Any]]:
    return [r for r in db.runs() if r.get("outcome") is not None]


def _planner_order(runs: Sequence[dict[str, Any]]) -> list[str]:
    order = {"seq-bitstar": 0, "bitstar": 1, "dovs": 2}
    return sorted({r["planner"] for r in runs}, key=lambda n: (order.get(n, 9), n))


def figure4(db: ResultsDB, path: str | Path, max_columns: int = 3, png_copy: Any = None) -> Path | None:
    """The Figure 4 grid (see the module docstring), 7.16 in wide, one time colour bar [s]
    shared by all panels and one legend; None if the database has no runs."""
    runs = _our_runs(db)
    scen = _scenarios(db)
    runs = [r for r in runs if r["experimentid"] in scen]
    if not runs:
        return None
    planners = _planner_order(runs)
    exps: dict[str, int] = {}
    for r in sorted(runs, key=lambda r: (r["n_moving"] or 0, r["scenario"], r["experimentid"])):
        exps.setdefault(r["scenario"], r["experimentid"])
    names: list[str] = [n for n in ("paper-1", "paper-2", "paper-3") if n in exps] or list(exps)
    names = names[:max_columns]
    panels: dict[tuple[int, int], tuple[dict[str, Any], dict[str, Any], list[dict[str, Any]]]] = {}
    for i, planner in enumerate(planners):
        for j, name in enumerate(names):
            cand = [r for r in runs if r["planner"] == planner and r["scenario"] == name]
            cand.sort(key=lambda r: (r["outcome"] != "reached", r["run_index"] or 0, r["id"]))
            res = db.result(int(cand[0]["id"])) if cand else None
            if res is not None:
                panels[(i, j)] = (cand[0], res, cand)
    t_max = max((float(res["trajectory"][-1][0]) for _, res, _ in panels.values() if res["trajectory"]),
                default=1.0)
    nr, nc = len(planners), len(names)
    sc0 = scen[exps[names[0]]]
    panel_w = (0.88 * TEXT_WIDTH_IN - 0.7) / nc
    panel_h = panel_w * (sc0.height + 0.6) / (sc0.width + 0.6) + 0.55
    with paper_style():
        fig_h = nr * panel_h + 1.2
        fig = new_figure((TEXT_WIDTH_IN, fig_h))
        axes = fig.subplots(nr, nc, squeeze=False)
        placers = []
        for (i, j), ax in np.ndenumerate(axes):
            planner, name = planners[i], names[j]
            if (i, j) not in panels:
                ax.set_axis_off()
                ax.set_title(f"{name}: no run")
                continue
            best, res, cand = panels[(i, j)]
            placers.append(draw_run_panel(ax, scen[best["experimentid"]], res, t_max=t_max))
            ok = sum(r["outcome"] == "reached" for r in cand)
            outcome = res.get("status", "?")
            if outcome == "collision":
                outcome = f"hit {res.get('collision_with')}"
            ax.set_title(f"{name}, run {best['run_index']}: {outcome}\n"
                         f"L = {res.get('path_length_m', float('nan')):.2f} m, {ok}/{len(cand)} reached")
            ax.set_ylabel(f"{planner}\ny [m]" if j == 0 else "")
            if i < nr - 1:
                ax.set_xlabel("")
        import matplotlib

        sm = matplotlib.cm.ScalarMappable(norm=Normalize(0.0, t_max), cmap=PATH_CMAP)
        tight(fig, (0.0, 0.65 / fig_h, 0.9, 1.0), h_pad=0.6, w_pad=0.4)
        cax = fig.add_axes((0.91, 0.25, 0.018, 0.6))
        fig.colorbar(sm, cax=cax).set_label("time [s]")
        fig.legend(handles=run_legend_handles(), loc="lower center", ncol=3, frameon=False)
        for p in placers:
            p.layout()
    return save_figure(fig, path, placers=placers, png_copy=png_copy)


BOX_METRICS = [("path_length", "path length [m]\n(successful runs)", True),
               ("planning_time_mean", "generation time [s]\n(mean per run)", False),
               ("time_to_goal", "time to goal [s]\n(successful runs)", True),
               ("min_clearance", "min. clearance [m]\n(all runs)", False)]


def boxplots(db: ResultsDB, path: str | Path, png_copy: Any = None) -> Path | None:
    """Box plots of the metrics per planner, grouped by the number of moving obstacles."""
    runs = _our_runs(db)
    if not runs:
        return None
    planners = _planner_order(runs)
    with paper_style():
        return _boxplots(runs, planners, path, png_copy)


def _boxplots(runs: list[dict[str, Any]], planners: list[str], path: str | Path, png_copy: Any) -> Path:
    ns = sorted({int(r["n_moving"]) for r in runs if r["n_moving"] is not None})
    fig = new_figure((TEXT_WIDTH_IN, 5.6))
    axes = fig.subplots(2, 2)
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
                ax.scatter(xs + jitter * width, np.concatenate(data), s=5, color=color, alpha=0.7,
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
        ax.yaxis.set_major_locator(MaxNLocator(nbins=5))
    fig.legend(*axes[0][0].get_legend_handles_labels(), loc="lower center", frameon=False,
               ncol=min(len(planners), 4))
    fig.suptitle("Metrics per planner and number of moving obstacles\n(boxes: quartiles and median; "
                 "dots: single runs)")
    rows = math.ceil(len(planners) / 4)
    tight(fig, (0.0, (0.1 + 0.17 * rows) / 5.6, 1.0, 1.0))
    return save_figure(fig, path, png_copy=png_copy)


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


def cost_time_figure(db: ResultsDB, path: str | Path, max_columns: int = 3,
                     png_copy: Any = None) -> Path | None:
    """Cost against time (see the module docstring), one panel per scenario (all of them, as
    small multiples ``max_columns`` wide); None if there is no progress data."""
    rows = db.query("SELECT p.runid, p.time, p.best_cost, p.source, c.name AS planner, r.experimentid, "
                    "r.sim_time, e.name AS scenario FROM progress p JOIN runs r ON r.id = p.runid "
                    "JOIN plannerConfigs c ON c.id = r.plannerid JOIN experiments e ON e.id = r.experimentid "
                    "WHERE p.best_cost IS NOT NULL ORDER BY p.runid, p.time")
    anytime = [r for r in rows if r["source"] in (None, "planner")]
    use = anytime if anytime else [r for r in rows if r["source"] == "plans"]
    if not use:
        return None
    by: dict[tuple[str, str], dict[int, list[tuple[float, float]]]] = {}
    ends: dict[int, float] = {}
    for r in use:
        by.setdefault((r["scenario"], r["planner"]), {}).setdefault(r["runid"], []).append(
            (float(r["time"]), float(r["best_cost"])))
        if r["sim_time"] is not None:
            ends[r["runid"]] = float(r["sim_time"])
    scenarios = sorted({k[0] for k in by})
    planners = sorted({k[1] for k in by})
    ompl_any = any(p.startswith(("geometric_", "control_")) for p in planners)
    nc = min(max_columns, len(scenarios))
    nr = math.ceil(len(scenarios) / nc)
    with paper_style():
        fig_w = TEXT_WIDTH_IN if nc > 1 else COLUMN_WIDTH_IN
        fig_h = 2.1 * nr + 1.1
        fig = new_figure((fig_w, fig_h))
        axes = fig.subplots(nr, nc, squeeze=False)
        for ax in axes.ravel()[len(scenarios):]:
            ax.set_axis_off()
        handles: dict[str, Any] = {}
        for ax, scn in zip(axes.ravel(), scenarios, strict=False):
            _cost_panel(ax, scn, by, planners, anytime=bool(anytime), ends=ends, handles=handles)
        if anytime:
            title = ("Best solution cost against planning time: median over runs (thick line), "
                     "inter-quartile range (band),\nsingle runs (thin lines)"
                     + ("; OMPL planners dashed" if ompl_any else ""))
        else:
            title = ("No anytime progress recorded: length of each new plan against the simulated "
                     "time it was made,\none line per run")
        fig.suptitle(textwrap.fill(title.replace("\n", " "), width=int(12 * fig_w), break_on_hyphens=False))
        fig.legend(handles=list(handles.values()), loc="lower center", frameon=False,
                   ncol=1 if nc == 1 else min(len(handles), 3))
        legend_rows = len(handles) if nc == 1 else math.ceil(len(handles) / 3)
        tight(fig, (0.0, (0.12 + 0.16 * legend_rows) / fig_h, 1.0, 1.0))
    return save_figure(fig, path, png_copy=png_copy)


def _cost_panel(ax: Any, scn: str, by: dict[tuple[str, str], dict[int, list[tuple[float, float]]]],
                planners: list[str], *, anytime: bool, ends: dict[int, float],
                handles: dict[str, Any]) -> None:
    times: list[float] = []
    t_all = [p[0] for pl in planners for v in (by.get((scn, pl)) or {}).values() for p in v]
    # Planning times in the unit that gives readable ticks (no "1e-5" offset).
    unit, scale = ("s", 1.0)
    if anytime and t_all and max(t_all) < 1.0:
        unit, scale = ("ms", 1e3) if max(t_all) >= 1e-3 else ("µs", 1e6)
    for k, planner in enumerate(planners):
        runs = by.get((scn, planner))
        if not runs:
            continue
        color = PLANNER_COLORS[k % len(PLANNER_COLORS)]
        ls = "--" if planner.startswith(("geometric_", "control_")) else "-"
        curves = []
        for runid, v in runs.items():
            t = scale * np.array([p[0] for p in v])
            c = np.array([p[1] for p in v])
            if anytime:  # anytime costs only improve: keep the running minimum
                c = np.minimum.accumulate(c)
            elif runid in ends and ends[runid] > t[-1]:  # the last plan holds to the run's end
                t, c = np.append(t, ends[runid]), np.append(c, c[-1])
            curves.append((t, c))
            times.extend(t.tolist())
        for t, c in curves:
            if len(t) == 1:  # one solution and no later improvement: a point
                ax.plot(t, c, marker="o", ms=3, color=color, alpha=0.6, ls="none")
            ax.step(t, c, where="post", color=color, alpha=0.3 if anytime else 0.6, lw=0.6, ls=ls)
        tmin = min(float(t[0]) for t, _ in curves)
        tmax = max(float(t[-1]) for t, _ in curves)
        label = f"{planner} ({len(curves)} runs)"
        if anytime and tmax > tmin:
            grid = np.geomspace(tmin, tmax, 200) if tmin > 0.0 else np.linspace(tmin, tmax, 200)
            med, lo, hi = _step_median(curves, grid)
            (line,) = ax.plot(grid, med, color=color, lw=1.6, ls=ls)
            ax.fill_between(grid, lo, hi, color=color, alpha=0.15, lw=0)
            label = f"{planner} (median of {len(curves)} runs)"
        else:
            (line,) = ax.plot([], [], color=color, lw=1.6, ls=ls)
        line.set_label(label)
        handles.setdefault(label, line)
    ax.set_title(scn)
    if anytime and times and min(times) > 0.0 and max(times) > 10.0 * min(times):
        # Anytime curves change most early on: a log axis once they span a decade.
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(LogLocator(numticks=4))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    else:
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
        if not anytime:  # a single plan at t = 0 would give a degenerate axis
            t_hi = max(times, default=1.0)
            ax.set_xlim(-0.02 * max(t_hi, 1.0), 1.05 * max(t_hi, 1.0))
    ax.yaxis.set_major_locator(MaxNLocator(nbins=5))
    ax.set_xlabel(f"planning time [{unit}]" if anytime else "simulated time [s]")
    ax.set_ylabel("best cost [m]" if anytime else "plan length [m]")
    ax.grid(alpha=0.3)


def build_report(db_path: str | Path, out: str | Path, fmt: str = "png") -> list[Path]:
    """Write the figures (in ``fmt``: png, svg or pdf), the tables and the interactive
    ``report.html`` of ``db_path`` into ``out``; returns the files written."""
    from anyplan.viz.report_data import report_data
    from anyplan.viz.report_html import render_page

    fmt = figure_path("x", fmt).suffix[1:]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with ResultsDB(db_path, readonly=True) as db:
        runs = db.runs()
        tables = summarize(runs)
        ptables = summarize(paper_runs(runs))
        pairs = compare_planners(runs)
        written = write_tables(tables, out, ptables, pairs)
        pngs: list[tuple[str, bytes]] = []
        for title, fn, name in (("Figure 4: executed paths", figure4, "figure4"),
                                ("Metrics", boxplots, "boxplots"),
                                ("Cost against time", cost_time_figure, "cost_time")):
            buf = io.BytesIO()
            p = fn(db, out / f"{name}.{fmt}", png_copy=buf)
            if p is not None:
                written.append(p)
                pngs.append((title, buf.getvalue()))
        data = report_data(db, _scenarios(db), db_name=Path(db_path).name)
    written.append(render_page(data, ptables, pngs, out / "report.html", pairs))
    return written
