"""Termination conditions and status semantics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.geometry import ObstacleSet
from anyplan.planning import (
    PlannerStatus,
    Problem,
    all_of,
    any_of,
    batches,
    first_solution,
    target_cost,
    timed,
)
from anyplan.planning.termination import as_condition


class FakePlanner:
    def __init__(self) -> None:
        self.n_batches = 0
        self.best_cost = math.inf


def test_status_truthiness():
    assert bool(PlannerStatus.EXACT_SOLUTION)
    for s in (PlannerStatus.TIMEOUT, PlannerStatus.INVALID_START, PlannerStatus.INVALID_GOAL,
              PlannerStatus.INFEASIBLE):
        assert not bool(s)


def test_timed_uses_the_clock_from_bind():
    now = [10.0]
    c = timed(0.5, clock=lambda: now[0])
    now[0] = 20.0
    c.bind(None)  # the budget starts here
    assert not c()
    now[0] = 20.49
    assert not c()
    now[0] = 20.5
    assert c()
    now[0] = 0.0
    assert c()  # latched


def test_progress_conditions_and_combinators():
    p = FakePlanner()
    b, t, f = batches(2), target_cost(10.0), first_solution()
    either, both = any_of(b, t), all_of(batches(2), first_solution())
    for c in (b, t, f, either, both):
        c.bind(p)
    assert not (b() or t() or f() or either() or both())
    p.n_batches = 2
    assert not b()
    p.n_batches = 3
    assert b() and either() and not both()
    p.best_cost = 12.0
    assert f() and both() and not t()
    p.best_cost = 10.0
    assert t()


def test_batches_counts_from_bind():
    p = FakePlanner()
    p.n_batches = 5
    c = batches(1).bind(p)
    assert not c()
    p.n_batches = 7
    assert c()


def test_terminate_and_operators():
    c = timed(100.0) | target_cost(1.0)
    assert not c()
    c.terminate()
    assert c()


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="seconds"):
        timed(-1.0)
    with pytest.raises(ValueError, match="n must be"):
        batches(0)
    with pytest.raises(TypeError):
        as_condition("1s")  # type: ignore[arg-type]


def test_problem_validation_names_the_field():
    obs = ObstacleSet([], bounds=(0.0, 0.0, 5.0, 5.0))
    with pytest.raises(ValueError, match="start"):
        Problem.create(obs, (1.0, np.nan), (2.0, 2.0), 0.1)
    with pytest.raises(ValueError, match="goal"):
        Problem.create(obs, (1.0, 1.0), (2.0, 2.0, 3.0), 0.1)
    with pytest.raises(ValueError, match="radius"):
        Problem.create(obs, (1.0, 1.0), (2.0, 2.0), -0.1)
    with pytest.raises(ValueError, match="bounds"):
        Problem.create(ObstacleSet([]), (1.0, 1.0), (2.0, 2.0), 0.1)
