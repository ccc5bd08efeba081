"""The differential-drive (unicycle) robot: limits, state and one exact integration step."""

from __future__ import annotations

import math
from dataclasses import dataclass

from anyplan.geometry.se2 import unicycle_arc, wrap_angle

__all__ = ["RobotLimits", "RobotSpec", "RobotState", "Command", "clip_command", "step"]


@dataclass(frozen=True)
class RobotLimits:
    """A disc robot's size and dynamic limits (the defaults: the paper's Table 1 robot).

    Attributes:
        radius: Radius [m] of a disc that contains the footprint.
        v_max: Maximum linear speed [m/s].
        omega_max: Maximum turn rate [rad/s].
        a_max: Maximum linear acceleration [m/s^2].
        alpha_max: Maximum angular acceleration [rad/s^2].
    """

    radius: float = 0.3
    v_max: float = 0.4
    omega_max: float = 0.4
    a_max: float = 0.4
    alpha_max: float = 1.0


@dataclass(frozen=True)
class RobotSpec:
    """A disc-shaped differential-drive robot and its task.

    Attributes:
        start: Start pose (x [m], y [m], heading [rad]).
        goal: Goal position (x [m], y [m]).
        goal_tolerance: The goal is reached within this distance [m].
        radius: Radius [m] of a disc that contains the footprint.
        v_max: Maximum linear speed [m/s]; commands are clipped to [-v_max, v_max].
        omega_max: Maximum turn rate [rad/s].
        a_max: Maximum linear acceleration [m/s^2].
        alpha_max: Maximum angular acceleration [rad/s^2].
        sensing_range: Moving obstacles are observed only within this distance [m] of the
            robot's centre; None means they are known from the start.
    """

    start: tuple[float, float, float]
    goal: tuple[float, float]
    radius: float = 0.3
    v_max: float = 0.4
    omega_max: float = 0.4
    a_max: float = 0.4
    alpha_max: float = 1.0
    goal_tolerance: float = 0.2
    sensing_range: float | None = None

    @property
    def arrival_radius(self) -> float:
        """Distance [m] from the goal within which a planned motion counts as arrived: half
        the goal tolerance (the run ends within the whole of it; the other half absorbs the
        tracking error). Checks of a motion that ends at the goal stop there."""
        return 0.5 * self.goal_tolerance

    @property
    def limits(self) -> RobotLimits:
        """The robot's size and dynamic limits as one record (e.g. for a planner's settings)."""
        return RobotLimits(self.radius, self.v_max, self.omega_max, self.a_max, self.alpha_max)


@dataclass(frozen=True)
class RobotState:
    """Pose (x [m], y [m], theta [rad]) and twist (v [m/s], omega [rad/s])."""

    x: float
    y: float
    theta: float
    v: float = 0.0
    omega: float = 0.0

    @property
    def position(self) -> tuple[float, float]:
        """(x, y) [m]."""
        return (self.x, self.y)

    def moved(self, v: float, omega: float, dt: float) -> RobotState:
        """This pose moved by the twist (``v`` [m/s], ``omega`` [rad/s]) held for ``dt`` [s],
        the unicycle integrated exactly (an arc, or a straight segment), with that twist."""
        x, y, th = unicycle_arc(self.x, self.y, self.theta, v, omega, dt)
        return RobotState(x, y, float(wrap_angle(th)), v, omega)


@dataclass(frozen=True)
class Command:
    """A velocity command: linear speed v [m/s] and turn rate omega [rad/s]."""

    v: float
    omega: float


def _clip(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else hi if x > hi else x


def clip_command(spec: RobotSpec, state: RobotState, cmd: Command, dt: float) -> Command:
    """Apply the dynamic constraints: the command actually achieved after ``dt`` [s].

    |v| <= v_max, |omega| <= omega_max, |dv| <= a_max dt and |d omega| <= alpha_max dt.
    Non-finite commands are treated as a request to stop.
    """
    v = cmd.v if math.isfinite(cmd.v) else 0.0
    w = cmd.omega if math.isfinite(cmd.omega) else 0.0
    v = _clip(v, -spec.v_max, spec.v_max)
    w = _clip(w, -spec.omega_max, spec.omega_max)
    dv = spec.a_max * dt
    dw = spec.alpha_max * dt
    v = _clip(v, state.v - dv, state.v + dv)
    w = _clip(w, state.omega - dw, state.omega + dw)
    return Command(v, w)


def step(spec: RobotSpec, state: RobotState, cmd: Command, dt: float) -> RobotState:
    """Advance the robot by ``dt`` [s] under ``cmd`` after clipping it to the limits.

    The clipped command is held constant over the step and the unicycle is integrated exactly
    (an arc of a circle, or a straight segment).
    """
    c = clip_command(spec, state, cmd, dt)
    return state.moved(c.v, c.omega, dt)
