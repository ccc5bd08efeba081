"""The stable entry point ``anyplan.planning.plan``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from planning_problems import peers_obstacles

from anyplan.errors import UnknownNameError
from anyplan.geometry import Circle, square
from anyplan.planning import PlannerStatus, PlanResult, plan


def test_plan_result_fields_bitstar():
    res = plan(peers_obstacles(), (1.0, 1.0), (14.0, 10.0), 0.25, time_budget_s=0.05, rng=1,
               samples_per_batch=100)
    assert isinstance(res, PlanResult) and res.status is PlannerStatus.EXACT_SOLUTION
    assert res.path.ndim == 2 and res.path.shape[1] == 2
    assert math.isfinite(res.cost) and res.first_solution_time_s <= res.solve_time_s
    assert res.history and res.history[-1][1] == res.cost
    assert res.lower_bound is None  # BIT* proves no bound


def test_plan_visgraph_reports_its_lower_bound():
    res = plan(peers_obstacles(), (1.0, 1.0), (14.0, 10.0), 0.25, planner="visgraph")
    assert res.status and res.lower_bound <= res.cost <= 1.001 * res.lower_bound


def test_plan_extra_shapes_are_avoided():
    obs = peers_obstacles()
    blocker = square((6.0, 8.5), 1.0)
    for planner in ("bitstar", "visgraph"):
        res = plan(obs, (1.0, 1.0), (14.0, 10.0), 0.25, planner=planner, time_budget_s=0.05,
                   rng=np.random.default_rng(0), extra_shapes=[blocker, Circle((10.0, 1.0), 0.5)])
        assert res.status
        assert obs.with_shapes([blocker, Circle((10.0, 1.0), 0.5)]).path_free(res.path, 0.25)


def test_plan_no_solution_and_bad_input():
    res = plan(peers_obstacles(), (4.0, 3.0), (14.0, 10.0), 0.25, time_budget_s=0.01)
    assert res.status is PlannerStatus.INVALID_START and res.cost == math.inf
    assert res.path.shape == (0, 2)
    with pytest.raises(UnknownNameError, match="unknown planner 'rrt'"):
        plan(peers_obstacles(), (1.0, 1.0), (14.0, 10.0), 0.25, planner="rrt")
    with pytest.raises(ValueError, match="time_budget_s"):
        plan(peers_obstacles(), (1.0, 1.0), (14.0, 10.0), 0.25, time_budget_s=-1.0)
    with pytest.raises(ValueError, match="unknown BIT\\* option"):
        plan(peers_obstacles(), (1.0, 1.0), (14.0, 10.0), 0.25, samples=3)
