"""Velocity space (VS) and dynamic window (DW) of DOVS, in the (omega, v) plane.

* The VS is v in [0, v_max] and, by default, the triangle v <= v_max (1 - |omega| / omega_max)
  of a differential drive's wheel-speed limits (Lorente, Owen & Montano, IJRR 2018, and the
  authors' code; ``docs/dovs.md``).
* A constant command (v, omega) with v > 0 drives the arc of curvature kappa = omega / v; all
  commands on the *ray* v = omega / kappa follow the same path at different speeds. The largest
  VS speed on a ray is :func:`ray_v_max`.
* The DW is the "diamond" |v - v0| / (a_v T) + |omega - omega0| / (a_omega T) <= 1 of commands
  reachable within one period T, intersected with the VS (§3.1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from anyplan.baselines.dovs.config import DOVSConfig

__all__ = ["vs_v_max", "ray_v_max", "in_velocity_space", "ray_deceleration", "DynamicWindow"]

#: Tolerance [m/s or rad/s] on VS and DW membership tests.
VEL_EPS = 1e-9


def vs_v_max(omega: np.ndarray | float, cfg: DOVSConfig) -> np.ndarray:
    """Largest admissible speed [m/s] at turn rate ``omega`` [rad/s] (0 outside |omega| <= omega_max)."""
    w = np.abs(np.asarray(omega, dtype=float))
    if cfg.velocity_space == "triangle":
        v = cfg.v_max * (1.0 - w / cfg.omega_max)
    else:
        v = np.full_like(w, cfg.v_max)
    return np.where(w <= cfg.omega_max + VEL_EPS, np.maximum(v, 0.0), 0.0)


def ray_v_max(kappa: np.ndarray | float, cfg: DOVSConfig) -> np.ndarray:
    """Largest admissible speed [m/s] on the ray of curvature ``kappa`` [1/m] (omega = kappa v).

    Triangle: v_max / (1 + v_max |kappa| / omega_max); rectangle: min(v_max, omega_max / |kappa|).
    """
    k = np.abs(np.asarray(kappa, dtype=float))
    if cfg.velocity_space == "triangle":
        return cfg.v_max / (1.0 + cfg.v_max * k / cfg.omega_max)
    with np.errstate(divide="ignore"):
        return np.minimum(cfg.v_max, np.where(k > 0.0, cfg.omega_max / np.maximum(k, 1e-300), np.inf))


def in_velocity_space(v: np.ndarray | float, omega: np.ndarray | float, cfg: DOVSConfig,
                      eps: float = VEL_EPS) -> np.ndarray:
    """Boolean mask: (v, omega) lies in the VS (v >= 0, |omega| <= omega_max, below the border)."""
    v = np.asarray(v, dtype=float)
    w = np.asarray(omega, dtype=float)
    return (v >= -eps) & (np.abs(w) <= cfg.omega_max + eps) & (v <= vs_v_max(w, cfg) + eps)


def ray_deceleration(kappa: np.ndarray | float, cfg: DOVSConfig) -> np.ndarray:
    """Deceleration [m/s^2] that the DW allows while staying on the ray of curvature ``kappa``.

    Slowing down by dv on the ray also changes omega by kappa dv, so the diamond allows
    dv <= T / (1 / a_v + |kappa| / a_omega) per period (box: min(a_v, a_omega / |kappa|)).
    With ``cfg.brake_along_ray`` False this returns a_v, as the authors' code does.
    """
    k = np.abs(np.asarray(kappa, dtype=float))
    if not cfg.brake_along_ray:
        return np.full_like(k, cfg.a_v)
    if cfg.window_shape == "diamond":
        return 1.0 / (1.0 / cfg.a_v + k / cfg.a_omega)
    with np.errstate(divide="ignore"):
        return np.minimum(cfg.a_v, np.where(k > 0.0, cfg.a_omega / np.maximum(k, 1e-300), np.inf))


@dataclass(frozen=True)
class DynamicWindow:
    """The commands reachable within one period from the current (v0, omega0).

    Attributes:
        v0: Current linear speed [m/s].
        omega0: Current turn rate [rad/s].
        dv: Half-width a_v T of the window in v [m/s].
        dw: Half-width a_omega T of the window in omega [rad/s].
        shape: "diamond" or "box".
    """

    v0: float
    omega0: float
    dv: float
    dw: float
    shape: str = "diamond"

    @classmethod
    def around(cls, v0: float, omega0: float, cfg: DOVSConfig) -> DynamicWindow:
        """The window of ``cfg`` around the current velocity."""
        T = cfg.control_period_s
        return cls(float(v0), float(omega0), cfg.a_v * T, cfg.a_omega * T, cfg.window_shape)

    def reachable(self, v: np.ndarray | float, omega: np.ndarray | float,
                  eps: float = VEL_EPS) -> np.ndarray:
        """Boolean mask: (v, omega) is inside the window (VS not tested)."""
        a = np.abs(np.asarray(v, dtype=float) - self.v0) / self.dv
        b = np.abs(np.asarray(omega, dtype=float) - self.omega0) / self.dw
        if self.shape == "diamond":
            return a + b <= 1.0 + eps
        return (a <= 1.0 + eps) & (b <= 1.0 + eps)

    def vertices(self) -> np.ndarray:
        """Polygon of the window (before VS clipping), rows (omega, v), closed."""
        v0, w0, dv, dw = self.v0, self.omega0, self.dv, self.dw
        if self.shape == "diamond":
            pts = [(w0, v0 + dv), (w0 - dw, v0), (w0, v0 - dv), (w0 + dw, v0)]
        else:
            pts = [(w0 - dw, v0 + dv), (w0 - dw, v0 - dv), (w0 + dw, v0 - dv), (w0 + dw, v0 + dv)]
        return np.array(pts + pts[:1], dtype=float)

    def candidates(self, cfg: DOVSConfig) -> tuple[np.ndarray, np.ndarray]:
        """Grid samples of the window that lie in the VS: arrays (v, omega) [m/s, rad/s].

        The window's bounding box is sampled on ``cfg.dw_samples`` points per axis, centred on
        the current velocity. If no sample lies in the VS (the current velocity is far outside
        it), the samples are projected onto the VS and those still in the window are returned.
        """
        n = cfg.dw_samples
        u = np.linspace(-1.0, 1.0, n)
        V, W = np.meshgrid(self.v0 + self.dv * u, self.omega0 + self.dw * u, indexing="ij")
        v, w = V.ravel(), W.ravel()
        keep = self.reachable(v, w) & in_velocity_space(v, w, cfg)
        if np.any(keep):
            return v[keep], w[keep]
        # Project onto the VS (clip omega, then v) and keep what the window still contains.
        w2 = np.clip(w, -cfg.omega_max, cfg.omega_max)
        v2 = np.clip(v, 0.0, vs_v_max(w2, cfg))
        keep = self.reachable(v2, w2, eps=1e-6)
        if np.any(keep):
            return v2[keep], w2[keep]
        # Still nothing: the VS point nearest to the current velocity (outside the window).
        i = int(np.argmin((v2 - self.v0) ** 2 + (w2 - self.omega0) ** 2))
        return v2[i:i + 1], w2[i:i + 1]
