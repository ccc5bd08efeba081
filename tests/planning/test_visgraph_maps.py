"""The visibility graph and BIT* on maps (merged cells as boxes): same optimum as the boxes given
as polygons (the general, per-shape construction), valid paths, and the lower bound below it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.geometry import ObstacleSet, Polygon
from anyplan.geometry.cells import cell_boxes, merge_cells
from anyplan.planning import plan
from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.visgraph import shortest_path


def _random_map(seed: int, ny: int = 16, nx: int = 20, p: float = 0.12, res: float = 0.25):
    rng = np.random.default_rng(seed)
    occ = rng.random((ny, nx)) < p
    occ[:2, :2] = False       # start corner
    occ[-2:, -2:] = False     # goal corner
    return occ, cell_boxes(merge_cells(occ), (0.0, 0.0), res)


def _as_polygons(boxes: np.ndarray) -> list[Polygon]:
    return [Polygon(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])) for x0, y0, x1, y1 in boxes]


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("radius", [0.0, 0.1])
def test_map_visgraph_equals_polygon_visgraph(seed, radius):
    _occ, boxes = _random_map(seed)
    bounds = (0.0, 0.0, 5.0, 4.0)
    start, goal = (0.25, 0.25), (4.75, 3.75)
    as_map = Problem.create(ObstacleSet([], bounds=bounds, boxes=boxes), start, goal, radius)
    as_polys = Problem.create(ObstacleSet(_as_polygons(boxes), bounds=bounds, index=False),
                              start, goal, radius)
    for variant in ("lower", "feasible"):
        a = shortest_path(as_map, variant=variant, arc_step=math.pi / 16)
        b = shortest_path(as_polys, variant=variant, arc_step=math.pi / 16)
        assert a.status == b.status
        if a.status is PlannerStatus.EXACT_SOLUTION:
            assert a.cost == pytest.approx(b.cost, rel=1e-9, abs=1e-9)
            if variant == "feasible":
                assert as_map.obstacles.path_free(a.path, as_map.check_radius)
            # corner pruning: far fewer nodes than one per box corner
            assert a.n_nodes <= b.n_nodes


def test_lower_bound_is_below_the_feasible_path_on_a_map():
    _occ, boxes = _random_map(12, 30, 40, 0.08, 0.2)
    obs = ObstacleSet([], bounds=(0.0, 0.0, 8.0, 6.0), boxes=boxes)
    prob = Problem.create(obs, (0.2, 0.2), (7.8, 5.8), 0.15)
    lo = shortest_path(prob, variant="lower", arc_step=math.pi / 8)
    hi = shortest_path(prob, variant="feasible", arc_step=math.pi / 8)
    assert lo.status is hi.status is PlannerStatus.EXACT_SOLUTION
    assert lo.cost <= hi.cost <= lo.cost * 1.01
    assert obs.path_free(hi.path, prob.check_radius)
    best = plan(obs, (0.2, 0.2), (7.8, 5.8), 0.15, time_budget_s=0.3, rng=0)
    assert best.status and best.cost >= lo.cost - 1e-9
    assert obs.path_free(best.path, 0.15)


def test_cell_cover_proves_disconnection_and_never_a_false_one():
    from anyplan.planning.connectivity import provably_disconnected

    occ = np.zeros((20, 30), dtype=bool)
    occ[:, 14:16] = True                       # a wall cutting the map in two
    boxes = cell_boxes(merge_cells(occ), (0.0, 0.0), 0.2)
    obs = ObstacleSet([], bounds=(0.0, 0.0, 6.0, 4.0), boxes=boxes)
    assert provably_disconnected(obs, (1.0, 2.0), (5.0, 2.0), 0.2)
    occ[9:12, 14:16] = False                   # a 0.6 m door: reachable for a 0.2 m disc
    boxes = cell_boxes(merge_cells(occ), (0.0, 0.0), 0.2)
    obs = ObstacleSet([], bounds=(0.0, 0.0, 6.0, 4.0), boxes=boxes)
    assert not provably_disconnected(obs, (1.0, 2.0), (5.0, 2.0), 0.2)
    prob = Problem.create(obs, (1.0, 2.0), (5.0, 2.0), 0.2)
    assert shortest_path(prob, variant="feasible").status is PlannerStatus.EXACT_SOLUTION
    for seed in range(8):   # never claims disconnection where the visibility graph finds a path
        _, boxes = _random_map(seed, 16, 20, 0.15, 0.25)
        obs = ObstacleSet([], bounds=(0.0, 0.0, 5.0, 4.0), boxes=boxes)
        prob = Problem.create(obs, (0.25, 0.25), (4.75, 3.75), 0.1)
        if shortest_path(prob, variant="feasible").status is PlannerStatus.EXACT_SOLUTION:
            assert not provably_disconnected(obs, (0.25, 0.25), (4.75, 3.75), 0.1)


def test_many_obstacle_scenarios_are_seeded_and_valid():
    from anyplan.experiments.many import many_obstacles

    a, b = many_obstacles(25, rng=3), many_obstacles(25, rng=3)
    assert len(a.moving_obstacles) == 25 and a.content_hash() == b.content_hash()
    assert many_obstacles(25, rng=4).content_hash() != a.content_hash()
    x0, y0, x1, y1 = a.bounds
    for o in a.moving_obstacles:  # they pace inside the hall, away from the start at t = 0
        for t in np.linspace(0.0, 120.0, 61):
            p = o.position(float(t))
            assert x0 <= p[0] <= x1 and y0 <= p[1] <= y1
        assert np.hypot(*(o.position(0.0) - np.array(a.robot.start[:2]))) >= 2.0


@pytest.mark.parametrize("seed", range(3))
def test_flood_fill_agrees_with_connected_component_labelling(seed):
    # The compiled 8-connected flood fill of provably_disconnected against scipy's labelling.
    from scipy import ndimage

    from anyplan.planning._connectivity_kernels import connected8

    rng = np.random.default_rng(seed)
    for _ in range(40):
        ny, nx = rng.integers(1, 30, size=2)
        grid = rng.random((ny, nx)) < rng.uniform(0.3, 0.8)
        labels, _ = ndimage.label(grid, structure=np.ones((3, 3), dtype=int))
        a = (int(rng.integers(ny)), int(rng.integers(nx)))
        b = (int(rng.integers(ny)), int(rng.integers(nx)))
        want = bool(labels[a] != 0 and labels[a] == labels[b])
        assert connected8(grid, *a, *b) == want


def test_long_routes_are_seeded_valid_and_driven():
    # The long-route corridors of benchmarks/maps.py: seeded, walkers inside the corridor, a
    # tracked sensor, pillars off the route's axis; a length below 10 m refused; and the 30 m
    # one driven to its goal without a collision.
    from anyplan.agents import make_agent
    from anyplan.experiments.many import long_route
    from anyplan.simulation import simulate

    a, b = long_route(150.0, rng=2), long_route(150.0, rng=2)
    assert a.content_hash() == b.content_hash() != long_route(150.0, rng=3).content_hash()
    assert len(a.moving_obstacles) == 4 and len(a.static_obstacles) == 12
    assert a.sensing.mode == "tracked" and a.robot.sensing_range == 8.0
    x0, y0, x1, y1 = a.bounds
    for o in a.moving_obstacles:
        for t in np.linspace(0.0, 200.0, 101):
            p = o.position(float(t))
            assert x0 <= p[0] <= x1 and y0 <= p[1] <= y1
    axis = np.array([a.robot.start[:2], a.robot.goal[:2]])  # the pillars leave the axis free
    assert ObstacleSet([s.shape for s in a.static_obstacles]).segment_free(*axis, a.robot.radius)
    with pytest.raises(ValueError, match="length must be >= 10 m"):
        long_route(5.0)
    res = simulate(long_route(30.0, rng=1), make_agent("st-bitstar"), seed=0)
    assert res.reached_goal and not res.collision
