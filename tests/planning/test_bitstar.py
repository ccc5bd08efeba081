"""BIT*: validity, bounds, anytime monotonicity, determinism, failures, run-time obstacles.

Every budget here is a batch count, not a time, so the assertions are machine-independent.
Most tests use 100 samples per batch (OMPL's default) to stay fast.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from planning_problems import box, peers_obstacles, peers_problem

from anyplan.geometry import Circle, ObstacleSet, Polygon
from anyplan.planning import (
    BITStar,
    PlannerStatus,
    Problem,
    any_of,
    batches,
    first_solution,
    lower_bound,
    target_cost,
)
from anyplan.world import load_scenario

SPB = 100


def bit(problem: Problem, seed, **kw) -> BITStar:  # noqa: ANN001
    kw.setdefault("samples_per_batch", SPB)
    return BITStar(problem, rng=seed, **kw)


@pytest.fixture(scope="module")
def peers_lb() -> float:
    return lower_bound(peers_problem(0.25))


def test_paths_are_collision_free_and_above_the_lower_bound(peers_lb):
    p = peers_problem(0.25)
    for seed in range(3):
        planner = bit(p, seed)
        assert planner.solve(batches(40)) is PlannerStatus.EXACT_SOLUTION
        res = planner.result()
        assert p.path_valid(res.path)
        assert np.allclose(res.path[0], p.start) and np.allclose(res.path[-1], p.goal)
        length = float(np.sum(np.hypot(*np.diff(res.path, axis=0).T)))
        assert res.cost == pytest.approx(length, rel=1e-9)
        assert res.cost >= peers_lb - 1e-9


def test_converges_within_five_percent_of_the_optimum(peers_lb):
    """A fixed work budget (about 0.2-0.3 s on the dev machine) reaches <= 1.05 x optimum."""
    p = peers_problem(0.25)
    for seed in (0, 1, 2):
        planner = bit(p, seed)
        planner.solve(batches(60))
        assert peers_lb <= planner.best_cost <= 1.05 * peers_lb


@pytest.mark.parametrize("scenario", ["paper-1", "paper-2", "paper-3"])
def test_paper_scenarios_static(scenario):
    sc = load_scenario(scenario)
    p = Problem.create(sc.obstacle_set(), sc.robot.start[:2], sc.robot.goal, sc.robot.radius)
    planner = bit(p, 7)
    assert planner.solve(batches(30))
    res = planner.result()
    assert p.path_valid(res.path)
    assert res.cost >= lower_bound(p) - 1e-9


def test_cost_never_increases_across_solve_calls():
    """OMPL's 2dcircles_optimize property: repeated solve() calls only improve the cost."""
    p = peers_problem(0.25)
    planner = bit(p, 4)
    costs = []
    for _ in range(25):
        planner.solve(batches(1))
        costs.append(planner.best_cost)
    assert math.isfinite(costs[-1])
    assert all(b <= a for a, b in zip(costs, costs[1:], strict=False))
    hist = [c for _, c in planner.result().history]
    assert all(b < a for a, b in zip(hist, hist[1:], strict=False))
    times = [t for t, _ in planner.result().history]
    assert times == sorted(times)


def test_deterministic_for_a_seed():
    p = peers_problem(0.25)
    a = bit(p, np.random.default_rng(11))
    b = bit(p, np.random.default_rng(11))
    a.solve(batches(15))
    b.solve(batches(15))
    ra, rb = a.result(), b.result()
    assert np.array_equal(ra.path, rb.path)
    assert [c for _, c in ra.history] == [c for _, c in rb.history]
    assert ra.stats == rb.stats
    c = bit(p, 12)
    c.solve(batches(15))
    assert not np.array_equal(c.result().path, ra.path)


def test_callback_sees_every_improvement():
    seen = []
    p = peers_problem(0.25)
    planner = bit(p, 2, callback=lambda t, c, path: seen.append((t, c, path)))
    planner.solve(batches(10))
    hist = planner.result().history
    assert [(t, c) for t, c, _ in seen] == hist
    assert np.array_equal(seen[-1][2], planner.result().path)


def test_termination_by_target_cost_and_first_solution():
    p = peers_problem(0.25)
    planner = bit(p, 3)
    planner.solve(first_solution())
    first = planner.best_cost
    assert math.isfinite(first) and len(planner.result().history) == 1
    planner.solve(any_of(target_cost(0.99 * first), batches(200)))
    assert planner.best_cost <= 0.99 * first


def test_k_nearest_mode_finds_valid_paths(peers_lb):
    p = peers_problem(0.25)
    planner = bit(p, 5, use_k_nearest=True)
    assert planner.solve(batches(30))
    res = planner.result()
    assert p.path_valid(res.path) and res.cost >= peers_lb - 1e-9


def test_infeasible_problem_times_out_without_a_path():
    wall = ObstacleSet([box(4.0, 0.0, 5.0, 10.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    planner = bit(Problem.create(wall, (1.0, 5.0), (8.0, 5.0), 0.2), 0)
    assert planner.solve(batches(5)) is PlannerStatus.TIMEOUT
    res = planner.result()
    assert res.path.shape == (0, 2) and res.cost == math.inf and res.first_solution_time_s is None


def test_infeasible_problem_returns_at_its_time_budget():
    """With a time budget the search stops (it neither hangs nor claims a solution)."""
    wall = ObstacleSet([box(4.0, 0.0, 5.0, 10.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    planner = BITStar(Problem.create(wall, (1.0, 5.0), (8.0, 5.0), 0.2), rng=0)
    assert planner.solve(0.05) is PlannerStatus.TIMEOUT
    res = planner.result()
    assert 0.05 <= res.solve_time_s < 5.0  # generous: only catches a search that never stops
    assert res.path.shape == (0, 2) and res.history == []


def test_start_or_goal_in_collision_gives_a_clear_status():
    obs = peers_obstacles()
    s = BITStar(Problem.create(obs, (4.0, 3.0), (14.0, 10.0), 0.2), rng=0)
    assert s.solve(batches(3)) is PlannerStatus.INVALID_START
    g = BITStar(Problem.create(obs, (1.0, 1.0), (14.0, 10.9), 0.2), rng=0)  # too close to a wall
    assert g.solve(batches(3)) is PlannerStatus.INVALID_GOAL
    assert g.result().path.shape == (0, 2)


def test_straight_line_problem_stops_at_the_optimum():
    obs = ObstacleSet([Circle((5.0, 8.0), 1.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    planner = BITStar(Problem.create(obs, (1.0, 2.0), (9.0, 2.0), 0.3), rng=0)
    planner.solve(batches(1000))  # returns early: the straight line cannot be beaten
    assert planner.best_cost == pytest.approx(8.0)
    assert planner.n_batches == 0  # tried before any sampling
    assert planner.result().first_solution_time_s is not None
    assert np.array_equal(planner.result().path, [[1.0, 2.0], [9.0, 2.0]])


def test_add_obstacles_invalidates_only_what_they_block_and_reuses_work():
    p = peers_problem(0.25)
    planner = bit(p, 0)
    planner.solve(batches(20))
    path = planner.result().path
    blocker = [Circle(path[len(path) // 2], 0.6)]
    p2 = p.with_shapes(blocker)
    assert not p2.path_valid(path)  # the blocker cuts the current solution
    n_vertices = planner.stats["n_vertices"]
    checks_before = planner.stats["n_edge_checks"]
    planner.add_obstacles(blocker)
    assert planner.best_cost == math.inf  # the solution is gone ...
    assert planner.result().history[-1][1] == math.inf
    assert planner.stats["n_vertices"] > 0.5 * n_vertices  # ... most of the tree is not
    target = 1.03 * lower_bound(p2)
    planner.solve(any_of(target_cost(target), batches(300)))
    res = planner.result()
    assert res.status is PlannerStatus.EXACT_SOLUTION and p2.path_valid(res.path)
    assert res.cost <= target
    reused_checks = planner.stats["n_edge_checks"] - checks_before
    fresh = bit(p2, 0)
    fresh.solve(any_of(target_cost(target), batches(300)))
    assert fresh.best_cost <= target
    assert reused_checks < 0.5 * fresh.stats["n_edge_checks"]


def test_add_obstacles_keeps_an_unblocked_solution():
    p = peers_problem(0.25)
    planner = bit(p, 1)
    planner.solve(batches(10))
    cost = planner.best_cost
    far = [Polygon([[13.0, 0.5], [14.5, 0.5], [14.5, 1.5]])]  # nowhere near the solution
    planner.add_obstacles(far)
    assert planner.best_cost == cost
    planner.solve(batches(5))
    assert planner.best_cost <= cost
    assert p.with_shapes(far).path_valid(planner.result().path)


def test_add_obstacles_on_the_goal_reports_it():
    p = peers_problem(0.25)
    planner = bit(p, 1)
    planner.solve(batches(5))
    planner.add_obstacles([Circle((14.0, 10.0), 0.3)])
    assert planner.solve(batches(2)) is PlannerStatus.INVALID_GOAL


def test_bad_options_raise_naming_the_field():
    p = peers_problem(0.25)
    with pytest.raises(ValueError, match="rewire_factor"):
        BITStar(p, rewire_factor=0.5)
    with pytest.raises(ValueError, match="samples_per_batch"):
        BITStar(p, samples_per_batch=0)
    with pytest.raises(ValueError, match="unknown BIT\\* option 'sample_per_batch'"):
        BITStar(p, sample_per_batch=10)


@pytest.mark.slow
def test_one_second_budget_within_five_percent_on_random_worlds():
    """The issue's wording: <= 1.05 x the bound after 1 s (default settings), fixed seeds."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from bitstar import peers, random_world  # benchmarks/bitstar.py

    problems = [peers(0.25), peers(0.0)] + [random_world(i, i % 2 == 1) for i in range(6)]
    for k, p in enumerate(problems):
        lb = lower_bound(p)
        planner = BITStar(p, rng=100 + k)
        planner.solve(1.0)
        res = planner.result()
        assert res.status and p.path_valid(res.path)
        assert lb - 1e-9 <= res.cost <= 1.05 * lb


def test_a_new_batch_queues_exactly_the_vertices_a_new_sample_comes_near():
    """A batch queues the tree's vertices whose g + h_hat beats the solution and that were never
    expanded or have one of the batch's new samples within r (other vertices saw every older
    sample): the planner asks the new samples' grid about each vertex; brute force here."""
    p = peers_problem(0.25)
    queued = skipped = 0
    for seed in (0, 1):
        planner = bit(p, seed)
        for n in range(1, 9):
            planner.solve(batches(1) if n > 1 else first_solution())
            planner._new_batch()  # the batch's start, as the search makes it
            pts, tree, b = planner._points, planner._tree, planner._batch
            q = planner._queue
            m = int(pts.n[0])
            new = np.asarray(b.new)
            expect = set()
            for i in np.flatnonzero(tree.vertex[:m]):
                if tree.g[i] + pts.h_hat[i] >= planner.best_cost:
                    continue
                d = np.hypot(*(pts.xy[new] - pts.xy[i]).T)
                if tree.expanded[i] < 0 or b.k > 0 or np.any((d <= b.radius) & (new != i)):
                    expect.add(int(i))
            got = set(q.vertex[: q.nv[0]].tolist())
            assert got == expect
            queued += len(expect)
            skipped += int(tree.vertex[:m].sum()) - len(expect)
    assert queued > 0 and skipped > 0  # both kinds of vertex occur
