"""The benchmark runner: every (scenario, planner, run) in parallel, results into the database.

Work is split into :class:`RunTask` objects (picklable: the validated scenario and its content
hash, the validated :class:`~anyplan.simulation.SimConfig`, the planner's registry name and
config, the seed): settings are validated once, at the edge, and a worker neither re-parses nor
re-hashes them. :func:`execute_task` (safe for ``spawn`` workers and Dask alike) builds the agent
and returns the whole ``result.json`` dictionary or the planner's error. Only the coordinating
process writes the database, one transaction per finished run, so an interruption loses no
finished run and ``resume=True`` runs only the missing ones. Run ``i`` uses the seed
``derive_seed(master_seed, i)`` (common random numbers). Backends: in-process (``jobs=1``), a
spawn ``ProcessPoolExecutor`` (``jobs>1``) or a Dask cluster (``scheduler=...``, extra
``anyplan[dask]``). See ``docs/experiments.md``.
"""

from __future__ import annotations

import json
import logging
import os
import socket
import sys
import time
import traceback
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from anyplan.agents.base import AGENTS, Agent, make_agent
from anyplan.agents.settings import SettingsError, build_agent_config
from anyplan.errors import AnyplanError
from anyplan.experiments.db import ExperimentKey, ResultsDB, agent_settings_string, run_row, settings_string
from anyplan.experiments.progress import ProgressBar
from anyplan.simulation.simulator import SimConfig, simulate
from anyplan.world.scenario import Scenario

__all__ = ["PlannerSpec", "RunTask", "BenchError", "BenchInterrupted", "BenchSummary", "derive_seed",
           "execute_task", "plan_tasks", "run_bench", "parse_planners", "check_planner_config"]

log = logging.getLogger(__name__)


class BenchError(AnyplanError):
    """Bad bench input (unknown planner, overlapping runs without resume, ...)."""


class BenchInterrupted(RuntimeError):
    """The bench stopped early (a worker died, the scheduler went away); finished runs are saved."""


@dataclass(frozen=True)
class PlannerSpec:
    """A planner to benchmark: registry ``name`` and keyword ``config`` for :func:`make_agent`."""

    name: str
    config: Mapping[str, Any] = field(default_factory=dict)

    @property
    def settings(self) -> str:
        """OMPL-style settings string of the config."""
        return settings_string(self.config)


def parse_planners(text: str, configs: Sequence[str] = ()) -> list[PlannerSpec]:
    """Planners from a comma-separated list of registry names (``"seq-bitstar,dovs"``), each
    with the keyword config given by a ``NAME=JSON-object`` item of ``configs`` (e.g.
    ``'bitstar={"time_budget_s": 0.2}'``), if any.

    Raises:
        BenchError: an empty list, a repeated name, or a malformed/unused config.
    """
    names = [s.strip() for s in text.split(",") if s.strip()]
    if not names:
        raise BenchError.about("planners", ": expected a comma-separated list of planner names")
    if len(set(names)) != len(names):
        raise BenchError.about("planners", f": a planner is listed twice ({text})")
    cfg: dict[str, dict[str, Any]] = {}
    for item in configs:
        name, sep, blob = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise BenchError.about("config", f": expected NAME=JSON, got '{item}'")
        if name not in names:
            raise BenchError.about("config", f": planner '{name}' is not in {{planners}} "
                                   f"({', '.join(names)})", "planners")
        try:
            obj = json.loads(blob)
        except json.JSONDecodeError as exc:
            raise BenchError.about("config", f" {name}: not JSON ({exc.msg} at column {exc.colno})") from None
        except (ValueError, RecursionError) as exc:  # an int of more than 4300 digits; [[[...
            why = "nested too deeply" if isinstance(exc, RecursionError) else "a number with too many digits"
            raise BenchError.about("config", f" {name}: cannot read the JSON ({why})") from None
        if not isinstance(obj, dict):
            raise BenchError.about("config", f" {name}: expected a JSON object like {{\"key\": 1}}")
        cfg.setdefault(name, {}).update(obj)
    return [PlannerSpec(n, cfg.get(n, {})) for n in names]


def check_planner_config(spec: PlannerSpec) -> PlannerSpec:
    """``spec`` with its config checked as ``--set`` checks agent settings
    (:func:`~anyplan.agents.settings.build_agent_config`: known keys, their types, the agent's
    own checks), so a bad config fails before the bench. A value is kept as given unless the
    check converted it into another one (the string ``"0.5"`` of a float setting becomes 0.5),
    so the recorded settings of a good config are unchanged.

    Raises:
        BenchError: about ``config``, naming the planner; or the planner is not an agent
            class (:func:`_planner_entry`).
    """
    _planner_entry(spec.name)
    return _checked_config(spec)


def _checked_config(spec: PlannerSpec) -> PlannerSpec:
    """:func:`check_planner_config` once the planner is known to be an agent class."""
    if not spec.config:
        return spec
    try:
        checked = build_agent_config(AGENTS.get(spec.name), spec.name, dict(spec.config))
    except SettingsError as exc:
        raise BenchError.about("config", f" {spec.name}: {exc.rest.lstrip(': ')}") from None
    return PlannerSpec(spec.name, {k: v if _same(v, checked[k]) else checked[k]
                                   for k, v in spec.config.items()})


def _same(given: Any, checked: Any) -> bool:
    """Whether the checked value is the given one (``1`` and ``1.0``, ``[1, 2]`` and
    ``(1.0, 2.0)`` are; the string ``"1"`` and ``1.0`` are not)."""
    if isinstance(given, list | tuple) and isinstance(checked, list | tuple):
        return len(given) == len(checked) and all(map(_same, given, checked))
    return isinstance(given, str) == isinstance(checked, str) and bool(given == checked)


def derive_seed(master_seed: int, run_index: int) -> int:
    """The seed of run ``run_index``: 32 bits of ``SeedSequence([master_seed, run_index])``."""
    ss = np.random.SeedSequence([int(master_seed) & 0xFFFFFFFFFFFFFFFF, int(run_index)])
    return int(ss.generate_state(1, np.uint32)[0])


@dataclass(frozen=True)
class RunTask:
    """One simulated run, as validated objects that pickle to a worker."""

    scenario: Scenario
    scenario_name: str
    scenario_hash: str
    planner: str
    planner_config: dict[str, Any]
    planner_entry: str | None
    run_index: int
    seed: int
    sim: SimConfig
    experimentid: int = -1
    plannerid: int = -1

    @property
    def label(self) -> str:
        """``scenario/planner#run``."""
        return f"{self.scenario_name}/{self.planner}#{self.run_index}"


def _worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def execute_task(task: RunTask) -> dict[str, Any]:
    """Run one task (in any process); returns ``{result, error, wall_time, worker}``.

    An exception of the planner (or simulator) is caught and returned as ``error`` (the run is
    stored with OMPL's status "Crash"); ``KeyboardInterrupt`` and ``SystemExit`` propagate.
    """
    t0 = time.perf_counter()
    try:
        if task.planner not in AGENTS and task.planner_entry:
            AGENTS.register(task.planner, task.planner_entry)
        agent = make_agent(task.planner, **task.planner_config)
        result = simulate(task.scenario, agent, seed=task.seed, config=task.sim).to_dict()
        if result.get("planner") != task.planner:  # agents may set a different .name
            result["agent_name"] = result.get("planner")
            result["planner"] = task.planner
        return {"result": result, "error": None, "wall_time": time.perf_counter() - t0,
                "worker": _worker_name()}
    except Exception as exc:  # noqa: BLE001 - a planner bug is a result, not a bench failure
        tb = traceback.format_exc(limit=6)
        return {"result": None, "error": f"{type(exc).__name__}: {exc}\n{tb}",
                "wall_time": time.perf_counter() - t0, "worker": _worker_name()}


def _planner_entry(name: str) -> str | None:
    """``module:qualname`` of a registered agent class, for registration inside workers.

    Raises:
        BenchError: the planner cannot be imported, or is not an :class:`Agent` class.
    """
    try:
        cls = AGENTS.get(name)
    except ImportError as exc:
        raise BenchError(f"planner '{name}' is registered but cannot be imported ({exc})") from None
    if not (isinstance(cls, type) and issubclass(cls, Agent)):
        # refused before any run, as make_agent would refuse it in every one
        raise BenchError(f"planner '{name}' ({AGENTS.origin(name)}) is not an anyplan.agents.Agent "
                         f"subclass: {cls!r}")
    mod, qual = getattr(cls, "__module__", None), getattr(cls, "__qualname__", None)
    if not mod or not qual or "<locals>" in qual:
        return None
    return f"{mod}:{qual}"


def plan_tasks(scenarios: Sequence[Scenario], planners: Sequence[PlannerSpec], runs: int,
               master_seed: int, dt: float = 0.05, time_limit: float | None = None,
               sim: SimConfig | None = None) -> list[RunTask]:
    """All tasks, ordered run-major so that partial results cover every planner and scenario,
    each with its planner's config checked (:func:`check_planner_config`); ``sim`` (if given)
    replaces ``dt`` and ``time_limit``."""
    if runs < 1:
        raise BenchError.about("runs", f" must be >= 1, got {runs}")
    sim = sim if sim is not None else _sim_config(dt, time_limit)
    entries = {p.name: _planner_entry(p.name) for p in planners}  # every planner, then every config
    checked = [_checked_config(p) for p in planners]
    tasks = []
    for i in range(runs):
        seed = derive_seed(master_seed, i)
        for sc in scenarios:
            for p in checked:
                tasks.append(RunTask(sc, sc.name, sc.content_hash(), p.name, dict(p.config),
                                     entries[p.name], i, seed, sim))
    return tasks


def _sim_config(dt: float, time_limit: float | None) -> SimConfig:
    try:
        return SimConfig(dt=dt, time_limit=time_limit)
    except ValueError as exc:
        raise BenchError(str(exc)) from None


@dataclass
class BenchSummary:
    """What a bench did: ``planned`` tasks, ``skipped`` (already in the DB), ``finished`` now,
    ``errors`` among them, and ``interrupted``."""

    planned: int = 0
    skipped: int = 0
    finished: int = 0
    errors: int = 0
    interrupted: bool = False
    outcomes: dict[str, int] = field(default_factory=dict)
    wall_time_s: float = 0.0


# ------------------------------------------------------------------------------- backends
def _serial(tasks: Sequence[RunTask]) -> Iterator[tuple[RunTask, dict[str, Any]]]:
    for t in tasks:
        yield t, execute_task(t)


def _process_pool(tasks: Sequence[RunTask], jobs: int) -> Iterator[tuple[RunTask, dict[str, Any]]]:
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool

    from anyplan.experiments.workers import die_with_parent

    ex = ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn"),
                             initializer=die_with_parent, initargs=(os.getpid(),))
    ok = False
    try:
        futs = {ex.submit(execute_task, t): t for t in tasks}
        for f in as_completed(futs):
            try:
                out = f.result()
            except BrokenProcessPool as exc:
                raise BenchInterrupted(f"a worker process died ({exc})") from None
            yield futs[f], out
        ok = True
    finally:
        # On an interruption, drop the queued tasks and do not wait for running ones.
        ex.shutdown(wait=ok, cancel_futures=True)


def _dask(tasks: Sequence[RunTask], scheduler: Any) -> Iterator[tuple[RunTask, dict[str, Any]]]:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise BenchError.about("scheduler", " needs Dask: pip install 'anyplan[dask]'") from None
    own = not hasattr(scheduler, "submit")
    try:
        client = Client(scheduler, timeout="20s") if own else scheduler
    except (OSError, TimeoutError) as exc:
        raise BenchError.about("scheduler", f" {scheduler}: cannot connect ({exc})") from None
    try:
        futs = {}
        for t in tasks:
            f = client.submit(execute_task, t, pure=False, key=f"anyplan-{t.label}-{t.seed}-{os.getpid()}")
            futs[f] = t
        try:
            for f in as_completed(list(futs)):
                try:
                    out = f.result()
                except KeyboardInterrupt:
                    raise
                except Exception as exc:  # KilledWorker, CommClosedError, ...
                    raise BenchInterrupted(f"Dask task {futs[f].label} failed "
                                           f"({type(exc).__name__}: {exc})") from None
                yield futs[f], out
        finally:
            client.cancel([f for f in futs if not f.done()])
    finally:
        if own:
            client.close()


# ------------------------------------------------------------------------------- the bench
def run_bench(scenarios: Sequence[Scenario], planners: Sequence[PlannerSpec], runs: int,
              db_path: str | Path, *, master_seed: int = 0, jobs: int = 1, dt: float = 0.05,
              time_limit: float | None = None, resume: bool = False, scheduler: Any = None,
              suite: str = "", progress: bool = True, stream: TextIO | None = None,
              sim: SimConfig | None = None) -> BenchSummary:
    """Run every (scenario, planner, run) and store each finished run at once.

    Args:
        scenarios: The scenarios.
        planners: The planners (registry names and configs).
        runs: Runs per (scenario, planner).
        db_path: The SQLite results database (created if missing).
        master_seed: Seed from which every run's seed is derived.
        jobs: Worker processes (1 = in this process).
        dt: Simulation step [s].
        time_limit: Simulated time limit [s]; None uses each scenario's.
        resume: Run only the tasks missing from the database. Without it, a database that already
            holds any of the tasks is refused (to avoid duplicate runs).
        scheduler: A Dask scheduler address (or ``distributed.Client``); overrides ``jobs``.
        suite: The suite's name, recorded in ``experiments.suite``.
        progress: Show a progress bar on ``stream``.
        stream: Where progress and notices go (default stderr).
        sim: Validated simulation settings; replaces ``dt`` and ``time_limit`` when given.

    Raises:
        BenchError: bad input, or runs already present without ``resume``.
        BenchInterrupted: a worker or the cluster failed; finished runs are saved.
        KeyboardInterrupt: after saving what finished and cancelling the rest.
    """
    stream = stream if stream is not None else sys.stderr
    if jobs < 1:
        raise BenchError.about("jobs", f" must be >= 1, got {jobs}")
    sim = sim if sim is not None else _sim_config(dt, time_limit)
    dt, time_limit = sim.dt, sim.time_limit
    all_tasks = plan_tasks(scenarios, planners, runs, master_seed, sim=sim)
    summary = BenchSummary(planned=len(all_tasks))
    t_start = time.perf_counter()
    with ResultsDB(db_path) as db:
        exp_ids: dict[str, int] = {}
        for sc in scenarios:
            h = sc.content_hash()
            key = ExperimentKey(sc.name, h, int(master_seed), float(dt),
                                float(time_limit if time_limit is not None else sc.time_limit))
            exp_ids[h] = db.experiment_id(key, scenario_json=json.dumps(sc.to_dict()),
                                          moving_obstacles=len(sc.moving_obstacles), runcount=runs,
                                          suite=suite)
        # the tracker's settings, the execution and localization errors (the same for every task) are part of
        # each planner's row
        # the tasks' configs are the checked ones (a value the check converted, converted)
        configs = {(t.planner, settings_string(t.planner_config)): t.planner_config for t in all_tasks}
        plan_ids = {key: db.planner_id(key[0], agent_settings_string(cfg, sim))
                    for key, cfg in configs.items()}
        done = db.done_keys()
        tasks = []
        for t in all_tasks:
            t2 = replace(t, experimentid=exp_ids[t.scenario_hash],
                         plannerid=plan_ids[(t.planner, settings_string(t.planner_config))])
            if (t2.experimentid, t2.plannerid, t2.run_index, t2.seed) in done:
                summary.skipped += 1
            else:
                tasks.append(t2)
        if summary.skipped and not resume:
            raise BenchError(f"{db_path} already holds {summary.skipped} of these "
                             f"{summary.planned} runs; pass --resume to finish the missing ones, "
                             "or use another --db")
        if resume and summary.skipped:
            stream.write(f"resume: {summary.skipped} of {summary.planned} runs already in {db_path}; "
                         f"running the {len(tasks)} missing\n")
        bar = ProgressBar(len(tasks), stream=stream, enabled=progress)
        if scheduler is not None:
            backend = _dask(tasks, scheduler)
        elif jobs == 1 or len(tasks) <= 1:
            backend = _serial(tasks)
        else:
            backend = _process_pool(tasks, min(jobs, len(tasks)))
        try:
            for task, out in backend:
                res = out["result"]
                row = run_row(res, run_index=task.run_index, seed=task.seed,
                              scenario_hash=task.scenario_hash, error=out["error"],
                              worker=out["worker"], wall_time=out["wall_time"])
                db.add_run(task.experimentid, task.plannerid, row, res)
                summary.finished += 1
                oc = row["outcome"]
                summary.outcomes[oc] = summary.outcomes.get(oc, 0) + 1
                if oc == "error":
                    summary.errors += 1
                    first = (out["error"] or "").splitlines()[0] if out["error"] else ""
                    log.warning("%s (seed %d) raised: %s", task.label, task.seed, first)
                bar.update(1, note=" ".join(f"{k} {v}" for k, v in sorted(summary.outcomes.items())))
        except (KeyboardInterrupt, BenchInterrupted):
            summary.interrupted = True
            bar.close()
            stream.write(f"\nbench stopped: {summary.finished} runs finished now and saved in "
                         f"{db_path}; {len(tasks) - summary.finished} missing. "
                         "Run the same command with --resume to finish.\n")
            raise
        finally:
            close = getattr(backend, "close", None)
            if close is not None:
                close()
        bar.close()
    summary.wall_time_s = time.perf_counter() - t_start
    if summary.errors:
        stream.write(f"warning: {summary.errors} runs raised an error in the planner "
                     "(stored with status Crash; see runs.error)\n")
    return summary
