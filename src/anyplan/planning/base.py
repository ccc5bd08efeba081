"""Planner base class and the result record, after OMPL's ``Planner`` contract.

``solve(ptc)`` may be called repeatedly on the same problem and resumes where it stopped (the
anytime contract); :meth:`Planner.clear` drops the search state and keeps the configuration.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.termination import TerminationCondition

__all__ = ["Planner", "PlanResult", "ImprovementCallback"]

#: Called as ``callback(t_s, cost_m, path)`` whenever the best solution improves; ``t_s`` is
#: the planner's cumulative solve time.
ImprovementCallback = Callable[[float, float, np.ndarray], None]


@dataclass
class PlanResult:
    """The outcome of planning.

    Attributes:
        status: What was achieved; ``bool(status)`` is True iff ``path`` is a solution.
        path: Waypoints from start to goal [m], shape (N, 2); shape (0, 2) without a solution.
        cost: Path length [m]; ``inf`` without a solution.
        solve_time_s: Cumulative wall-clock time spent in ``solve`` [s].
        first_solution_time_s: Solve time at which the first solution was found [s], or None.
        history: ``(t_s, cost_m)`` at each improvement, t in cumulative solve time (``inf``
            marks a solution lost to obstacles added at run time).
        lower_bound: A proven lower bound on the optimal cost [m] if known, else None.
        planner: Name of the planner.
        stats: Planner-specific counters (samples, edge checks, batches, ...).
    """

    status: PlannerStatus
    path: np.ndarray
    cost: float
    solve_time_s: float
    first_solution_time_s: float | None
    history: list[tuple[float, float]] = field(default_factory=list)
    lower_bound: float | None = None
    planner: str = ""
    stats: dict[str, Any] = field(default_factory=dict)

    @property
    def solved(self) -> bool:
        """True iff a solution path exists."""
        return bool(self.status)

    def cost_at(self, t_s: float) -> float:
        """Cost [m] of the solution held at solve time ``t_s`` [s] (``inf`` if none).

        The latest history entry at or before ``t_s``; entries only decrease, except where
        obstacles were added at run time (an entry ``inf`` marks a lost solution).
        """
        cost = math.inf
        for t, c in self.history:
            if t <= t_s:
                cost = c
        return cost

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (the ``anyplan plan`` output schema)."""
        return {
            "status": self.status.value,
            "cost": None if not math.isfinite(self.cost) else float(self.cost),
            "path": [[float(x), float(y)] for x, y in np.asarray(self.path).reshape(-1, 2)],
            "first_solution_time_s": self.first_solution_time_s,
            "solve_time_s": float(self.solve_time_s),
            "history": [[float(t), float(c) if math.isfinite(c) else None]
                        for t, c in self.history],
            "lower_bound": None if self.lower_bound is None else float(self.lower_bound),
            "planner": self.planner,
            "stats": dict(self.stats),
        }


class Planner(abc.ABC):
    """A planner bound to one :class:`Problem`.

    Attributes:
        name: Registry name of the planner.
        problem: The problem being solved.
    """

    name: str = "planner"

    def __init__(self, problem: Problem) -> None:
        self.problem = problem

    @abc.abstractmethod
    def solve(self, ptc: TerminationCondition | float) -> PlannerStatus:
        """Improve the solution until ``ptc()`` is True; calling again resumes (anytime)."""

    @abc.abstractmethod
    def result(self) -> PlanResult:
        """The best solution so far and the progress record."""

    @property
    @abc.abstractmethod
    def best_cost(self) -> float:
        """Cost [m] of the best solution so far (``inf`` if none)."""

    def clear(self) -> None:  # noqa: B027 - optional hook
        """Drop the search state, keep the configuration."""
