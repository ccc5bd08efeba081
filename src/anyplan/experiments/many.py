"""Scenarios with many moving obstacles (25, 50, 100, ...) in an open hall, and long routes.

The robot (:data:`anyplan.experiments.floorplans.ROBOT`, a 0.3 m disc at 1 m/s) crosses a
``width`` x ``height`` hall from (2, 2) to (width - 2, height - 2). Each obstacle is a disc
(radius 0.25-0.4 m) pacing back and forth at 0.3-1.0 m/s between two random points of the
hall (a looping ``waypoints`` motion), starting at least 2 m from the robot's start and goal;
a third of them pace across the robot's straight route (their two points on either side of
it), so that the route is crowded rather than merely surrounded. Everything is drawn from one
``numpy.random.Generator``: a seed gives the same scenario. :func:`long_route` is a corridor
hundreds of metres long with pillars and walkers along it (the cost of planning far ahead).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from anyplan.experiments.floorplans import ROBOT
from anyplan.world.scenario import Scenario, scenario_from_dict

__all__ = ["long_route", "many_obstacles"]


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


def long_route(length: float, rng: np.random.Generator | int = 0, *, width: float = 12.0,
               walker_every: float = 40.0) -> Scenario:
    """A ``length`` x ``width`` [m] corridor driven end to end (start and goal 2 m from its ends,
    on its axis): square pillars (1 m) every 12 m, alternately 2 m above and below the axis,
    and one walker (a 0.25 m disc) per ``walker_every`` metres pacing 20 m along the corridor
    at 0.8-1.2 m/s in a lane drawn across it, seen as the robot's sensor sees them
    (``sensing: tracked``, 8 m of range; the first walker paces towards the start).
    """
    if not length >= 10.0:
        raise ValueError(f"length must be >= 10 m, got {length}")
    g = np.random.default_rng(rng)
    mid = 0.5 * width
    pillars = [{"name": f"S{i}", "type": "rectangle", "center": [float(x), mid + (2.0 if i % 2 else -2.0)],
                "size": [1.0, 1.0], "angle": 0.0}
               for i, x in enumerate(np.arange(10.0, length - 5.0, 12.0))]
    walkers: list[dict[str, Any]] = []
    for k, x0 in enumerate(np.arange(8.0, length - 8.0, walker_every)):
        y = float(g.uniform(1.0, width - 1.0))
        a, b = float(x0) + 20.0, float(x0)  # from the far end towards the start first
        b = max(b, 3.0)
        v = float(g.uniform(0.8, 1.2))
        t1 = (a - b) / v
        walkers.append({"name": f"W{k}", "type": "waypoints", "radius": 0.25,
                        "keyframes": [[0.0, a, y], [round(t1, 6), b, y], [round(2 * t1, 6), a, y]]})
    route = length - 4.0
    data = {
        "name": f"long-route-{length:g}",
        "description": f"{length:g} m x {width:g} m corridor, pillars, {len(walkers)} walkers",
        "time_limit": 1.5 * route / ROBOT["v_max"] + 60.0,
        "arena": {"width": float(length), "height": float(width)},
        "robot": {"start": [2.0, mid, 0.0], "goal": [length - 2.0, mid], **ROBOT,
                  "sensing_range": 8.0},
        "static_obstacles": pillars,
        "dynamic_obstacles": walkers,
        "sensing": {"mode": "tracked"},
    }
    return scenario_from_dict(data, f"<long-route-{length:g}>")
