"""The world: scenarios, static and moving obstacles, the robot model."""

from anyplan.world.motion import Motion, UnicycleMotion, WaypointMotion
from anyplan.world.robot import Command, RobotSpec, RobotState, clip_command, step
from anyplan.world.scenario import (
    MovingObstacle,
    Scenario,
    StaticObstacle,
    builtin_scenarios,
    load_scenario,
    scenario_from_dict,
)

__all__ = [
    "Command",
    "Motion",
    "MovingObstacle",
    "RobotSpec",
    "RobotState",
    "Scenario",
    "StaticObstacle",
    "UnicycleMotion",
    "WaypointMotion",
    "builtin_scenarios",
    "clip_command",
    "load_scenario",
    "scenario_from_dict",
    "step",
]
