"""Plug your own method into anyplan and compare it with Sequential BIT* on the same runs.

An agent is reset with what it may know before the run (the static map, the robot and its goal)
and asked for a (v, omega) command every control step, given an observation of its own state
and of the moving obstacles it can see. Register it by name, and every tool (``simulate``,
``anyplan bench``, the figures) treats it like the built-in planners.

Run: ``python examples/custom_agent.py``
"""

from __future__ import annotations

import math

from anyplan.agents import AGENTS, make_agent
from anyplan.agents.straight import StraightAgent
from anyplan.simulation import simulate
from anyplan.world import Command, load_scenario


class CautiousStraightAgent(StraightAgent):
    """Drive straight at the goal, but stop while a moving obstacle is close ahead.

    Args:
        stop_distance: Stop when an obstacle's surface is closer than this [m] in front.
    """

    name = "cautious-straight"

    def __init__(self, stop_distance: float = 1.0) -> None:
        super().__init__()
        self.stop_distance = stop_distance

    def act(self, obs):  # noqa: ANN001, ANN201 - same signature as Agent.act
        cmd = super().act(obs)
        r = obs.robot
        for o in obs.obstacles:
            dx, dy = o.x - r.x, o.y - r.y
            ahead = dx * math.cos(r.theta) + dy * math.sin(r.theta) > 0.0
            gap = math.hypot(dx, dy) - o.radius - self.spec.radius
            if ahead and gap < self.stop_distance:
                return Command(0.0, 0.0)
        return cmd


def main() -> None:
    """Compare the custom agent with seq-bitstar on paper-1..3."""
    if "cautious-straight" not in AGENTS:
        AGENTS.register("cautious-straight", CautiousStraightAgent)
    for name in ("paper-1", "paper-2", "paper-3"):
        scenario = load_scenario(name)
        for planner in ("cautious-straight", "seq-bitstar"):
            res = simulate(scenario, make_agent(planner), seed=0)
            ttg = "-" if res.time_to_goal_s is None else f"{res.time_to_goal_s:.1f} s"
            print(f"{name}  {planner:18s} {res.status:9s} time to goal {ttg:>7s}  "
                  f"path {res.path_length_m:5.2f} m  min clearance {res.min_clearance_m:5.2f} m")


if __name__ == "__main__":
    main()
