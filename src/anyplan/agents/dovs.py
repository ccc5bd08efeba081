"""The ``dovs`` planner: DOVS-Greedy (Lorente, Owen & Montano, IJRR 2018) as a simulator agent.

Every control period T (``control_period_s``, default 0.2 s, i.e. every 4th simulator step of
0.05 s) the agent builds the DOVS from the observed moving obstacles (pose and twist, assumed
constant) and the static map given at reset, picks a command with the greedy selector and holds
it until the next period. ``stats.planning_times_s`` holds the wall-clock time of each period's
computation; its record (:class:`~anyplan.agents.stats.DOVSStats`) counts how often each
selection mode and goal target was used.

By default the config's ``limits`` are the scenario's robot's
(:attr:`~anyplan.world.robot.RobotSpec.limits`), so that the dynamic window never asks for more
than the robot can do; for the built-in paper scenarios they equal the paper's Table 1 values,
the defaults of :class:`~anyplan.baselines.dovs.config.DOVSConfig`.
"""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import replace
from typing import Any

import numpy as np

from anyplan.agents.base import Agent, AgentStats, Observation
from anyplan.agents.stats import DOVSStats
from anyplan.baselines.dovs.config import DOVSConfig, DOVSConfigError
from anyplan.baselines.dovs.model import StaticMap
from anyplan.baselines.dovs.planner import Decision, DOVSPlanner
from anyplan.world.robot import Command
from anyplan.world.scenario import Scenario

__all__ = ["DOVSAgent"]


class DOVSAgent(Agent):
    """DOVS-Greedy: recompute every ``control_period_s`` and hold the command in between.

    Args:
        config: A :class:`DOVSConfig`; keyword arguments override its fields.
        use_robot_limits: Take the config's ``limits`` (radius, speeds, accelerations) from the
            scenario's robot at reset (default True); False keeps ``config.limits``.
        **overrides: Any :class:`DOVSConfig` field.

    Raises:
        DOVSConfigError: An unknown parameter name or an invalid value.
    """

    name = "dovs"
    config_classes = (DOVSConfig,)
    deterministic_settings: dict = {}  # noqa: RUF012 - commands do not depend on the clock

    def __init__(self, config: DOVSConfig | None = None, use_robot_limits: bool = True,
                 **overrides: Any) -> None:
        super().__init__()
        base = config or DOVSConfig()
        unknown = sorted(set(overrides) - set(DOVSConfig.field_names()))
        if unknown:
            raise DOVSConfigError("", "dovs", f"unknown parameter(s) {', '.join(unknown)} "
                                  f"(known: {', '.join(DOVSConfig.field_names())})")
        self.base_config = replace(base, **overrides) if overrides else base
        self.use_robot_limits = use_robot_limits
        #: Horizon [s] at which a tracked obstacle's uncertain radius is taken.
        self.uncertainty_horizon_s = 1.0
        self.config = self.base_config
        self.planner: DOVSPlanner | None = None
        self.last_decision: Decision | None = None
        self.record = DOVSStats()

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        spec = scenario.robot
        cfg = self.base_config
        if self.use_robot_limits:
            cfg = replace(cfg, limits=spec.limits)
        self.config = cfg
        static = StaticMap([o.shape for o in scenario.static_obstacles], scenario.bounds, cfg)
        self.planner = DOVSPlanner(cfg, spec.goal, static)
        self.last_decision = None
        self._next_t: float | None = None
        self._held = Command(0.0, 0.0)
        self._modes: Counter[str] = Counter()
        self._targets: Counter[str] = Counter()
        self.record = DOVSStats(control_period_s=cfg.control_period_s, dovs_config=cfg.to_dict())
        self.stats = AgentStats(record=self.record)

    def decide(self, obs: Observation) -> Decision:
        """Run one DOVS period on ``obs`` (does not change the held command or the stats)."""
        if self.planner is None:
            raise RuntimeError("DOVSAgent.decide called before reset")
        r = obs.robot
        # An uncertain (tracked) obstacle enters DOVS's model as a disc grown to its uncertainty
        # at ``uncertainty_horizon_s`` ahead: DOVS's model takes one radius per obstacle.
        h = self.uncertainty_horizon_s
        seen = tuple(o if o.growth is None else replace(o, radius=o.radius + float(o.growth.at(obs.t + h)))
                     for o in obs.obstacles)
        return self.planner.decide((r.x, r.y, r.theta), (r.v, r.omega), seen)

    def act(self, obs: Observation) -> Command:
        if self._next_t is not None and obs.t < self._next_t - 1e-9:
            return self._held
        t0 = time.perf_counter()
        d = self.decide(obs)
        self.stats.planning_times_s.append(time.perf_counter() - t0)
        self.last_decision = d
        self._held = Command(d.selection.v, d.selection.omega)
        self._next_t = obs.t + self.config.control_period_s
        self._modes[d.selection.mode] += 1
        self._targets[d.goal.mode] += 1
        self.record.selection_modes = dict(self._modes)
        self.record.goal_targets = dict(self._targets)
        return self._held
