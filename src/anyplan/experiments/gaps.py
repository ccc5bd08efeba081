"""Gap worlds: a wall across a room with one gap, and walkers timed to meet the robot there.

A 12 m x 8 m room, a wall at x = 6 m with one gap of 1.0-1.6 m, the paper's robot, and walkers
(0.3 m discs on ``waypoints`` tracks) that either cross just behind the gap (``cross``) or come
through it head-on (``head-on``), timed to meet a robot that drives straight at v_max. Waiting
is always a way out, and each scenario is checked for it (:func:`waiting_is_safe`).
:func:`issue_gap_scenario` is the case of issue 10. ``gap_suite(seed, n)`` names its scenarios
``gap-s{seed}-{k}`` and draws scenario k from ``SeedSequence([seed, k])``.

How walkers are timed and what "waiting is safe" checks: ``docs/spacetime.md``, "Gap worlds:
how they are drawn".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from anyplan.experiments.generate import P3DX, GenerationError
from anyplan.geometry.se2 import dot2, dot2_rows
from anyplan.trajectory.path import polyline_length
from anyplan.world.scenario import Scenario, scenario_from_dict

__all__ = ["ROOM", "WALL_X", "gap_scenario", "gap_world", "gap_suite", "issue_gap_scenario",
           "waiting_is_safe"]

#: Room (width, height) [m].
ROOM = (12.0, 8.0)
#: x [m] of the wall's centre line; its thickness [m].
WALL_X, WALL_T = 6.0, 0.2
WALKER_R = 0.3
TIME_LIMIT = 90.0
_PARK = 1000.0  # [s] the last keyframe: walkers stay parked until then


def _walls(y_gap: float, width: float) -> list[dict[str, Any]]:
    h = ROOM[1]
    lo, hi = y_gap - width / 2.0, y_gap + width / 2.0
    return [{"name": "wall-low", "type": "rectangle", "center": [WALL_X, round(lo / 2.0, 4)],
             "size": [WALL_T, round(lo, 4)]},
            {"name": "wall-high", "type": "rectangle", "center": [WALL_X, round((hi + h) / 2.0, 4)],
             "size": [WALL_T, round(h - hi, 4)]}]


def _robot_time_to(point: np.ndarray, start: np.ndarray) -> float:
    """When a robot driving straight at v_max (after a turn allowance) reaches ``point`` [s]."""
    d = float(np.hypot(*(point - start)))
    return d / P3DX["v_max"] + P3DX["v_max"] / (2.0 * P3DX["a_max"]) + 1.0


def _track(points: list[tuple[float, float]], times: list[float]) -> list[list[float]]:
    rows = [[0.0, round(points[0][0], 4), round(points[0][1], 4)]]
    for (x, y), t in zip(points, times, strict=True):
        if t > rows[-1][0] + 1e-6:
            rows.append([round(t, 4), round(x, 4), round(y, 4)])
        else:
            rows[-1][1:] = [round(x, 4), round(y, 4)]
    rows.append([_PARK, rows[-1][1], rows[-1][2]])
    return rows


def _cross_walker(name: str, y_gap: float, t_meet: float, v: float, behind: float, up: bool
                  ) -> dict[str, Any]:
    """Crossing at speed ``v`` [m/s], ``behind`` [m] past the wall's far face (plus its radius)."""
    x = WALL_X + WALL_T / 2.0 + WALKER_R + behind
    y_end = ROOM[1] - WALKER_R - 0.05 if up else WALKER_R + 0.05
    y_from = y_gap - (y_end - y_gap) * 10.0  # far before: clipped to the room below
    y_start = min(max(y_from, WALKER_R + 0.05), ROOM[1] - WALKER_R - 0.05)
    t_start = t_meet - abs(y_gap - y_start) / v  # leaves y_start then (wait there before)
    t_end = t_meet + abs(y_end - y_gap) / v
    pts = [(x, y_start), (x, y_start), (x, y_end)]
    times = [0.0, max(t_start, 0.0), t_end]
    if t_start < 0.0:  # it would have to start outside the room: start on the way instead
        y0 = y_gap - math.copysign(v * t_meet, y_end - y_gap)
        pts = [(x, y0), (x, y_end)]
        times = [0.0, t_end]
    return {"name": name, "type": "waypoints", "keyframes": _track(pts, times), "radius": WALKER_R}


def _head_on_walker(rng: np.random.Generator, name: str, y_gap: float, t_meet: float
                    ) -> dict[str, Any]:
    v = float(rng.uniform(0.3, 0.6))
    x0 = float(rng.uniform(9.0, 10.5))
    y0 = y_gap + float(rng.uniform(-0.5, 0.5))
    p_gap = (WALL_X, y_gap)
    p_past = (WALL_X - 0.9, y_gap)
    corner = ((WALL_X - 1.2, WALKER_R + 0.1) if rng.random() < 0.5
              else (WALL_X - 1.2, ROOM[1] - WALKER_R - 0.1))
    d1 = math.hypot(x0 - p_gap[0], y0 - p_gap[1])
    t_start = t_meet - d1 / v
    pts = [(x0, y0), (x0, y0), p_gap, p_past, corner]
    t2 = t_meet + 0.9 / v
    t3 = t2 + math.hypot(corner[0] - p_past[0], corner[1] - p_past[1]) / v
    times = [0.0, max(t_start, 0.0), t_meet, t2, t3]
    if t_start < 0.0:
        f = v * t_meet / d1
        pts[0] = pts[1] = (p_gap[0] + (x0 - p_gap[0]) * f, p_gap[1] + (y0 - p_gap[1]) * f)
    return {"name": name, "type": "waypoints", "keyframes": _track(pts, times), "radius": WALKER_R}


def waiting_is_safe(scenario: Scenario, y_gap: float, step: float = 0.05) -> bool:
    """True if waiting at the start, then driving the route, is a way out (see
    ``docs/spacetime.md``, "Gap worlds: how they are drawn").

    Checked on a time grid of ``step`` seconds, with the clearances enlarged by the distance a
    walker can cover in half a step.
    """
    r = scenario.robot
    start = np.array(r.start[:2])
    route = np.array([start, [WALL_X, y_gap], r.goal])
    t = np.arange(0.0, scenario.time_limit + step, step)
    clear_from = 0.0
    for o in scenario.moving_obstacles:
        p = o.motion.positions(t)
        slack = 0.5 * o.motion.max_speed * step
        if np.min(np.hypot(*(p - start).T)) < r.radius + o.radius + 0.15 + slack:
            return False
        near = _route_distance(p, route) < r.radius + o.radius + 0.3 + slack
        if near.any():
            clear_from = max(clear_from, float(t[np.flatnonzero(near)[-1]]) + step)
    length = polyline_length(route)
    return clear_from + length / r.v_max + 10.0 <= scenario.time_limit


def _route_distance(p: np.ndarray, route: np.ndarray) -> np.ndarray:
    best = np.full(len(p), np.inf)
    for a, b in zip(route[:-1], route[1:], strict=True):
        ab = b - a
        u = np.clip(dot2_rows(p - a, ab) / dot2(ab, ab), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(p - (a + u[:, None] * ab)).T))
    return best


def gap_world(name: str, desc: str, start: np.ndarray, goal: np.ndarray, y_gap: float, width: float,
              movers: list[dict[str, Any]]) -> Scenario:
    """The room with its gapped wall, the robot from ``start`` (facing the gap) to ``goal``
    and the moving obstacles ``movers`` (scenario dictionaries)."""
    heading = math.atan2(y_gap - start[1], WALL_X - start[0])
    data = {"name": name, "description": desc, "time_limit": TIME_LIMIT,
            "arena": {"width": ROOM[0], "height": ROOM[1]},
            "robot": {"start": [float(start[0]), round(float(start[1]), 4), round(heading, 5)],
                      "goal": [float(goal[0]), round(float(goal[1]), 4)], **P3DX},
            "static_obstacles": _walls(y_gap, width), "dynamic_obstacles": movers}
    return scenario_from_dict(data, f"<generated {name}>")


def gap_scenario(rng: np.random.Generator | int, name: str = "gap", kind: str | None = None,
                 max_attempts: int = 100) -> Scenario:
    """A random gap world (docs/spacetime.md, "Gap worlds"); ``kind`` is ``cross``, ``head-on`` or ``both``
    (one walker of each), random if None."""
    rng = np.random.default_rng(rng)
    for _ in range(max_attempts):
        k = kind if kind is not None else str(rng.choice(["cross", "head-on", "both"]))
        if k not in ("cross", "head-on", "both"):
            raise ValueError(f"kind: must be cross, head-on or both, got {kind!r}")
        width = float(rng.uniform(1.0, 1.6))
        y_gap = float(rng.uniform(2.5, 5.5))
        start = np.array([1.5, float(rng.uniform(2.0, 6.0))])
        goal = np.array([10.5, float(rng.uniform(2.0, 6.0))])
        t_meet = _robot_time_to(np.array([WALL_X, y_gap]), start) + float(rng.uniform(-0.5, 1.5))
        movers = []
        if k in ("cross", "both"):
            movers.append(_cross_walker("W1", y_gap, t_meet + (1.0 if k == "both" else 0.0),
                                        float(rng.uniform(0.3, 0.6)), float(rng.uniform(0.3, 0.8)),
                                        bool(rng.random() < 0.5)))
        if k in ("head-on", "both"):
            movers.append(_head_on_walker(rng, f"W{len(movers) + 1}", y_gap, t_meet))
        desc = f"Gap world: {width:.2f} m gap at y = {y_gap:.2f} m, walkers: {k}."
        sc = gap_world(name, desc, start, goal, y_gap, width, movers)
        if waiting_is_safe(sc, y_gap):
            return sc
    raise GenerationError(f"no gap world where waiting is safe in {max_attempts} attempts")


def gap_suite(seed: int, n: int = 20) -> list[Scenario]:
    """``n`` gap worlds ``gap-s{seed}-{k}`` (scenario k from ``SeedSequence([seed, k])``)."""
    return [gap_scenario(np.random.default_rng(np.random.SeedSequence([seed, k])), f"gap-s{seed}-{k}")
            for k in range(n)]


def issue_gap_scenario() -> Scenario:
    """Issue 10's case: 12 m x 8 m, a 1.2 m gap at y = 4 m, a walker at 0.3 m/s crossing 0.5 m
    behind the wall's far face, timed to be in front of the gap when the robot would be."""
    start, goal, y_gap = np.array([1.5, 4.0]), np.array([10.5, 4.0]), 4.0
    t_meet = _robot_time_to(np.array([WALL_X, y_gap]), start)
    walker = _cross_walker("W1", y_gap, t_meet, 0.3, 0.5 - WALKER_R, True)
    return gap_world("gap-issue", "Issue 10: wall with a 1.2 m gap, a walker (0.3 m/s) crossing "
                     "just behind it.", start, goal, y_gap, 1.2, [walker])
