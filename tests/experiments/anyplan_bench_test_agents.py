"""Agents used only by the experiments tests (importable by spawn workers via sys.path).

* ``HalfSpeedAgent``: the straight baseline at half its speed (a second, different planner).
* ``InterruptOnceAgent``: raises KeyboardInterrupt in its first ``act`` while ``flag_file`` does not
  exist (and creates it), as a user pressing Ctrl-C in the middle of a run.
* ``DieOnceAgent``: kills its own process (``os._exit``) once, as an out-of-memory kill.
* ``RaisingAgent``: always raises ValueError (a planner bug).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from anyplan.agents.straight import StraightAgent
from anyplan.world.robot import Command

TINY = {
    "name": "tiny",
    "time_limit": 40.0,
    "arena": {"width": 6.0, "height": 3.0},
    "robot": {"start": [0.5, 1.2, 0.0], "goal": [5.5, 1.2], "radius": 0.3, "v_max": 0.8,
              "omega_max": 0.8, "a_max": 0.8, "alpha_max": 1.0},
    "static_obstacles": [{"name": "S1", "type": "rectangle", "center": [3.0, 2.6], "size": [1.0, 0.6]}],
    "dynamic_obstacles": [{"name": "D1", "start": [1.0, 2.6, 0.0], "v": 0.1, "omega": 0.0,
                           "radius": 0.2}],
}


class HalfSpeedAgent(StraightAgent):
    """Also reports one straight plan and a made-up anytime cost history (for the figures)."""

    name = "half-speed"

    def reset(self, scenario, rng):
        super().reset(scenario, rng)
        s = scenario.robot
        length = float(np.hypot(s.goal[0] - s.start[0], s.goal[1] - s.start[1]))
        self.stats.plans.append({"t": 0.0, "path": [list(s.start[:2]), list(s.goal)]})
        self.stats.extra["progress"] = [[0.001, 1.3 * length], [0.004 + 0.001 * rng.random(), length]]

    def act(self, obs):
        c = super().act(obs)
        return Command(0.5 * c.v, c.omega)


class InterruptOnceAgent(StraightAgent):
    name = "interrupt-once"

    def __init__(self, flag_file: str = "") -> None:
        super().__init__()
        self.flag_file = flag_file

    def act(self, obs):
        if self.flag_file and not Path(self.flag_file).exists():
            Path(self.flag_file).write_text("interrupted once")
            raise KeyboardInterrupt
        return super().act(obs)


class DieOnceAgent(StraightAgent):
    name = "die-once"

    def __init__(self, flag_file: str = "") -> None:
        super().__init__()
        self.flag_file = flag_file

    def act(self, obs):
        if self.flag_file and not Path(self.flag_file).exists():
            Path(self.flag_file).write_text("died once")
            os._exit(3)
        return super().act(obs)


class RaisingAgent(StraightAgent):
    name = "raising"

    def act(self, obs):
        raise ValueError("planner bug for the test")


def register_all() -> None:
    from anyplan.agents.base import AGENTS

    for name, cls in (("half-speed", HalfSpeedAgent), ("interrupt-once", InterruptOnceAgent),
                      ("die-once", DieOnceAgent), ("raising", RaisingAgent)):
        if name not in AGENTS:
            AGENTS.register(name, cls)
