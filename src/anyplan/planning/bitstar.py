"""BIT* (Batch Informed Trees) for a disc robot among static obstacles in the plane.

Reference:
    J. D. Gammell, S. S. Srinivasa and T. D. Barfoot, "Batch Informed Trees (BIT*):
    Sampling-based optimal planning via the heuristically guided search of implicit random
    geometric graphs", ICRA 2015, doi:10.1109/ICRA.2015.7139620; and J. D. Gammell,
    T. D. Barfoot and S. S. Srinivasa, "Batch Informed Trees (BIT*): Informed asymptotically
    optimal anytime search", IJRR 39(5), 2020, doi:10.1177/0278364919890396.
    Informed sampling: J. D. Gammell, S. S. Srinivasa and T. D. Barfoot, "Informed RRT*",
    IROS 2014, doi:10.1109/IROS.2014.6942976.

The search processes batches of samples. Each batch is an implicit random geometric graph
(RGG) over the samples and the tree vertices, searched in order of the potential solution cost
through it (like A*); edges are checked for collision only when they are popped (lazily), and
exactly. Once a solution exists, new samples are drawn only from the informed set (the ellipse
with foci start and goal whose points could improve the solution), and points outside it are
pruned.

Notation (paper symbols used for locals):

=============  =================================================================
``g_hat(x)``   admissible cost-to-come heuristic, ``||x - start||`` [m]
``h_hat(x)``   admissible cost-to-go heuristic, ``||goal - x||`` [m]
``c_hat(v,x)`` edge cost heuristic, ``||x - v||`` [m] (the true cost when the edge is free)
``g_T(x)``     cost-to-come of ``x`` in the current tree (inf for a sample) [m]
``c_best``     cost of the best solution, ``g_T(goal)`` [m]
``r``          RGG connection radius [m], ``eta * 2 sqrt((1 + 1/d) (lambda(X_hat) / zeta_d)
               log(q) / q)``, d = 2, ``eta`` the rewire factor, ``q`` the number of points,
               ``lambda(X_hat)`` the measure of the informed set (capped by the arena's),
               ``zeta_d`` the unit-ball measure (pi)
``k``          k-nearest alternative, ``eta * e * (1 + 1/d) * log(q)``
=============  =================================================================

The compiled search (numba, cached on disk) is in :mod:`anyplan.planning._bitstar_core`.
Obstacles can be added between ``solve`` calls (:meth:`BITStar.add_obstacles`): tree edges and
points they block are removed, the rest of the graph is kept and the search resumes.
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

from anyplan.config import setting, validate
from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.geometry.shapes import Shape
from anyplan.planning import _bitstar_core as core
from anyplan.planning.base import ImprovementCallback, Planner, PlanResult
from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.termination import TerminationCondition, as_condition

__all__ = ["BITStar", "BITStarConfig", "PlannerData", "warm_up"]

logger = logging.getLogger(__name__)

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
    p.add_obstacles([Circle((3.0, 1.0), 0.2)])  # blocked_edges (Sequential BIT* uses it)
    dt = time.perf_counter() - t0
    logger.debug("BIT* kernels ready in %.3f s", dt)
    return dt


@dataclass(frozen=True)
class BITStarConfig:
    """BIT* settings.

    Attributes:
        samples_per_batch: Samples added per batch, >= 1. OMPL's default is 100; with the
            compiled search, 400 converges faster per second on our benchmark problems
            (``benchmarks/bitstar.py``) while the first solution still takes ~1 ms.
        first_batch_samples: Samples of the first batch (0: same as ``samples_per_batch``).
        rewire_factor: ``eta``, the factor on the RGG radius (or k), in [1.0, 3.0]; 1.1 as in
            OMPL.
        use_k_nearest: Connect to the k nearest points instead of an r-disc.
        prune: Drop samples and vertices that cannot improve the solution at each new batch.
        chunk_s: Target wall time [s] between two checks of the termination condition.
    """

    samples_per_batch: int = setting(400, lo=1, doc="samples added per batch")
    first_batch_samples: int = setting(0, lo=0, doc="samples of the first batch (0: samples_per_batch)")
    rewire_factor: float = setting(1.1, lo=1.0, hi=3.0, doc="eta, the factor on the RGG radius")
    use_k_nearest: bool = setting(False, doc="k nearest instead of an r-disc")
    prune: bool = setting(True, doc="drop what cannot improve the solution")
    chunk_s: float = setting(2e-4, lo=0.0, lo_open=True, hi=1.0, unit="s",
                             doc="wall time between termination checks")

    def __post_init__(self) -> None:
        validate(self, owner="")  # messages "rewire_factor: must be in [1, 3], got 5.0"


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
        self._center = (problem.start + problem.goal) / 2.0
        d = problem.goal - problem.start
        ang = math.atan2(d[1], d[0]) if self._c_min > 0.0 else 0.0
        self._rot = np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]])

    def clear(self) -> None:
        """Drop the graph and the progress record; keep the configuration and the rng."""
        cap = 1024
        self._P = np.zeros((cap, 2))
        self._F = np.full((cap, 3), math.inf)
        self._I = np.full((cap, 7), -1, np.int64)
        self._vk = np.zeros(cap)
        self._vp = np.zeros((cap, 2), np.int64)
        self._ek = np.zeros(4 * cap)
        self._ep = np.zeros((4 * cap, 2), np.int64)
        self._stack = np.zeros(cap, np.int64)
        self._nb = np.zeros(cap, np.int64)
        self._nd = np.zeros(cap)
        self._S = np.zeros(8)
        self._N = np.zeros(16, np.int64)
        self._cstart = np.zeros(2, np.int64)
        self._citems = np.zeros(0, np.int64)
        self._nstart = np.zeros(2, np.int64)
        self._nitems = np.zeros(0, np.int64)
        self._S[core.S_CBEST] = math.inf
        self._S[core.S_LIMIT] = self._limit
        # Start (0) and goal (1).
        for i, p in enumerate((self.problem.start, self.problem.goal)):
            self._P[i] = p
            self._F[i, core.G_HAT] = np.hypot(*(p - self.problem.start))
            self._F[i, core.H_HAT] = np.hypot(*(self.problem.goal - p))
            self._I[i, core.FLAGS] = 0
        self._F[0, core.G_T] = 0.0
        self._I[0, core.FLAGS] = core.F_VERTEX
        self._N[core.N_N] = 2
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
        return float(self._S[core.S_CBEST])

    @property
    def n_batches(self) -> int:
        """Batches started so far."""
        return int(self._N[core.N_BATCH])

    @property
    def stats(self) -> dict[str, int | float]:
        """Counters: points, vertices, batches, edge checks, ..."""
        n = int(self._N[core.N_N])
        nv = int(np.count_nonzero(self._I[:n, core.FLAGS] & core.F_VERTEX))
        return {
            "n_points": n, "n_vertices": nv, "n_samples": n - nv,
            "n_samples_drawn": self._n_samples_drawn, "n_batches": self.n_batches,
            "n_edge_checks": int(self._N[core.N_CHECKS]),
            "n_edge_checks_failed": int(self._N[core.N_FAILS]),
            "n_expansions": int(self._N[core.N_EXP]), "n_rewirings": int(self._N[core.N_REWIRE]),
            "n_iterations": int(self._N[core.N_ITERS]),
            "n_edges_queued": int(self._N[core.N_QUEUED]),
            "radius_m": float(self._S[core.S_R]),
        }

    # --- sampling --------------------------------------------------------------------------------
    def _informed_measure(self, c_best: float) -> float:
        xmin, ymin, xmax, ymax = self._box
        box = (xmax - xmin) * (ymax - ymin)
        if not math.isfinite(c_best):
            return box
        a = c_best / 2.0
        b = math.sqrt(max(c_best * c_best - self._c_min * self._c_min, 0.0)) / 2.0
        return min(math.pi * a * b, box)

    def _sample(self, m: int, c_best: float) -> np.ndarray:
        """``m`` collision-free samples from the informed set (fewer if it is nearly all blocked)."""
        xmin, ymin, xmax, ymax = self._box
        box_area = (xmax - xmin) * (ymax - ymin)
        out: list[np.ndarray] = []
        got = 0
        for _ in range(64):
            need = m - got
            if need <= 0:
                break
            k = int(need * 1.3) + 8
            if math.isfinite(c_best) and self._informed_measure(c_best) < box_area:
                # Direct sampling of the ellipse: uniform in the unit disc, scaled and rotated.
                a = c_best / 2.0
                b = math.sqrt(max(c_best * c_best - self._c_min * self._c_min, 0.0)) / 2.0
                u = self.rng.random((k, 2))
                rho = np.sqrt(u[:, 0])
                th = 2.0 * math.pi * u[:, 1]
                local = np.column_stack([a * rho * np.cos(th), b * rho * np.sin(th)])
                pts = local @ self._rot.T + self._center
                inside = ((pts[:, 0] > xmin) & (pts[:, 0] < xmax)
                          & (pts[:, 1] > ymin) & (pts[:, 1] < ymax))
                pts = pts[inside]
            else:
                u = self.rng.random((k, 2))
                pts = np.column_stack([xmin + u[:, 0] * (xmax - xmin), ymin + u[:, 1] * (ymax - ymin)])
                if math.isfinite(c_best):
                    f = (np.hypot(*(pts - self.problem.start).T) + np.hypot(*(pts - self.problem.goal).T))
                    pts = pts[f < c_best]
            if len(pts):
                pts = pts[self._obs.points_clear(pts, self._limit)]
            pts = pts[:need]
            out.append(pts)
            got += len(pts)
        return np.vstack(out) if out else np.zeros((0, 2))

    # --- capacity ----------------------------------------------------------------------------------
    def _ensure_points(self, need: int) -> None:
        cap = self._P.shape[0]
        if need <= cap:
            return
        new = max(need, 2 * cap)
        self._P = np.vstack([self._P, np.zeros((new - cap, 2))])
        self._F = np.vstack([self._F, np.full((new - cap, 3), math.inf)])
        self._I = np.vstack([self._I, np.full((new - cap, 7), -1, np.int64)])
        self._stack = np.zeros(new, np.int64)
        self._nb = np.zeros(new, np.int64)
        self._nd = np.zeros(new)

    def _grow_queues(self) -> None:
        n = int(self._N[core.N_N])
        if self._ek.shape[0] - self._N[core.N_ES] < n + 8:
            size = max(2 * self._ek.shape[0], int(self._N[core.N_ES]) + 2 * n + 16)
            self._ek = np.concatenate([self._ek, np.zeros(size - self._ek.shape[0])])
            self._ep = np.vstack([self._ep, np.zeros((size - self._ep.shape[0], 2), np.int64)])
        if self._vk.shape[0] - self._N[core.N_VS] < 8:
            size = 2 * self._vk.shape[0]
            self._vk = np.concatenate([self._vk, np.zeros(size - self._vk.shape[0])])
            self._vp = np.vstack([self._vp, np.zeros((size - self._vp.shape[0], 2), np.int64)])

    # --- batches ------------------------------------------------------------------------------------
    def _prune(self) -> None:
        """Drop points that cannot improve the solution: f_hat(x) = g_hat(x) + h_hat(x) >= c_best."""
        c_best = self.best_cost
        n = int(self._N[core.N_N])
        f = self._F[:n, core.G_HAT] + self._F[:n, core.H_HAT]
        is_v = (self._I[:n, core.FLAGS] & core.F_VERTEX) != 0
        # Samples: f_hat(x) < c_best ?  Vertices: f_hat(v) <= c_best ? (solution vertices lie on
        # the boundary up to rounding, so vertices get a small tolerance)
        state = np.where(f < c_best, 1, 0).astype(np.int64)
        state[is_v & (f <= c_best * (1.0 + 1e-12) + 1e-12)] = 2
        core.compact(self._P, self._F, self._I, self._N, state, self._stack)
        self._pruned_cost = c_best

    def _new_batch(self, add_samples: bool = True) -> None:
        cfg = self.config
        c_best = self.best_cost
        if cfg.prune and c_best < self._pruned_cost:
            self._prune()
        if add_samples:
            m = cfg.samples_per_batch
            if self.n_batches == 0 and cfg.first_batch_samples > 0:
                m = cfg.first_batch_samples
            pts = self._sample(m, c_best)
            n = int(self._N[core.N_N])
            self._ensure_points(n + len(pts))
            k = len(pts)
            self._P[n:n + k] = pts
            self._F[n:n + k, core.G_HAT] = np.hypot(*(pts - self.problem.start).T)
            self._F[n:n + k, core.H_HAT] = np.hypot(*(pts - self.problem.goal).T)
            self._F[n:n + k, core.G_T] = math.inf
            self._I[n:n + k] = -1
            self._I[n:n + k, core.FLAGS] = 0
            self._I[n:n + k, core.SBATCH] = self.n_batches + 1
            self._N[core.N_N] = n + k
            self._n_samples_drawn += k
        n = int(self._N[core.N_N])
        q = max(n, 2)
        lam = self._informed_measure(c_best)
        eta = cfg.rewire_factor
        # r = eta * 2 * sqrt((1 + 1/d) * (lambda / zeta_d) * log(q) / q), d = 2
        r = eta * 2.0 * math.sqrt(1.5 * (lam / math.pi) * math.log(q) / q) if q > 1 else math.inf
        xmin, ymin, xmax, ymax = self._box
        r = min(r, math.hypot(xmax - xmin, ymax - ymin))
        self._S[core.S_R] = r
        if cfg.use_k_nearest:
            # k = eta * e * (1 + 1/d) * log(q)
            self._N[core.N_K] = max(1, math.ceil(eta * math.e * 1.5 * math.log(q)))
        cell = max(r, 1e-9)
        ncx = max(1, min(int(math.ceil((xmax - xmin) / cell)), 4096))
        ncy = max(1, min(int(math.ceil((ymax - ymin) / cell)), 4096))
        cell = max(cell, (xmax - xmin) / ncx, (ymax - ymin) / ncy)
        self._S[core.S_X0] = xmin
        self._S[core.S_Y0] = ymin
        self._S[core.S_CELL] = cell
        self._N[core.N_NCX] = ncx
        self._N[core.N_NCY] = ncy
        self._cstart, self._citems = core.build_grid(self._P, np.arange(n), xmin, ymin, cell, ncx, ncy)
        new = np.flatnonzero((self._I[:n, core.SBATCH] == self.n_batches + 1)
                             & ((self._I[:n, core.FLAGS] & core.F_VERTEX) == 0))
        self._nstart, self._nitems = core.build_grid(self._P, new, xmin, ymin, cell, ncx, ncy)
        if self._vk.shape[0] < n + 8:
            size = 2 * (n + 8)
            self._vk = np.zeros(size)
            self._vp = np.zeros((size, 2), np.int64)
        core.start_batch(self._P, self._F, self._I, self._vk, self._vp, self._S, self._N,
                         self._cstart, self._citems, new, self._nb, self._nd)
        self._batch_open = True

    # --- solve --------------------------------------------------------------------------------------
    def _extract_path(self) -> np.ndarray:
        if not math.isfinite(self.best_cost):
            return np.zeros((0, 2))
        chain = [1]
        while chain[-1] != 0:
            chain.append(int(self._I[chain[-1], core.PAR]))
            if len(chain) > self._P.shape[0]:
                raise RuntimeError("BIT* tree corrupted: cycle in the parent chain")
        return self._P[chain[::-1]].copy()

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
        ptc = as_condition(ptc).bind(self)
        obs = self._obs.arrays
        t0 = time.perf_counter()
        clock_base = self._solve_time - t0
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
            rc = core.iterate(self._P, self._F, self._I, self._vk, self._vp, self._ek, self._ep,
                              self._cstart, self._citems, self._nstart, self._nitems, self._S,
                              self._N, self._stack, self._nb, self._nd, obs, self._chunk)
            dt = time.perf_counter() - tc
            if rc == core.RC_BUDGET:
                # Adapt the chunk so that ptc() is polled about every chunk_s seconds.
                if dt < 0.5 * cfg.chunk_s:
                    self._chunk = min(self._chunk * 2, 1 << 14)
                elif dt > 2.0 * cfg.chunk_s:
                    self._chunk = max(self._chunk // 2, 1)
            elif rc == core.RC_BATCH_DONE:
                self._batch_open = False
            elif rc == core.RC_GROW:
                self._grow_queues()
            elif rc == core.RC_IMPROVED:
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
        self._F[1, core.G_T] = self._c_min
        it = self._I
        it[1, core.PAR] = 0
        it[1, core.PSIB] = -1
        it[1, core.NSIB] = it[0, core.FCHILD]
        if it[0, core.FCHILD] >= 0:
            it[it[0, core.FCHILD], core.PSIB] = 1
        it[0, core.FCHILD] = 1
        it[1, core.FLAGS] = core.F_VERTEX
        self._N[core.N_CHECKS] += 1
        self._S[core.S_CBEST] = self._c_min
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
        self._S[core.S_LIMIT] = self._limit
        n = int(self._N[core.N_N])
        state = np.where((self._I[:n, core.FLAGS] & core.F_VERTEX) != 0, 2, 1).astype(np.int64)
        free = new_only.clearances(self._P[:n]) >= self._limit
        state[~free] = 0
        blocked = core.blocked_edges(self._P, self._I, n, new_only.arrays, self._limit)
        state[blocked & free] = 1
        core.compact(self._P, self._F, self._I, self._N, state, self._stack)
        old_cost = self.best_cost
        g_goal = float(self._F[1, core.G_T])
        self._S[core.S_CBEST] = g_goal
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
        n = int(self._N[core.N_N])
        is_v = (self._I[:n, core.FLAGS] & core.F_VERTEX) != 0
        par = self._I[:n, core.PAR]
        child = np.flatnonzero(is_v & (par >= 0))
        edges = np.stack([self._P[par[child]], self._P[child]], axis=1) if len(child) else \
            np.zeros((0, 2, 2))
        return PlannerData(self._P[:n][~is_v].copy(), self._P[:n][is_v].copy(), edges,
                           self._path.copy(), self.problem.start.copy(), self.problem.goal.copy(),
                           self.best_cost, float(self._S[core.S_R]))
