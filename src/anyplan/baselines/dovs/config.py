"""Parameters of the DOVS baseline, with their defaults and where each default comes from.

Sources of the defaults:

* Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic Environment",
  Table 1 (the robot R: v = 0.4 m/s, omega = 0.4 rad/s, a_max = 0.4 m/s^2, alpha_max = 1 rad/s^2).
* Lorente, Owen & Montano, "Model-based robocentric planning and navigation for dynamic
  environments", IJRR 37(8), 2018, as described in ``shared/research/dovs.md`` (its §3.6 and §6.4
  list the values used by the authors' public implementation: T = 0.2 s, safety factor 1.1,
  braking margin 0.1 m, static-speed threshold 0.1 m/s, goal-switch distance 2 m, goal behind
  beyond 3 pi / 4).
* Our own choices, marked "ours" below.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from anyplan.errors import AnyplanError

__all__ = ["DOVSConfig", "DOVSConfigError"]


class DOVSConfigError(AnyplanError, ValueError):
    """A :class:`DOVSConfig` field has an invalid value (the message names the field)."""


@dataclass(frozen=True)
class DOVSConfig:
    """Parameters of DOVS-Greedy (SI units: m, s, rad).

    Attributes:
        control_period_s: T [s], the DOVS sampling period: the command is recomputed every T and
            held in between. The dynamic window is the set reachable within T. Default 0.2 s
            (5 Hz, the authors' ROS node).
        v_max: Maximum linear speed [m/s] (Table 1: 0.4).
        omega_max: Maximum turn rate [rad/s] (Table 1: 0.4).
        a_v: Linear acceleration limit [m/s^2] used by the dynamic window and the braking rule
            (Table 1: a_max = 0.4).
        a_omega: Angular acceleration limit [rad/s^2] (Table 1: alpha_max = 1.0).
        robot_radius: Robot disc radius [m] (0.3: a Pioneer P3-DX footprint, as in the
            built-in scenarios).
        safety_factor: Moving obstacles are inflated to R = rho_obstacle + safety_factor *
            robot_radius; static obstacles are kept at safety_factor * robot_radius (1.1, the
            authors' code).
        time_horizon_s: T_h [s]: conflicts whose obstacle arrives after T_h are ignored and
            rays are examined up to the arc length v_max(ray) * T_h (8 s; ours, spec §6.4; the
            authors' code has it off).
        d_safe: Braking margin [m] of the static rule: on each ray, speeds above
            sqrt(2 a (s_hit - d_safe)) are forbidden, s_hit being the arc length to first
            contact (0.1 m, the authors' code).
        static_range: The paper's D_safe [m]: a static obstacle enters the model only when the
            robot's clearance to it is below this. None (default) uses the braking reach
            ``d_safe + v_max^2 / (2 a_v)``, beyond which the braking rule cannot forbid anything.
        static_speed_threshold: Observed obstacles slower than this [m/s] are modelled as static
            discs (0.1, the authors' code).
        circular_omega_threshold: Observed obstacles with |omega| above this [rad/s] are
            modelled as moving on a circle, otherwise on a straight line (1e-3, the authors'
            code).
        neighbourhood: Only moving obstacles within this distance [m] of the robot are modelled;
            None models all observed obstacles (default; the authors' code uses 4 m).
        merge: How the DOVs of several obstacles on one ray combine: "hull" (forbid from the
            smallest lower bound to the largest upper bound, as in the authors' code; default)
            or "union" (forbid only the union of the intervals).
        velocity_space: "triangle" (v <= v_max (1 - |omega| / omega_max), wheel-speed limits
            of a differential drive; default, as in the authors' VS) or "rectangle".
        window_shape: "diamond" (|dv| / (a_v T) + |dw| / (a_omega T) <= 1, the authors' DW;
            default) or "box" (|dv| <= a_v T and |dw| <= a_omega T).
        brake_along_ray: If True (default; ours), the braking rule uses the deceleration the
            window allows while keeping the ray (v / omega constant); if False, a_v as in the
            authors' code (optimistic on curved rays).
        dw_samples: The dynamic window's bounding box is sampled on a dw_samples x dw_samples
            grid (odd, so that the current velocity is a sample; 21).
        vs_samples: Samples per axis of the velocity-space grid used by the escape fallback
            (100, the authors' code).
        goal_switch_distance: Below this distance to the goal [m] the target is the fastest
            command on the goal arc; above it, the pursuit-style "dirGoal" (2.0, the authors'
            code).
        goal_behind_angle: A goal whose bearing exceeds this [rad] is "behind": the target is
            rotation in place (3 pi / 4, the authors' code).
    """

    control_period_s: float = 0.2
    v_max: float = 0.4
    omega_max: float = 0.4
    a_v: float = 0.4
    a_omega: float = 1.0
    robot_radius: float = 0.3
    safety_factor: float = 1.1
    time_horizon_s: float = 8.0
    d_safe: float = 0.1
    static_range: float | None = None
    static_speed_threshold: float = 0.1
    circular_omega_threshold: float = 1e-3
    neighbourhood: float | None = None
    merge: str = "hull"
    velocity_space: str = "triangle"
    window_shape: str = "diamond"
    brake_along_ray: bool = True
    dw_samples: int = 21
    vs_samples: int = 100
    goal_switch_distance: float = 2.0
    goal_behind_angle: float = 3.0 * math.pi / 4.0

    def __post_init__(self) -> None:
        positive = ("control_period_s", "v_max", "omega_max", "a_v", "a_omega", "robot_radius",
                    "time_horizon_s")
        for name in positive:
            _check_number(self, name, lo=0.0, lo_open=True)
        _check_number(self, "safety_factor", lo=1.0)
        _check_number(self, "d_safe", lo=0.0)
        _check_number(self, "static_speed_threshold", lo=0.0)
        _check_number(self, "circular_omega_threshold", lo=0.0)
        _check_number(self, "goal_switch_distance", lo=0.0)
        _check_number(self, "goal_behind_angle", lo=0.0, lo_open=True, hi=math.pi)
        if self.time_horizon_s > 600.0:
            raise DOVSConfigError(f"DOVSConfig.time_horizon_s: must be <= 600 s, got {self.time_horizon_s}")
        for name in ("static_range", "neighbourhood"):
            if getattr(self, name) is not None:
                _check_number(self, name, lo=0.0, lo_open=True)
        _check_choice(self, "merge", ("hull", "union"))
        _check_choice(self, "velocity_space", ("triangle", "rectangle"))
        _check_choice(self, "window_shape", ("diamond", "box"))
        if not isinstance(self.brake_along_ray, bool):
            raise DOVSConfigError(f"DOVSConfig.brake_along_ray: must be a bool, got {self.brake_along_ray!r}")
        for name, lo in (("dw_samples", 3), ("vs_samples", 10)):
            val = getattr(self, name)
            if isinstance(val, bool) or not isinstance(val, int) or val < lo or val > 1001:
                raise DOVSConfigError(f"DOVSConfig.{name}: must be an integer in [{lo}, 1001], got {val!r}")
        if self.dw_samples % 2 == 0:
            raise DOVSConfigError(f"DOVSConfig.dw_samples: must be odd, got {self.dw_samples}")

    # --- derived quantities ---------------------------------------------------------------
    @property
    def static_clearance(self) -> float:
        """Clearance [m] kept from static obstacles: safety_factor * robot_radius."""
        return self.safety_factor * self.robot_radius

    def inflated_radius(self, obstacle_radius: float) -> float:
        """R [m] of a moving obstacle of radius ``obstacle_radius`` [m]."""
        return obstacle_radius + self.safety_factor * self.robot_radius

    @property
    def effective_static_range(self) -> float:
        """The D_safe in use [m] (``static_range``, or the braking reach if None)."""
        if self.static_range is not None:
            return self.static_range
        return self.d_safe + self.v_max ** 2 / (2.0 * self.a_v)

    @classmethod
    def field_names(cls) -> list[str]:
        """Names of all parameters."""
        return [f.name for f in fields(cls)]


def _check_number(cfg: DOVSConfig, name: str, *, lo: float | None = None, lo_open: bool = False,
                  hi: float | None = None) -> None:
    val = getattr(cfg, name)
    if isinstance(val, bool) or not isinstance(val, int | float) or not math.isfinite(val):
        raise DOVSConfigError(f"DOVSConfig.{name}: must be a finite number, got {val!r}")
    if lo is not None and (val < lo or (lo_open and val == lo)):
        op = ">" if lo_open else ">="
        raise DOVSConfigError(f"DOVSConfig.{name}: must be {op} {lo}, got {val}")
    if hi is not None and val > hi:
        raise DOVSConfigError(f"DOVSConfig.{name}: must be <= {hi}, got {val}")


def _check_choice(cfg: DOVSConfig, name: str, choices: tuple[str, ...]) -> None:
    val = getattr(cfg, name)
    if val not in choices:
        raise DOVSConfigError(f"DOVSConfig.{name}: must be one of {', '.join(choices)}, got {val!r}")
