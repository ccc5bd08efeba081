"""Random scenarios with moving obstacles that cross the robot's route.

A generated scenario has the paper's arena (15 m x 11 m) and robot, a few random static shapes
and ``n_moving`` moving discs, each aimed at a point of the straight start-goal segment and
reaching it when a robot driving the segment at ``v_max`` would: a robot that ignores them
collides. Every scenario returned is checked valid (free start and goal, goal reachable among the
static obstacles, obstacles starting inside the arena). The same seed gives the same scenario.

Crossing angles, turning obstacles and the validity checks: ``docs/scenarios.md``, "Generated
scenarios".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.world.motion import UnicycleMotion
from anyplan.world.scenario import Scenario, scenario_from_dict

__all__ = ["random_scenario", "random_suite", "route_is_connected", "GenerationError"]

ARENA = (15.0, 11.0)
#: Robot profile of the paper's scenarios (Pioneer P3-DX), SI units.
P3DX = {"radius": 0.3, "v_max": 0.4, "omega_max": 0.4, "a_max": 0.4, "alpha_max": 1.0,
        "goal_tolerance": 0.2}


class GenerationError(RuntimeError):
    """No valid scenario was found within the attempt budget."""


def route_is_connected(scenario: Scenario, resolution: float = 0.05) -> bool:
    """True if the goal is reachable from the start among the static obstacles.

    Free space is the set of grid cells (side ``resolution`` [m]) whose centres have clearance
    at least the robot radius (walls included); start and goal must share a 4-connected component.
    """
    from scipy import ndimage

    r = scenario.robot.radius
    nx = int(math.ceil(scenario.width / resolution))
    ny = int(math.ceil(scenario.height / resolution))
    xs = (np.arange(nx) + 0.5) * resolution
    ys = (np.arange(ny) + 0.5) * resolution
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    free = scenario.obstacle_set().points_free(pts, r).reshape(nx, ny)

    def cell(p: tuple[float, ...]) -> tuple[int, int]:
        return (min(int(p[0] / resolution), nx - 1), min(int(p[1] / resolution), ny - 1))

    cs, cg = cell(scenario.robot.start), cell(scenario.robot.goal)
    # The exact start/goal are free (schema check); their cell centres may be a hair off.
    free[cs] = free[cg] = True
    labels, _ = ndimage.label(free)
    return bool(labels[cs] != 0 and labels[cs] == labels[cg])


def _static_obstacles(rng: np.random.Generator, n: int) -> list[dict[str, Any]]:
    out = []
    for i in range(n):
        cx, cy = rng.uniform(3.0, 12.0), rng.uniform(1.0, 10.0)
        if rng.random() < 0.6:
            w, h = rng.uniform(0.6, 2.0, size=2)
            out.append({"name": f"S{i + 1}", "type": "rectangle", "center": [round(cx, 3), round(cy, 3)],
                        "size": [round(w, 3), round(h, 3)], "angle": round(rng.uniform(0, math.pi), 4)})
        else:
            out.append({"name": f"S{i + 1}", "type": "circle", "center": [round(cx, 3), round(cy, 3)],
                        "radius": round(rng.uniform(0.4, 1.0), 3)})
    return out


def _moving_obstacle(rng: np.random.Generator, idx: int, start: np.ndarray, goal: np.ndarray,
                     robot: dict[str, float], statics: ObstacleSet) -> dict[str, Any] | None:
    route = goal - start
    length = float(np.hypot(*route))
    heading = math.atan2(route[1], route[0])
    s = rng.uniform(0.2, 0.85)
    cross = start + s * route
    radius = float(rng.uniform(0.25, 0.45))
    if statics.clearance(cross) < radius + 0.1:
        return None
    # When would a robot that ignores the obstacle be here? Accelerate to v_max, then cruise.
    v_r, a_r = robot["v_max"], robot["a_max"]
    t_cross = s * length / v_r + v_r / (2 * a_r) + rng.uniform(0.0, 2.0)
    v = float(rng.uniform(0.1, 0.3))
    side = 1.0 if rng.random() < 0.5 else -1.0
    theta_at_cross = heading + side * rng.uniform(math.radians(45), math.radians(135))
    omega = 0.0 if rng.random() < 2 / 3 else float(rng.uniform(-0.05, 0.05))
    # Integrate the unicycle backwards from the crossing point: reversed time flips v and omega.
    back = UnicycleMotion(float(cross[0]), float(cross[1]), theta_at_cross, -v, -omega)
    p0 = back.position(t_cross)
    th0 = theta_at_cross - omega * t_cross
    w, h = ARENA
    if not (radius <= p0[0] <= w - radius and radius <= p0[1] <= h - radius):
        return None
    for q in (start, goal):
        if float(np.hypot(*(p0 - q))) < radius + robot["radius"] + 0.5:
            return None
    return {"name": f"D{idx + 1}", "start": [round(float(p0[0]), 4), round(float(p0[1]), 4),
                                            round(float(th0), 5)],
            "v": round(v, 4), "omega": round(omega, 5), "radius": round(radius, 3)}


def random_scenario(rng: np.random.Generator | int, n_moving: int | None = None,
                    name: str = "random", n_static: int | None = None,
                    max_attempts: int = 200) -> Scenario:
    """A valid random scenario (see the module docstring).

    Args:
        rng: Generator or seed.
        n_moving: Number of moving obstacles, 1-6; random in that range if None.
        name: Scenario name.
        n_static: Number of static shapes, random 2-5 if None.
        max_attempts: Attempts before :class:`GenerationError`.
    """
    rng = np.random.default_rng(rng)
    if n_moving is None:
        n_moving = int(rng.integers(1, 7))
    if not 1 <= n_moving <= 6:
        raise ValueError(f"n_moving must be in 1..6, got {n_moving}")
    w, h = ARENA
    for _ in range(max_attempts):
        start = np.array([1.5, rng.uniform(2.0, 9.0)])
        goal = np.array([13.5, rng.uniform(2.0, 9.0)])
        ns = int(rng.integers(2, 6)) if n_static is None else n_static
        statics = _static_obstacles(rng, ns)
        data: dict[str, Any] = {
            "name": name,
            "description": f"Generated: {ns} static shapes, {n_moving} moving obstacles crossing "
                           "the start-goal route.",
            "time_limit": 120.0,
            "arena": {"width": w, "height": h},
            "robot": {"start": [1.5, round(float(start[1]), 4),
                                round(math.atan2(*(goal - start)[::-1]), 5)],
                      "goal": [13.5, round(float(goal[1]), 4)], **P3DX},
            "static_obstacles": statics,
            "dynamic_obstacles": [],
        }
        start = np.array(data["robot"]["start"][:2])
        goal = np.array(data["robot"]["goal"])
        try:
            sc = scenario_from_dict(data, f"<generated {name}>")
        except ValueError:  # start or goal inside a static shape
            continue
        if not route_is_connected(sc):
            continue
        obs = sc.obstacle_set()
        movers = []
        for i in range(n_moving):
            for _ in range(50):
                m = _moving_obstacle(rng, i, start, goal, P3DX, obs)
                if m is not None:
                    movers.append(m)
                    break
        if len(movers) < n_moving:
            continue
        data["dynamic_obstacles"] = movers
        return scenario_from_dict(data, f"<generated {name}>")
    raise GenerationError(f"no valid scenario with {n_moving} moving obstacles in {max_attempts} attempts")


def random_suite(seed: int, per_count: int = 1, counts: range | list[int] = range(1, 7)) -> list[Scenario]:
    """``per_count`` random scenarios for each number of moving obstacles in ``counts``.

    Scenario ``random-s{seed}-m{n}-{k}`` is drawn from ``SeedSequence([seed, n, k])``, so it does
    not change when ``per_count`` or ``counts`` change.
    """
    out = []
    for n in counts:
        for k in range(per_count):
            rng = np.random.default_rng(np.random.SeedSequence([seed, n, k]))
            out.append(random_scenario(rng, n_moving=n, name=f"random-s{seed}-m{n}-{k}"))
    return out
