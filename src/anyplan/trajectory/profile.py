"""Time-optimal speed profile along a fixed curve under the robot's limits (forward/backward passes).

Limits of a differential-drive robot along a curve with curvature kappa(s): v <= v_max,
|omega| = v |kappa| <= omega_max, |dv/dt| <= a_max and |d omega/dt| = |kappa' v^2 + kappa dv/dt|
<= alpha_max (kappa' = dkappa/ds). With x = v^2 as the state the profile is piecewise constant
acceleration on a grid in s; bounds K_i, K'_i of |kappa|, |kappa'| on each interval make every
limit hold everywhere between grid points, not only at them. The scheme is the classic numerical
integration for time-optimal path parameterisation (Bobrow, Dubowsky & Gibson 1985; Shin & McKay
1985; Pham 2014): a maximum velocity curve, a backward pass braking as late as possible from
rest at the goal, a forward pass accelerating as hard as possible from the current speed.
The time lower bound (:func:`time_lower_bound`) ignores curvature.
Derivation and measurements: ``docs/motion.md`` ("Speed profile").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from anyplan.trajectory.spline import ProfileArrays, SmoothCurve
from anyplan.world.robot import RobotSpec

__all__ = ["ProfileArrays", "SpeedProfile", "time_parameterize", "time_lower_bound"]

#: Relative inflation of the sampled curvature bounds on each grid interval.
KAPPA_INFLATION = 1.02
#: Sub-samples per grid interval used to bound |kappa| and |kappa'|.
SUBSAMPLES = 6
_FR = np.linspace(0.0, 1.0, SUBSAMPLES + 1)
# keep the right end inside the same cubic piece: kappa' jumps at the knots
_FR[-1] = 1.0 - 1e-9
_FR[0] = 1e-9


@dataclass
class SpeedProfile:
    """Speed along a curve: piecewise constant acceleration on the grid ``s``.

    Attributes:
        s: Arc-length grid [m] (M,).
        u: Curve parameter at the grid (M,).
        v: Speed [m/s] at the grid (M,), v[-1] == 0.
        t: Time [s] since the start of the profile at the grid (M,).
        kappa_max: Bound on |kappa| [1/m] on each interval (M-1,).
        dkappa_max: Bound on |dkappa/ds| [1/m^2] on each interval (M-1,).
        feasible: False if the requested start speed was above what the curve allows (the
            profile then starts from the highest admissible speed instead).
        v_start_requested: The requested start speed [m/s].
    """

    s: np.ndarray
    u: np.ndarray
    v: np.ndarray
    t: np.ndarray
    kappa_max: np.ndarray
    dkappa_max: np.ndarray
    feasible: bool
    v_start_requested: float

    @property
    def duration(self) -> float:
        """Total time [s]."""
        return float(self.t[-1])

    @property
    def arrays(self) -> ProfileArrays:
        """(s, v, t) as one :class:`ProfileArrays` record (for compiled kernels)."""
        return ProfileArrays(np.ascontiguousarray(self.s, dtype=float),
                             np.ascontiguousarray(self.v, dtype=float),
                             np.ascontiguousarray(self.t, dtype=float))

    @property
    def accel(self) -> np.ndarray:
        """Constant acceleration [m/s^2] on each interval (M-1,)."""
        return (self.v[1:] ** 2 - self.v[:-1] ** 2) / (2.0 * np.diff(self.s))

    def at_time(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s [m], v [m/s], a [m/s^2]) at times ``tau`` [s] since the profile's start (clamped)."""
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.t[-1])
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.t) - 2)
        a = self.accel[i]
        dt = tau - self.t[i]
        v = np.maximum(self.v[i] + a * dt, 0.0)
        s = np.minimum(self.s[i] + self.v[i] * dt + 0.5 * a * dt * dt, self.s[i + 1])
        return s, v, a


def _interval_bounds(curve: SmoothCurve, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds on |kappa| and |kappa'| over each interval [u_i, u_{i+1}] (never across a knot)."""
    # Sub-samples at fractions fr of each interval; endpoint values, exactly at the grid points,
    # also count for |kappa| (kappa is continuous).
    k, dk = curve.curvature_bounds(u, _FR, True)
    return k * KAPPA_INFLATION + 1e-9, dk * KAPPA_INFLATION + 1e-9


@njit(cache=True)
def _step(x_from: float, ds: float, k: float, dk: float, a2: float, al: float) -> float:
    """Largest |dx/ds| on an interval from its lower end value ``x_from``, moving up to
    ``x_from + |d| ds``: K' (x_from + |d| ds) + K |d| / 2 <= alpha and |d| <= 2 a."""
    num = al - dk * x_from
    if num <= 0.0:
        return 0.0
    return min(a2, num / (dk * ds + 0.5 * k))


@njit(cache=True)
def _passes(ds: np.ndarray, mvc: np.ndarray, kmax: np.ndarray, dkmax: np.ndarray, a2: float,
            al: float, x0: float) -> tuple[np.ndarray, np.ndarray]:
    """Backward pass from rest at the end, then forward pass from ``x0``; returns (x, back)."""
    n = len(mvc)
    back = np.empty(n)
    back[n - 1] = 0.0
    for i in range(n - 2, -1, -1):
        # Braking into node i+1 from node i: x_i = x_{i+1} + |d| ds; the interval maximum is x_i.
        back[i] = min(mvc[i], back[i + 1] + _step(back[i + 1], ds[i], kmax[i], dkmax[i], a2, al) * ds[i])
    x = np.empty(n)
    x[0] = min(x0, back[0])
    for i in range(n - 1):
        # Accelerating from x_i. If the result is clipped by back[i+1] < x_i, braking from x_i to
        # back[i+1] is admissible: back[i] >= x_i was built from back[i+1] with the largest
        # admissible |d|, and the constraint is monotone in both x_i and |d|.
        x[i + 1] = min(back[i + 1], x[i] + _step(x[i], ds[i], kmax[i], dkmax[i], a2, al) * ds[i])
    return x, back


@njit(cache=True)
def _profile(s: np.ndarray, kmax: np.ndarray, dkmax: np.ndarray, v_max: float, omega_max: float,
             a2: float, al: float, x0: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Speeds and times on the grid ``s`` (and the backward pass's start value, in v^2)."""
    n = s.shape[0]
    ds = np.empty(n - 1)
    for i in range(n - 1):
        ds[i] = s[i + 1] - s[i]
    # Maximum velocity curve (in x = v^2) per interval, then per node (min of both sides).
    xi = np.empty(n - 1)
    for i in range(n - 1):
        xi[i] = min(min(v_max ** 2, (omega_max / kmax[i]) ** 2), al / dkmax[i])
    mvc = np.empty(n)
    mvc[0] = xi[0]
    mvc[n - 1] = xi[n - 2]
    for i in range(1, n - 1):
        mvc[i] = min(xi[i - 1], xi[i])
    x, back = _passes(ds, mvc, kmax, dkmax, a2, al, x0)
    v = np.empty(n)
    for i in range(n):
        v[i] = math.sqrt(max(x[i], 0.0))
    t = np.empty(n)
    t[0] = 0.0
    acc = 0.0
    for i in range(n - 1):
        vs = v[i] + v[i + 1]
        acc += 2.0 * ds[i] / vs if vs > 0.0 else np.inf
        t[i + 1] = acc
    return v, t, back[0]


def time_parameterize(curve: SmoothCurve, spec: RobotSpec, v_start: float = 0.0) -> SpeedProfile:
    """Time-optimal (on the grid) speed profile from ``v_start`` to rest at the curve's end.

    Args:
        curve: The geometric path.
        spec: Robot limits (v_max, omega_max, a_max, alpha_max).
        v_start: Current forward speed [m/s] (negative values are treated as 0).

    Returns:
        A :class:`SpeedProfile` that satisfies all four limits everywhere along the curve.
    """
    s, u = curve.s_grid, curve.u_grid
    kmax, dkmax = _interval_bounds(curve, u)
    v0 = max(float(v_start), 0.0)
    v, t, back0 = _profile(s, kmax, dkmax, float(spec.v_max), float(spec.omega_max),
                           2.0 * spec.a_max, float(spec.alpha_max), v0 * v0)
    feasible = v0 * v0 <= back0 * (1.0 + 1e-9) + 1e-12
    return SpeedProfile(s=s.copy(), u=u.copy(), v=v, t=t, kappa_max=kmax, dkappa_max=dkmax,
                        feasible=bool(feasible), v_start_requested=float(v_start))


def time_lower_bound(length: float, spec: RobotSpec, v_start: float = 0.0) -> float:
    """Least time [s] to cover ``length`` [m] from speed ``v_start`` to rest, ignoring curvature.

    Trapezoidal (or triangular) speed under v_max and a_max. For a path long enough to reach
    v_max from rest this is ``length / v_max + v_max / a_max``.
    """
    if length <= 0.0:
        return 0.0
    a, vm = spec.a_max, spec.v_max
    v0 = min(max(v_start, 0.0), vm)
    d_acc = (vm * vm - v0 * v0) / (2.0 * a)
    d_dec = vm * vm / (2.0 * a)
    if d_acc + d_dec <= length:
        return (vm - v0) / a + (length - d_acc - d_dec) / vm + vm / a
    # Triangle: peak vp with (vp^2 - v0^2) / 2a + vp^2 / 2a = length.
    vp2 = a * length + 0.5 * v0 * v0
    if vp2 < v0 * v0:  # cannot stop in time: the bound is the braking time itself
        return v0 / a
    vp = math.sqrt(vp2)
    return (vp - v0) / a + vp / a
