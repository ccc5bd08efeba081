"""Parameters of the DOVS baseline, with their defaults and where each default comes from.

Sources of the defaults:

* Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic Environment",
  Table 1 (the robot R: v = 0.4 m/s, omega = 0.4 rad/s, a_max = 0.4 m/s^2, alpha_max = 1 rad/s^2).
* Lorente, Owen & Montano, "Model-based robocentric planning and navigation for dynamic
  environments", IJRR 37(8), 2018, and the authors' public implementation (T = 0.2 s, safety
  factor 1.1, braking margin 0.1 m, static-speed threshold 0.1 m/s, goal-switch distance 2 m,
  goal behind beyond 3 pi / 4); see ``docs/dovs.md``.
* Our own choices, marked "ours" below.

Every field is declared with :func:`anyplan.config.setting` (range, choices, unit), checked by
:func:`anyplan.config.validate` and listed by ``anyplan planners --settings``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

from anyplan.config import SettingError, setting, validate
from anyplan.world.robot import RobotLimits

__all__ = ["DOVSConfig", "DOVSConfigError"]

#: The robot's limits under DOVS's names: (DOVS name, RobotLimits attribute).
_LIMIT_NAMES = (("v_max", "v_max"), ("omega_max", "omega_max"), ("a_v", "a_max"),
                ("a_omega", "alpha_max"), ("robot_radius", "radius"))


class DOVSConfigError(SettingError):
    """A :class:`DOVSConfig` field has an invalid value (the message names the field)."""


@dataclass(frozen=True)
class DOVSConfig:
    """Parameters of DOVS-Greedy (SI units: m, s, rad).

    Attributes:
        control_period_s: T [s], the DOVS sampling period: the command is recomputed every T and
            held in between. The dynamic window is the set reachable within T. Default 0.2 s
            (5 Hz, the authors' ROS node).
        limits: The robot's radius and dynamic limits (:class:`~anyplan.world.robot.RobotLimits`;
            the default is Table 1's robot: radius 0.3 m, v_max = omega_max = a_max = 0.4,
            alpha_max = 1.0). The model reads them under DOVS's names, as the read-only views
            ``v_max``, ``omega_max``, ``a_v`` (= a_max), ``a_omega`` (= alpha_max) and
            ``robot_radius``; the ``dovs`` agent takes them from the scenario's robot.
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

    control_period_s: float = setting(0.2, lo=0.0, lo_open=True, unit="s", doc="sampling period T")
    limits: RobotLimits = field(default_factory=RobotLimits)  # checked in __post_init__
    safety_factor: float = setting(1.1, lo=1.0, doc="inflation of the robot radius")
    time_horizon_s: float = setting(8.0, lo=0.0, lo_open=True, hi=600.0, unit="s",
                                    doc="conflicts later than this are ignored")
    d_safe: float = setting(0.1, lo=0.0, unit="m", doc="braking margin")
    static_range: float | None = setting(None, lo=0.0, lo_open=True, unit="m",
                                         doc="D_safe; None: the braking reach")
    static_speed_threshold: float = setting(0.1, lo=0.0, unit="m/s",
                                            doc="slower obstacles are static")
    circular_omega_threshold: float = setting(1e-3, lo=0.0, unit="rad/s",
                                              doc="faster-turning obstacles move on circles")
    neighbourhood: float | None = setting(None, lo=0.0, lo_open=True, unit="m",
                                          doc="model only obstacles this near; None: all")
    merge: str = setting("hull", choices=("hull", "union"), doc="how DOVs on one ray combine")
    velocity_space: str = setting("triangle", choices=("triangle", "rectangle"))
    window_shape: str = setting("diamond", choices=("diamond", "box"))
    brake_along_ray: bool = setting(True, doc="braking rule keeps the ray")
    dw_samples: int = setting(21, lo=3, hi=1001, doc="dynamic-window grid per axis (odd)")
    vs_samples: int = setting(100, lo=10, hi=1001, doc="velocity-space grid per axis")
    goal_switch_distance: float = setting(2.0, lo=0.0, unit="m", doc="nearer: aim along the goal arc")
    goal_behind_angle: float = setting(3.0 * math.pi / 4.0, lo=0.0, lo_open=True, hi=math.pi,
                                       unit="rad", doc="a goal beyond this bearing is behind")

    def __post_init__(self) -> None:
        if not isinstance(self.limits, RobotLimits):
            raise DOVSConfigError("DOVSConfig", "limits", f"must be a RobotLimits, got {self.limits!r}")
        for name, attr in _LIMIT_NAMES:
            val = getattr(self.limits, attr)
            if isinstance(val, bool) or not isinstance(val, int | float) or not math.isfinite(val) \
                    or not val > 0.0:
                raise DOVSConfigError("DOVSConfig", name, f"must be > 0 (limits.{attr}), got {val!r}")
        validate(self, DOVSConfigError)
        if self.dw_samples % 2 == 0:
            raise DOVSConfigError("DOVSConfig", "dw_samples", f"must be odd, got {self.dw_samples}")

    # --- the robot's limits under DOVS's names (views of ``limits``, not copies) ------------
    @property
    def v_max(self) -> float:
        """Maximum linear speed [m/s]: ``limits.v_max``."""
        return self.limits.v_max

    @property
    def omega_max(self) -> float:
        """Maximum turn rate [rad/s]: ``limits.omega_max``."""
        return self.limits.omega_max

    @property
    def a_v(self) -> float:
        """Linear acceleration limit [m/s^2] of the window and the braking rule: ``limits.a_max``."""
        return self.limits.a_max

    @property
    def a_omega(self) -> float:
        """Angular acceleration limit [rad/s^2]: ``limits.alpha_max``."""
        return self.limits.alpha_max

    @property
    def robot_radius(self) -> float:
        """Robot disc radius [m]: ``limits.radius``."""
        return self.limits.radius

    def to_dict(self) -> dict[str, Any]:
        """The parameters as a flat dictionary (the limits under DOVS's names, as in
        ``result.json``'s ``extra.dovs_config``)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            if f.name == "limits":
                out.update((name, getattr(self.limits, attr)) for name, attr in _LIMIT_NAMES)
            else:
                out[f.name] = getattr(self, f.name)
        return out

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

