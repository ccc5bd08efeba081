"""Planning test problems: the peers' problem (benchmarks/scenarios/peers.yaml) and friends.

Imported by the tests of this folder (``from planning_problems import ...``)."""

from __future__ import annotations

from anyplan.geometry import ObstacleSet, Polygon
from anyplan.planning import Problem

PEERS_RECTS = [(3.0, 0.0, 5.0, 7.0), (7.0, 4.0, 9.0, 11.0), (10.5, 2.0, 12.5, 8.0)]
#: Exact optimum for a point robot, from the extremitypathfinder oracle.
PEERS_POINT_OPTIMUM = 22.233237


def box(x0: float, y0: float, x1: float, y1: float) -> Polygon:
    return Polygon([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def peers_obstacles() -> ObstacleSet:
    return ObstacleSet([box(*r) for r in PEERS_RECTS], bounds=(0.0, 0.0, 15.0, 11.0))


def peers_problem(radius: float = 0.25) -> Problem:
    return Problem.create(peers_obstacles(), (1.0, 1.0), (14.0, 10.0), radius)
