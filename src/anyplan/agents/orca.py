"""The ``orca`` peer: ORCA (van den Berg, Guy, Lin & Manocha, "Reciprocal n-body collision
avoidance", ISRR 2009) through the ``pyrvo`` bindings of the RVO2 library, driving the same
differential-drive robot.

Every control period (0.1 s) a fresh RVO2 simulation is built around the robot: the robot is an
agent (radius, v_max, its current velocity) whose preferred velocity points at v_max to the next
corner of the shortest path among the static obstacles (visibility graph, computed at reset);
each observed moving obstacle is an agent at its position with its observed velocity as both
velocity and preferred velocity (ORCA assumes the others share the avoidance; the replayed people
do not, as in every crowd benchmark that runs ORCA against recordings); the static obstacles and
walls are RVO2 polygons (circles as circumscribed 16-gons). ORCA's new velocity (vx, vy) is turned
into a unicycle command: heading error e to its direction, ``omega = 2 e`` and
``v = |u| cos e`` (0 when |e| > pi/2), both clipped to the robot's limits (the simulator applies
its accelerations). Tracked obstacles enter with their disc grown to its 1 s uncertainty.

Needs the optional ``orca`` extra (``pip install "anyplan[orca]"``, i.e. ``pyrvo``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from anyplan.agents.base import Agent, Observation, checked_number
from anyplan.geometry.se2 import wrap_angle
from anyplan.geometry.shapes import Circle, Polygon
from anyplan.planning.api import plan
from anyplan.world.robot import Command
from anyplan.world.scenario import Scenario

__all__ = ["ORCAAgent"]


def _ccw(poly: np.ndarray) -> list[list[float]]:
    x, y = poly[:, 0], poly[:, 1]
    area = 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    pts = poly if area > 0 else poly[::-1]
    return [[float(a), float(b)] for a, b in pts]


class ORCAAgent(Agent):
    """ORCA via pyrvo.

    Args:
        period_s: Control period [s].
        time_horizon_s: ORCA's time horizon for agents [s].
        time_horizon_obst_s: ORCA's time horizon for static obstacles [s].
        neighbor_dist_m: Neighbour distance [m].
        max_neighbors: Maximum neighbours considered.
        safety_m: Added to the robot's radius [m].
        uncertainty_horizon_s: Horizon [s] at which a tracked obstacle's grown radius is taken.
    """

    name = "orca"

    def __init__(self, period_s: float = 0.1, time_horizon_s: float = 3.0,
                 time_horizon_obst_s: float = 1.0, neighbor_dist_m: float = 8.0,
                 max_neighbors: int = 30, safety_m: float = 0.05,
                 uncertainty_horizon_s: float = 1.0) -> None:
        super().__init__()
        import pyrvo  # noqa: F401  (fail at construction when the extra is missing)

        self.period_s = checked_number("period_s", period_s, lo_open=True)
        self.time_horizon_s = checked_number("time_horizon_s", time_horizon_s, lo_open=True)
        self.time_horizon_obst_s = checked_number("time_horizon_obst_s", time_horizon_obst_s,
                                                  lo_open=True)
        self.neighbor_dist_m = checked_number("neighbor_dist_m", neighbor_dist_m, lo_open=True)
        if isinstance(max_neighbors, bool) or not isinstance(max_neighbors, int) or max_neighbors < 1:
            raise ValueError(f"max_neighbors: must be an integer >= 1, got {max_neighbors!r}")
        self.max_neighbors = max_neighbors
        self.safety_m = checked_number("safety_m", safety_m)
        self.uncertainty_horizon_s = checked_number("uncertainty_horizon_s", uncertainty_horizon_s)

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        self.stats.planning_times_s.clear()
        self.stats.extra.clear()
        self.spec = scenario.robot
        obstacles = scenario.obstacle_set()
        res = plan(obstacles, self.spec.start[:2], self.spec.goal, self.spec.radius + self.safety_m,
                   planner="visgraph")
        self.path = (np.asarray(res.path, dtype=float) if res.status and res.path is not None
                     else np.array([self.spec.start[:2], self.spec.goal], dtype=float))
        self._k = 1
        polys = []
        for o in scenario.static_obstacles:
            s = o.shape
            if isinstance(s, Polygon):
                polys.append(_ccw(np.asarray(s.vertices, dtype=float)))
            elif isinstance(s, Circle):
                n = 16
                rr = s.radius / math.cos(math.pi / n)
                a = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
                polys.append(_ccw(np.column_stack([s.center[0] + rr * np.cos(a),
                                                   s.center[1] + rr * np.sin(a)])))
        w, h = scenario.width, scenario.height
        t = 1.0  # walls as thin boxes just outside the arena
        for box in ([-t, -t, w + t, 0.0], [-t, h, w + t, h + t], [-t, 0.0, 0.0, h], [w, 0.0, w + t, h]):
            x0, y0, x1, y1 = box
            polys.append(_ccw(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])))
        self.polys = polys
        self._next_t: float | None = None
        self._held = Command(0.0, 0.0)

    def _preferred(self, p: np.ndarray) -> np.ndarray:
        while self._k < len(self.path) - 1 and np.hypot(*(self.path[self._k] - p)) < 0.5:
            self._k += 1
        d = self.path[self._k] - p
        n = float(np.hypot(*d))
        dist_goal = float(np.hypot(*(self.path[-1] - p)))
        speed = min(self.spec.v_max, math.sqrt(2.0 * self.spec.a_max * dist_goal))
        return d / n * speed if n > 1e-9 else np.zeros(2)

    def act(self, obs: Observation) -> Command:
        if self._next_t is not None and obs.t < self._next_t - 1e-9:
            return self._held
        import pyrvo

        w0 = time.perf_counter()
        r = obs.robot
        s = self.spec
        sim = pyrvo.RVOSimulator()
        sim.set_time_step(self.period_s)
        sim.set_agent_defaults(self.neighbor_dist_m, self.max_neighbors, self.time_horizon_s,
                               self.time_horizon_obst_s, s.radius + self.safety_m, s.v_max)
        p = np.array([r.x, r.y])
        me = sim.add_agent([r.x, r.y])
        sim.set_agent_velocity(me, [r.v * math.cos(r.theta), r.v * math.sin(r.theta)])
        sim.set_agent_pref_velocity(me, [float(v) for v in self._preferred(p)])
        for o in obs.obstacles:
            rad = o.radius
            if o.growth is not None:
                rad += float(o.growth.at(obs.t + self.uncertainty_horizon_s))
            vel = [o.v * math.cos(o.theta), o.v * math.sin(o.theta)]
            k = sim.add_agent([o.x, o.y])
            sim.set_agent_radius(k, rad)
            sim.set_agent_max_speed(k, max(abs(o.v), 1e-3))
            sim.set_agent_velocity(k, vel)
            sim.set_agent_pref_velocity(k, vel)
        for poly in self.polys:
            sim.add_obstacle(poly)
        sim.process_obstacles()
        sim.do_step()
        u = sim.get_agent_velocity(me)
        ux, uy = float(u.x), float(u.y)
        speed = math.hypot(ux, uy)
        if speed < 1e-6:
            cmd = Command(0.0, 0.0)
        else:
            e = float(wrap_angle(math.atan2(uy, ux) - r.theta))
            v = speed * math.cos(e) if abs(e) < 0.5 * math.pi else 0.0
            cmd = Command(min(max(v, 0.0), s.v_max), max(-s.omega_max, min(s.omega_max, 2.0 * e)))
        self.stats.planning_times_s.append(time.perf_counter() - w0)
        self._held = cmd
        self._next_t = obs.t + self.period_s
        return cmd
