"""The Dynamic Object Velocity Space model: per-ray forbidden speed intervals.

Lorente, Owen & Montano, "Model-based robocentric planning and navigation for dynamic
environments", IJRR 37(8), 2018 (no code of the authors' implementation is reused).

Every control period the obstacles are expressed in the robot frame (robot at the origin,
heading +x). A command (v, w) held constant drives the arc of curvature kappa = w / v; every
command on that *ray* follows the same path. Moving obstacles (linear or circular) forbid on
each ray the closed speed interval [s_a / t_out, s_b / t_in] of every arc stretch [s_a, s_b]
they occupy during [t_in, t_out]; static ones forbid the speeds v > sqrt(2 a (s_hit - d_safe))
from which the robot cannot brake before the first contact at arc length s_hit. The model is
conservative (tested against brute-force simulation in ``tests/baselines``). Derivation: the
section "The model (one control period)" of ``docs/dovs.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from anyplan.baselines.dovs.config import DOVSConfig
from anyplan.baselines.dovs.selection import braking_speed
from anyplan.baselines.dovs.window import ray_deceleration, ray_v_max
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Shape

__all__ = ["ModelObstacle", "to_robot_frame", "to_world_frame", "model_obstacles", "arc_points",
           "RayIntervals", "StaticMap", "DOVSModel", "KAPPA_MIN"]

TWO_PI = 2.0 * math.pi
#: Rays straighter than this curvature [1/m] are evaluated at this curvature; the lateral
#: deviation (<= KAPPA_MIN s^2 / 2) is added to the inflated radius, keeping the model exact-safe.
KAPPA_MIN = 1e-4
#: Speeds [m/s] at or below this are "not moving" (rotation in place).
V_EPS = 1e-9


class ObstacleLike(Protocol):
    """What the model reads from an observed obstacle (world frame, SI units; read-only)."""

    @property
    def name(self) -> str: ...
    @property
    def x(self) -> float: ...
    @property
    def y(self) -> float: ...
    @property
    def theta(self) -> float: ...
    @property
    def v(self) -> float: ...
    @property
    def omega(self) -> float: ...
    @property
    def radius(self) -> float: ...


@dataclass(frozen=True)
class ModelObstacle:
    """An obstacle in the robot frame, classified and inflated.

    Attributes:
        name: Obstacle name.
        kind: "linear", "circular" or "static".
        x, y: Centre [m] in the robot frame (for a static disc, the disc's centre).
        theta: Heading [rad] in the robot frame.
        v: Speed [m/s] (>= 0).
        omega: Turn rate [rad/s].
        radius: Inflated radius R [m] (for a static disc: the radius the robot's centre must
            keep away from).
    """

    name: str
    kind: str
    x: float
    y: float
    theta: float
    v: float
    omega: float
    radius: float


def to_robot_frame(pose: Sequence[float], x: np.ndarray | float, y: np.ndarray | float,
                   theta: np.ndarray | float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World (x, y, theta) -> robot frame of ``pose`` = (X, Y, Theta): Rot(-Theta) (p - P)."""
    X, Y, TH = (float(pose[0]), float(pose[1]), float(pose[2]))
    c, s = math.cos(TH), math.sin(TH)
    dx, dy = np.asarray(x, dtype=float) - X, np.asarray(y, dtype=float) - Y
    return c * dx + s * dy, -s * dx + c * dy, np.asarray(theta, dtype=float) - TH


def to_world_frame(pose: Sequence[float], x: np.ndarray | float, y: np.ndarray | float,
                   theta: np.ndarray | float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Robot frame of ``pose`` -> world: P + Rot(Theta) p (inverse of :func:`to_robot_frame`)."""
    X, Y, TH = (float(pose[0]), float(pose[1]), float(pose[2]))
    c, s = math.cos(TH), math.sin(TH)
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return X + c * x - s * y, Y + s * x + c * y, np.asarray(theta, dtype=float) + TH


def arc_points(kappa: np.ndarray | float, s: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Robot-frame points at arc length ``s`` [m] on the arcs of curvature ``kappa`` [1/m].

    (sin(kappa s) / kappa, (1 - cos(kappa s)) / kappa), stable as kappa -> 0; broadcasts.
    """
    k, s = np.asarray(kappa, dtype=float), np.asarray(s, dtype=float)
    x = k * s
    px = s * np.sinc(x / math.pi)
    py = 0.5 * k * s * s * np.sinc(x / TWO_PI) ** 2
    return px, py


def model_obstacles(pose: Sequence[float], observations: Sequence[ObstacleLike],
                    cfg: DOVSConfig) -> list[ModelObstacle]:
    """Transform observed obstacles to the robot frame and classify them (§2.3 of the spec).

    Slower than ``static_speed_threshold``: a static disc; |omega| above
    ``circular_omega_threshold``: circular, unless its turning radius is <= R, when it is a
    static disc of radius |rho| + R around its turning centre; otherwise linear. Obstacles
    farther than ``neighbourhood`` (if set) are dropped. Negative speeds are turned into a
    forward motion with the heading reversed.
    """
    out: list[ModelObstacle] = []
    for o in observations:
        x, y, th = (float(a) for a in to_robot_frame(pose, o.x, o.y, o.theta))
        v, w = float(o.v), float(o.omega)
        if v < 0.0:
            v, th = -v, th + math.pi
        R = cfg.inflated_radius(float(o.radius))
        if cfg.neighbourhood is not None and math.hypot(x, y) - R > cfg.neighbourhood:
            continue
        if v < cfg.static_speed_threshold or v <= 0.0:
            out.append(ModelObstacle(o.name, "static", x, y, th, v, w, R))
        elif abs(w) > cfg.circular_omega_threshold:
            rho = v / w
            if abs(rho) <= R:
                cx, cy = x - rho * math.sin(th), y + rho * math.cos(th)
                out.append(ModelObstacle(o.name, "static", cx, cy, th, v, w, R + abs(rho)))
            else:
                out.append(ModelObstacle(o.name, "circular", x, y, th, v, w, R))
        else:
            out.append(ModelObstacle(o.name, "linear", x, y, th, v, 0.0, R))
    return out


# --------------------------------------------------------------------------------------------
# Closed-form band crossings
# --------------------------------------------------------------------------------------------
def _cos_band(gamma: np.ndarray, c_lo: np.ndarray, c_hi: np.ndarray,
              phi_max: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sub-intervals of phi in [0, phi_max] where c_lo <= cos(phi - gamma) <= c_hi.

    All inputs shape (n,). Returns (phi_a, phi_b), shape (n, m), NaN where there is none.
    Adjacent pieces are not merged (a finer split is still exact for the model).
    """
    g = (gamma + math.pi) % TWO_PI - math.pi
    kmax = int(math.ceil(float(np.max(phi_max, initial=0.0)) / TWO_PI)) + 1
    ks = TWO_PI * np.arange(-1, kmax + 1, dtype=float)
    cols = [np.zeros((len(g), 1)), phi_max[:, None]]
    for c in (c_lo, c_hi):
        ok = np.abs(c) < 1.0
        a = np.arccos(np.clip(c, -1.0, 1.0))
        for sg in (1.0, -1.0):
            r = (g + sg * a)[:, None] + ks[None, :]
            good = ok[:, None] & (r > 0.0) & (r < phi_max[:, None])
            cols.append(np.where(good, r, np.inf))
    b = np.sort(np.concatenate(cols, axis=1), axis=1)
    a0, a1 = b[:, :-1], b[:, 1:]
    seg = np.isfinite(a1) & (a1 > a0)
    with np.errstate(invalid="ignore"):
        cm = np.cos(0.5 * (a0 + a1) - g[:, None])
    inside = seg & (cm >= c_lo[:, None]) & (cm <= c_hi[:, None])
    keep = np.any(inside, axis=0)
    pa = np.where(inside, a0, np.nan)[:, keep]
    pb = np.where(inside, a1, np.nan)[:, keep]
    return pa, pb


def _sin_range(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) of sin over [a, b] (elementwise, a <= b; NaN propagates)."""
    sa, sb = np.sin(a), np.sin(b)
    with np.errstate(invalid="ignore"):
        has_max = np.floor((b - 0.5 * math.pi) / TWO_PI) >= np.ceil((a - 0.5 * math.pi) / TWO_PI)
        has_min = np.floor((b + 0.5 * math.pi) / TWO_PI) >= np.ceil((a + 0.5 * math.pi) / TWO_PI)
    return np.where(has_min, -1.0, np.minimum(sa, sb)), np.where(has_max, 1.0, np.maximum(sa, sb))


@dataclass
class _Rays:
    """Per-ray working arrays (mirrored so that the curvature is positive)."""

    kappa: np.ndarray      # signed curvature as given [1/m]
    sgn: np.ndarray        # -1 where kappa < 0 (scene mirrored across the x-axis), else +1
    k: np.ndarray          # |kappa| clipped below at KAPPA_MIN [1/m]
    v_max: np.ndarray      # VS speed bound on the ray [m/s]
    s_max: np.ndarray      # examined arc length [m]
    margin: np.ndarray     # radius margin for clipped curvatures [m]

    @property
    def phi_max(self) -> np.ndarray:
        return self.k * self.s_max


def _make_rays(kappa: np.ndarray, cfg: DOVSConfig) -> _Rays:
    kappa = np.asarray(kappa, dtype=float).reshape(-1)
    vmax = ray_v_max(kappa, cfg)
    s_max = vmax * cfg.time_horizon_s
    ak = np.abs(kappa)
    k = np.maximum(ak, KAPPA_MIN)
    margin = np.where(ak < KAPPA_MIN, 0.5 * (KAPPA_MIN - ak) * s_max ** 2 + 1e-12, 0.0)
    sgn = np.where(kappa < 0.0, -1.0, 1.0)
    return _Rays(kappa, sgn, k, vmax, s_max, margin)


def _window_to_speeds(s_a: np.ndarray, s_b: np.ndarray, t_in: np.ndarray, t_out: np.ndarray,
                      valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forbidden speed interval [s_a / t_out, s_b / t_in] of a stretch occupied in [t_in, t_out]."""
    with np.errstate(divide="ignore", invalid="ignore"):
        lo = np.where(valid, s_a / t_out, np.nan)
        hi = np.where(valid, np.where(t_in > 0.0, s_b / t_in, np.inf), np.nan)
    return lo, hi


def _linear_intervals(rays: _Rays, ob: ModelObstacle, cfg: DOVSConfig) -> tuple[np.ndarray, np.ndarray]:
    k = rays.k
    y, th = rays.sgn * ob.y, rays.sgn * ob.theta
    R = ob.radius + rays.margin
    st, ct = np.sin(th), np.cos(th)
    eta_o = -st * ob.x + ct * y           # n . p_o, n = (-sin th, cos th)
    xi_o = ct * ob.x + st * y             # u . p_o, u = (cos th, sin th)
    # eta(phi) = (cos th - cos(phi - th)) / k - eta_o must lie in [-R, R].
    pa, pb = _cos_band(th, ct - k * (eta_o + R), ct - k * (eta_o - R), rays.phi_max)
    if pa.shape[1] == 0:
        return pa, pb
    thc, kc, Rc = th[:, None], k[:, None], R[:, None]
    smin, smax = _sin_range(pa - thc, pb - thc)
    # xi(phi) = (sin th + sin(phi - th)) / k - xi_o, exact extremes over the stretch.
    xi_min = (st[:, None] + smin) / kc - xi_o[:, None]
    xi_max = (st[:, None] + smax) / kc - xi_o[:, None]
    t_in = np.maximum(xi_min - Rc, 0.0) / ob.v
    t_out = (xi_max + Rc) / ob.v
    valid = np.isfinite(pa) & (t_out > 0.0) & (t_in <= cfg.time_horizon_s)
    return _window_to_speeds(pa / kc, pb / kc, t_in, t_out, valid)


def _circle_geometry(rays: _Rays, cx: np.ndarray, cy: np.ndarray, r_in: np.ndarray | float | None,
                     r_out: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Stretches of each ray's arc inside the annulus r_in <= |p - c| <= r_out (c per ray);
    ``r_in`` None means a disc."""
    k = rays.k
    r = 1.0 / k
    H = np.hypot(cx, cy - r)                  # distance from c to the arc's centre (0, r)
    gamma = np.arctan2(-cx, cy - r)
    base = (r - cy) + 0.5 * (cx * cx + cy * cy) * k
    # |P(phi) - c|^2 / (2 r) = base + H cos(phi - gamma)
    deg = H < 1e-12
    Hs = np.where(deg, 1.0, H)
    c_hi = (0.5 * np.square(r_out) * k - base) / Hs
    if r_in is None:
        c_lo = np.full_like(c_hi, -2.0)
        r_in = 0.0
    else:
        c_lo = (0.5 * np.square(r_in) * k - base) / Hs
    d_const = np.where(deg, r, 0.0)
    inside_const = (d_const >= r_in) & (d_const <= r_out)
    c_lo = np.where(deg, np.where(inside_const, -2.0, 2.0), c_lo)
    c_hi = np.where(deg, np.where(inside_const, 2.0, 2.0), c_hi)
    return _cos_band(gamma, c_lo, c_hi, rays.phi_max)


def _circular_intervals(rays: _Rays, ob: ModelObstacle, cfg: DOVSConfig) -> tuple[np.ndarray, np.ndarray]:
    k = rays.k
    y, th, w = rays.sgn * ob.y, rays.sgn * ob.theta, rays.sgn * ob.omega
    rho_s = ob.v / w
    rho = abs(ob.v / ob.omega)
    cx = ob.x - rho_s * np.sin(th)
    cy = y + rho_s * np.cos(th)
    R = ob.radius + rays.margin
    pa, pb = _circle_geometry(rays, cx, cy, rho - R, rho + R)
    m = pa.shape[1]
    if m == 0:
        return pa, pb
    r = 1.0 / k
    H = np.hypot(cx, cy - r)
    # Samples: stretch ends, uniform points (consecutive samples < one revolution apart) and the
    # extremes of the polar angle about c (where the arc is tangent to a ray from c).
    n_rev = int(math.ceil(float(np.nanmax(pb - pa)) / TWO_PI)) if np.any(np.isfinite(pa)) else 0
    u = np.linspace(0.0, 1.0, 2 + 2 * n_rev)
    phis = [pa[:, :, None] + (pb - pa)[:, :, None] * u[None, None, :]]
    outside = r <= H
    zeta = np.arctan2(cx, cy - r)
    ac = np.arccos(np.clip(-r / np.where(H > 0, H, 1.0), -1.0, 1.0))
    jmax = int(math.ceil(float(np.max(rays.phi_max)) / TWO_PI)) + 1
    for j in range(-1, jmax + 1):
        for sg in (1.0, -1.0):
            c = (-zeta + sg * ac + TWO_PI * j)[:, None]
            good = outside[:, None] & (c > pa) & (c < pb)
            phis.append(np.where(good, c, pa)[:, :, None])
    ph = np.sort(np.concatenate(phis, axis=2), axis=2)
    px, py = arc_points(k[:, None, None], ph / k[:, None, None])
    ang = np.arctan2(py - cy[:, None, None], px - cx[:, None, None])
    d = np.diff(ang, axis=2)
    # Angle about an interior point increases monotonically on a CCW arc; seen from an exterior
    # point it stays within less than pi.
    d = np.where(outside[:, None, None], (d + math.pi) % TWO_PI - math.pi, d % TWO_PI)
    unwrapped = ang[:, :, :1] + np.concatenate([np.zeros_like(d[:, :, :1]), np.cumsum(d, axis=2)], axis=2)
    psi0 = np.arctan2(y - cy, ob.x - cx)
    sw = np.sign(w)[:, None, None]
    delta_ang = sw * (unwrapped - psi0[:, None, None])
    dmin = np.min(delta_ang, axis=2)
    dmax = np.max(delta_ang, axis=2)
    half = np.arcsin(np.minimum(1.0, R / rho))[:, None]
    a0 = dmin - half
    b0 = dmax + half
    with np.errstate(invalid="ignore"):
        shift = TWO_PI * np.ceil(-b0 / TWO_PI)
    a0, b0 = a0 + shift, b0 + shift
    W = abs(ob.omega)
    n_pass = int(math.ceil(W * cfg.time_horizon_s / TWO_PI)) + 1
    los, his = [], []
    for p in range(n_pass):
        t_in = np.maximum(a0 + TWO_PI * p, 0.0) / W
        t_out = (b0 + TWO_PI * p) / W
        valid = np.isfinite(pa) & (t_out > 0.0) & (t_in <= cfg.time_horizon_s)
        lo, hi = _window_to_speeds(pa / k[:, None], pb / k[:, None], t_in, t_out, valid)
        los.append(lo)
        his.append(hi)
    return np.concatenate(los, axis=1), np.concatenate(his, axis=1)


def _static_disc_contact(rays: _Rays, ob: ModelObstacle) -> np.ndarray:
    """Arc length [m] to the first contact with a static disc (inf if none within s_max)."""
    y = rays.sgn * ob.y
    R = ob.radius + rays.margin
    cx = np.full_like(rays.k, ob.x)
    pa, _ = _circle_geometry(rays, cx, y, None, R)
    if pa.shape[1] == 0:
        return np.full_like(rays.k, np.inf)
    first = np.nanmin(np.where(np.isfinite(pa), pa, np.inf), axis=1)
    return first / rays.k


def _origin_threat(ob: ModelObstacle, cfg: DOVSConfig) -> bool:
    """Whether a robot standing still at the origin is reached within the horizon."""
    Th = cfg.time_horizon_s
    if ob.kind == "static":
        return False
    R = ob.radius
    if ob.kind == "linear":
        st, ct = math.sin(ob.theta), math.cos(ob.theta)
        eta = -(-st * ob.x + ct * ob.y)
        xi = -(ct * ob.x + st * ob.y)
        return abs(eta) <= R and xi + R >= 0.0 and (xi - R) / ob.v <= Th
    rho_s = ob.v / ob.omega
    rho = abs(rho_s)
    cx, cy = ob.x - rho_s * math.sin(ob.theta), ob.y + rho_s * math.cos(ob.theta)
    d = math.hypot(cx, cy)
    if not (rho - R <= d <= rho + R):
        return False
    half = math.asin(min(1.0, R / rho))
    delta = math.copysign(1.0, ob.omega) * (math.atan2(-cy, -cx) - math.atan2(ob.y - cy, ob.x - cx))
    b0 = delta + half
    b0 += TWO_PI * math.ceil(-b0 / TWO_PI)
    a0 = b0 - 2.0 * half
    return max(a0, 0.0) / abs(ob.omega) <= Th


# --------------------------------------------------------------------------------------------
# Static map
# --------------------------------------------------------------------------------------------
class StaticMap:
    """The known static obstacles, for the braking rule (world frame).

    Args:
        shapes: Static circles and polygons.
        bounds: Arena (xmin, ymin, xmax, ymax) [m] (walls), or None.
        cfg: Parameters (clearance kept, D_safe).
    """

    def __init__(self, shapes: Sequence[Shape], bounds: Sequence[float] | None,
                 cfg: DOVSConfig) -> None:
        self.shapes = tuple(shapes)
        self.bounds = None if bounds is None else tuple(float(b) for b in bounds)
        self.cfg = cfg
        self._single = [ObstacleSet([s]) for s in self.shapes]
        self._walls = ObstacleSet([], bounds=self.bounds) if self.bounds is not None else None
        self._cache: dict[tuple[int, ...], ObstacleSet] = {}

    def active_set(self, xy: Sequence[float]) -> tuple[tuple[int, ...], ObstacleSet | None]:
        """Indices of the shapes within D_safe of the robot (-1 = walls) and their set."""
        rc, dsafe = self.cfg.static_clearance, self.cfg.effective_static_range
        idx = [i for i, o in enumerate(self._single) if o.clearance(xy) - rc <= dsafe]
        walls = self._walls is not None and self._walls.clearance(xy) - rc <= dsafe
        key = tuple(idx) + ((-1,) if walls else ())
        if not key:
            return key, None
        if key not in self._cache:
            self._cache[key] = ObstacleSet([self.shapes[i] for i in idx],
                                           bounds=self.bounds if walls else None)
        return key, self._cache[key]

    def first_contact(self, pose: Sequence[float], kappa: np.ndarray, s_limit: np.ndarray,
                      max_iter: int = 60, tol: float = 1e-4) -> np.ndarray:
        """Arc length [m] to first contact along each ray, by sphere tracing.

        The clearance is 1-Lipschitz along the arc, so advancing by the current clearance never
        steps past a contact: the result is a lower bound on the true s_hit (exact to ``tol``
        when converged); inf where no contact occurs before ``s_limit``.
        """
        kappa = np.asarray(kappa, dtype=float)
        out = np.full(kappa.shape, np.inf)
        _, oset = self.active_set(pose[:2])
        if oset is None:
            return out
        rc = self.cfg.static_clearance
        s = np.zeros_like(kappa)
        active = np.ones(kappa.shape, dtype=bool)
        for _ in range(max_iter):
            idx = np.nonzero(active)[0]
            if len(idx) == 0:
                break
            px, py = arc_points(kappa[idx], s[idx])
            wx, wy, _ = to_world_frame(pose, px, py)
            c = oset.clearances(np.column_stack([wx, wy])) - rc
            hit = c <= tol
            out[idx[hit]] = s[idx[hit]]
            s[idx] += np.maximum(c, 0.0)
            active[idx[hit]] = False
            active[idx[~hit & (s[idx] > s_limit[idx])]] = False
        out[active] = s[active]
        return out


# --------------------------------------------------------------------------------------------
# The model of one control period
# --------------------------------------------------------------------------------------------
@dataclass
class RayIntervals:
    """Forbidden speed intervals on a batch of rays, clipped to the velocity space.

    Attributes:
        kappa: Curvature of each ray [1/m], shape (n,).
        v_max: VS speed bound on each ray [m/s], shape (n,).
        lo, hi: Closed intervals [lo, hi] [m/s], shape (n, m); NaN where a column is empty.
        owner: Source of each column, shape (m,): the obstacle's index in ``DOVSModel.obstacles``,
            or -1 for the static map.
    """

    kappa: np.ndarray
    v_max: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    owner: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def merged(self, merge: str = "hull") -> tuple[np.ndarray, np.ndarray]:
        """Per-ray hull (n, 1) or the intervals themselves (n, m) for "union"."""
        if merge == "union" or self.lo.shape[1] == 0:
            return self.lo, self.hi
        with np.errstate(all="ignore"):
            any_ = np.any(~np.isnan(self.lo), axis=1)
            lo = np.where(any_, np.min(np.where(np.isnan(self.lo), np.inf, self.lo), axis=1), np.nan)
            hi = np.where(any_, np.max(np.where(np.isnan(self.hi), -np.inf, self.hi), axis=1), np.nan)
        return lo[:, None], hi[:, None]

    def contains(self, v: np.ndarray, merge: str = "hull") -> np.ndarray:
        """Boolean (n,): speed ``v[i]`` lies in a forbidden interval of ray i."""
        lo, hi = self.merged(merge)
        v = np.asarray(v, dtype=float)[:, None]
        with np.errstate(invalid="ignore"):
            return np.any((lo <= v) & (v <= hi), axis=1)


class DOVSModel:
    """The DOVS of one control period: which (v, w) commands lead to a collision.

    Args:
        obstacles: Moving obstacles in the robot frame (:func:`model_obstacles`).
        cfg: Parameters.
        static_map: Known static obstacles (braking rule), or None.
        pose: The robot's world pose (x, y, theta), needed with ``static_map``.
    """

    def __init__(self, obstacles: Sequence[ModelObstacle], cfg: DOVSConfig,
                 static_map: StaticMap | None = None, pose: Sequence[float] | None = None) -> None:
        self.obstacles = list(obstacles)
        self.cfg = cfg
        self.static_map = static_map
        self.pose = None if pose is None else tuple(float(p) for p in pose)
        if static_map is not None and self.pose is None:
            raise ValueError("DOVSModel: a static map needs the robot pose")
        self.origin_threat = any(_origin_threat(o, cfg) for o in self.obstacles)

    def intervals(self, kappa: np.ndarray, include_static: bool = True) -> RayIntervals:
        """Forbidden intervals of every source on the rays ``kappa`` [1/m]."""
        cfg = self.cfg
        rays = _make_rays(kappa, cfg)
        n = len(rays.k)
        los, his, owners = [], [], []
        for i, ob in enumerate(self.obstacles):
            if ob.kind == "linear":
                lo, hi = _linear_intervals(rays, ob, cfg)
            elif ob.kind == "circular":
                lo, hi = _circular_intervals(rays, ob, cfg)
            else:
                if not include_static or math.hypot(ob.x, ob.y) - ob.radius > cfg.effective_static_range:
                    continue
                s_hit = _static_disc_contact(rays, ob)
                lo = braking_speed(s_hit, rays.kappa, cfg)[:, None]
                hi = np.where(np.isfinite(s_hit), np.inf, np.nan)[:, None]
                lo = np.where(np.isfinite(s_hit)[:, None], lo, np.nan)
            los.append(lo)
            his.append(hi)
            owners.extend([i] * lo.shape[1])
        if include_static and self.static_map is not None and self.pose is not None:
            reach = cfg.d_safe + rays.v_max ** 2 / (2.0 * ray_deceleration(rays.kappa, cfg)) + 1e-6
            s_hit = self.static_map.first_contact(self.pose, rays.kappa, np.minimum(reach, rays.s_max))
            fin = np.isfinite(s_hit)
            los.append(np.where(fin, braking_speed(s_hit, rays.kappa, cfg), np.nan)[:, None])
            his.append(np.where(fin, np.inf, np.nan)[:, None])
            owners.append(-1)
        lo = np.concatenate(los, axis=1) if los else np.zeros((n, 0))
        hi = np.concatenate(his, axis=1) if his else np.zeros((n, 0))
        # Clip to the VS: an interval starting above the ray's speed bound is empty; one that
        # reaches it is left open above (speeds beyond the bound are inadmissible anyway, and
        # this keeps commands on the VS border, up to rounding, inside it).
        vm = rays.v_max[:, None]
        with np.errstate(invalid="ignore"):
            empty = ~(lo <= vm * (1.0 + 1e-12))
            hi = np.where(hi >= vm, np.inf, hi)
        lo = np.where(empty, np.nan, lo)
        hi = np.where(empty, np.nan, hi)
        return RayIntervals(rays.kappa, rays.v_max, lo, hi, np.asarray(owners, dtype=int))

    def forbidden(self, v: np.ndarray, omega: np.ndarray, merge: str | None = None) -> np.ndarray:
        """Boolean mask: command (v [m/s], omega [rad/s]) is in the DOVS.

        Each command with v > 0 is evaluated on its own ray kappa = omega / v. A command with
        v = 0 (rotation in place) is forbidden iff a moving obstacle will reach the standing
        robot within the horizon.
        """
        merge = merge or self.cfg.merge
        v = np.asarray(v, dtype=float).reshape(-1)
        w = np.asarray(omega, dtype=float).reshape(-1)
        out = np.full(v.shape, self.origin_threat, dtype=bool)
        mv = v > V_EPS
        if np.any(mv):
            iv = self.intervals(w[mv] / v[mv])
            out[mv] = iv.contains(v[mv], merge)
        return out

    def forbidden_by_source(self, v: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, list[str]]:
        """Per-source masks (n, n_sources) and source names, for pictures (no merging)."""
        v = np.asarray(v, dtype=float).reshape(-1)
        w = np.asarray(omega, dtype=float).reshape(-1)
        names = [o.name for o in self.obstacles] + (["static map"] if self.static_map else [])
        out = np.zeros((len(v), len(names)), dtype=bool)
        mv = v > V_EPS
        if np.any(mv):
            iv = self.intervals(w[mv] / v[mv])
            vv = v[mv][:, None]
            with np.errstate(invalid="ignore"):
                hit = (iv.lo <= vv) & (vv <= iv.hi)
            for j in range(len(names)):
                src = j if j < len(self.obstacles) else -1
                cols = iv.owner == src
                if np.any(cols):
                    out[np.nonzero(mv)[0], j] = np.any(hit[:, cols], axis=1)
        for j, o in enumerate(self.obstacles):
            if _origin_threat(o, self.cfg):
                out[~mv, j] = True
        return out, names
