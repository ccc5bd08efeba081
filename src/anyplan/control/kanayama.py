"""Trajectory tracking with Kanayama's control law, as in §4 of the paper.

Kanayama, Kimura, Miyazaki & Noguchi, "A stable tracking control method for an autonomous
mobile robot", ICRA 1990. With the error (e_x, e_y, e_theta) of the robot's pose against the
reference in the robot frame, the command is

    v     = v_r cos(e_theta) + K_x e_x
    omega = omega_r + v_r (K_y e_y + K_theta sin(e_theta)) + K_turn sin(e_theta)

saturated to the robot's speed and acceleration limits; v_r, omega_r are the reference's mean
rates over the coming control period (feedforward), ``K_turn`` our heading feedback for turning
in place. The gains, the feedforward and the limitation are derived in ``docs/motion.md``,
"Tracking (Kanayama et al., ICRA 1990)".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from anyplan.config import setting, validate
from anyplan.geometry.se2 import wrap_angle
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world.robot import Command, RobotSpec, RobotState, clip_command

__all__ = ["KanayamaGains", "KanayamaController", "tracking_errors"]


@dataclass(frozen=True)
class KanayamaGains:
    """Gains of the Kanayama tracking law.

    Attributes:
        k_x: Along-track gain [1/s].
        k_y: Cross-track gain [1/m^2].
        k_theta: Heading gain [1/m].
        k_turn: Heading gain [1/s] independent of v_r (our addition; 0 = Kanayama's law).
    """

    k_x: float = setting(2.0, lo=0.0, unit="1/s", doc="along-track gain")
    k_y: float = setting(16.0, lo=0.0, unit="1/m^2", doc="cross-track gain")
    k_theta: float = setting(8.0, lo=0.0, unit="1/m", doc="heading gain")
    k_turn: float = setting(2.0, lo=0.0, unit="1/s", doc="heading gain independent of v_r")

    def __post_init__(self) -> None:
        validate(self)


def tracking_errors(x_r: float, y_r: float, th_r: float, state: RobotState) -> tuple[float, float, float]:
    """Kanayama's error (e_x [m], e_y [m], e_theta [rad]) of ``state`` in the robot frame."""
    dx, dy = x_r - state.x, y_r - state.y
    c, s = math.cos(state.theta), math.sin(state.theta)
    return c * dx + s * dy, -s * dx + c * dy, float(wrap_angle(th_r - state.theta))


class KanayamaController:
    """Tracks a :class:`~anyplan.trajectory.trajectory.Trajectory` with Kanayama's law.

    Args:
        spec: Robot limits used for saturation.
        gains: Control gains.
        dt: Control period [s] (the simulator's step), used for the mean-rate feedforward and the
            acceleration saturation.
    """

    def __init__(self, spec: RobotSpec, gains: KanayamaGains | None = None, dt: float = 0.05) -> None:
        if not dt > 0.0:
            raise ValueError(f"dt must be > 0 s, got {dt}")
        self.spec = spec
        self.gains = gains or KanayamaGains()
        self.dt = float(dt)

    def reference(self, traj: Trajectory, t: float) -> tuple[float, float, float, float, float]:
        """Reference pose at ``t`` and mean (v_r, omega_r) over [t, t + dt]."""
        ts = t + self.dt * np.linspace(0.0, 1.0, 5)
        x, y, th, v, _ = traj.sample(ts)
        # Simpson's rule: v is piecewise linear in time, so this is exact within a segment.
        # written out, not ``w @ v`` (BLAS: machine-dependent bits, geometry.se2)
        v_r = (float(v[0]) + 4.0 * float(v[1]) + 2.0 * float(v[2]) + 4.0 * float(v[3])
               + float(v[4])) / 12.0
        w_r = float(np.sum(wrap_angle(np.diff(th)))) / self.dt
        return float(x[0]), float(y[0]), float(th[0]), v_r, w_r

    def command(self, traj: Trajectory, state: RobotState, t: float) -> Command:
        """The saturated command for the period starting at ``t`` [s]."""
        g = self.gains
        x_r, y_r, th_r, v_r, w_r = self.reference(traj, t)
        e_x, e_y, e_th = tracking_errors(x_r, y_r, th_r, state)
        v = v_r * math.cos(e_th) + g.k_x * e_x
        w = w_r + v_r * (g.k_y * e_y + g.k_theta * math.sin(e_th)) + g.k_turn * math.sin(e_th)
        return clip_command(self.spec, state, Command(v, w), self.dt)
