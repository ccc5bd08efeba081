"""The proofs that no path exists: the cell cover with its refinement near the obstacles, and the
visibility graph's relaxation among few obstacles. A proof is never wrong (checked against the
exact visibility graph); the refinement proves passages the coarse cover cannot."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.geometry import ObstacleSet, Polygon, rectangle
from anyplan.planning.connectivity import (
    MAX_EXACT_CORNERS,
    exactly_unsolvable,
    provably_disconnected,
)
from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.visgraph import shortest_path

R = 0.33
START, GOAL = (1.5, 3.0), (10.5, 3.5)


def _wall():
    """A wall at x = 6 (faces at 5.9 and 6.1) with a gap at y 2.2 .. 3.7."""
    return [rectangle((6.0, 1.1), (0.2, 2.2)), rectangle((6.0, 5.85), (0.2, 4.3))]


def _gap_and_square(dx: float, dy: float) -> ObstacleSet:
    """:func:`_wall` and a 1.2 m square just behind the gap, at ``dx`` from the wall's face
    and ``dy`` above the gap's lower edge (the square's corner)."""
    x0, y0 = 6.1 + dx, 2.2 + dy
    square = Polygon(np.array([[x0, y0], [x0 + 1.2, y0], [x0 + 1.2, y0 + 1.2], [x0, y0 + 1.2]]))
    return ObstacleSet([*_wall(), square], bounds=(0.0, 0.0, 12.0, 8.0))


def test_the_refinement_proves_a_passage_the_coarse_cover_cannot():
    # The square's lower corner stands 0.3 m right of the wall and 0.38 m above the gap's edge:
    # the passage (0.48 m) is narrower than the robot (0.66 m), but not by the coarse cells' loss.
    obs = _gap_and_square(0.3, 0.38)
    assert shortest_path(Problem.create(obs, START, GOAL, R)).status is PlannerStatus.INFEASIBLE
    assert not provably_disconnected(obs, START, GOAL, R, refine=1)
    assert provably_disconnected(obs, START, GOAL, R)


def test_the_visibility_graph_proves_what_no_cell_can():
    # 2 cm narrower than the robot: finer than the refined cells, exact for the visibility graph.
    def behind(d: float) -> ObstacleSet:  # a block whose face stands d from the wall's
        return ObstacleSet([*_wall(), rectangle((6.1 + d + 0.6, 2.95), (1.2, 4.0))],
                           bounds=(0.0, 0.0, 12.0, 8.0))

    obs = behind(2.0 * R - 0.02)
    assert not provably_disconnected(obs, START, GOAL, R)
    assert exactly_unsolvable(Problem.create(obs, START, GOAL, R))
    assert not exactly_unsolvable(Problem.create(behind(2.0 * R + 0.02), START, GOAL, R))


def test_the_visibility_graph_is_not_asked_among_many_obstacles():
    # Beyond MAX_EXACT_CORNERS the (quadratic) visibility graph is not built: no proof.
    walls = [rectangle((6.0, 4.0), (0.2, 8.0))]
    n = MAX_EXACT_CORNERS // 4 + 1
    clutter = [rectangle((0.5 + 0.2 * k, 7.7), (0.05, 0.05)) for k in range(n)]
    problem = Problem.create(ObstacleSet(walls + clutter, bounds=(0.0, 0.0, 12.0, 8.0)),
                             START, GOAL, R)
    assert not exactly_unsolvable(problem)
    assert exactly_unsolvable(Problem.create(ObstacleSet(walls, bounds=(0.0, 0.0, 12.0, 8.0)),
                                             START, GOAL, R))


@pytest.mark.parametrize("seed", range(4))
def test_no_proof_where_the_visibility_graph_finds_a_path(seed):
    # Squares scattered behind the gap at random: every proof agrees with the exact graph.
    rng = np.random.default_rng(seed)
    proved = found = 0
    for _ in range(25):
        obs = _gap_and_square(*rng.uniform((0.0, -1.5), (1.2, 1.8)))
        exact = shortest_path(Problem.create(obs, START, GOAL, R)).status
        cover = provably_disconnected(obs, START, GOAL, R)
        graph = exactly_unsolvable(Problem.create(obs, START, GOAL, R))
        if exact is PlannerStatus.EXACT_SOLUTION:
            found += 1
            assert not cover and not graph
        else:  # (the exact graph may miss a path by its arcs; then nothing is asserted)
            proved += cover
            assert graph or not cover
    assert found and proved


@pytest.mark.parametrize("seed", range(3))
def test_the_default_cover_proves_all_that_half_radius_cells_prove(seed):
    # Every cell the half-radius cover blocks stays blocked on the nested finer grid, so the
    # default (radius cells, refined) proves at least as much, on maps (many boxes) included.
    from anyplan.geometry.cells import cell_boxes, merge_cells

    rng = np.random.default_rng(seed)
    old_proofs = 0
    for _ in range(12):
        occ = rng.random((24, 32)) < 0.3
        boxes = cell_boxes(merge_cells(occ), (0.0, 0.0), 0.25)
        obs = ObstacleSet([], bounds=(0.0, 0.0, 8.0, 6.0), boxes=boxes)
        free = np.argwhere(~occ)
        a, b = free[rng.choice(len(free), 2, replace=False)]
        s, g = (a[1] * 0.25 + 0.125, a[0] * 0.25 + 0.125), (b[1] * 0.25 + 0.125, b[0] * 0.25 + 0.125)
        r = float(rng.uniform(0.08, 0.12))
        old = provably_disconnected(obs, s, g, r, cell=r / 2.0, refine=1)
        old_proofs += old
        if old:
            assert provably_disconnected(obs, s, g, r)
    assert old_proofs


def test_a_maps_kept_cell_tests_give_the_answers_of_testing_the_whole_set():
    # On an indexed map the boxes' cell tests are kept across calls and combined with the
    # squares' (tested only near their boxes): every mask equals the direct test of the whole
    # set, for squares and circles that change from call to call as a replanning's do.
    from anyplan.geometry import Circle
    from anyplan.geometry.cells import cell_boxes, merge_cells
    from anyplan.planning import connectivity as cn

    rng = np.random.default_rng(7)
    occ = rng.random((40, 48)) < 0.25
    boxes = cell_boxes(merge_cells(occ), (0.0, 0.0), 0.25)
    world = ObstacleSet([rectangle((3.0, 3.0), (0.4, 0.4))], bounds=(0.0, 0.0, 12.0, 10.0),
                        boxes=boxes)
    assert world.indexed
    cn._MASKS.clear(), cn._FINE.clear()
    for call in range(6):
        extra = [rectangle(tuple(rng.uniform((1.0, 1.0), (11.0, 9.0))),
                           tuple(rng.uniform(0.3, 1.5, 2))) for _ in range(call % 3)]
        extra += [Circle(tuple(rng.uniform((1.0, 1.0), (11.0, 9.0))), 0.4)] * (call % 2)
        obs = world.with_shapes(extra)
        assert obs.split_boxes()[0] is world.split_boxes()[0]  # one base, so one memo
        h, nx, ny = 0.3, 40, 34
        centres = cn._centres(0.0, 0.0, h, nx, ny)
        cover = cn._Cover(obs, 0.0, 0.0, h, nx, ny, centres)
        for limit in (0.1, 0.35):
            assert np.array_equal(cover.clear(limit),
                                  obs.points_clear(centres, limit).reshape(ny, nx))
        near = rng.random((ny, nx)) < 0.3
        fine = np.zeros((ny * 4, nx * 4), dtype=bool)
        cover.refine(fine, near, 4, 0.12)
        fi, fj = cn._fine_cells(near, 4)
        pts = np.column_stack([(fj + 0.5) * h / 4, (fi + 0.5) * h / 4])
        assert np.array_equal(fine[fi, fj], obs.points_clear(pts, 0.12))
        assert not fine[~np.repeat(np.repeat(near, 4, axis=0), 4, axis=1)].any()
