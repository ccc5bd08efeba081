"""Fixed-step simulation of the robot, the moving obstacles and an agent."""

from anyplan.simulation.simulator import RunResult, SimConfig, simulate

__all__ = ["RunResult", "SimConfig", "simulate"]
