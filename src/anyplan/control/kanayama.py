"""Trajectory tracking with the control law of Kanayama, Kimura, Miyazaki & Noguchi,
"A stable tracking control method for an autonomous mobile robot" (ICRA 1990), as in §4 of the
paper.

With the reference pose (x_r, y_r, theta_r) and the robot pose (x, y, theta), the error in the
robot frame is::

    e_x     =  cos(theta) (x_r - x) + sin(theta) (y_r - y)
    e_y     = -sin(theta) (x_r - x) + cos(theta) (y_r - y)
    e_theta =  wrap(theta_r - theta)

and the command is::

    v     = v_r cos(e_theta) + K_x e_x
    omega = omega_r + v_r (K_y e_y + K_theta sin(e_theta)) + K_turn sin(e_theta)

saturated to |v| <= v_max, |omega| <= omega_max and to the acceleration limits over one control
period. ``K_turn`` is our addition (0 gives Kanayama's law exactly): with v_r = 0 (turning in
place) Kanayama's law has no heading feedback at all. It keeps Kanayama's Lyapunov function
V = (e_x^2 + e_y^2) / 2 + (1 - cos e_theta) / K_y decreasing: it adds -K_turn sin^2(e_theta) / K_y
to dV/dt.

Feedforward. The simulator holds each command for one period dt. Using the reference's *mean*
speed and turn rate over the coming period, v_r = (s(t+dt) - s(t)) / dt and
omega_r = (theta_r(t+dt) - theta_r(t)) / dt, makes the robot land on the reference at the end of
the period when it starts on it, so the feedback only has to correct disturbances and saturation,
not discretisation lag.

Gains (defaults). Linearising about zero error with constant v_r gives e_x' = -K_x e_x and
e_y'' + v_r K_theta e_y' + v_r^2 K_y e_y = 0: a lateral oscillator of natural frequency
w_n = v_r sqrt(K_y) and damping K_theta / (2 sqrt(K_y)). We choose critical damping,
K_y = K_theta^2 / 4, with K_theta = 8 1/m and K_y = 16 1/m^2, so that at v_r = 0.4 m/s the
lateral error decays at w_n = 1.6 rad/s (time constant ~0.6 s, about one robot length travelled).
K_x = 2 1/s gives the same ~0.5 s time constant along the path. These are smaller than
Kanayama's (K_x = 10, K_y = 64, K_theta = 16 in SI units): our robot's omega_max = 0.4 rad/s and
alpha_max = 1 rad/s^2 are so low that stiffer gains only saturate and make the corrections
bang-bang; and with dt = 0.05 s, K_x dt and w_n dt stay far below the discrete stability limit 2.
K_turn = 2 1/s: heading errors while turning in place decay in ~0.5 s.

Limitation: a robot that lags behind a reference running at v_max cannot catch up (its speed is
capped at v_max too); the along-track error then persists until the reference slows down. The
references of :func:`~anyplan.trajectory.plan_motion` start at the robot's own state, so in
simulation the error stays at the micrometre level.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

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

    k_x: float = 2.0
    k_y: float = 16.0
    k_theta: float = 8.0
    k_turn: float = 2.0

    def __post_init__(self) -> None:
        for name in ("k_x", "k_y", "k_theta", "k_turn"):
            if not getattr(self, name) >= 0.0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)}")


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
        w_s = np.array([1.0, 4.0, 2.0, 4.0, 1.0]) / 12.0
        v_r = float(w_s @ v)
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
