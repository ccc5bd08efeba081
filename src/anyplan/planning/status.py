"""Planner outcome, after OMPL's ``PlannerStatus`` (Sucan, Moll & Kavraki, IEEE RAM 2012)."""

from __future__ import annotations

import enum

__all__ = ["PlannerStatus"]


class PlannerStatus(enum.Enum):
    """What a call to ``solve`` achieved; ``bool(status)`` is True iff a path was found.

    Members:
        EXACT_SOLUTION: A collision-free path from start to goal exists in the result.
        TIMEOUT: The termination condition fired before any solution was found.
        INVALID_START: The start is in collision (or outside the arena).
        INVALID_GOAL: The goal is in collision (or outside the arena).
        INFEASIBLE: The planner proved that no path exists (only exact planners can).
    """

    EXACT_SOLUTION = "exact"
    TIMEOUT = "timeout"
    INVALID_START = "invalid_start"
    INVALID_GOAL = "invalid_goal"
    INFEASIBLE = "infeasible"

    def __bool__(self) -> bool:
        return self is PlannerStatus.EXACT_SOLUTION

    def __str__(self) -> str:
        return self.value
