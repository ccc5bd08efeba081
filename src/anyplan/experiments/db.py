"""The results database: one SQLite file in the layout of OMPL's benchmark database.

OMPL's ``ompl_benchmark_statistics.py`` (and so Planner Arena) reads its five tables
(``experiments``, ``plannerConfigs``, ``enums``, ``runs``, ``progress``); we write the same
tables with the same required columns plus our own, and one table of our own, ``results``: the
whole ``result.json`` of each run, zlib-compressed (read back with :meth:`ResultsDB.run_result`,
through :meth:`~anyplan.simulation.RunResult.from_dict`). Only the coordinating process writes,
one committed transaction per finished run, under a writer lock
(:class:`~anyplan.experiments.dbfile.WriterLock`); a file that is not an anyplan database is
refused and never modified; a run's key ``(experimentid, plannerid, run_index, seed)`` is
UNIQUE in the schema. Tables and columns: ``docs/experiments.md``, "The results database".
"""

from __future__ import annotations

import json
import math
import platform
import sqlite3
import zlib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from anyplan import __version__
from anyplan.experiments.dbfile import (
    DEFAULT_LOCK_TIMEOUT_S,
    DatabaseFileError,
    WriterLock,
    check_database,
    connect_readonly,
)
from anyplan.simulation.result import RunResult, RunStatus
from anyplan.trajectory.path import polyline_length

__all__ = [
    "ResultsDB",
    "agent_settings_string",
    "STATUS",
    "STATUS_OF_OUTCOME",
    "RUN_COLUMNS",
    "settings_string",
    "run_row",
    "progress_rows",
    "check_database",
    "DatabaseFileError",
]

SCHEMA_VERSION = "1"

#: OMPL's PlannerStatus descriptions (values 0-9) and our Collision (10).
STATUS: dict[int, str] = {
    0: "Unknown status", 1: "Invalid start", 2: "Invalid goal", 3: "Unrecognized goal type",
    4: "Timeout", 5: "Approximate solution", 6: "Exact solution", 7: "Crash", 8: "Abort",
    9: "Infeasible", 10: "Collision",
}
#: Our run outcome -> status value. ``error`` (the planner raised) is OMPL's "Crash";
#: ``unreachable`` (the goal is proven out of reach before the run) is "Infeasible".
STATUS_OF_OUTCOME = {RunStatus.REACHED: 6, RunStatus.TIMEOUT: 4, RunStatus.COLLISION: 10, "error": 7,
                     RunStatus.UNREACHABLE: 9}

#: Run columns beyond experimentid/plannerid: (name, SQL type). OMPL's first, then ours.
RUN_COLUMNS: list[tuple[str, str]] = [
    ("status", "ENUM"), ("solved", "BOOLEAN"), ("approximate_solution", "BOOLEAN"),
    ("correct_solution", "BOOLEAN"), ("time", "REAL"), ("best_cost", "REAL"),
    ("solution_length", "REAL"), ("memory", "REAL"),
    ("run_index", "INTEGER"), ("seed", "INTEGER"), ("scenario_hash", "TEXT"),
    ("anyplan_version", "TEXT"), ("outcome", "TEXT"), ("reached", "BOOLEAN"), ("collided", "BOOLEAN"),
    ("path_length", "REAL"), ("time_to_goal", "REAL"), ("sim_time", "REAL"),
    ("planning_calls", "INTEGER"), ("planning_time_first", "REAL"), ("planning_time_mean", "REAL"),
    ("planning_time_p95", "REAL"), ("planning_time_max", "REAL"), ("planning_time_total", "REAL"),
    ("replans", "INTEGER"), ("virtual_obstacles", "INTEGER"), ("plans", "INTEGER"),
    ("min_clearance", "REAL"), ("collision_with", "TEXT"), ("collision_time", "REAL"),
    ("wall_time", "REAL"), ("worker", "TEXT"), ("error", "TEXT"),
    ("robot_caused", "BOOLEAN"), ("time_lower_bound", "REAL"), ("time_over_lower_bound", "REAL"),
    ("fallbacks", "INTEGER"), ("min_distance_to_moving", "REAL"), ("discomfort_time", "REAL"),
]

_EXPERIMENT_EXTRA = [("scenario_hash", "TEXT"), ("moving_obstacles", "INTEGER"), ("suite", "TEXT"),
                     ("sim_dt", "REAL")]


def settings_string(config: Mapping[str, Any]) -> str:
    """OMPL-style planner settings: ``"key = value;"`` per entry, sorted; empty for {}."""
    return "".join(f"{k} = {json.dumps(config[k], sort_keys=True)};" for k in sorted(config))


#: The robot's errors a settings string names, as (prefix, ``SimConfig`` property, the names of
#: its two spreads): ``--actuation-noise`` and ``--localization-noise``.
_ERRORS = (("actuation", "actuation", ("sigma_v", "sigma_omega")),
           ("localization", "localization", ("sigma_xy", "sigma_theta")))


def agent_settings_string(config: Mapping[str, Any], sim: Any = None) -> str:
    """The settings string of a benchmarked agent: its planner's (:func:`settings_string`), then,
    from the simulation settings ``sim`` (a :class:`~anyplan.simulation.SimConfig`; None: none),
    its tracker's (``SimConfig.tracker``, ``anyplan bench --tracker``) as
    ``tracker.NAME = VALUE;`` in name order, then the robot's execution error when there is one
    (``SimConfig.actuation``; ``--actuation-noise``) as
    ``actuation.sigma_v = V;actuation.sigma_omega = W;``, then its localization error when there
    is one (``SimConfig.localization``; ``--localization-noise``) as
    ``localization.sigma_xy = S;localization.sigma_theta = T;``: runs with other tracker
    settings or another execution or localization error are another planner row."""
    out = settings_string(config)
    if sim is None:
        return out
    out += "".join(f"tracker.{k} = {json.dumps(float(v))};" for k, v in sorted(sim.tracker))
    for prefix, prop, names in _ERRORS:
        spreads = getattr(sim, prop)
        if any(float(a) != 0.0 for a in spreads):
            out += "".join(f"{prefix}.{n} = {json.dumps(float(a))};"
                           for n, a in zip(names, spreads, strict=True))
    return out


def _fin(x: Any) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def run_row(result: Mapping[str, Any] | None, *, run_index: int, seed: int, scenario_hash: str,
            error: str | None = None, worker: str = "", wall_time: float | None = None) -> dict[str, Any]:
    """The ``runs`` row of one run's ``result.json`` (or of a run whose planner raised)."""
    if result is None:
        return {"status": STATUS_OF_OUTCOME["error"], "solved": 0, "approximate_solution": 0,
                "correct_solution": 0, "time": None, "best_cost": None, "solution_length": None,
                "memory": None, "run_index": run_index, "seed": seed, "scenario_hash": scenario_hash,
                "anyplan_version": __version__, "outcome": "error", "reached": 0, "collided": 0,
                "wall_time": _fin(wall_time), "worker": worker, "error": error}
    res = RunResult.from_dict(result)
    outcome = str(res.status)
    reached = bool(res.reached_goal) and res.status == RunStatus.REACHED
    pts = np.asarray(res.planning_times_s, dtype=float)
    traj = res.trajectory or [[0.0]]
    length = _fin(res.path_length_m)
    return {
        "status": STATUS_OF_OUTCOME.get(outcome, 0),
        "solved": int(reached), "approximate_solution": 0, "correct_solution": int(reached),
        "time": float(pts.sum()) if pts.size else 0.0,
        "best_cost": length if reached else None, "solution_length": length if reached else None,
        "memory": None,
        "run_index": run_index, "seed": seed, "scenario_hash": scenario_hash,
        "anyplan_version": str(res.anyplan_version),
        "outcome": outcome, "reached": int(reached), "collided": int(bool(res.collision)),
        "path_length": length, "time_to_goal": _fin(res.time_to_goal_s),
        "sim_time": _fin(traj[-1][0]),
        "planning_calls": int(pts.size),
        "planning_time_first": float(pts[0]) if pts.size else None,
        "planning_time_mean": float(pts.mean()) if pts.size else None,
        "planning_time_p95": float(np.percentile(pts, 95)) if pts.size else None,
        "planning_time_max": float(pts.max()) if pts.size else None,
        "planning_time_total": float(pts.sum()) if pts.size else 0.0,
        "replans": int(res.replans or 0),
        "virtual_obstacles": len(res.virtual_obstacles),
        "plans": len(res.plans),
        "min_clearance": _fin(res.min_clearance_m),
        "collision_with": res.collision_with,
        "collision_time": _fin(res.collision_time_s),
        "wall_time": _fin(wall_time if wall_time is not None else res.wall_time_s),
        "worker": worker, "error": error,
        "robot_caused": (None if res.collision_robot_caused is None
                         else int(bool(res.collision_robot_caused))),
        "time_lower_bound": _fin(res.time_lower_bound_s),
        "time_over_lower_bound": _fin(res.time_over_lower_bound),
        "fallbacks": len(res.extra.get("fallbacks") or []),
        "min_distance_to_moving": _fin(res.min_distance_to_moving_m),
        "discomfort_time": _fin(res.discomfort_time_s),
    }


def _polyline_length(path: Any) -> float | None:
    p = np.asarray(path, dtype=float)
    if p.ndim != 2 or p.shape[0] < 2 or p.shape[1] < 2:
        return None
    return polyline_length(p[:, :2])


def progress_rows(result: Mapping[str, Any]) -> list[tuple[float, float, int | None, str]]:
    """``(time, best_cost, plan_index, source)`` rows of a run (see the module docstring).

    An anytime planner's own history (``extra["progress"]``) is preferred; otherwise the lengths
    of the executed plans against the simulated time they were made. Duplicate times keep the
    last value (the table's key is ``(runid, time)``).
    """
    extra = result.get("extra") or {}
    rows: dict[float, tuple[float, float, int | None, str]] = {}
    hist = extra.get("progress") if isinstance(extra, Mapping) else None
    if hist:
        for item in hist:
            try:
                t, c = float(item[0]), float(item[1])
            except (TypeError, ValueError, IndexError):
                continue
            if math.isfinite(t) and math.isfinite(c):
                rows[t] = (t, c, None, "planner")
        if rows:
            return sorted(rows.values())
    for i, plan in enumerate(result.get("plans") or []):
        try:
            t = float(plan["t"])
        except (KeyError, TypeError, ValueError):
            continue
        length = _polyline_length(plan.get("path"))
        if length is not None and math.isfinite(t):
            rows[t] = (t, length, i, "plans")
    return sorted(rows.values())


@dataclass(frozen=True)
class ExperimentKey:
    """What identifies an experiment row: the scenario's content and the bench settings."""

    name: str
    scenario_hash: str
    seed: int
    sim_dt: float
    timelimit: float


class ResultsDB:
    """Read and write a results database (see the module docstring).

    Args:
        path: The SQLite file; created with the schema if missing (unless ``readonly``).
        readonly: Open an existing database read-only (no lock, nothing can be changed).
        lock_timeout_s: How long to wait for another writer [s] before refusing.

    Raises:
        DatabaseFileError: not an anyplan database, damaged, read-only (for writing), missing
            (for reading), or being written by another process.
    """

    def __init__(self, path: str | Path, *, readonly: bool = False,
                 lock_timeout_s: float = DEFAULT_LOCK_TIMEOUT_S) -> None:
        self.path = Path(path)
        self.readonly = readonly
        self._lock: WriterLock | None = None
        if readonly:
            check_database(self.path, "database")
            self.conn = connect_readonly(self.path)
            return
        if self.path.is_dir():
            raise DatabaseFileError(f"database {self.path}: is a folder, not a results database")
        self._lock = WriterLock(self.path, "database", lock_timeout_s)
        self._lock.acquire()
        try:
            # Checked under the lock: the file may have been created by the previous writer.
            check_database(self.path, "database", must_exist=False, writable=True)
            self.conn = sqlite3.connect(str(self.path), timeout=30.0)
            try:
                self.conn.execute("PRAGMA foreign_keys = ON")
                self._create()
            except BaseException:
                self.conn.close()
                raise
        except sqlite3.DatabaseError as exc:
            self._lock.release()
            raise DatabaseFileError(f"database {self.path}: cannot write ({exc})") from None
        except BaseException:
            self._lock.release()
            raise

    # ---------------------------------------------------------------- schema
    def _create(self) -> None:
        c = self.conn
        c.executescript("""
            CREATE TABLE IF NOT EXISTS experiments
              (id INTEGER PRIMARY KEY AUTOINCREMENT, name VARCHAR(512), totaltime REAL,
               timelimit REAL, memorylimit REAL, runcount INTEGER, version VARCHAR(128),
               hostname VARCHAR(1024), cpuinfo TEXT, date DATETIME, seed VARCHAR(24), setup TEXT);
            CREATE TABLE IF NOT EXISTS plannerConfigs
              (id INTEGER PRIMARY KEY AUTOINCREMENT, name VARCHAR(512) NOT NULL, settings TEXT);
            CREATE TABLE IF NOT EXISTS enums
              (name VARCHAR(512), value INTEGER, description TEXT, PRIMARY KEY (name, value));
            CREATE TABLE IF NOT EXISTS runs
              (id INTEGER PRIMARY KEY AUTOINCREMENT, experimentid INTEGER, plannerid INTEGER,
               FOREIGN KEY (experimentid) REFERENCES experiments(id) ON DELETE CASCADE,
               FOREIGN KEY (plannerid) REFERENCES plannerConfigs(id) ON DELETE CASCADE);
            CREATE TABLE IF NOT EXISTS progress
              (runid INTEGER, time REAL, PRIMARY KEY (runid, time),
               FOREIGN KEY (runid) REFERENCES runs(id) ON DELETE CASCADE);
            CREATE TABLE IF NOT EXISTS results
              (runid INTEGER PRIMARY KEY, encoding TEXT NOT NULL, data BLOB NOT NULL,
               FOREIGN KEY (runid) REFERENCES runs(id) ON DELETE CASCADE);
            CREATE TABLE IF NOT EXISTS anyplan_meta (key TEXT PRIMARY KEY, value TEXT);
        """)
        self._add_columns("experiments", _EXPERIMENT_EXTRA)
        self._add_columns("runs", RUN_COLUMNS)
        self._add_columns("progress", [("best_cost", "REAL"), ("plan_index", "INTEGER"),
                                       ("source", "TEXT")])
        c.execute("DROP INDEX IF EXISTS runs_by_key")  # the unique index below replaces it
        try:
            c.execute("CREATE UNIQUE INDEX IF NOT EXISTS runs_unique_key "
                      "ON runs (experimentid, plannerid, run_index, seed)")
        except sqlite3.IntegrityError:
            c.rollback()
            n = c.execute("SELECT count(*) - count(DISTINCT experimentid || ',' || plannerid || ',' "
                          "|| run_index || ',' || seed) FROM runs WHERE run_index IS NOT NULL").fetchone()[0]
            raise DatabaseFileError(f"database {self.path}: holds {n} runs stored twice (by an "
                                    "older anyplan); it is left unchanged. Copy it, delete the "
                                    "duplicate rows of table runs, then retry") from None
        for value, desc in STATUS.items():
            c.execute("INSERT OR IGNORE INTO enums VALUES ('status', ?, ?)", (value, desc))
        c.execute("INSERT OR IGNORE INTO anyplan_meta VALUES ('schema_version', ?)", (SCHEMA_VERSION,))
        self.compute_views()
        c.commit()

    def _columns(self, table: str) -> list[str]:
        return [r[1] for r in self.conn.execute(f"PRAGMA table_info({table})")]

    def _add_columns(self, table: str, cols: Iterable[tuple[str, str]]) -> None:
        have = set(self._columns(table))
        for name, typ in cols:
            if name not in have:
                self.conn.execute(f"ALTER TABLE {table} ADD {name} {typ}")

    def compute_views(self) -> None:
        """(Re)create OMPL's two summary views (best planner configurations by solved, time)."""
        base = ("SELECT plannerid, plannerConfigs.name AS plannerName, experimentid, solved, "
                "time AS total_time FROM plannerConfigs INNER JOIN experiments INNER JOIN runs "
                "ON plannerConfigs.id = runs.plannerid AND experiments.id = runs.experimentid")
        per_exp = (f"SELECT plannerid, plannerName, experimentid, AVG(solved) AS avg_solved, "
                   f"AVG(total_time) AS avg_total_time FROM ({base}) GROUP BY plannerid, experimentid")
        overall = (f"SELECT plannerid, plannerName, AVG(solved) AS avg_solved, "
                   f"AVG(total_time) AS avg_total_time FROM ({base}) GROUP BY plannerid")
        c = self.conn
        c.execute("DROP VIEW IF EXISTS bestPlannerConfigsPerExperiment")
        c.execute("CREATE VIEW bestPlannerConfigsPerExperiment AS SELECT plannerid, experimentid, "
                  f"MAX(avg_solved) AS avg_solved, avg_total_time FROM ({per_exp}) "
                  "GROUP BY plannerName, experimentid ORDER BY avg_solved DESC, avg_total_time ASC")
        c.execute("DROP VIEW IF EXISTS bestPlannerConfigs")
        c.execute("CREATE VIEW bestPlannerConfigs AS SELECT plannerid, MAX(avg_solved) AS avg_solved, "
                  f"avg_total_time FROM ({overall}) GROUP BY plannerName "
                  "ORDER BY avg_solved DESC, avg_total_time ASC")

    def close(self) -> None:
        """Commit, close and release the writer's lock."""
        try:
            if not self.readonly:
                self.conn.commit()
            self.conn.close()
        finally:
            if self._lock is not None:
                self._lock.release()
                self._lock = None

    def __enter__(self) -> ResultsDB:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ---------------------------------------------------------------- writing
    def experiment_id(self, key: ExperimentKey, *, scenario_json: str, moving_obstacles: int,
                      runcount: int, suite: str) -> int:
        """The id of the experiment ``key``, created (and committed) if new."""
        row = self.conn.execute(
            "SELECT id FROM experiments WHERE name = ? AND scenario_hash = ? AND seed = ? "
            "AND abs(sim_dt - ?) < 1e-12 AND abs(timelimit - ?) < 1e-9",
            (key.name, key.scenario_hash, str(key.seed), key.sim_dt, key.timelimit)).fetchone()
        if row is not None:
            self.conn.execute("UPDATE experiments SET runcount = max(runcount, ?) WHERE id = ?",
                              (runcount, row[0]))
            self.conn.commit()
            return int(row[0])
        cur = self.conn.execute(
            "INSERT INTO experiments (name, totaltime, timelimit, memorylimit, runcount, version, "
            "hostname, cpuinfo, date, seed, setup, scenario_hash, moving_obstacles, suite, sim_dt) "
            "VALUES (?, 0.0, ?, 0.0, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (key.name, key.timelimit, runcount, f"anyplan {__version__}", platform.node(),
             f"{platform.processor() or platform.machine()}; python {platform.python_version()}",
             datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S"), str(key.seed), scenario_json,
             key.scenario_hash, moving_obstacles, suite, key.sim_dt))
        self.conn.commit()
        return int(cur.lastrowid or 0)

    def planner_id(self, name: str, settings: str) -> int:
        """The id of planner configuration (name, settings), created (and committed) if new."""
        row = self.conn.execute("SELECT id FROM plannerConfigs WHERE name = ? AND settings = ?",
                                (name, settings)).fetchone()
        if row is not None:
            return int(row[0])
        cur = self.conn.execute("INSERT INTO plannerConfigs (name, settings) VALUES (?, ?)",
                                (name, settings))
        self.conn.commit()
        return int(cur.lastrowid or 0)

    def done_keys(self) -> set[tuple[int, int, int, int]]:
        """``(experimentid, plannerid, run_index, seed)`` of every stored run."""
        return {(int(r[0]), int(r[1]), int(r[2]), int(r[3])) for r in self.conn.execute(
            "SELECT experimentid, plannerid, run_index, seed FROM runs WHERE run_index IS NOT NULL")}

    def add_run(self, experimentid: int, plannerid: int, row: Mapping[str, Any],
                result: Mapping[str, Any] | None) -> int:
        """Insert one finished run (runs, progress, results) and commit it; returns its id."""
        cols = ["experimentid", "plannerid"] + list(row)
        vals = [experimentid, plannerid] + list(row.values())
        key = (experimentid, plannerid, row.get("run_index"), row.get("seed"))
        with self.conn:  # one transaction: all of the run or nothing
            try:
                cur = self.conn.execute(
                    f"INSERT INTO runs ({', '.join(cols)}) VALUES ({', '.join('?' * len(cols))})", vals)
            except sqlite3.IntegrityError:  # the run is stored already: keep the first copy
                old = self.conn.execute(
                    "SELECT id FROM runs WHERE experimentid = ? AND plannerid = ? AND run_index = ? "
                    "AND seed = ?", key).fetchone()
                if old is None:
                    raise
                return int(old[0])
            runid = int(cur.lastrowid or 0)
            if result is not None:
                self.conn.executemany(
                    "INSERT OR REPLACE INTO progress (runid, time, best_cost, plan_index, source) "
                    "VALUES (?, ?, ?, ?, ?)", [(runid, *r) for r in progress_rows(result)])
                blob = zlib.compress(json.dumps(result, separators=(",", ":")).encode(), 6)
                self.conn.execute("INSERT INTO results VALUES (?, 'json+zlib', ?)", (runid, blob))
            wall = row.get("wall_time")
            if wall is not None:  # OMPL's "seconds spent to collect the data"
                self.conn.execute("UPDATE experiments SET totaltime = coalesce(totaltime, 0) + ? "
                                  "WHERE id = ?", (float(wall), experimentid))
        return runid

    # ---------------------------------------------------------------- reading
    def result(self, runid: int) -> dict[str, Any] | None:
        """The whole ``result.json`` of run ``runid`` (None if not stored)."""
        row = self.conn.execute("SELECT encoding, data FROM results WHERE runid = ?", (runid,)).fetchone()
        if row is None:
            return None
        enc, data = row
        if enc == "json+zlib":
            return json.loads(zlib.decompress(data).decode())
        if enc == "json":
            return json.loads(data)
        raise ValueError(f"run {runid}: unknown result encoding '{enc}'")

    def run_result(self, runid: int) -> RunResult | None:
        """The stored result of run ``runid`` as a :class:`RunResult` (None if not stored)."""
        data = self.result(runid)
        return None if data is None else RunResult.from_dict(data)

    def query(self, sql: str, params: tuple[Any, ...] = ()) -> list[dict[str, Any]]:
        """Rows of ``sql`` as dictionaries."""
        cur = self.conn.execute(sql, params)
        names = [d[0] for d in cur.description]
        return [dict(zip(names, r, strict=True)) for r in cur.fetchall()]

    def runs(self) -> list[dict[str, Any]]:
        """Every run joined with its planner and experiment (``planner``, ``settings``,
        ``scenario``, ``n_moving``, ``experiment_seed`` and all run columns)."""
        have = set(self._columns("experiments"))
        n_moving = "e.moving_obstacles" if "moving_obstacles" in have else "NULL"
        return self.query(
            f"SELECT r.*, p.name AS planner, p.settings AS settings, e.name AS scenario, "
            f"{n_moving} AS n_moving, e.seed AS experiment_seed, e.version AS experiment_version "
            "FROM runs r JOIN plannerConfigs p ON p.id = r.plannerid "
            "JOIN experiments e ON e.id = r.experimentid ORDER BY r.id")

    def progress(self, runid: int) -> list[dict[str, Any]]:
        """Progress rows of run ``runid``, by time."""
        return self.query("SELECT * FROM progress WHERE runid = ? ORDER BY time", (runid,))

    def experiments(self) -> list[dict[str, Any]]:
        """All experiment rows."""
        return self.query("SELECT * FROM experiments ORDER BY id")
