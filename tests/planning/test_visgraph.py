"""The visibility-graph optimum: hand-verified values, bounds and border handling."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest
from planning_problems import PEERS_POINT_OPTIMUM, PEERS_RECTS, box, peers_obstacles, peers_problem

from anyplan.geometry import Circle, ObstacleSet, Polygon
from anyplan.planning import PlannerStatus, Problem, VisGraphPlanner, lower_bound, shortest_path


def test_peers_point_robot_optimum():
    """The peers' problem: 22.233237 m via (3,7) (5,7) (7,4) (9,4) (10.5,8) for a point robot."""
    p = peers_problem(0.0)
    lo = shortest_path(p, variant="lower")
    assert lo.status is PlannerStatus.EXACT_SOLUTION
    assert lo.cost == pytest.approx(PEERS_POINT_OPTIMUM, abs=1e-6)
    via = {(3.0, 7.0), (5.0, 7.0), (7.0, 4.0), (9.0, 4.0), (10.5, 8.0)}
    assert {tuple(np.round(q, 9)) for q in lo.path[1:-1]} == via
    # The feasible variant keeps a 1 micrometre clearance (the exact check's minimum radius).
    fe = shortest_path(p, variant="feasible")
    assert PEERS_POINT_OPTIMUM - 1e-6 <= fe.cost <= PEERS_POINT_OPTIMUM + 1e-4
    assert p.path_valid(fe.path)


def test_bitangent_pruning_matches_the_complete_graph():
    """Brute force: the complete visibility graph gives the same optimum (convex, point robot)."""
    rng = np.random.default_rng(3)
    for _ in range(8):
        rects = []
        for _ in range(6):
            x, y = rng.uniform(1.0, 13.0), rng.uniform(1.0, 9.0)
            w, h = rng.uniform(0.3, 2.5, size=2)
            rects.append(box(x, y, x + w, y + h))
        obs = ObstacleSet(rects, bounds=(0.0, 0.0, 15.0, 11.0))
        p = Problem.create(obs, (0.5, 0.5), (14.5, 10.5), 0.0)
        a = shortest_path(p, variant="lower")
        b = shortest_path(p, variant="lower", prune_tangent=False)
        assert a.cost == pytest.approx(b.cost, abs=1e-9)
        assert a.n_edges <= b.n_edges


def test_disc_obstacle_matches_the_analytic_length():
    """Around one disc: two tangents plus an arc, 2 sqrt(d^2 - R^2) + R (pi - 2 acos(R / d))."""
    r, rc, d = 0.4, 1.1, 4.0
    obs = ObstacleSet([Circle((5.0, 5.0), rc)], bounds=(0.0, 0.0, 10.0, 10.0))
    p = Problem.create(obs, (5.0 - d, 5.0), (5.0 + d, 5.0), r)
    big_r = rc + r
    exact = 2.0 * math.sqrt(d * d - big_r * big_r) + big_r * (math.pi - 2.0 * math.acos(big_r / d))
    lo = shortest_path(p, variant="lower").cost
    hi = shortest_path(p, variant="feasible")
    assert lo <= exact <= hi.cost
    assert hi.cost - lo < 2e-3 * exact
    assert p.path_valid(hi.path)


def test_rounded_corner_matches_the_analytic_length():
    """Around one corner of a square inflated by r: tangent, quarter-ish arc, tangent."""
    r = 0.5
    obs = ObstacleSet([box(4.0, 0.0, 6.0, 4.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    s, g = np.array([2.0, 1.0]), np.array([8.0, 1.0])
    p = Problem.create(obs, s, g, r)
    # Shortest path wraps the two top corners (4,4) and (6,4) inflated by r: by symmetry it is
    # tangent from s to circle((4,4), r), the top segment of length 2, tangent to g.
    c1 = np.array([4.0, 4.0])
    dist = float(np.hypot(*(c1 - s)))
    tangent = math.sqrt(dist * dist - r * r)
    # Direction angles: from s to c1, and the tangent point angle on the circle.
    phi = math.atan2(c1[1] - s[1], c1[0] - s[0])
    alpha = math.asin(r / dist)
    heading = phi + alpha  # the tangent leaves s to the left of the centre line
    arc = r * heading  # the path turns right from 'heading' to horizontal around the corner
    exact = 2.0 * (tangent + arc) + 2.0
    lo = shortest_path(p, variant="lower").cost
    hi = shortest_path(p, variant="feasible")
    assert lo <= exact + 1e-9 and exact <= hi.cost + 1e-9
    assert hi.cost - lo < 1e-3 * exact
    assert p.path_valid(hi.path)


@pytest.mark.parametrize(("gap", "radius", "passes_under"), [(0.3, 0.25, False), (0.3, 0.1, True),
                                                              (0.0, 0.0, False)])
def test_border_touching_and_near_border_obstacles(gap, radius, passes_under):
    """Obstacles are not clipped at a wall: a gap to it narrower than 2 r is closed; a wider one is open."""
    obs = ObstacleSet([box(3.0, gap, 5.0, 7.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    p = Problem.create(obs, (1.0, 1.0), (7.0, 1.0), radius)
    for variant in ("lower", "feasible"):
        res = shortest_path(p, variant=variant)
        assert res.status is PlannerStatus.EXACT_SOLUTION
        over = res.path[:, 1].max() >= 7.0
        assert over != passes_under
    assert p.path_valid(shortest_path(p, variant="feasible").path)


def test_nonconvex_obstacle_bounds_bracket_and_feasible_path_is_valid():
    u_shape = Polygon([[3, 2], [8, 2], [8, 8], [3, 8], [3, 7], [7, 7], [7, 3], [3, 3]])
    obs = ObstacleSet([u_shape, Circle((10.0, 6.0), 0.6)], bounds=(0.0, 0.0, 12.0, 10.0))
    p = Problem.create(obs, (5.0, 5.0), (11.0, 1.0), 0.3)  # start inside the U's mouth
    lo = shortest_path(p, variant="lower")
    hi = shortest_path(p, variant="feasible")
    assert lo.status is PlannerStatus.EXACT_SOLUTION and hi.status is PlannerStatus.EXACT_SOLUTION
    assert lo.cost <= hi.cost < lo.cost * 1.002
    assert p.path_valid(hi.path)
    assert hi.path[:, 0].min() < 3.0  # it must leave the U through its mouth


def test_peers_inflated_bounds_and_planner():
    p = peers_problem(0.25)
    planner = VisGraphPlanner(p)
    assert planner.solve(0.0)
    res = planner.result()
    assert res.lower_bound is not None and res.lower_bound <= res.cost < res.lower_bound * 1.001
    assert p.path_valid(res.path)
    # Closed form for the disc robot: the point robot's via corners (3,7) (5,7) (7,4) (9,4)
    # (10.5,8), each rounded to a circle of radius r. The walls are r or more away from the
    # path. The path is tangent segments plus arcs. A corner is passed with the obstacle on the
    # right (rho = +r: over box 1, left of box 3) or on the left (rho = -r: under box 2). The
    # tangent from circle (c1, rho1) to (c2, rho2) with centre distance L at angle phi has the
    # direction phi - asin((rho1 - rho2) / L) and the length sqrt(L^2 - (rho1 - rho2)^2); each
    # arc is r times the turn between the two tangents' directions.
    r = 0.25
    via = [((1.0, 1.0), 0.0), ((3.0, 7.0), r), ((5.0, 7.0), r), ((7.0, 4.0), -r), ((9.0, 4.0), -r),
           ((10.5, 8.0), r), ((14.0, 10.0), 0.0)]
    heading, exact = [], 0.0
    for (c1, r1), (c2, r2) in zip(via, via[1:], strict=False):
        big_l = math.dist(c1, c2)
        heading.append(math.atan2(c2[1] - c1[1], c2[0] - c1[0]) - math.asin((r1 - r2) / big_l))
        exact += math.sqrt(big_l ** 2 - (r1 - r2) ** 2)
    exact += sum(r * abs(b - a) for a, b in zip(heading, heading[1:], strict=False))  # |turns| < pi
    assert res.lower_bound <= exact + 1e-9 and exact <= res.cost + 1e-9
    assert res.cost < exact * (1.0 + 1e-4)
    # Square (Minkowski-box) inflation is an upper bound for a disc robot. Its optimum is
    # computed here by brute force: Dijkstra over the complete visibility graph of the start,
    # the goal and the inflated boxes' corners that lie inside the arena shrunk by r. Its
    # path is the polyline through the grown via corners (24.0463 m).
    box_cost = _box_inflated_optimum(PEERS_RECTS, (0.0, 0.0, 15.0, 11.0), (1.0, 1.0), (14.0, 10.0), r)
    grown_via = [(1.0, 1.0), (2.75, 7.25), (5.25, 7.25), (6.75, 3.75), (9.25, 3.75), (10.25, 8.25),
                 (14.0, 10.0)]
    assert box_cost == pytest.approx(sum(map(math.dist, grown_via, grown_via[1:])), abs=1e-9)
    assert res.cost < box_cost


def _box_inflated_optimum(rects, bounds, start, goal, r):
    """Shortest point-robot path among the boxes grown by r (test-local, no anyplan code)."""
    grown = [(x0 - r, y0 - r, x1 + r, y1 + r) for x0, y0, x1, y1 in rects]

    def blocked(p, q):  # does pq enter a grown box's open interior? (Liang-Barsky clipping)
        for x0, y0, x1, y1 in grown:
            dx, dy = q[0] - p[0], q[1] - p[1]
            t0, t1 = 0.0, 1.0
            for den, num in ((-dx, p[0] - x0), (dx, x1 - p[0]), (-dy, p[1] - y0), (dy, y1 - p[1])):
                if den == 0.0:
                    t0 = t0 if num >= 0.0 else 2.0
                elif den < 0.0:
                    t0 = max(t0, num / den)
                else:
                    t1 = min(t1, num / den)
            tm = 0.5 * (t0 + t1)
            mx, my = p[0] + tm * dx, p[1] + tm * dy
            if t1 - t0 > 1e-12 and x0 + 1e-9 < mx < x1 - 1e-9 and y0 + 1e-9 < my < y1 - 1e-9:
                return True
        return False

    lo_x, lo_y, hi_x, hi_y = bounds[0] + r, bounds[1] + r, bounds[2] - r, bounds[3] - r
    nodes = [start, goal] + [(x, y) for x0, y0, x1, y1 in grown for x in (x0, x1) for y in (y0, y1)
                             if lo_x <= x <= hi_x and lo_y <= y <= hi_y]
    dist, todo = {0: 0.0}, [(0.0, 0)]
    while todo:
        d, i = heapq.heappop(todo)
        if i == 1:
            return d
        if d > dist[i]:
            continue
        for j, q in enumerate(nodes):
            nd = d + math.dist(nodes[i], q)
            if j != i and nd < dist.get(j, math.inf) and not blocked(nodes[i], q):
                dist[j] = nd
                heapq.heappush(todo, (nd, j))
    return math.inf


def test_infeasible_and_invalid_endpoints():
    wall = ObstacleSet([box(4.0, 0.0, 5.0, 10.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    p = Problem.create(wall, (1.0, 5.0), (8.0, 5.0), 0.2)
    assert shortest_path(p, variant="lower").status is PlannerStatus.INFEASIBLE
    assert lower_bound(p) == math.inf
    planner = VisGraphPlanner(p)
    assert planner.solve(0.0) is PlannerStatus.INFEASIBLE
    obs = peers_obstacles()
    assert shortest_path(Problem.create(obs, (4.0, 3.0), (14.0, 10.0), 0.2)).status \
        is PlannerStatus.INVALID_START
    assert shortest_path(Problem.create(obs, (1.0, 1.0), (14.9, 10.0), 0.2)).status \
        is PlannerStatus.INVALID_GOAL
