"""DOVS-Greedy: the Dynamic Object Velocity Space planner used as the paper's baseline.

Lorente, Owen & Montano, "Model-based robocentric planning and navigation for dynamic
environments", IJRR 37(8):867-889, 2018: the analytic per-ray DOV model with the greedy
selector. See ``docs/dovs.md`` for the model, the parameters and the deviations from the
authors' code.

Modules: :mod:`.config` (parameters), :mod:`.model` (robocentric transforms, collision bands,
per-ray forbidden intervals, static braking), :mod:`.window` (velocity space and dynamic
window), :mod:`.selection` (goal velocities, braking rule, greedy selection) and
:mod:`.planner` (one control period).
"""

from anyplan.baselines.dovs.config import DOVSConfig, DOVSConfigError
from anyplan.baselines.dovs.model import (
    DOVSModel,
    ModelObstacle,
    RayIntervals,
    StaticMap,
    arc_points,
    model_obstacles,
    to_robot_frame,
    to_world_frame,
)
from anyplan.baselines.dovs.planner import Decision, DOVSPlanner
from anyplan.baselines.dovs.selection import (
    GoalVelocities,
    Selection,
    braking_speed,
    goal_velocities,
    select_greedy,
    vs_grid,
)
from anyplan.baselines.dovs.window import (
    DynamicWindow,
    in_velocity_space,
    ray_deceleration,
    ray_v_max,
    vs_v_max,
)

__all__ = [
    "DOVSConfig", "DOVSConfigError", "DOVSModel", "ModelObstacle", "RayIntervals", "StaticMap",
    "arc_points", "model_obstacles", "to_robot_frame", "to_world_frame", "Decision", "DOVSPlanner",
    "GoalVelocities", "Selection", "braking_speed", "goal_velocities", "select_greedy", "vs_grid",
    "DynamicWindow", "in_velocity_space", "ray_deceleration", "ray_v_max", "vs_v_max",
]
