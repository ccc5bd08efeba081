"""``anyplan/Nav-v0``: drive the robot to its goal among static and moving obstacles.

The environment (Gymnasium's ``Env`` API) steps :class:`anyplan.simulation.simulator.Simulation`,
the simulator every planner runs in. Observation: a float32 vector of ``8 + 7 * max_obstacles``
values from :class:`anyplan.agents.policy.ObservationEncoder`; action: ``(v [m/s], omega
[rad/s])`` within the robot's limits; reward: progress to the goal minus a time penalty, plus a
goal reward or minus a collision penalty; terminated at the goal or a collision, truncated at
the time limit.

Scenarios, seeding, reward terms and ``info``: ``docs/integrations.md``, "Gymnasium: the
environment".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from anyplan.agents.policy import ObservationEncoder
from anyplan.simulation.simulator import SimConfig, Simulation
from anyplan.world.robot import Command
from anyplan.world.scenario import Scenario, load_scenario

__all__ = ["NavEnv"]

ScenarioLike = str | Path | Scenario

#: Bound of every observation value (m, m/s, rad/s): far beyond any arena or speed.
OBS_BOUND = 1.0e4


class NavEnv(gymnasium.Env):
    """See the module docstring.

    Args:
        scenario: A scenario, a list of them (a suite), or ``"random"``.
        max_obstacles: Obstacle slots of the observation.
        dt: Step [s], in (0, 0.05].
        time_limit: Episode length [s]; None uses each scenario's ``time_limit``.
        progress_weight, time_penalty, goal_reward, collision_penalty: Reward terms.
        announce_motions: As :class:`~anyplan.simulation.SimConfig` (not in the vector; kept for
            parity with the planners' runs).
        actuation_noise: The robot's execution error, spreads (m/s, rad/s) at full motion
            (``SimConfig.actuation_sigma_v``, ``actuation_sigma_omega``; seeded with the
            episode's seed, as the sensor); (0, 0): the robot drives its actions exactly.
        localization_noise: The robot's localization error, spreads (m per axis, rad): the
            observation's pose, and the obstacles it senses, are where the robot believes them
            (``SimConfig.localization_sigma_xy``, ``localization_sigma_theta``; seeded with the
            episode's seed); (0, 0): exactly.
    """

    metadata = {"render_modes": []}  # noqa: RUF012 - gymnasium's convention
    action_space: spaces.Box
    observation_space: spaces.Box

    def __init__(self, scenario: ScenarioLike | Sequence[ScenarioLike] = "paper-3", max_obstacles: int = 8,
                 dt: float = 0.05, time_limit: float | None = None, progress_weight: float = 1.0,
                 time_penalty: float = 0.01, goal_reward: float = 10.0, collision_penalty: float = 10.0,
                 announce_motions: bool = True,
                 actuation_noise: tuple[float, float] = (0.0, 0.0),
                 localization_noise: tuple[float, float] = (0.0, 0.0)) -> None:
        self.config = SimConfig(dt=dt, time_limit=time_limit, announce_motions=announce_motions,
                                actuation_sigma_v=actuation_noise[0],
                                actuation_sigma_omega=actuation_noise[1],
                                localization_sigma_xy=localization_noise[0],
                                localization_sigma_theta=localization_noise[1])
        self.random_worlds = isinstance(scenario, str) and scenario == "random"
        if self.random_worlds:
            from anyplan.experiments.generate import random_scenario

            self._random_scenario = random_scenario
            self.scenarios = [random_scenario(np.random.default_rng(0), n_moving=1)]
        else:
            items = [scenario] if isinstance(scenario, str | Path | Scenario) else list(scenario)
            if not items:
                raise ValueError("scenario: an empty suite")
            self.scenarios = [s if isinstance(s, Scenario) else load_scenario(s) for s in items]
        self.max_obstacles = max_obstacles
        self.weights = (float(progress_weight), float(time_penalty), float(goal_reward),
                        float(collision_penalty))
        n = ObservationEncoder((0.0, 0.0), max_obstacles).size
        self.observation_space = spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(n,), dtype=np.float32)
        v = max(s.robot.v_max for s in self.scenarios)
        w = max(s.robot.omega_max for s in self.scenarios)
        if self.random_worlds:  # every random world uses the paper's robot
            v, w = self.scenarios[0].robot.v_max, self.scenarios[0].robot.omega_max
        self.action_space = spaces.Box(np.array([-v, -w], dtype=np.float32),
                                       np.array([v, w], dtype=np.float32), dtype=np.float32)
        self.sim: Simulation | None = None
        self._seed = 0
        self.scenario: Scenario | None = None

    def _distance(self) -> float:
        s, g = self.sim.state, self.scenario.robot.goal  # type: ignore[union-attr]
        return math.hypot(g[0] - s.x, g[1] - s.y)

    def _obs(self) -> np.ndarray:
        return self.encoder.encode(self.sim.observation())  # type: ignore[union-attr]

    def _info(self) -> dict[str, Any]:
        sim = self.sim
        assert sim is not None
        return {"t": sim.t, "status": sim.status, "scenario": self.scenario.name,  # type: ignore[union-attr]
                "min_clearance_m": float(sim.min_clearance_m), "collision_with": sim.collision_with}

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Start an episode; ``options={"scenario": i}`` picks the suite's i-th scenario."""
        super().reset(seed=seed)
        if seed is not None:
            self._seed = int(seed)
        if self.random_worlds:
            n = int(self.np_random.integers(1, 7))
            self.scenario = self._random_scenario(self.np_random, n_moving=n)
        elif options and "scenario" in options:
            self.scenario = self.scenarios[int(options["scenario"])]
        else:
            self.scenario = self.scenarios[int(self.np_random.integers(len(self.scenarios)))]
        self.sim = Simulation(self.scenario, self.config, seed=self._seed)
        if self.sim.done:
            why = "goal proven unreachable" if self.sim.unreachable else "start at the goal"
            raise ValueError(f"scenario {self.scenario.name}: nothing to simulate ({why})")
        self.encoder = ObservationEncoder(self.scenario.robot.goal, self.max_obstacles)
        self._dist = self._distance()
        return self._obs(), self._info()

    def step(self, action):
        """Apply ``action`` = (v [m/s], omega [rad/s]) for one step."""
        if self.sim is None or self.sim.done:
            raise RuntimeError("call reset() first: the episode is over")
        a = np.asarray(action, dtype=float).reshape(-1)
        a = np.clip(a, self.action_space.low, self.action_space.high)
        self.sim.step(Command(float(a[0]), float(a[1])))
        dist = self._distance()
        wp, wt, wg, wc = self.weights
        reward = wp * (self._dist - dist) - wt
        self._dist = dist
        collided = self.sim.collision_with is not None
        terminated = collided or self.sim.reached
        if self.sim.reached and not collided:
            reward += wg
        if collided:
            reward -= wc
        truncated = self.sim.done and not terminated
        info = self._info()
        if terminated or truncated:
            info["result"] = self.sim.result("gym", self._seed)
        return self._obs(), float(reward), bool(terminated), bool(truncated), info
