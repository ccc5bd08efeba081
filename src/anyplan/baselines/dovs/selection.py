"""Goal velocities, the static braking rule and the greedy command selector of DOVS.

Follows the authors' "Greedy" planner (Lorente, Owen & Montano, IJRR 2018, and their public
code; described in ``docs/dovs.md``), written from its description:

1. the target command is "FollowGoal": the command reaching the goal in one period if it is
   admissible, else the fastest command on the goal arc within ``goal_switch_distance`` of the
   goal, else the pursuit-style "dirGoal"; rotation in place if the goal is behind;
2. among the dynamic-window samples outside the DOVS, the one nearest (Euclidean in (v, omega))
   to the target;
3. if every sample is forbidden: the free VS velocity nearest to the current one, and the window
   sample nearest to *it*, ignoring the DOVS ("escape");
4. if the whole VS is forbidden: the window sample nearest to (0, 0) ("stop").
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from anyplan.baselines.dovs.config import DOVSConfig
from anyplan.baselines.dovs.window import (
    DynamicWindow,
    in_velocity_space,
    ray_deceleration,
    ray_v_max,
    vs_v_max,
)

__all__ = ["GoalVelocities", "Selection", "goal_velocities", "braking_speed", "select_greedy",
           "vs_grid"]

#: Signature of a forbidden-set test: (v [m/s], omega [rad/s]) arrays -> boolean mask.
ForbiddenFn = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class GoalVelocities:
    """Goal-directed commands (v [m/s], omega [rad/s]) for a goal in the robot frame.

    Attributes:
        distance: Distance to the goal [m].
        bearing: Bearing of the goal [rad] (0 straight ahead, > 0 on the left).
        vel_goal: Command reaching the goal in one period (may be outside the VS).
        command_goal: Fastest admissible command on the goal arc.
        dir_goal: Pursuit compromise between the goal arc and turning toward the goal.
        target: The command greedy selection aims at.
        mode: Which one the target is: "vel_goal", "command_goal", "dir_goal" or "rotate".
    """

    distance: float
    bearing: float
    vel_goal: tuple[float, float]
    command_goal: tuple[float, float]
    dir_goal: tuple[float, float]
    target: tuple[float, float]
    mode: str


@dataclass(frozen=True)
class Selection:
    """The chosen command and how it was found.

    Attributes:
        v: Chosen linear speed [m/s].
        omega: Chosen turn rate [rad/s].
        mode: "greedy" (free and nearest to the target), "escape" (no free window sample: toward
            the free VS velocity nearest to the current one) or "stop" (the VS is all forbidden).
        free: Whether the chosen command is outside the DOVS.
        n_candidates: Number of window samples examined.
        n_free: Number of them outside the DOVS.
        escape_to: The free VS velocity (v, omega) aimed at in "escape" mode, else None.
    """

    v: float
    omega: float
    mode: str
    free: bool
    n_candidates: int
    n_free: int
    escape_to: tuple[float, float] | None = None


def goal_velocities(goal_xy: tuple[float, float], cfg: DOVSConfig) -> GoalVelocities:
    """FollowGoal and its ingredients for a goal at ``goal_xy`` [m] in the robot frame.

    The circle through the robot, tangent to its heading and through the goal has curvature
    kappa_g = 2 g_y / d^2 and reaches the goal after the arc angle 2 beta (beta the bearing), i.e.
    the arc length d beta / sin(beta).
    """
    gx, gy = float(goal_xy[0]), float(goal_xy[1])
    d = math.hypot(gx, gy)
    beta = math.atan2(gy, gx) if d > 0.0 else 0.0
    T = cfg.control_period_s
    kappa_g = 2.0 * gy / (d * d) if d > 0.0 else 0.0
    s_g = d / float(np.sinc(beta / math.pi)) if abs(beta) < math.pi - 1e-9 else math.inf
    vel_goal = (s_g / T, 2.0 * beta / T)
    v_c = float(ray_v_max(kappa_g, cfg))
    command_goal = (v_c, kappa_g * v_c)
    w_dir = 0.5 * (command_goal[1] + float(np.clip(beta / T, -cfg.omega_max, cfg.omega_max)))
    dir_goal = (float(vs_v_max(w_dir, cfg)), w_dir)
    if abs(beta) > cfg.goal_behind_angle:
        target, mode = (0.0, math.copysign(cfg.omega_max, beta)), "rotate"
    elif math.isfinite(s_g) and bool(in_velocity_space(vel_goal[0], vel_goal[1], cfg)):
        target, mode = vel_goal, "vel_goal"
    elif d < cfg.goal_switch_distance:
        target, mode = command_goal, "command_goal"
    else:
        target, mode = dir_goal, "dir_goal"
    return GoalVelocities(d, beta, vel_goal, command_goal, dir_goal, target, mode)


def braking_speed(s_hit: np.ndarray, kappa: np.ndarray, cfg: DOVSConfig) -> np.ndarray:
    """The static braking rule: the largest safe speed [m/s] on each ray.

    ``sqrt(2 a (s_hit - d_safe))``, with ``s_hit`` [m] the arc length to first contact with a
    static obstacle and ``a`` the deceleration available on the ray
    (:func:`~anyplan.baselines.dovs.window.ray_deceleration`); 0 when s_hit <= d_safe.
    """
    d = np.maximum(np.asarray(s_hit, dtype=float) - cfg.d_safe, 0.0)
    return np.sqrt(2.0 * ray_deceleration(kappa, cfg) * d)


def vs_grid(cfg: DOVSConfig, n: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """An n x n grid (v, omega) over [0, v_max] x [-omega_max, omega_max], kept inside the VS."""
    n = cfg.vs_samples if n is None else n
    V, W = np.meshgrid(np.linspace(0.0, cfg.v_max, n), np.linspace(-cfg.omega_max, cfg.omega_max, n),
                       indexing="ij")
    v, w = V.ravel(), W.ravel()
    keep = in_velocity_space(v, w, cfg)
    return v[keep], w[keep]


def select_greedy(window: DynamicWindow, target: tuple[float, float], forbidden: ForbiddenFn,
                  cfg: DOVSConfig) -> Selection:
    """DOVS-Greedy: the free reachable command nearest to ``target``, with the two fallbacks.

    Args:
        window: The dynamic window around the current velocity.
        target: Goal command (v [m/s], omega [rad/s]).
        forbidden: Test of the DOVS (True = forbidden) on arrays of commands.
        cfg: Parameters (grid sizes, limits).
    """
    v, w = window.candidates(cfg)
    bad = np.asarray(forbidden(v, w), dtype=bool)
    free = ~bad
    n_free = int(free.sum())
    if n_free:
        d2 = (v - target[0]) ** 2 + (w - target[1]) ** 2
        d2 = np.where(free, d2, np.inf)
        i = int(np.argmin(d2))
        return Selection(float(v[i]), float(w[i]), "greedy", True, len(v), n_free)
    gv, gw = vs_grid(cfg)
    gfree = ~np.asarray(forbidden(gv, gw), dtype=bool)
    if np.any(gfree):
        d2 = np.where(gfree, (gv - window.v0) ** 2 + (gw - window.omega0) ** 2, np.inf)
        j = int(np.argmin(d2))
        esc = (float(gv[j]), float(gw[j]))
        i = int(np.argmin((v - esc[0]) ** 2 + (w - esc[1]) ** 2))
        return Selection(float(v[i]), float(w[i]), "escape", False, len(v), 0, esc)
    i = int(np.argmin(v ** 2 + w ** 2))
    return Selection(float(v[i]), float(w[i]), "stop", False, len(v), 0)
