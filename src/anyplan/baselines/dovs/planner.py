"""One DOVS-Greedy control period: model, window, goal velocities and selection together."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from anyplan.baselines.dovs.config import DOVSConfig
from anyplan.baselines.dovs.model import (
    DOVSModel,
    ModelObstacle,
    ObstacleLike,
    StaticMap,
    model_obstacles,
    to_robot_frame,
)
from anyplan.baselines.dovs.selection import GoalVelocities, Selection, goal_velocities, select_greedy
from anyplan.baselines.dovs.window import DynamicWindow

__all__ = ["Decision", "DOVSPlanner"]


@dataclass(frozen=True)
class Decision:
    """Everything DOVS computed in one period (enough to draw the paper's Figure 2).

    Attributes:
        pose: Robot pose (x [m], y [m], theta [rad]) in the world.
        velocity: Current (v [m/s], omega [rad/s]).
        obstacles: Modelled obstacles, robot frame.
        model: The DOVS of this period.
        window: The dynamic window.
        goal: Goal velocities (robot frame).
        selection: The chosen command.
    """

    pose: tuple[float, float, float]
    velocity: tuple[float, float]
    obstacles: tuple[ModelObstacle, ...]
    model: DOVSModel
    window: DynamicWindow
    goal: GoalVelocities
    selection: Selection

    @property
    def command(self) -> tuple[float, float]:
        """The chosen (v [m/s], omega [rad/s])."""
        return (self.selection.v, self.selection.omega)


class DOVSPlanner:
    """DOVS-Greedy for one robot: call :meth:`decide` once per control period.

    Args:
        cfg: Parameters.
        goal: Goal position (x, y) [m], world frame.
        static_map: Known static obstacles (braking rule), or None.
    """

    def __init__(self, cfg: DOVSConfig, goal: Sequence[float], static_map: StaticMap | None = None) -> None:
        self.cfg = cfg
        self.goal = (float(goal[0]), float(goal[1]))
        self.static_map = static_map

    def decide(self, pose: Sequence[float], velocity: Sequence[float],
               observations: Sequence[ObstacleLike]) -> Decision:
        """The command for the next period from the robot's pose, twist and observed obstacles."""
        cfg = self.cfg
        pose_t = (float(pose[0]), float(pose[1]), float(pose[2]))
        v0, w0 = float(velocity[0]), float(velocity[1])
        obs = tuple(model_obstacles(pose_t, observations, cfg))
        model = DOVSModel(obs, cfg, self.static_map, pose_t)
        window = DynamicWindow.around(v0, w0, cfg)
        gx, gy, _ = to_robot_frame(pose_t, self.goal[0], self.goal[1])
        goal = goal_velocities((float(gx), float(gy)), cfg)
        sel = select_greedy(window, goal.target, model.forbidden, cfg)
        return Decision(pose_t, (v0, w0), obs, model, window, goal, sel)

