"""One-call planning: :func:`plan` (the stable entry point used by the other layers)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from anyplan.errors import UnknownNameError
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Shape
from anyplan.planning.base import Planner, PlanResult
from anyplan.planning.problem import Problem
from anyplan.planning.termination import timed

__all__ = ["plan", "make_planner", "PLANNERS"]

#: Planner names accepted by :func:`plan` and ``anyplan plan --planner``.
PLANNERS = ("bitstar", "visgraph")


def make_planner(name: str, problem: Problem, *, rng: np.random.Generator | int | None = None,
                 **config: Any) -> Planner:
    """A planner by name ("bitstar" or "visgraph") for ``problem``; ``config`` are its options."""
    if name == "bitstar":
        from anyplan.planning.bitstar import BITStar

        return BITStar(problem, rng=rng, **config)
    if name == "visgraph":
        from anyplan.planning.visgraph import VisGraphPlanner

        return VisGraphPlanner(problem, **config)
    raise UnknownNameError("planner", name, list(PLANNERS))


def plan(obstacles: ObstacleSet, start: Sequence[float] | np.ndarray,
         goal: Sequence[float] | np.ndarray, radius: float, *, planner: str = "bitstar",
         time_budget_s: float = 0.1, rng: np.random.Generator | int | None = None,
         extra_shapes: Iterable[Shape] = (), **config: Any) -> PlanResult:
    """Plan a collision-free path for a disc robot from ``start`` to ``goal``.

    Args:
        obstacles: Static obstacles; its ``bounds`` (the arena walls) are required and are
            the sampling domain.
        start: Start (x, y) [m].
        goal: Goal (x, y) [m].
        radius: Robot radius [m] (the obstacles are inflated by it).
        planner: "bitstar" (anytime) or "visgraph" (exact, non-iterative).
        time_budget_s: Wall-clock budget [s] for BIT*.
        rng: Generator or seed for the sampling planners (deterministic for a seed, up to
            where the time budget stops the search).
        extra_shapes: Obstacles added to ``obstacles`` for this query (e.g. virtual obstacles).
        **config: Planner options (see :class:`~anyplan.planning.bitstar.BITStarConfig`, or
            ``arc_step`` for visgraph).

    Returns:
        The :class:`PlanResult`; ``bool(result.status)`` tells whether a path was found, and a
        found path is collision-free under the exact check.

    Example:
        >>> from anyplan.geometry import ObstacleSet, square
        >>> obs = ObstacleSet([square((5.0, 5.0), 2.0)], bounds=(0.0, 0.0, 10.0, 10.0))
        >>> res = plan(obs, (1.0, 5.0), (9.0, 5.0), 0.3, time_budget_s=0.05, rng=0)
        >>> bool(res.status), res.path.shape[1]
        (True, 2)
    """
    if not (isinstance(time_budget_s, int | float) and time_budget_s >= 0.0):
        raise ValueError(f"time_budget_s: must be a number >= 0, got {time_budget_s!r}")
    extra = tuple(extra_shapes)
    obs = obstacles.with_shapes(extra) if extra else obstacles
    problem = Problem.create(obs, start, goal, radius)
    p = make_planner(planner, problem, rng=rng, **config)
    p.solve(timed(float(time_budget_s)))
    return p.result()
