"""A lower bound on the time to the goal: the static shortest path driven at the robot's limits.

``time_lower_bound_s`` of a scenario is the least time in which the robot, starting at rest,
can reach the edge of the goal tolerance disc under ``|v| <= v_max`` and ``|dv/dt| <= a_max``,
ignoring the turn-rate limits and every moving obstacle: the length L of the shortest path
among the static obstacles (the visibility graph's proven lower bound) minus the goal tolerance,
driven from rest at a_max up to v_max. No robot beats it, so ``time_to_goal /
time_lower_bound_s >= 1`` for every run. It is computed once per static layout; on an
occupancy-grid map L is the straight start-goal distance (looser, but fast).

The derivation: ``docs/planning.md``, "Time lower bound".
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Any

import numpy as np

from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.visgraph import shortest_path

__all__ = ["min_time_from_rest", "static_path_length", "time_lower_bound_to_goal",
           "scenario_time_lower_bound"]

_CACHE: dict[str, float | None] = {}
_CACHE_MAX = 512


def min_time_from_rest(distance: float, v_max: float, a_max: float) -> float:
    """Least time [s] to cover ``distance`` [m] from rest, with speed <= ``v_max`` [m/s] and
    acceleration <= ``a_max`` [m/s^2], arriving at any speed.

    Examples:
        >>> min_time_from_rest(10.0, 0.5, 0.5)   # 0.25 m to reach 0.5 m/s, then cruise
        20.5
        >>> round(min_time_from_rest(0.1, 0.5, 0.5), 6)  # never reaches v_max: sqrt(2 d / a)
        0.632456
    """
    if not (v_max > 0.0 and a_max > 0.0):
        raise ValueError(f"v_max and a_max must be > 0, got {v_max}, {a_max}")
    if distance <= 0.0:
        return 0.0
    d_acc = v_max * v_max / (2.0 * a_max)
    if distance >= d_acc:
        return distance / v_max + v_max / (2.0 * a_max)
    return math.sqrt(2.0 * distance / a_max)


def static_path_length(obstacles: Any, start: Any, goal: Any, radius: float) -> float | None:
    """Length [m] of the shortest path of a disc of ``radius`` among the static ``obstacles``
    (an :class:`~anyplan.geometry.collision.ObstacleSet` with walls), a proven lower bound on
    the optimum; None when the start or goal is blocked or no path exists."""
    problem = Problem.create(obstacles, np.asarray(start, float)[:2], np.asarray(goal, float)[:2],
                             radius)
    res = shortest_path(problem, variant="lower")
    if res.status is not PlannerStatus.EXACT_SOLUTION or not math.isfinite(res.cost):
        return None
    return float(res.cost)


def time_lower_bound_to_goal(obstacles: Any, start: Any, goal: Any, radius: float,
                             goal_tolerance: float, v_max: float, a_max: float) -> float | None:
    """:func:`min_time_from_rest` over the static shortest path minus the goal tolerance [s];
    None when there is no static path."""
    length = static_path_length(obstacles, start, goal, radius)
    if length is None:
        return None
    return min_time_from_rest(max(length - goal_tolerance, 0.0), v_max, a_max)


def _key(scenario: Any) -> str:
    r = scenario.robot
    blob = json.dumps({"static": scenario.to_dict()["static_obstacles"],
                       "map": _has_map(scenario),
                       "arena": [scenario.width, scenario.height],
                       "robot": [list(map(float, r.start)), list(map(float, r.goal)),
                                 r.radius, r.goal_tolerance, r.v_max, r.a_max]},
                      sort_keys=True, default=float).encode()
    return hashlib.sha256(blob).hexdigest()


def _has_map(scenario: Any) -> bool:
    return getattr(scenario, "static_map", None) is not None


def scenario_time_lower_bound(scenario: Any) -> float | None:
    """The time lower bound [s] of a :class:`~anyplan.world.Scenario` (cached per static layout
    and robot); None when the static world has no path from start to goal."""
    key = _key(scenario)
    if key not in _CACHE:
        if len(_CACHE) >= _CACHE_MAX:
            _CACHE.pop(next(iter(_CACHE)))
        r = scenario.robot
        if _has_map(scenario):
            d = math.hypot(r.goal[0] - r.start[0], r.goal[1] - r.start[1])
            _CACHE[key] = min_time_from_rest(max(d - r.goal_tolerance, 0.0), r.v_max, r.a_max)
            return _CACHE[key]
        _CACHE[key] = time_lower_bound_to_goal(scenario.obstacle_set(), r.start, r.goal, r.radius,
                                               r.goal_tolerance, r.v_max, r.a_max)
    return _CACHE[key]
