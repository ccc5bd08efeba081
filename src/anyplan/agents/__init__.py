"""Agents: planners and controllers behind one per-step interface.

Every method that drives the robot in the simulator (the ``straight`` baseline, ``bitstar``,
``seq-bitstar``, ``st-bitstar``, ``dovs``, ``orca``, ``policy``, or yours) is an
:class:`Agent`: it is reset with what it may know before the run (the static map, the robot
and its goal) and then asked for a :class:`~anyplan.world.robot.Command` at every control
step, given an :class:`Observation`.
Agents are selected by name from :data:`AGENTS`; register your own with
``AGENTS.register("name", MyAgent)`` or a lazy ``"module:Class"`` string.
"""

from anyplan.agents.base import AGENTS, Agent, Observation, make_agent

__all__ = ["AGENTS", "Agent", "Observation", "make_agent"]
