"""Planning: problem, status, termination conditions, BIT* and the visibility-graph optimum.

The stable entry point is :func:`plan`; the planner classes follow OMPL's contract
(``solve(ptc)`` resumes, ``bool(status)`` means "solved").
"""

from anyplan.planning.api import PLANNERS, make_planner, plan
from anyplan.planning.base import Planner, PlanResult
from anyplan.planning.bitstar import BITStar, BITStarConfig, PlannerData
from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.termination import (
    TerminationCondition,
    all_of,
    any_of,
    batches,
    first_solution,
    target_cost,
    timed,
)
from anyplan.planning.visgraph import VisGraphPlanner, lower_bound, shortest_path

__all__ = [
    "BITStar",
    "BITStarConfig",
    "PLANNERS",
    "PlanResult",
    "Planner",
    "PlannerData",
    "PlannerStatus",
    "Problem",
    "TerminationCondition",
    "VisGraphPlanner",
    "all_of",
    "any_of",
    "batches",
    "first_solution",
    "lower_bound",
    "make_planner",
    "plan",
    "shortest_path",
    "target_cost",
    "timed",
]
