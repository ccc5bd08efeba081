"""The BIT* planner object (:class:`BITStar`): batches, termination, results, new obstacles.

It owns the search state, one record per concept (the points and batch of :mod:`._graph`, the
tree of :mod:`._tree`, the queues of :mod:`._queue`, the progress of :mod:`._search`), and runs
the compiled search in chunks between polls of the termination condition.
"""

from __future__ import annotations

import gc
import logging
import math
import time
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.geometry.shapes import Shape
from anyplan.planning.base import ImprovementCallback, Planner, PlanResult
from anyplan.planning.bitstar import _graph, _queue, _search, _tree
from anyplan.planning.bitstar.config import BITStarConfig
from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.termination import TerminationCondition, as_condition

__all__ = ["BITStar", "PlannerData", "warm_up"]

logger = logging.getLogger("anyplan.planning.bitstar")

_WARM = False


def warm_up() -> float:
    """Load (or compile, the first time on a machine) the compiled kernels; returns seconds.

    Called by the first :class:`BITStar` of a process so that a planner's time budget is not
    spent loading machine code. Numba caches the code on disk, so only the very first process
    pays the compilation (tens of seconds); later ones take a fraction of a second.
    """
    global _WARM
    if _WARM:
        return 0.0
    _WARM = True
    from anyplan.geometry.shapes import Circle
    from anyplan.planning.termination import batches

    t0 = time.perf_counter()
    obs = ObstacleSet([Circle((2.0, 2.0), 0.5)], bounds=(0.0, 0.0, 4.0, 4.0))
    p = BITStar(Problem.create(obs, (0.5, 0.5), (3.5, 3.5), 0.1), rng=0, samples_per_batch=30)
    p.solve(batches(2))  # iterate, start_batch, build_grid, compact (prune), sampling
    p.add_obstacles([Circle((3.0, 1.0), 0.2)])  # Sequential BIT* uses it
    dt = time.perf_counter() - t0
    logger.debug("BIT* kernels ready in %.3f s", dt)
    return dt


@dataclass(frozen=True)
class PlannerData:
    """A snapshot of the planner for plots and tests.

    Attributes:
        samples: Unconnected samples (N, 2) [m].
        vertices: Tree vertices (M, 2) [m].
        edges: Tree edges as (parent, child) point pairs, shape (M - 1, 2, 2) [m].
        path: Best path (K, 2) [m], (0, 2) if none.
        start: Start (2,) [m].
        goal: Goal (2,) [m].
        c_best: Best cost [m] (inf if none); with start and goal it defines the informed
            ellipse.
        radius: Current connection radius [m].
    """

    samples: np.ndarray
    vertices: np.ndarray
    edges: np.ndarray
    path: np.ndarray
    start: np.ndarray
    goal: np.ndarray
    c_best: float
    radius: float


class BITStar(Planner):
    """Batch Informed Trees for a disc robot (anytime, resumable, deterministic for a seed).

    Args:
        problem: The problem (obstacles with walls, start, goal, robot radius).
        config: Settings; keyword ``overrides`` replace single fields.
        rng: A numpy Generator, a seed, or None (fresh entropy).
        callback: Called as ``callback(t_s, cost_m, path)`` at each improvement.

    Example:
        >>> from anyplan.geometry import ObstacleSet, square
        >>> from anyplan.planning import Problem, BITStar, batches
        >>> obs = ObstacleSet([square((5.0, 5.0), 2.0)], bounds=(0.0, 0.0, 10.0, 10.0))
        >>> planner = BITStar(Problem.create(obs, (1.0, 5.0), (9.0, 5.0), 0.3), rng=1)
        >>> bool(planner.solve(batches(3)))
        True
    """

    name = "bitstar"

    def __init__(self, problem: Problem, config: BITStarConfig | None = None, *,
                 rng: np.random.Generator | int | None = None,
                 callback: ImprovementCallback | None = None, **overrides: Any) -> None:
        super().__init__(problem)
        cfg = config or BITStarConfig()
        if overrides:
            known = set(asdict(cfg))
            for key in overrides:
                if key not in known:
                    raise ValueError(f"unknown BIT* option '{key}' (known: {', '.join(sorted(known))})")
            cfg = BITStarConfig(**{**asdict(cfg), **overrides})
        self.config = cfg
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        self.callback = callback
        if not _WARM:
            warm_up()
        self._setup_problem(problem)
        self.clear()

    # --- setup ------------------------------------------------------------------------------
    def _setup_problem(self, problem: Problem) -> None:
        self.problem = problem
        self._obs = problem.obstacles
        self._limit = problem.check_radius - COLLISION_EPS
        self._start_ok = problem.start_valid()
        self._goal_ok = problem.goal_valid()
        xmin, ymin, xmax, ymax = problem.bounds
        self._box = (xmin, ymin, xmax, ymax)
        self._c_min = problem.straight_distance
        self._sampler = _graph.InformedSampler(problem.start, problem.goal, self._box)

    def clear(self) -> None:
        """Drop the graph and the progress record; keep the configuration and the rng."""
        cap = 1024
        self._points = _graph.new_points(cap, self.problem.start, self.problem.goal)
        self._tree = _tree.new_tree(cap)
        self._queue = _queue.new_queue(cap)
        self._batch = _graph.first_batch()
        self._progress = _search.new_progress()
        self._batch_open = False
        self._pruned_cost = math.inf
        self._solve_time = 0.0
        self._first_time: float | None = None
        self._history: list[tuple[float, float]] = []
        self._path = np.zeros((0, 2))
        self._chunk = 64
        self._n_samples_drawn = 0
        self._pending_rebatch = False

    # --- public properties ---------------------------------------------------------------------
    @property
    def best_cost(self) -> float:
        """Cost [m] of the best solution so far (inf if none)."""
        return float(self._progress[0]["best"])

    @property
    def n_batches(self) -> int:
        """Batches started so far."""
        return self._batch.number

    @property
    def stats(self) -> dict[str, int | float]:
        """Counters: points, vertices, batches, edge checks, ..."""
        n = int(self._points.n[0])
        nv = int(np.count_nonzero(self._tree.vertex[:n]))
        pr = self._progress[0]
        return {
            "n_points": n, "n_vertices": nv, "n_samples": n - nv,
            "n_samples_drawn": self._n_samples_drawn, "n_batches": self.n_batches,
            "n_edge_checks": int(pr["edge_checks"]),
            "n_edge_checks_failed": int(pr["edge_checks_failed"]),
            "n_expansions": int(pr["expansions"]), "n_rewirings": int(pr["rewirings"]),
            "n_iterations": int(pr["edges_popped"]),
            "n_edges_queued": int(pr["edges_queued"]),
            "radius_m": float(self._batch.radius),
        }

    # --- batches ------------------------------------------------------------------------------------
    def _prune(self) -> None:
        """Drop points that cannot improve the solution: f_hat(x) = g_hat(x) + h_hat(x) >= c_best."""
        c_best = self.best_cost
        p, t = self._points, self._tree
        n = int(p.n[0])
        f = p.g_hat[:n] + p.h_hat[:n]
        # Samples: f_hat(x) < c_best ?  Vertices: f_hat(v) <= c_best ? (solution vertices lie on
        # the boundary up to rounding, so vertices get a small tolerance)
        state = np.where(f < c_best, 1, 0).astype(np.int64)
        state[t.vertex[:n] & (f <= c_best * (1.0 + 1e-12) + 1e-12)] = 2
        _graph.compact(p, t, state, self.n_batches + 1)
        self._pruned_cost = c_best

    def _new_batch(self, add_samples: bool = True) -> None:
        cfg = self.config
        c_best = self.best_cost
        if cfg.prune and c_best < self._pruned_cost:
            self._prune()
        number = self.n_batches + 1
        if add_samples:
            m = cfg.samples_per_batch
            if self.n_batches == 0 and cfg.first_batch_samples > 0:
                m = cfg.first_batch_samples
            pts = self._sampler.sample(self.rng, m, c_best, self._obs, self._limit)
            n = int(self._points.n[0])
            k = len(pts)
            if n + k > self._points.xy.shape[0]:
                cap = max(n + k, 2 * self._points.xy.shape[0])
                self._points = _graph.with_capacity(self._points, cap)
                self._tree = _tree.with_capacity(self._tree, cap)
            _tree.reset(self._tree, n, n + k)
            _graph.append_samples(self._points, pts, self.problem.start, self.problem.goal,
                                  number)
            self._n_samples_drawn += k
        self._batch = _graph.next_batch(self._points, self._tree.vertex, number,
                                        self._sampler.measure(c_best), cfg.rewire_factor,
                                        cfg.use_k_nearest, self._box)
        self._queue = _queue.with_vertex_room(self._queue, int(self._points.n[0]))
        _search.begin_batch(self._points, self._tree, self._queue, self._batch, self._progress)
        self._batch_open = True

    # --- solve --------------------------------------------------------------------------------------
    def _extract_path(self) -> np.ndarray:
        if not math.isfinite(self.best_cost):
            return np.zeros((0, 2))
        return _tree.path_to(self._tree, self._points.xy, 1)

    def _status(self) -> PlannerStatus:
        if not self._start_ok:
            return PlannerStatus.INVALID_START
        if not self._goal_ok:
            return PlannerStatus.INVALID_GOAL
        return PlannerStatus.EXACT_SOLUTION if math.isfinite(self.best_cost) else PlannerStatus.TIMEOUT

    def solve(self, ptc: TerminationCondition | float) -> PlannerStatus:
        """Search until ``ptc()`` is True (a condition, or a time budget in seconds).

        Calling again resumes the search and can only lower the cost.
        """
        if not (self._start_ok and self._goal_ok):
            return self._status()
        # The search allocates almost no Python objects, so the cyclic garbage collector is
        # paused while it runs: a full collection in a big process costs milliseconds, which
        # is a large part of a short planning budget.
        gc_was_enabled = gc.isenabled()
        gc.disable()
        try:
            return self._solve(ptc)
        finally:
            if gc_was_enabled:
                gc.enable()

    def _solve(self, ptc: TerminationCondition | float) -> PlannerStatus:
        # The solve clock starts before the condition is bound (a time budget starts there),
        # so that a search stopped by its budget reports at least the budget as its time.
        t0 = time.perf_counter()
        clock_base = self._solve_time - t0
        ptc = as_condition(ptc).bind(self)
        obs = self._obs.arrays
        if self.n_batches == 0 and not math.isfinite(self.best_cost):
            self._try_direct_edge(clock_base)
        cfg = self.config
        c_min = self._c_min
        while not ptc():
            if self.best_cost <= c_min * (1.0 + 1e-12):
                break  # the straight line is optimal
            if not self._batch_open:
                self._new_batch(add_samples=not self._pending_rebatch)
                self._pending_rebatch = False
                continue
            tc = time.perf_counter()
            rc = _search.run(self._points, self._tree, self._queue, self._batch, self._progress,
                             obs, self._limit, self._chunk)
            dt = time.perf_counter() - tc
            if rc == _search.BUDGET:
                # Adapt the chunk so that ptc() is polled about every chunk_s seconds.
                if dt < 0.5 * cfg.chunk_s:
                    self._chunk = min(self._chunk * 2, 1 << 14)
                elif dt > 2.0 * cfg.chunk_s:
                    self._chunk = max(self._chunk // 2, 1)
            elif rc == _search.BATCH_DONE:
                self._batch_open = False
            elif rc == _search.GROW:
                self._queue = _queue.grown(self._queue, int(self._points.n[0]))
            elif rc == _search.IMPROVED:
                t = time.perf_counter() + clock_base
                cost = self.best_cost
                if self._first_time is None:
                    self._first_time = t
                self._history.append((t, cost))
                self._path = self._extract_path()
                if self.callback is not None:
                    self.callback(t, cost, self._path.copy())
        self._solve_time = time.perf_counter() + clock_base
        return self._status()

    def _try_direct_edge(self, clock_base: float) -> None:
        """Before the first batch: if the straight start-goal motion is free, it is optimal."""
        p = self.problem
        if not p.obstacles.segment_free(p.start, p.goal, p.check_radius):
            return
        _tree.attach_root_child(self._tree, 1, self._c_min)
        self._progress[0]["edge_checks"] += 1
        self._progress[0]["best"] = self._c_min
        t = time.perf_counter() + clock_base
        self._first_time = t
        self._history.append((t, self._c_min))
        self._path = self._extract_path()
        if self.callback is not None:
            self.callback(t, self._c_min, self._path.copy())

    def result(self) -> PlanResult:
        """The best path so far, with timing and the cost history."""
        status = self._status()
        path = self._path.copy() if bool(status) else np.zeros((0, 2))
        return PlanResult(status, path, self.best_cost if bool(status) else math.inf,
                          self._solve_time, self._first_time, list(self._history), None,
                          self.name, dict(self.stats))

    # --- run-time obstacles -------------------------------------------------------------------------
    def add_obstacles(self, shapes: Iterable[Shape]) -> None:
        """Add static obstacles and keep as much of the graph as they allow.

        Samples inside the new obstacles are dropped; tree edges they block are cut and the
        subtrees below become samples again (a vertex stays in the tree only if its whole
        path from the start is still free). The cost history restarts from the remaining
        solution (if any), and the next :meth:`solve` continues with the surviving graph.
        """
        shapes = tuple(shapes)
        if not shapes:
            return
        new_only = ObstacleSet(shapes, bounds=None)
        self._setup_problem(self.problem.with_shapes(shapes))
        p, t = self._points, self._tree
        n = int(p.n[0])
        state = np.where(t.vertex[:n], 2, 1).astype(np.int64)
        free = new_only.clearances(p.xy[:n]) >= self._limit
        state[~free] = 0
        # tree edges (parent -> vertex) that the new obstacles block
        child = np.flatnonzero(t.parent[:n] >= 0)
        blocked = np.zeros(n, np.bool_)
        blocked[child] = ~new_only.segments_clear(p.xy[t.parent[child]], p.xy[child], self._limit)
        state[blocked & free] = 1
        _graph.compact(p, t, state, self.n_batches + 1)
        old_cost = self.best_cost
        g_goal = float(t.g[1])
        self._progress[0]["best"] = g_goal
        if g_goal > old_cost or not math.isfinite(g_goal):
            self._pruned_cost = math.inf
        self._path = self._extract_path()
        if self._path.shape[0] and not self._obs.path_free(self._path, self.problem.check_radius):
            raise RuntimeError("internal error: surviving solution collides with new obstacles")
        if g_goal != old_cost:
            # The solution was cut (inf) or rerouted: record it, so that the history stays the
            # best cost over time (it only decreases between calls to add_obstacles).
            self._history.append((self._solve_time, g_goal))
        # Re-expand every surviving vertex over the surviving points before sampling more.
        self._batch_open = False
        self._pending_rebatch = True

    # --- inspection ------------------------------------------------------------------------------
    def planner_data(self) -> PlannerData:
        """A snapshot of samples, tree, path and ellipse for plotting."""
        p, t = self._points, self._tree
        n = int(p.n[0])
        is_v = t.vertex[:n]
        par = t.parent[:n]
        child = np.flatnonzero(is_v & (par >= 0))
        edges = np.stack([p.xy[par[child]], p.xy[child]], axis=1) if len(child) else \
            np.zeros((0, 2, 2))
        return PlannerData(p.xy[:n][~is_v].copy(), p.xy[:n][is_v].copy(), edges,
                           self._path.copy(), self.problem.start.copy(), self.problem.goal.copy(),
                           self.best_cost, float(self._batch.radius))
