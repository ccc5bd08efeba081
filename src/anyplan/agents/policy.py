"""``policy``: any function from an observation vector to a command (v, omega), as an agent.

This is the bridge between learned policies and the benchmark: the vector is the one the
Gymnasium environment ``anyplan/Nav-v0`` (:mod:`anyplan.gym`) gives, built by
:class:`ObservationEncoder` from what the agent observes (its own state, the goal given at reset,
the moving obstacles it sees; never the simulator's truth): float32, ``8 + 7 * max_obstacles``
values, the robot's 8 then one slot of 7 per visible moving obstacle, nearest first. A policy
trained in the environment runs with ``anyplan run --planner policy --set
policy=my_pkg.module:act`` and is benchmarked beside ``seq-bitstar`` with ``anyplan bench``.

The vector's layout: ``docs/integrations.md``, "Gymnasium: the observation vector".
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from anyplan.agents.base import Agent, Observation
from anyplan.world.robot import Command
from anyplan.world.scenario import Scenario

__all__ = ["ObservationEncoder", "PolicyAgent", "ROBOT_FEATURES", "OBSTACLE_FEATURES"]

ROBOT_FEATURES = 8
OBSTACLE_FEATURES = 7


class ObservationEncoder:
    """Fixed-size, padded observation vectors (see the module docstring).

    Args:
        goal: The goal (x, y) [m].
        max_obstacles: Obstacle slots.
    """

    def __init__(self, goal: tuple[float, float], max_obstacles: int = 8) -> None:
        if not (isinstance(max_obstacles, int) and max_obstacles >= 0):
            raise ValueError(f"max_obstacles: must be an int >= 0, got {max_obstacles!r}")
        self.goal = (float(goal[0]), float(goal[1]))
        self.max_obstacles = max_obstacles

    @property
    def size(self) -> int:
        """Length of a vector."""
        return ROBOT_FEATURES + OBSTACLE_FEATURES * self.max_obstacles

    def encode(self, obs: Observation) -> np.ndarray:
        """The vector of observation ``obs``."""
        r = obs.robot
        out = np.zeros(self.size, dtype=np.float32)
        out[:ROBOT_FEATURES] = (self.goal[0] - r.x, self.goal[1] - r.y, math.cos(r.theta),
                                math.sin(r.theta), r.v, r.omega, r.x, r.y)
        near = sorted(obs.obstacles, key=lambda o: math.hypot(o.x - r.x, o.y - r.y))[:self.max_obstacles]
        for k, o in enumerate(near):
            i = ROBOT_FEATURES + OBSTACLE_FEATURES * k
            out[i:i + OBSTACLE_FEATURES] = (1.0, o.x - r.x, o.y - r.y, o.v * math.cos(o.theta),
                                            o.v * math.sin(o.theta), o.omega, o.radius)
        return out


def _load(ref: str) -> Callable[[np.ndarray], Any]:
    mod, sep, attr = ref.partition(":")
    if not sep or not mod or not attr:
        raise ValueError(f"policy: expected 'module:function', got {ref!r}")
    try:
        obj: Any = importlib.import_module(mod)
        for part in attr.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as exc:
        raise ValueError(f"policy: cannot load {ref!r} ({type(exc).__name__}: {exc})") from None
    if not callable(obj):
        raise ValueError(f"policy: {ref!r} is not callable")
    return obj


class PolicyAgent(Agent):
    """Commands from a policy ``f(observation_vector) -> (v, omega)``.

    Args:
        policy: The function, or ``"module:function"`` (importable in benchmark workers; a class
            named so is instantiated once per run, and its instances called).
        max_obstacles: Obstacle slots of the observation vector (as the environment's).
    """

    name = "policy"
    deterministic_settings: dict = {}  # noqa: RUF012 - as deterministic as the policy itself

    def __init__(self, policy: str | None = None, max_obstacles: int = 8) -> None:
        super().__init__()
        if policy is None:
            raise ValueError("policy: give the policy as 'module:function' (the setting policy=...)")
        self.policy_ref = policy if isinstance(policy, str) else None
        self._fn = _load(policy) if isinstance(policy, str) else policy
        if not callable(self._fn):
            raise ValueError("policy: not callable")
        ObservationEncoder((0.0, 0.0), max_obstacles)  # checks max_obstacles
        self.max_obstacles = max_obstacles

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        self.encoder = ObservationEncoder(scenario.robot.goal, self.max_obstacles)
        self.fn = self._fn() if isinstance(self._fn, type) else self._fn

    def act(self, obs: Observation) -> Command:
        a = np.asarray(self.fn(self.encoder.encode(obs)), dtype=float).reshape(-1)
        if a.shape != (2,) or not np.all(np.isfinite(a)):
            raise ValueError(f"policy returned {a!r}; expected two finite numbers (v [m/s], omega [rad/s])")
        return Command(float(a[0]), float(a[1]))
