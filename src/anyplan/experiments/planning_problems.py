"""Static planning problems where planners differ: ``anyplan bench-planning``'s default suite.

On the paper's layouts the straight start-goal segment is free, so every planner returns the
same straight line at once. The ``planning`` suite instead holds:

* ``peers``: the shared comparison problem of the project's peer study (15 m x 11 m, two walls
  touching the border and a block; a 0.25 m disc from (1, 1) to (14, 10));
* ``cluttered-s{seed}-{k}``: random cluttered 15 m x 11 m worlds (25-40 rectangles, discs and
  polygons; every other one also has two or three long walls that force detours), with the
  paper's robot. Each is drawn from ``SeedSequence([seed, k])`` and kept only when the start
  and goal are free, the straight segment between them is **blocked**, and the goal is
  reachable (:func:`~anyplan.experiments.generate.route_is_connected`).

They have no moving obstacles (a planning benchmark uses only the static part).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from anyplan.errors import ScenarioError
from anyplan.experiments.generate import P3DX, GenerationError, route_is_connected
from anyplan.world.scenario import Scenario, scenario_from_dict

__all__ = ["peers_problem", "cluttered_world", "planning_suite"]

_W, _H = 15.0, 11.0


def _rect(name: str, x0: float, y0: float, x1: float, y1: float, angle: float = 0.0) -> dict[str, Any]:
    return {"name": name, "type": "rectangle", "center": [round((x0 + x1) / 2, 4), round((y0 + y1) / 2, 4)],
            "size": [round(x1 - x0, 4), round(y1 - y0, 4)], "angle": round(angle, 4)}


def _robot(start: tuple[float, float], goal: tuple[float, float], radius: float) -> dict[str, Any]:
    heading = math.atan2(goal[1] - start[1], goal[0] - start[0])
    return {**P3DX, "radius": radius, "start": [start[0], start[1], round(heading, 4)],
            "goal": [goal[0], goal[1]]}


def peers_problem() -> Scenario:
    """The peer study's shared problem (static only)."""
    return scenario_from_dict({
        "name": "peers", "description": "peer study's shared problem: two border walls and a block",
        "arena": {"width": _W, "height": _H}, "robot": _robot((1.0, 1.0), (14.0, 10.0), 0.25),
        "static_obstacles": [_rect("A", 3.0, 0.0, 5.0, 7.0), _rect("B", 7.0, 4.0, 9.0, 11.0),
                             _rect("C", 10.5, 2.0, 12.5, 8.0)],
    }, "<planning suite: peers>")


def _shapes(rng: np.random.Generator, walls: bool) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    if walls:
        xs = np.sort(rng.choice(np.linspace(3.5, 11.5, 9), size=int(rng.integers(2, 4)), replace=False))
        for k, x in enumerate(xs):
            length, t = rng.uniform(6.0, 8.5), rng.uniform(0.3, 0.5)
            y0 = 0.0 if k % 2 == 0 else _H - length  # alternate bottom and top: a slalom
            out.append(_rect(f"W{k + 1}", x, y0, x + t, y0 + length))
    for i in range(int(rng.integers(15, 25) if walls else rng.integers(25, 40))):
        cx, cy = rng.uniform([2.0, 0.5], [_W - 2.0, _H - 0.5])
        kind = int(rng.integers(0, 3))
        name = f"C{i + 1}"
        if kind == 0:
            w, h = rng.uniform(0.3, 1.4, size=2)
            out.append(_rect(name, cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2, rng.uniform(0, math.pi)))
        elif kind == 1:
            out.append({"name": name, "type": "circle", "center": [round(cx, 4), round(cy, 4)],
                        "radius": round(rng.uniform(0.2, 0.7), 4)})
        else:
            n, r, ph = int(rng.integers(3, 7)), rng.uniform(0.3, 0.8), rng.uniform(0, math.pi)
            out.append({"name": name, "type": "polygon", "points": [
                [round(cx + r * math.cos(ph + 2 * math.pi * j / n), 4),
                 round(cy + r * math.sin(ph + 2 * math.pi * j / n), 4)] for j in range(n)]})
    return out


def cluttered_world(seed: int, k: int, walls: bool | None = None, max_attempts: int = 200) -> Scenario:
    """Random cluttered world ``k`` of ``seed`` (walls when ``k`` is odd, unless ``walls`` says).

    Raises:
        GenerationError: no valid world within ``max_attempts``.
    """
    walls = bool(k % 2) if walls is None else walls
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), int(k)]))
    name = f"cluttered-s{seed}-{k}"
    for _ in range(max_attempts):
        start = (1.0, round(float(rng.uniform(1.0, _H - 1.0)), 3))
        goal = (_W - 1.0, round(float(rng.uniform(1.0, _H - 1.0)), 3))
        data = {"name": name, "description": f"random cluttered world{' with walls' if walls else ''}",
                "arena": {"width": _W, "height": _H}, "robot": _robot(start, goal, P3DX["radius"]),
                "static_obstacles": _shapes(rng, walls)}
        try:
            sc = scenario_from_dict(data, f"<planning suite: {name}>")
        except ScenarioError:  # start or goal inside a shape
            continue
        r = sc.robot
        if sc.obstacle_set().segment_free(r.start[:2], r.goal, r.radius):
            continue  # a straight line: planners would not differ
        if route_is_connected(sc):
            return sc
    raise GenerationError(f"no valid cluttered world for seed {seed}, k {k}")


def planning_suite(seed: int = 0, count: int = 4) -> list[Scenario]:
    """``peers`` and ``count`` cluttered worlds of ``seed``."""
    return [peers_problem()] + [cluttered_world(seed, k) for k in range(count)]
