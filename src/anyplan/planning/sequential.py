"""Sequential BIT*: plan among static obstacles, then add virtual obstacles where moving ones hit.

Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic Environment"
(Algorithm 1): plan a shortest path with BIT* (:class:`~anyplan.planning.bitstar.BITStar`), turn
it into a timed reference motion (a :class:`MotionModel` that the caller passes in, e.g.
:class:`anyplan.trajectory.reference.Departure`: this module stays below the trajectory layer),
predict the first collision with a moving obstacle
(:func:`anyplan.prediction.collision.first_collision`), put a virtual square of side
2 (r + r_o) at the robot's reference position then, and plan again until the motion is free.
Our extensions (continued search, shrunk squares, waiting): ``docs/sequential.md``.

Notation: r robot radius [m], r_o obstacle radius [m], c collision point [m], s square side [m].
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Protocol

import numpy as np

from anyplan.config import setting, validate
from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.geometry.shapes import Shape, square
from anyplan.planning.bitstar import BITStar, BITStarConfig
from anyplan.planning.connectivity import exactly_unsolvable, provably_disconnected
from anyplan.planning.problem import Problem
from anyplan.planning.termination import any_of, batches, first_solution, timed
from anyplan.prediction.base import PredictedObstacle
from anyplan.prediction.collision import PredictedCollision, TimedMotion, first_collision

__all__ = ["SequentialConfig", "VirtualObstacle", "SequentialResult", "SequentialBITStar",
           "MotionModel", "shrink_square"]


class MotionModel(Protocol):
    """What the loop needs from the trajectory layer: timed motions from one start state.

    ``model(path, extra_shapes, delay_s)`` is the timed reference motion along ``path`` (N, 2)
    [m] among the static obstacles plus ``extra_shapes`` (the virtual squares so far),
    departing ``delay_s`` [s] late. :class:`anyplan.trajectory.reference.Departure` is one.
    A motion departing late may say when it leaves the point where it waits (``departs_s``
    [s]; before that, a later departure along the same path is the same motion): the waiting
    search then tries no later departure along a path whose contact comes while it waits.
    """

    def __call__(self, path: np.ndarray, extra_shapes: Sequence[Shape], delay_s: float,
                 /) -> TimedMotion: ...


@dataclass(frozen=True)
class SequentialConfig:
    """Settings of the Sequential BIT* loop (times in s, lengths in m).

    Attributes:
        max_iterations: Cap on BIT* plans per replanning (the paper needed about 3).
        first_budget_s: BIT* budget of the first plan (among the static obstacles).
        iteration_budget_s: BIT* budget after each virtual obstacle is added.
        batches_per_plan: If set, each plan stops after this many batches (after a first
            solution), or after 20 times as many without one, instead of a time budget: the
            search is then deterministic for a seed.
        warm_start: Continue the previous search after adding a square (else start anew, the
            default: measured faster by ``benchmarks/replan.py``).
        margin: Extra clearance [m] required between the robot's reference and an obstacle in
            the prediction (absorbs the tracking error).
        side_factor: Square side = ``side_factor * 2 (r + r_o)``; 1.0 is the paper's size.
        min_side: Smallest side [m] a shrunk square may keep.
        anchor: Where the square is centred: ``"robot"`` (the paper: the robot's reference
            position at the collision), ``"obstacle"`` (the obstacle's centre then) or
            ``"midpoint"``.
        wait_delays_s: Departure delays tried when the loop fails (on the first and the last
            path found).
        max_time_s: Wall-clock cap [s] on the iterations of one replanning; the waiting
            search that may follow has the same cap again. A replanning that runs out of time
            returns its best effort (the motion whose first collision is latest).
        prove_blocked: A detour search (after a square) that has no solution after its
            ordinary budget stops at once when the squares provably disconnect start and goal
            (:func:`~anyplan.planning.connectivity.provably_disconnected`, then
            :func:`~anyplan.planning.connectivity.exactly_unsolvable`), instead of going on
            for up to 20 budgets in vain; the answer (no path) is the same.
        prediction_dt: The motion is resampled every ``prediction_dt`` seconds for the
            collision prediction (certified: the contact distance is enlarged by the
            interpolation error bound, at most v_max * prediction_dt / 2); None predicts on the
            motion itself (slower).
        bitstar: BIT* settings.
    """

    max_iterations: int = setting(8, lo=1, doc="BIT* plans per replanning")
    first_budget_s: float = setting(0.005, lo=0.0, lo_open=True, unit="s", doc="first plan's budget")
    iteration_budget_s: float = setting(0.002, lo=0.0, lo_open=True, unit="s",
                                        doc="budget after each virtual obstacle")
    batches_per_plan: int | None = setting(None, lo=1, doc="batch budget instead of a time budget")
    warm_start: bool = setting(False, doc="continue the previous search")
    margin: float = setting(0.05, lo=0.0, unit="m", doc="extra clearance from predicted obstacles")
    side_factor: float = setting(1.0, lo=0.0, lo_open=True, doc="square side / 2 (r + r_o)")
    min_side: float = setting(0.1, lo=0.0, lo_open=True, unit="m", doc="smallest shrunk side")
    anchor: str = setting("robot", choices=("robot", "obstacle", "midpoint"), doc="square centre")
    wait_delays_s: tuple[float, ...] = setting((0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 12.0), lo=0.0,
                                               lo_open=True, unit="s", doc="departure delays tried")
    prediction_dt: float | None = setting(0.02, lo=0.0, lo_open=True, unit="s",
                                          doc="resampling step of the prediction; None: exact")
    max_time_s: float = setting(0.5, lo=0.0, lo_open=True, unit="s", doc="wall-clock cap of a replanning")
    prove_blocked: bool = setting(True, doc="skip detour searches that provably cannot succeed")
    bitstar: BITStarConfig = field(default_factory=BITStarConfig)

    def __post_init__(self) -> None:
        validate(self, owner="")  # messages "anchor: must be one of robot, ..., got 'x'"


@dataclass(frozen=True)
class VirtualObstacle:
    """A virtual static square.

    Attributes:
        center: (x, y) [m].
        side: Side [m] (after any shrinking).
        created_at_s: Time of the replanning that created it [s].
        collision_time_s: Predicted collision time [s] that it stands for.
        obstacle: Name of the moving obstacle.
        shrunk: True if the side was reduced so that the robot fits at the start or the goal.
    """

    center: tuple[float, float]
    side: float
    created_at_s: float
    collision_time_s: float
    obstacle: str
    shrunk: bool = False

    @cached_property
    def shape(self) -> Shape:
        """The square as a polygon (built once: the loop asks for it at every iteration)."""
        return square(self.center, self.side)

    def to_dict(self) -> dict[str, Any]:
        """The ``result.json`` form ``{center, side, created_at_s, ...}``."""
        return {"center": [float(self.center[0]), float(self.center[1])], "side": float(self.side),
                "created_at_s": float(self.created_at_s),
                "collision_time_s": float(self.collision_time_s), "obstacle": self.obstacle,
                "shrunk": bool(self.shrunk)}


@dataclass
class SequentialResult:
    """Outcome of one Sequential BIT* replanning.

    Attributes:
        status: ``"collision_free"``, ``"waiting"`` (collision-free after a delayed departure),
            ``"collision_predicted"`` (no collision-free motion found; the best effort is
            returned), ``"plan_failed"`` (BIT* found no path) or ``"invalid_start"``.
        path: The chosen path (N, 2) [m] (empty when planning failed).
        motion: Its timed reference motion (None when planning failed).
        virtual_obstacles: The squares added in this replanning.
        iterations: BIT* plans made.
        delay_s: Departure delay of the chosen motion [s].
        collision: The first predicted collision of the returned motion, if any.
        plan_time_s: Wall-clock time of the BIT* searches [s].
        motion_time_s: Wall-clock time spent building motions and predicting [s].
        costs: Path cost [m] of each plan.
        history: Cost against solve time of the first BIT* search, [(t [s], cost [m]), ...].
    """

    status: str
    path: np.ndarray
    motion: TimedMotion | None
    virtual_obstacles: list[VirtualObstacle]
    iterations: int
    delay_s: float = 0.0
    collision: PredictedCollision | None = None
    plan_time_s: float = 0.0
    motion_time_s: float = 0.0
    costs: list[float] = field(default_factory=list)
    history: list[tuple[float, float]] = field(default_factory=list)

    @property
    def collision_free(self) -> bool:
        """True if the returned motion is predicted collision-free."""
        return self.status in ("collision_free", "waiting")


def _box_distance(p: np.ndarray, center: np.ndarray, half: float) -> float:
    d = np.maximum(np.abs(p - center) - half, 0.0)
    return float(math.hypot(d[0], d[1]))


def shrink_square(center: np.ndarray, side: float, keep_clear: Sequence[np.ndarray],
                  clearance: float) -> float:
    """Largest side <= ``side`` [m] such that the square centred at ``center`` stays at least
    ``clearance`` [m] away from every point of ``keep_clear``; 0 if none exists.

    Examples:
        >>> round(shrink_square(np.array([0.0, 0.0]), 2.0, [np.array([1.5, 0.0])], 0.3), 6)
        2.0
        >>> round(shrink_square(np.array([0.0, 0.0]), 2.0, [np.array([1.0, 0.0])], 0.3), 6)
        1.4
    """
    half = side / 2.0
    for p in keep_clear:
        # The distance to an axis-aligned box decreases with its half side h; it is
        # ||max(|p - c| - h, 0)||, so the largest admissible h is found by bisection.
        if _box_distance(p, center, half) >= clearance:
            continue
        lo, hi = 0.0, half
        if _box_distance(p, center, 0.0) < clearance:
            return 0.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if _box_distance(p, center, mid) >= clearance:
                lo = mid
            else:
                hi = mid
        half = lo
    return 2.0 * half


class SequentialBITStar:
    """The Sequential BIT* replanning loop (the paper's Algorithm 1, with our extensions).

    Args:
        obstacles: Static obstacles with the arena walls.
        robot_radius: [m].
        plan_radius: Radius [m] BIT* plans for (robot radius plus a planning margin).
        motion: Builds the timed motion along a path (a :class:`MotionModel`); may instead be
            given to each :meth:`replan` (it usually depends on the state the motion starts
            from).
        config: Loop settings.
        rng: Random generator of BIT*.
    """

    def __init__(self, obstacles: ObstacleSet, *, robot_radius: float, plan_radius: float,
                 motion: MotionModel | None = None, config: SequentialConfig | None = None,
                 rng: np.random.Generator | None = None) -> None:
        self.obstacles = obstacles
        self.robot_radius = float(robot_radius)
        self.plan_radius = float(plan_radius)
        self.motion = motion
        self.config = config or SequentialConfig()
        self.rng = rng if rng is not None else np.random.default_rng()

    # --- one BIT* search ---------------------------------------------------------------------------
    def _budget(self, first: bool) -> Any:
        cfg = self.config
        if cfg.batches_per_plan is not None:
            # Work, not time, decides when a search without a solution gives up (20 times the
            # batches, as the timed budget below allows 20 budgets): a search that may not find
            # one (a robot boxed in by its squares) stays deterministic.
            n = cfg.batches_per_plan
            return any_of(batches(n) & first_solution(), batches(20 * n), timed(10.0))
        budget = cfg.first_budget_s if first else cfg.iteration_budget_s
        # At least a first solution: keep searching (up to 20 budgets) until one exists.
        return any_of(timed(budget) & first_solution(), timed(20.0 * budget))

    def _solve(self, planner: BITStar, first: bool) -> None:
        """One BIT* search on its budget; with ``prove_blocked``, a detour search first gets
        only its ordinary budget and goes on only if start and goal may still be connected
        (the same stopping points as :meth:`_budget` otherwise)."""
        cfg = self.config
        if first or not cfg.prove_blocked:
            planner.solve(self._budget(first))
            return
        # the probe, the cell cover's proof, four more budgets, the visibility graph's proof
        # (among few obstacles; it also proves passages closed by less than a cell, but costs
        # more when the squares leave a way), then the rest of the 20 budgets
        if cfg.batches_per_plan is not None:
            n = cfg.batches_per_plan
            probe, more = batches(n), any_of(first_solution(), batches(4 * n), timed(10.0))
            rest = any_of(first_solution(), batches(15 * n), timed(10.0))
        else:
            b = cfg.iteration_budget_s
            probe, more = timed(b), any_of(first_solution(), timed(4.0 * b))
            rest = any_of(first_solution(), timed(15.0 * b))
        planner.solve(probe)
        if planner.result().solved:
            return
        p = planner.problem
        if provably_disconnected(p.obstacles, p.start, p.goal, p.radius):
            return
        planner.solve(more)
        if planner.result().solved or exactly_unsolvable(p):
            return
        planner.solve(rest)

    def replan(self, start: np.ndarray, goal: np.ndarray, predictions: Sequence[PredictedObstacle],
               t_now: float, motion: MotionModel | None = None,
               chain: Sequence[VirtualObstacle] = (),
               verified: Callable[[TimedMotion], bool] | None = None,
               stop: Callable[[Sequence[VirtualObstacle]], bool] | None = None,
               rng: np.random.Generator | None = None) -> SequentialResult:
        """Plan from ``start`` to ``goal`` until the predicted motion is collision-free.

        Args:
            start: Position (x, y) [m] where the new motion starts.
            goal: Goal (x, y) [m].
            predictions: Predicted moving obstacles (absolute times).
            t_now: Time [s] stamped on the virtual obstacles created.
            motion: The motion model for this replanning (default: the constructor's).
            chain: Virtual obstacles to start with (a chain an earlier replanning left off;
                they count towards ``max_iterations``); dropped if the start or the goal
                is no longer clear of them.
            verified: True for a motion of ``motion`` that the model itself has checked free
                of the predictions: the loop takes it without checking it again.
            stop: Asked before each search after this replanning's first, with the squares it
                would search among: True ends the iterations there, as ``max_time_s`` does
                (an anytime caller's budget, spent before a search rather than after it).
            rng: BIT*'s generator for this replanning (default: the loop's own, whose stream
                runs on from one replanning to the next).
        """
        motion_fn = motion or self.motion
        if motion_fn is None:
            raise ValueError("motion: give a motion model to the constructor or to replan")
        cfg = self.config
        start = np.asarray(start, dtype=float)
        goal = np.asarray(goal, dtype=float)
        squares: list[VirtualObstacle] = list(chain)
        candidates: list[tuple[np.ndarray, list[Shape]]] = []
        plan_time = motion_time = 0.0
        costs: list[float] = []
        history: list[tuple[float, float]] = []
        problem = Problem.create(self.obstacles, start, goal, self.plan_radius)
        if not problem.start_valid():
            # Hugging an obstacle: plan for the robot itself, without the planning margin.
            problem = Problem.create(self.obstacles, start, goal, self.robot_radius)
            if not problem.start_valid():
                return SequentialResult("invalid_start", np.zeros((0, 2)), None, [], 0)
        with_squares = problem.with_shapes([s.shape for s in squares]) if squares else problem
        if squares and not (with_squares.start_valid() and with_squares.goal_valid()):
            squares, with_squares = [], problem  # the robot moved into one: start afresh
        first_it = len(squares)
        gen = self.rng if rng is None else rng
        planner = BITStar(with_squares, cfg.bitstar, rng=gen)
        best: SequentialResult | None = None
        blocked = False
        status = "collision_predicted"
        deadline = time.perf_counter() + cfg.max_time_s
        for it in range(first_it, max(cfg.max_iterations, first_it + 1)):
            t0 = time.perf_counter()
            if it > first_it and (t0 > deadline or (stop is not None and stop(squares))):
                break
            if not cfg.warm_start and it > 0:
                planner = BITStar(problem.with_shapes([s.shape for s in squares]), cfg.bitstar,
                                  rng=gen)
            # the first plan's budget for the plan among the static obstacles only (a chain
            # taken up starts with a detour search)
            self._solve(planner, not squares)
            res = planner.result()
            plan_time += time.perf_counter() - t0
            if not res.solved:
                status = "plan_failed"
                break
            costs.append(float(res.cost))
            if it == first_it:
                history = list(res.history)
            t1 = time.perf_counter()
            shapes = [s.shape for s in squares]
            timed_motion = motion_fn(res.path, shapes, 0.0)
            hit = None if verified is not None and verified(timed_motion) else first_collision(
                timed_motion, predictions, self.robot_radius, margin=cfg.margin,
                sample_dt=cfg.prediction_dt)
            motion_time += time.perf_counter() - t1
            candidates.append((res.path, shapes))
            attempt = SequentialResult("collision_free" if hit is None else "collision_predicted",
                                       res.path, timed_motion, list(squares), it + 1, 0.0, hit)
            if hit is None:
                attempt.plan_time_s, attempt.motion_time_s, attempt.costs = plan_time, motion_time, costs
                attempt.history = history
                return attempt
            if best is None or hit.t > best.collision.t:  # type: ignore[union-attr]
                best = attempt
            vo = self._virtual_obstacle(hit, start, goal, t_now)
            if vo is None:
                blocked = True
                break
            squares.append(vo)
            if cfg.warm_start:
                planner.add_obstacles([vo.shape])
        # Algorithm 1 did not converge: try waiting before departing on the paths found.
        t1 = time.perf_counter()
        waited = self._try_waiting(candidates, predictions, motion_fn,
                                   time.perf_counter() + cfg.max_time_s)
        motion_time += time.perf_counter() - t1
        if waited is not None:
            path, shapes, delay, waiting_motion = waited
            n = len(shapes)
            return SequentialResult("waiting", path, waiting_motion, squares[:n], len(costs), delay, None,
                                    plan_time, motion_time, costs, history)
        if best is None:
            return SequentialResult(status if not blocked else "plan_failed", np.zeros((0, 2)), None,
                                    squares, len(costs), plan_time_s=plan_time,
                                    motion_time_s=motion_time, costs=costs)
        best.status = "collision_predicted"
        best.iterations = len(costs)
        best.plan_time_s, best.motion_time_s, best.costs = plan_time, motion_time, costs
        best.history = history
        return best

    def _virtual_obstacle(self, hit: PredictedCollision, start: np.ndarray, goal: np.ndarray,
                          t_now: float) -> VirtualObstacle | None:
        cfg = self.config
        if cfg.anchor == "robot":
            c = hit.robot_position
        elif cfg.anchor == "obstacle":
            c = hit.obstacle_position
        else:
            c = 0.5 * (hit.robot_position + hit.obstacle_position)
        side = cfg.side_factor * 2.0 * (self.robot_radius + hit.obstacle_radius)
        # The robot must fit at the start and at the goal: shrink the square if needed.
        need = self.plan_radius + 1e-6 + COLLISION_EPS
        s = shrink_square(np.asarray(c), side, [start, goal], need)
        if s < cfg.min_side:
            return None
        return VirtualObstacle((float(c[0]), float(c[1])), s, float(t_now), hit.t, hit.obstacle,
                               s < side)

    def _try_waiting(self, candidates: list[tuple[np.ndarray, list[Shape]]],
                     predictions: Sequence[PredictedObstacle], motion_fn: MotionModel, deadline: float
                     ) -> tuple[np.ndarray, list[Shape], float, TimedMotion] | None:
        if not candidates:
            return None
        # The first path (shortest, no squares) and the last (around every square so far).
        order = [0] if len(candidates) == 1 else [0, len(candidates) - 1]
        cfg = self.config
        # A contact this long before the departure lies where every later departure along the
        # same path stands still too (the same positions, samples and speed bound): one more
        # step of the prediction's resampling on either side, and its time accuracy.
        slack = 2.0 * (cfg.prediction_dt or 0.0) + 1e-3
        struck: dict[int, float] = {}  # path -> the least delay struck while it waits
        for delay in cfg.wait_delays_s:
            for i in order:
                if delay >= struck.get(i, math.inf):
                    continue  # it would wait longer where that departure is struck
                if time.perf_counter() > deadline:
                    return None
                path, shapes = candidates[i]
                motion = motion_fn(path, shapes, delay)
                hit = first_collision(motion, predictions, self.robot_radius, margin=cfg.margin,
                                      sample_dt=cfg.prediction_dt)
                if hit is None:
                    return path, shapes, delay, motion
                departs = getattr(motion, "departs_s", None)
                if departs is not None and hit.t + slack <= departs:
                    struck[i] = min(delay, struck.get(i, math.inf))
        return None
