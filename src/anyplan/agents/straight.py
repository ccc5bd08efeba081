"""The ``straight`` baseline: turn toward the goal and drive straight at it, ignoring obstacles.

It proves the pipeline (simulator, metrics, pictures) and is the "robot that ignores the moving
obstacles" of the built-in scenarios: it collides there.
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.agents.base import Agent, Observation, checked_number
from anyplan.geometry.se2 import wrap_angle
from anyplan.world.robot import Command
from anyplan.world.scenario import Scenario

__all__ = ["StraightAgent"]


class StraightAgent(Agent):
    """Rotate in place until facing the goal, then drive to it with a proportional heading law.

    Args:
        heading_gain: Turn-rate gain [1/s] on the heading error.
        align_tolerance: Heading error [rad] below which the robot drives forward.
    """

    name = "straight"
    deterministic_settings: dict = {}  # noqa: RUF012 - no clock involved

    def __init__(self, heading_gain: float = 2.0, align_tolerance: float = 0.05) -> None:
        super().__init__()
        self.heading_gain = checked_number("heading_gain", heading_gain, lo_open=True)
        self.align_tolerance = checked_number("align_tolerance", align_tolerance)

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        self.spec = scenario.robot
        self._driving = False

    def act(self, obs: Observation) -> Command:
        s, r = self.spec, obs.robot
        dx, dy = s.goal[0] - r.x, s.goal[1] - r.y
        dist = math.hypot(dx, dy)
        err = float(wrap_angle(math.atan2(dy, dx) - r.theta))
        # Braking distance: v <= sqrt(2 a d) lets the robot stop at the goal.
        v_stop = math.sqrt(2.0 * s.a_max * max(dist, 0.0))
        # Turn rate that can still stop at zero heading error: |w| <= sqrt(2 alpha |err|).
        w = math.copysign(min(s.omega_max, self.heading_gain * abs(err),
                              math.sqrt(2.0 * s.alpha_max * abs(err))), err)
        if not self._driving and abs(err) > self.align_tolerance:
            return Command(0.0, w)
        self._driving = True
        return Command(min(s.v_max, v_stop), w)
