"""``patient-straight``: drive straight at the goal, but wait while a moving obstacle is about to
cross the robot's way.

The agent only uses anyplan's public interface: it subclasses :class:`anyplan.agents.Agent`,
reads the static scenario at :meth:`reset` and sees moving obstacles through observations.
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.agents import Agent, Observation
from anyplan.world import Command, Scenario


class PatientStraightAgent(Agent):
    """Turn to the goal, drive at it, and stop while an obstacle will come close.

    Args:
        horizon_s: How far ahead [s] each obstacle's motion is extrapolated (constant twist).
        gap_m: Stop when an obstacle is predicted closer than this [m] to the robot's surface
            within the horizon, ahead of the robot.
        heading_gain: Turn-rate gain [1/s] on the heading error.
    """

    name = "patient-straight"

    def __init__(self, horizon_s: float = 2.0, gap_m: float = 0.3, heading_gain: float = 2.0) -> None:
        super().__init__()
        if not horizon_s > 0.0:
            raise ValueError(f"horizon_s: must be > 0 s, got {horizon_s}")
        self.horizon_s = float(horizon_s)
        self.gap_m = float(gap_m)
        self.heading_gain = float(heading_gain)

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        self.robot = scenario.robot
        self.stats.extra["waiting_steps"] = 0

    def _blocked(self, obs: Observation, heading: float, speed: float) -> bool:
        r = obs.robot
        for t in np.linspace(0.0, self.horizon_s, 9):
            # Where the robot would be at full speed, and where each obstacle is predicted.
            rx, ry = r.x + speed * t * math.cos(heading), r.y + speed * t * math.sin(heading)
            for o in obs.obstacles:
                ox = o.x + o.v * t * math.cos(o.theta + 0.5 * o.omega * t)
                oy = o.y + o.v * t * math.sin(o.theta + 0.5 * o.omega * t)
                if math.hypot(ox - rx, oy - ry) - o.radius - self.robot.radius < self.gap_m:
                    return True
        return False

    def act(self, obs: Observation) -> Command:
        s, r = self.robot, obs.robot
        dx, dy = s.goal[0] - r.x, s.goal[1] - r.y
        heading = math.atan2(dy, dx)
        err = math.atan2(math.sin(heading - r.theta), math.cos(heading - r.theta))
        w = max(-s.omega_max, min(s.omega_max, self.heading_gain * err))
        v = min(s.v_max, math.sqrt(2.0 * s.a_max * math.hypot(dx, dy)))
        if abs(err) > 0.1:
            return Command(0.0, w)
        if self._blocked(obs, heading, v):
            self.stats.extra["waiting_steps"] += 1
            return Command(0.0, w)
        return Command(v, w)
