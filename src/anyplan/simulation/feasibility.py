"""Feasibility check before a run: is the goal provably out of reach among the static obstacles?

The visibility graph's "lower" variant (:func:`anyplan.planning.visgraph.lower_bound`) is a
relaxation: its obstacles (inflated by the robot radius, rounded corners replaced by inscribed
chords) lie inside the true ones, so when it finds no path, no collision-free path to the goal
point exists. A run ends at the goal when the robot is within ``goal_tolerance`` of it, so the
proof also needs that whole disc to be free: it is then connected to the goal point and cut off
from the start like it. Otherwise the check is inconclusive and the run goes ahead. On a map
(``static_map``), :func:`anyplan.planning.connectivity.provably_disconnected` (a cell cover,
linear in the arena's area) gives the proof instead.
"""

from __future__ import annotations

import math

from anyplan.planning.connectivity import provably_disconnected
from anyplan.planning.problem import Problem
from anyplan.planning.visgraph import lower_bound
from anyplan.world.scenario import Scenario

__all__ = ["goal_unreachable"]


def goal_unreachable(scenario: Scenario) -> bool:
    """True only when it is proven that the robot cannot reach the goal region (see above)."""
    r = scenario.robot
    obstacles = scenario.obstacle_set()
    start, goal = r.start[:2], r.goal
    if math.hypot(start[0] - goal[0], start[1] - goal[1]) <= r.goal_tolerance:
        return False
    if not obstacles.clearance(goal) - r.radius > r.goal_tolerance:
        return False  # part of the goal region may lie in another free component
    problem = Problem.create(obstacles, start, goal, r.radius)
    if not (problem.start_valid() and problem.goal_valid()):
        return False  # the loader refuses these; nothing is proven here
    if scenario.static_map is not None:
        # a map's many corners make the visibility graph slow: a cell-cover proof instead
        return provably_disconnected(obstacles, start, goal, r.radius)
    return math.isinf(lower_bound(problem))
