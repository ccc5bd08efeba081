"""Gymnasium environment ``anyplan/Nav-v0``: the anyplan simulator, one control step per action.

``import anyplan.gym`` registers it (needs the extra ``anyplan[gym]``)::

    import gymnasium as gym
    import anyplan.gym  # noqa: F401

    env = gym.make("anyplan/Nav-v0", scenario="paper-3")
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

See :class:`anyplan.gym.env.NavEnv` for the observation, the action, the reward and the
termination. A policy trained here runs as the ``policy`` planner
(:class:`anyplan.agents.policy.PolicyAgent`) in ``anyplan run`` and ``anyplan bench``, beside
``seq-bitstar`` on the same scenarios.
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("anyplan.gym needs Gymnasium: pip install 'anyplan[gym]'") from exc

from anyplan.gym.env import NavEnv

__all__ = ["NavEnv", "ENV_ID"]

ENV_ID = "anyplan/Nav-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="anyplan.gym.env:NavEnv")
