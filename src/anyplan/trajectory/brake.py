"""Braking to rest: v and omega decelerated at a_max and alpha_max from the current twist.

:class:`BrakeSegment` tabulates the position by midpoint integration with the exact heading
(step 2 ms, error O(dt^2 v omega) < 1e-6 m); heading and twist are exact. Its compiled
evaluation (:func:`brake_eval`) is beside it. :class:`SwerveSegment` ramps the twist to a target
instead (a fallback's arc entered without stopping), tabulated the same way. Notation: v0,
omega0 the twist at the start, theta0 the heading, t0 the absolute start time [s].
See ``docs/motion.md`` ("``plan_motion`` and ``Trajectory``").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from anyplan.trajectory.kinds import SegmentKind
from anyplan.trajectory.segment import Sample, Segment

__all__ = ["BrakeSegment", "SwerveSegment", "brake_eval"]


@njit(cache=True)
def brake_eval(tau: np.ndarray, t_end: float, v0: float, w0: float, theta0: float, a_max: float,
               alpha_max: float, grid: np.ndarray, gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    """(x, y, theta, v, omega) of braking at a_max and alpha_max, at ``tau`` clamped to
    [0, t_end]; the position is interpolated linearly in the tabulated (grid, gx, gy)."""
    n = tau.shape[0]
    out = np.empty((5, n))
    tv = abs(v0) / a_max
    tw = abs(w0) / alpha_max
    sv = math.copysign(a_max, v0)
    sw = math.copysign(alpha_max, w0)
    tt = np.empty(n)
    for j in range(n):
        t = min(max(tau[j], 0.0), t_end)
        tt[j] = t
        cv = min(t, tv)
        cw = min(t, tw)
        out[2, j] = theta0 + w0 * cw - 0.5 * sw * cw * cw
        out[3, j] = v0 - sv * cv
        out[4, j] = w0 - sw * cw
    # linear interpolation of the table, as numpy.interp computes it
    last = grid.shape[0] - 1
    for j in range(n):
        t = tt[j]
        if t >= grid[last]:
            out[0, j] = gx[last]
            out[1, j] = gy[last]
            continue
        i = max(np.searchsorted(grid, t, side="right") - 1, 0)
        if grid[i] == t:
            out[0, j] = gx[i]
            out[1, j] = gy[i]
            continue
        h = grid[i + 1] - grid[i]
        out[0, j] = (gx[i + 1] - gx[i]) / h * (t - grid[i]) + gx[i]
        out[1, j] = (gy[i + 1] - gy[i]) / h * (t - grid[i]) + gy[i]
    return out


class _RampSegment(Segment):
    """v and omega ramped at a_max and alpha_max from (``v0``, ``omega0``) to (``v1``,
    ``omega1``), then held, from absolute time ``t0`` for ``duration`` [s]. The position is
    tabulated by midpoint integration with the exact heading (step ``dt``, error
    O(dt^2 v omega)) and interpolated linearly in the table; heading and twist are exact."""

    def __init__(self, x: float, y: float, theta: float, v0: float, omega0: float, v1: float,
                 omega1: float, a_max: float, alpha_max: float, t0: float, duration: float,
                 dt: float = 0.002) -> None:
        self.v0, self.w0, self.v1, self.w1 = float(v0), float(omega0), float(v1), float(omega1)
        self.a, self.al, self.theta0, self.t0 = a_max, alpha_max, float(theta), float(t0)
        dur = max(float(duration), 0.0)
        self.t1 = self.t0 + dur
        n = max(2, math.ceil(dur / dt) + 1)
        self._tau = np.linspace(0.0, dur, n)
        tm = 0.5 * (self._tau[:-1] + self._tau[1:])
        _, _, thm, vm, _ = self._twist(tm)
        h = np.diff(self._tau)
        self._x = x + np.concatenate([[0.0], np.cumsum(vm * np.cos(thm) * h)])
        self._y = y + np.concatenate([[0.0], np.cumsum(vm * np.sin(thm) * h)])
        self.max_speed = max(abs(self.v0), abs(self.v1)) * 1.001
        self.length = float(np.sum(np.abs(vm) * h))

    def _twist(self, tau: np.ndarray) -> Sample:
        tau = np.asarray(tau, dtype=float)
        tv = abs(self.v1 - self.v0) / self.a
        tw = abs(self.w1 - self.w0) / self.al
        sv = math.copysign(self.a, self.v1 - self.v0)
        sw = math.copysign(self.al, self.w1 - self.w0)
        cv, cw = np.minimum(tau, tv), np.minimum(tau, tw)
        v = self.v0 + sv * cv
        w = self.w0 + sw * cw
        th = self.theta0 + self.w0 * cw + 0.5 * sw * cw * cw + self.w1 * np.maximum(tau - tw, 0.0)
        z = np.zeros(tau.shape)
        return z, z, th, v, w

    def path_points(self, step: float) -> np.ndarray:
        return np.column_stack([self._x, self._y])


class BrakeSegment(_RampSegment):
    """Braking to rest: v and omega go to zero at a_max and alpha_max, from time ``t0`` [s]."""

    kind = SegmentKind.BRAKE

    def __init__(self, x: float, y: float, theta: float, v0: float, omega0: float, a_max: float,
                 alpha_max: float, t0: float, dt: float = 0.002) -> None:
        super().__init__(x, y, theta, v0, omega0, 0.0, 0.0, a_max, alpha_max, t0,
                         max(abs(v0) / a_max, abs(omega0) / alpha_max), dt)

    def sample(self, t: np.ndarray) -> Sample:
        t = np.asarray(t, dtype=float)
        out = brake_eval(t.ravel() - self.t0, self.t1 - self.t0, self.v0,
                         self.w0, self.theta0, self.a, self.al, self._tau, self._x, self._y)
        return tuple(o.reshape(t.shape) for o in out)


class SwerveSegment(_RampSegment):
    """Swerving: v and omega ramp at a_max and alpha_max from (``v0``, ``omega0``) to a target
    twist (``v1``, ``omega1``) and then hold it, from ``t0`` for ``duration`` [s]: an arc of the
    unicycle entered without stopping first, tabulated as :class:`BrakeSegment`."""

    kind = SegmentKind.SWERVE

    def sample(self, t: np.ndarray) -> Sample:
        t = np.asarray(t, dtype=float)
        tau = np.clip(t - self.t0, 0.0, self.t1 - self.t0)
        _, _, th, v, w = self._twist(tau)
        return (np.interp(tau, self._tau, self._x), np.interp(tau, self._tau, self._y), th, v, w)

    def xy(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tau = np.clip(np.asarray(t, dtype=float) - self.t0, 0.0, self.t1 - self.t0)
        return np.interp(tau, self._tau, self._x), np.interp(tau, self._tau, self._y)
