"""The interactive report page: one self-contained HTML file (no network, no CDN).

Sections, listed in a table of contents: overview and metadata (with the definitions of "±" and
"n"), the paper-style tables, ours against the paper, interactive plots (SVG drawn by the page's
own script, values on hover, click for the runs), all runs, the trajectory playback, the paper
figures (PNG embedded) and the experiments. Every number of a table is a link to the runs behind
it; every run has a button that plays its trajectory (robot and moving obstacles animated).

The page's script and style sheet (``assets/report.js``, ``assets/report.css``) are inlined, and
the data (:func:`anyplan.viz.report_data.report_data`) travels as JSON in the page.
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

from anyplan.experiments.tables import (
    COMPARISON_HEADERS,
    PAPER_TABLES,
    PlannerPair,
    PlannerTable,
    pair_cells,
)

__all__ = ["render_page"]

SECTIONS = [("overview", "Overview"), ("tables", "Tables"), ("paper", "Ours against the paper"),
            ("plots", "Interactive plots"), ("runs", "Runs"), ("playback", "Playback"),
            ("figures", "Figures"), ("experiments", "Experiments")]


def _asset(name: str) -> str:
    return resources.files("anyplan.viz").joinpath("assets", name).read_text(encoding="utf-8")


def _e(x: Any) -> str:
    return html.escape("" if x is None else str(x), quote=True)


def _fmt(x: Any, digits: int) -> str:
    return "-" if x is None else f"{float(x):.{digits}f}"


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]], attrs: str = "",
           row_attrs: Sequence[str] | None = None) -> str:
    """Rows are lists of ready ``<td>`` HTML; ``row_attrs`` are extra attributes per row."""
    head = "".join(f"<th>{_e(h)}</th>" for h in headers)
    ra = row_attrs or [""] * len(rows)
    body = "".join(f"<tr{a}>" + "".join(r) + "</tr>" for r, a in zip(rows, ra, strict=True))
    return f"<table class='sortable'{attrs}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _td(text: str, v: Any = None) -> str:
    dv = "" if v is None else f" data-v='{_e(v)}'"
    return f"<td{dv}>{_e(text)}</td>"


def _drill(cell: Mapping[str, Any], what: str) -> str:
    ids = " ".join(str(i) for i in cell["runs"])
    v = cell.get("mean", cell.get("n"))
    dv = "" if v is None else f" data-v='{_e(v)}'"
    label = f"{what} (n = {cell['n']})"
    return (f"<td{dv}><a class='drill' href='#runs' data-runs='{ids}' data-what='{_e(label)}' "
            f"title='{_e(label)}: show these runs'>{_e(cell['text'])}</a></td>")


def _summary_tables(data: Mapping[str, Any]) -> str:
    metrics = data["metrics"]
    headers = (["moving obstacles", "runs"] + [f"{m['label']} [{m['unit']}]" for m in metrics]
               + ["successes", "crashes", "timeouts", "errors"])
    parts = []
    for t in data["tables"]:
        rows = []
        for row in t["rows"]:
            where = f"{t['title']}, {row['n_moving']} moving obstacles"
            cells = [_td(str(row["n_moving"]), row["n_moving"]),
                     _drill({"text": str(len(row["runs"])), "n": len(row["runs"]), "runs": row["runs"]},
                            f"{where}: all runs")]
            cells += [_drill(row[m["key"]], f"{where}: {m['label']}") for m in metrics]
            cells += [_drill(row[k], f"{where}: {k}") for k in ("successes", "crashes", "timeouts", "errors")]
            rows.append(cells)
        parts.append(f"<h3>{_e(t['title'])}</h3>" + _table(headers, rows))
    return "".join(parts) or "<p>No anyplan runs in this database.</p>"


def _paper_tables(ptables: Sequence[PlannerTable]) -> str:
    parts = []
    for t in ptables:
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
            rows.append([_td(str(n), n), _td(oc[0]), _td(pc[0]), _td(oc[1]), _td(pc[1]), _td(oc[2]),
                         _td(pc[2]), _td(oc[3])])
        parts.append(f"<h3>{_e(t.title)} against {_e(paper['title'])}</h3>" + _table(
            ["moving obstacles", "path length [m] ours", "paper", "generation time [s] ours", "paper",
             "time to goal [s] ours", "paper", "successes ours"], rows))
    return "".join(parts) or "<p>No runs on the paper's scenarios (paper-1..3).</p>"


def _runs_table(data: Mapping[str, Any]) -> str:
    headers = ["run", "planner", "scenario", "moving obstacles", "run index", "seed", "outcome",
               "path length [m]", "time to goal [s]", "generation time [s]", "min. clearance [m]",
               "virtual obstacles", "playback"]
    rows = []
    for r in data["runs"]:
        play = (f"<td><button class='play' data-run='{r['id']}' title='play run {r['id']}'>play</button></td>"
                if str(r["id"]) in data["tracks"] else "<td>-</td>")
        name = r["planner"] + (f" [{r['settings']}]" if r["settings"] else "")
        rows.append([_td(str(r["id"]), r["id"]), _td(name),
                     _td(r["scenario"]), _td(str(r["n_moving"]), r["n_moving"]),
                     _td(str(r["run_index"]), r["run_index"]), _td(str(r["seed"]), r["seed"]),
                     _td(r["outcome"] + (f" ({r['collision_with']})" if r.get("collision_with") else "")),
                     _td(_fmt(r["path_length"], 3), r["path_length"]),
                     _td(_fmt(r["time_to_goal"], 2), r["time_to_goal"]),
                     _td(_fmt(r["planning_time_mean"], 4), r["planning_time_mean"]),
                     _td(_fmt(r["min_clearance"], 3), r["min_clearance"]),
                     _td(str(r["virtual_obstacles"] or 0), r["virtual_obstacles"] or 0), play])
    return _table(headers, rows, " id='runs-table'", [f" data-id='{r['id']}'" for r in data["runs"]])


def _meta(data: Mapping[str, Any]) -> str:
    m = data["meta"]
    items = [("report written (UTC)", m["generated_utc"]), ("by anyplan", m["anyplan_version"]),
             ("git commit", m["git_commit"] or "not a git checkout"), ("on host", m["host"]),
             ("Python", m["python"]), ("database", m["database"]),
             ("runs", f"{m['n_runs']} anyplan runs" + (f", {m['n_imported_runs']} imported runs"
                                                        if m["n_imported_runs"] else "")),
             ("master seeds", ", ".join(m["master_seeds"]) or "-")]
    exps = data["experiments"]
    for key, label in (("date", "benchmarked (UTC)"), ("hostname", "benchmark hosts"),
                       ("version", "benchmark versions")):
        vals = sorted({str(e[key]) for e in exps if e.get(key)})
        if vals and key == "date":
            items.append((label, vals[0] if len(vals) == 1 else f"{vals[0]} to {vals[-1]}"))
        elif vals:
            items.append((label, ", ".join(vals)))
    dl = "".join(f"<dt>{_e(k)}</dt><dd>{_e(v)}</dd>" for k, v in items)
    defs = "".join(f"<dt>{_e(k)}</dt><dd>{_e(v)}</dd>" for k, v in m["definitions"].items())
    return (f"<dl class='meta'>{dl}</dl><h3>Definitions</h3><dl class='meta' id='definitions'>{defs}</dl>"
            "<p class='note'>Click a number in a table (or a point in a plot) for the runs behind it, "
            "and <em>play</em> in the runs table for a run's trajectory.</p>")


def _experiments(data: Mapping[str, Any]) -> str:
    headers = ["experiment", "scenario", "moving obstacles", "scenario hash", "master seed",
               "runs per planner",
               "date (UTC)", "host", "version", "suite", "dt [s]", "time limit [s]"]
    rows = [[_td(str(e["id"]), e["id"]), _td(e["name"]), _td(str(e.get("moving_obstacles") or ""),
                                                            e.get("moving_obstacles")),
             _td(e.get("scenario_hash")), _td(e["seed"]), _td(str(e["runcount"]), e["runcount"]),
             _td(e.get("date")), _td(e.get("hostname")), _td(e.get("version")), _td(e.get("suite")),
             _td(str(e.get("sim_dt")), e.get("sim_dt")), _td(str(e.get("timelimit")), e.get("timelimit"))]
            for e in data["experiments"]]
    return _table(headers, rows)


def _finite(obj: Any) -> Any:
    """``obj`` with every non-finite float replaced by None (JSON has no NaN or infinity)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Mapping):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    return obj


def _pairs(pairs: Sequence[PlannerPair]) -> str:
    if not pairs:
        return ""
    rows = [[_td(c) for c in pair_cells(p)] for p in pairs]
    return ("<h3>Paired comparisons</h3><p class='note'>Two configurations over the runs both "
            "made (same scenario, run index and seed): the difference of their rates with its "
            "95 % interval (Newcombe) and McNemar's exact p. An interval that holds 0 does not "
            "show a difference at that level.</p>" + _table(COMPARISON_HEADERS, rows))


def render_page(data: Mapping[str, Any], ptables: Sequence[PlannerTable],
                figures: Sequence[tuple[str, bytes]], out: Path,
                pairs: Sequence[PlannerPair] = ()) -> Path:
    """Write ``out`` (the HTML file) from the report data, the paper comparison tables, the
    figures as PNG bytes ``(title, png)`` and the paired comparisons ``pairs``
    (:func:`anyplan.experiments.tables.compare_planners`); returns ``out``."""
    toc = "".join(f"<li><a href='#{sid}'>{_e(title)}</a></li>" for sid, title in SECTIONS)
    figs = "".join(f"<h3>{_e(t)}</h3><img alt='{_e(t)}' src='data:image/png;base64,"
                   f"{base64.b64encode(png).decode()}'>" for t, png in figures) or "<p>No figures.</p>"
    body = {
        "overview": _meta(data),
        "tables": ("<p class='note'>One table per planner configuration, one row per number of "
                   "moving obstacles. Path length and time to goal are over the successful runs; "
                   "crashes are collisions; errors are planner exceptions.</p>" + _summary_tables(data)
                   + _pairs(pairs)),
        "paper": _paper_tables(ptables),
        "plots": "<div class='plots' id='plots-box'></div>",
        "runs": "<p id='runs-filter'></p>" + _runs_table(data),
        "playback": ("<p id='pb-title'>Choose a run (play) in the runs table.</p>"
                     "<div class='pb-controls'><button id='pb-play'>play</button>"
                     "<input type='range' id='pb-slider' min='0' max='1' step='0.05' value='0' "
                     "aria-label='time'><span id='pb-time'></span>"
                     "<label>speed <select id='pb-speed'><option value='1'>x1</option>"
                     "<option value='4' selected>x4</option><option value='10'>x10</option>"
                     "</select></label></div><canvas id='pb-canvas' width='900' height='660'></canvas>"
                     "<p class='legend'><span><i class='sw' style='background:#1f77b4'></i>robot and "
                     "its path</span><span><i class='sw' style='background:#d62728'></i>moving "
                     "obstacles (true motion)</span><span><i class='sw' style='background:#b0b0b0'>"
                     "</i>static obstacles</span><span><i class='sw' style='background:rgba(30,99,214,.3)'>"
                     "</i>virtual obstacles (from their creation)</span></p>"),
        "figures": figs,
        "experiments": _experiments(data),
    }
    sections = "".join(f"<section id='{sid}'><h2>{_e(title)}</h2>{body[sid]}</section>"
                       for sid, title in SECTIONS)
    blob = json.dumps(_finite(data), separators=(",", ":"), allow_nan=False).replace("</", "<\\/")
    page = ("<!doctype html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width,initial-scale=1'>"
            "<title>anyplan benchmark report</title><style>" + _asset("report.css") + "</style></head><body>"
            f"<nav id='toc'><h2>Contents</h2><ol>{toc}</ol></nav><main><h1>anyplan benchmark report</h1>"
            f"{sections}</main><script type='application/json' id='report-data'>{blob}</script>"
            "<script>" + _asset("report.js") + "</script></body></html>")
    out.write_text(page, encoding="utf-8")
    return out
