"""What the interactive report shows, read from a results database alone, as plain JSON data.

* ``meta``: when and by what the report was written (UTC date, anyplan version, git commit of
  the anyplan source if it is a git checkout, host, Python) and the definitions of "±" and "n".
* ``experiments``: one entry per experiment row (scenario, date, host, version, master seed...).
* ``runs``: one entry per run with its metrics and seed.
* ``tables``: the paper-style tables (same rules as :func:`anyplan.experiments.tables.summarize`),
  every cell with the ids of the runs it is computed from (the report's drill-down).
* ``series``: per metric, per planner, mean ± std against the number of moving obstacles.
* ``scenes`` and ``tracks``: per experiment the static scene and the moving obstacles' true
  positions sampled every :data:`PLAYBACK_DT_S` (recomputed from the scenario stored in the
  database; obstacle motions do not depend on the run), and per run the robot's trajectory at
  the same times, its virtual obstacles and its collision: what the playback animates.
"""

from __future__ import annotations

import math
import platform
import subprocess
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from anyplan import __version__
from anyplan.experiments.db import ResultsDB
from anyplan.experiments.tables import Stat
from anyplan.geometry.shapes import Circle
from anyplan.world.scenario import Scenario

__all__ = ["report_data", "PLAYBACK_DT_S", "DEFINITIONS", "git_commit"]

#: Time step [s] of the playback samples.
PLAYBACK_DT_S = 0.2

DEFINITIONS = {
    "±": "mean ± sample standard deviation (divisor n − 1) over the runs counted in that cell; "
         "no ± when n < 2.",
    "n": "number of runs counted in that cell: runs that reached the goal for path length and "
         "time to goal; runs with at least one planning call for path generation time; all runs "
         "for the outcome counts and minimum clearance.",
    "path generation time": "per run, the mean wall time [s] of its planning calls.",
    "success": "reached the goal without a collision within the time limit.",
    "seed": "each run's agent seed, derived from the experiment's master seed and the run index.",
}

#: Table columns: (key, header, unit, digits, which runs count).
METRICS = [("path_length", "path length", "m", 3, "reached"),
           ("planning_time_mean", "path generation time", "s", 4, "planned"),
           ("time_to_goal", "time to goal", "s", 2, "reached"),
           ("min_clearance", "minimum clearance", "m", 3, "all")]
OUTCOMES = [("reached", "successes"), ("collision", "crashes"), ("timeout", "timeouts"),
            ("error", "errors")]

RUN_KEYS = ["id", "planner", "settings", "scenario", "experimentid", "n_moving", "run_index", "seed",
            "outcome", "path_length", "time_to_goal", "planning_time_mean", "planning_calls",
            "min_clearance", "virtual_obstacles", "replans", "sim_time", "collision_with",
            "anyplan_version"]


def git_commit(where: str | Path | None = None) -> str | None:
    """The git commit (short hash, ``+dirty`` if modified) of the anyplan source, or None."""
    where = Path(where) if where is not None else Path(__file__).resolve().parent
    try:
        out = subprocess.run(["git", "-C", str(where), "rev-parse", "--short=12", "HEAD"],
                             capture_output=True, text=True, timeout=5, check=False)
        if out.returncode != 0:
            return None
        dirty = subprocess.run(["git", "-C", str(where), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5, check=False)
        return out.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return None


def _num(x: Any, digits: int = 6) -> float | None:
    if x is None:
        return None
    x = float(x)
    return round(x, digits) if math.isfinite(x) else None


def _counted(r: Mapping[str, Any], which: str) -> bool:
    if which == "reached":
        return r.get("outcome") == "reached"
    if which == "planned":
        return (r.get("planning_calls") or 0) > 0
    return True


def _cell(runs: Sequence[Mapping[str, Any]], key: str, digits: int, which: str) -> dict[str, Any]:
    used = [r for r in runs if _counted(r, which) and _num(r.get(key)) is not None]
    st = Stat.of(float(r[key]) for r in used)
    return {"text": st.fmt(digits), "mean": _num(st.mean), "std": _num(st.std), "n": st.n,
            "runs": [int(r["id"]) for r in used]}


def _tables(runs: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    groups: dict[tuple[str, str], dict[int, list[Mapping[str, Any]]]] = {}
    for r in runs:
        if r.get("outcome") is None or r.get("n_moving") is None:
            continue
        groups.setdefault((str(r["planner"]), str(r.get("settings") or "")), {}).setdefault(
            int(r["n_moving"]), []).append(r)
    order = {"seq-bitstar": 0, "bitstar": 1, "dovs": 2}
    out = []
    for (planner, settings), by_n in sorted(groups.items(), key=lambda kv: (order.get(kv[0][0], 9), kv[0])):
        rows = []
        for n in sorted(by_n):
            rs = by_n[n]
            row: dict[str, Any] = {"n_moving": n, "runs": [int(r["id"]) for r in rs]}
            for key, _, _, digits, which in METRICS:
                row[key] = _cell(rs, key, digits, which)
            for outcome, name in OUTCOMES:
                ids = [int(r["id"]) for r in rs if r["outcome"] == outcome]
                row[name] = {"text": f"{len(ids)}/{len(rs)}" if outcome == "reached" else str(len(ids)),
                             "n": len(ids), "runs": ids}
            rows.append(row)
        out.append({"planner": planner, "settings": settings,
                    "title": planner + (f" [{settings}]" if settings else ""), "rows": rows})
    return out


def _series(tables: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    out = []
    for key, label, unit, _, which in METRICS:
        lines = []
        for t in tables:
            pts = [{"x": row["n_moving"], "y": row[key]["mean"], "sd": row[key]["std"], "n": row[key]["n"],
                    "runs": row[key]["runs"]} for row in t["rows"] if row[key]["n"] > 0]
            lines.append({"name": t["title"], "points": pts})
        out.append({"key": key, "label": f"{label} [{unit}]", "counted": which, "lines": lines})
    return out


def _scene(sc: Scenario) -> dict[str, Any]:
    statics = []
    for o in sc.static_obstacles:
        s = o.shape
        if isinstance(s, Circle):
            statics.append({"name": o.name, "circle": [_num(s.center[0], 4), _num(s.center[1], 4),
                                                       _num(s.radius, 4)]})
        else:
            statics.append({"name": o.name, "polygon": np.round(np.asarray(s.vertices), 4).tolist()})
    r = sc.robot
    x0, y0, _, _ = sc.bounds
    return {"name": sc.name, "x0": x0, "y0": y0, "width": sc.width, "height": sc.height,
            "statics": statics, "static_map": sc.static_map is not None,
            "robot_radius": r.radius, "start": [float(v) for v in r.start],
            "goal": [float(v) for v in r.goal],
            "goal_tolerance": r.goal_tolerance,
            "movers": [{"name": o.name, "radius": o.radius,
                        "span": [_num(v, 3) if math.isfinite(v) else None for v in o.motion.span]}
                       for o in sc.moving_obstacles]}


def _track(res: Mapping[str, Any], ts: np.ndarray) -> dict[str, Any]:
    traj = np.asarray(res.get("trajectory") or [[0.0, 0, 0, 0, 0, 0]], dtype=float).reshape(-1, 6)
    t = ts[ts <= traj[-1, 0] + 1e-9]
    if len(t) == 0 or t[-1] < traj[-1, 0] - 1e-9:
        t = np.append(t, traj[-1, 0])
    xs = np.interp(t, traj[:, 0], traj[:, 1])
    ys = np.interp(t, traj[:, 0], traj[:, 2])
    th = np.interp(t, traj[:, 0], np.unwrap(traj[:, 3]))
    return {"t": np.round(t, 3).tolist(), "x": np.round(xs, 3).tolist(), "y": np.round(ys, 3).tolist(),
            "th": np.round(th, 3).tolist(),
            "virtual": [[_num(v["center"][0], 3), _num(v["center"][1], 3), _num(v["side"], 3),
                         _num(v.get("created_at_s", 0.0), 3)] for v in res.get("virtual_obstacles") or []],
            "collision": (None if not res.get("collision") else
                          {"t": _num(res.get("collision_time_s"), 3), "with": res.get("collision_with")}),
            "status": res.get("status")}


def report_data(db: ResultsDB, scenarios: Mapping[int, Scenario], db_name: str = "") -> dict[str, Any]:
    """Everything the interactive report shows (see the module docstring).

    Args:
        db: The open results database.
        scenarios: Scenario of each experiment id (experiments whose setup is not a scenario,
            such as imported OMPL logs, are left out of the playback).
        db_name: How to name the database in the report.
    """
    all_runs = db.runs()
    runs = [r for r in all_runs if r.get("outcome") is not None]
    exps = db.experiments()
    tables = _tables(runs)
    seeds = sorted({str(e["seed"]) for e in exps})
    meta = {"generated_utc": datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S"),
            "anyplan_version": __version__, "git_commit": git_commit(), "host": platform.node(),
            "python": platform.python_version(), "database": db_name,
            "master_seeds": seeds, "n_runs": len(runs), "n_imported_runs": len(all_runs) - len(runs),
            "definitions": DEFINITIONS, "playback_dt_s": PLAYBACK_DT_S}
    experiments = [{k: e.get(k) for k in ("id", "name", "date", "hostname", "cpuinfo", "version", "seed",
                                          "runcount", "suite", "scenario_hash", "moving_obstacles",
                                          "sim_dt", "timelimit", "totaltime")} for e in exps]
    scenes: dict[str, Any] = {}
    tracks: dict[str, Any] = {}
    by_exp: dict[int, list[dict[str, Any]]] = {}
    for r in runs:
        by_exp.setdefault(int(r["experimentid"]), []).append(r)
    for eid, rs in by_exp.items():
        sc = scenarios.get(eid)
        if sc is None:
            continue
        t_end = max((float(r["sim_time"] or 0.0) for r in rs), default=0.0)
        ts = np.arange(0.0, t_end + PLAYBACK_DT_S, PLAYBACK_DT_S)
        scene = _scene(sc)
        scene["t"] = np.round(ts, 3).tolist()
        scene["mover_xy"] = [np.round(o.motion.positions(ts), 3).T.tolist() for o in sc.moving_obstacles]
        scenes[str(eid)] = scene
        for r in rs:
            res = db.result(int(r["id"]))
            if res is not None:
                tracks[str(r["id"])] = _track(res, ts)
    return {"meta": meta, "experiments": experiments,
            "runs": [{k: (_num(r.get(k)) if isinstance(r.get(k), float) else r.get(k)) for k in RUN_KEYS}
                     for r in runs],
            "tables": tables, "series": _series(tables),
            "metrics": [{"key": k, "label": lab, "unit": u, "counted": w} for k, lab, u, _, w in METRICS],
            "scenes": scenes, "tracks": tracks}
