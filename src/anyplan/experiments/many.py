"""Scenarios with many moving obstacles (25, 50, 100, ...) in an open hall.

The robot (:data:`anyplan.experiments.floorplans.ROBOT`, a 0.3 m disc at 1 m/s) crosses a
``width`` x ``height`` hall from (2, 2) to (width - 2, height - 2). Each obstacle is a disc
(radius 0.25-0.4 m) pacing back and forth at 0.3-1.0 m/s between two random points of the
hall (a looping ``waypoints`` motion), starting at least 2 m from the robot's start and goal;
a third of them pace across the robot's straight route (their two points on either side of
it), so that the route is crowded rather than merely surrounded. Everything is drawn from one
``numpy.random.Generator``: a seed gives the same scenario.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from anyplan.experiments.floorplans import ROBOT
from anyplan.world.scenario import Scenario, scenario_from_dict

__all__ = ["many_obstacles"]


def many_obstacles(n: int, rng: np.random.Generator | int = 0, *, width: float = 40.0,
                   height: float = 30.0, keep_clear: float = 2.0) -> Scenario:
    """A hall with ``n`` pacing obstacles (see the module docstring)."""
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    seed = rng if isinstance(rng, int) else None
    g = np.random.default_rng(rng)
    start = np.array([2.0, 2.0])
    goal = np.array([width - 2.0, height - 2.0])
    route = goal - start
    normal = np.array([-route[1], route[0]]) / float(np.hypot(*route))
    obstacles: list[dict[str, Any]] = []
    lo = np.array([1.0, 1.0])
    hi = np.array([width - 1.0, height - 1.0])
    while len(obstacles) < n:
        rad = float(g.uniform(0.25, 0.4))
        if len(obstacles) % 3 == 0:
            c = start + g.uniform(0.15, 0.85) * route
            half = float(g.uniform(2.0, 6.0))
            a = np.clip(c - half * normal, lo, hi)
            b = np.clip(c + half * normal, lo, hi)
        else:
            a, b = g.uniform(lo, hi), g.uniform(lo, hi)
        length = float(np.hypot(*(b - a)))
        if length < 1.0:
            continue
        u = float(g.uniform(0.0, 1.0))
        p = a + u * (b - a)
        if min(np.hypot(*(p - start)), np.hypot(*(p - goal))) < keep_clear + rad:
            continue
        v = float(g.uniform(0.3, 1.0))
        t1 = (1.0 - u) * length / v
        t2 = t1 + length / v
        t3 = t2 + u * length / v
        kf = [[0.0, *p], [t1, *b], [t2, *a], [t3, *p]]
        if t1 <= 1e-6 or t3 - t2 <= 1e-6:
            continue
        obstacles.append({"name": f"D{len(obstacles) + 1}", "type": "waypoints",
                          "radius": round(rad, 3),
                          "keyframes": [[round(float(x), 6) for x in row] for row in kf]})
    data = {
        "name": f"many-{n}",
        "description": f"{width:g} m x {height:g} m hall, {n} pacing obstacles (seed {seed})",
        "time_limit": 3.0 * math.hypot(*route) / ROBOT["v_max"] + 30.0,
        "arena": {"width": width, "height": height},
        "robot": {"start": [*start.tolist(), math.atan2(route[1], route[0])],
                  "goal": goal.tolist(), **ROBOT},
        "dynamic_obstacles": obstacles,
    }
    return scenario_from_dict(data, f"<many-{n}>")
