"""Fixed-step simulation of the robot, the moving obstacles and an agent."""

from anyplan.simulation.result import RunResult, RunStatus
from anyplan.simulation.simulator import SimConfig, simulate

__all__ = ["RunResult", "RunStatus", "SimConfig", "simulate"]
