"""Compiled sampling of driving along the curve with a speed profile (:class:`CurveSegment`).

The profile is piecewise constant acceleration on its grid (s, v, t); at a time tau the arc
length s(tau) is mapped to the curve parameter u(s) (:mod:`._arclength`) and the curve gives
position, heading and curvature kappa, so omega = kappa v.
See ``docs/motion.md`` ("``plan_motion`` and ``Trajectory``").
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from anyplan.trajectory.spline._arclength import hermite_one
from anyplan.trajectory.spline._pp import curv_at, locate

if TYPE_CHECKING:
    from anyplan.trajectory.spline.arrays import CurveArrays, ProfileArrays


@njit(cache=True)
def speed_bound(cv: CurveArrays, prof: ProfileArrays, nsub: int) -> float:
    """Max over profile intervals of (largest chord rate |dr|/ds over ``nsub`` equal parts)
    times the interval's larger end speed."""
    x, c, s_grid, u_grid, dus = cv.x, cv.c, cv.s_grid, cv.u_grid, cv.dus
    length = s_grid[-1]
    s, v = prof.s, prof.v
    best = 0.0
    xe = x[-1]
    i = np.int64(0)  # not a literal: one specialisation of the callee
    ih = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(s.shape[0] - 1):
        h = s[j + 1] - s[j]
        px = 0.0
        py = 0.0
        rmax = 0.0
        for q in range(nsub + 1):
            sq = s[j] + h * (q / nsub)
            uq, ih = hermite_one(s_grid, u_grid, dus, length, sq, ih)
            uq = min(max(uq, 0.0), xe)
            i = locate(x, uq, i)
            t = uq - x[i]
            qx = c[i, 0, 0] + t * (c[i, 1, 0] + t * (c[i, 2, 0] + t * c[i, 3, 0]))
            qy = c[i, 0, 1] + t * (c[i, 1, 1] + t * (c[i, 2, 1] + t * c[i, 3, 1]))
            if q > 0:
                rmax = max(rmax, math.hypot(qx - px, qy - py) / (h / nsub))
            px = qx
            py = qy
        best = max(best, rmax * max(v[j], v[j + 1]))
    return best


@njit(cache=True)
def curve_sample(x: np.ndarray, c: np.ndarray, s_grid: np.ndarray, u_grid: np.ndarray,
                 dus: np.ndarray, ps: np.ndarray, pv: np.ndarray, pt: np.ndarray,
                 tau: np.ndarray, full: bool) -> np.ndarray:
    """Reference (x, y, theta, v, omega) at profile times ``tau`` (clamped); shape (5, N), or
    (x, y) alone, shape (2, N), when not ``full``.

    The fields of the curve's and the profile's records, spread: called once per sample query,
    where a record argument would cost more than the evaluation (see :mod:`._pp`). Each
    lookup starts from the previous sample's interval (:func:`locate`: the same interval as a
    binary search; increasing times, the common case, rarely search at all).
    """
    length = s_grid[-1]
    n = tau.shape[0]
    out = np.empty((5 if full else 2, n))
    t_end = pt[-1]
    xe = x[-1]
    i = np.int64(0)  # not a literal: one specialisation of the callee
    ih = np.int64(0)
    p = np.int64(0)
    for j in range(n):
        tj = min(max(tau[j], 0.0), t_end)
        i = locate(pt, tj, i)
        a = (pv[i + 1] ** 2 - pv[i] ** 2) / (2.0 * (ps[i + 1] - ps[i]))
        dt = tj - pt[i]
        vj = max(pv[i] + a * dt, 0.0)
        sj = min(ps[i] + pv[i] * dt + 0.5 * a * dt * dt, ps[i + 1])
        uj, ih = hermite_one(s_grid, u_grid, dus, length, sj, ih)
        uj = min(max(uj, 0.0), xe)
        p = locate(x, uj, p)
        t = uj - x[p]
        out[0, j] = c[p, 0, 0] + t * (c[p, 1, 0] + t * (c[p, 2, 0] + t * c[p, 3, 0]))
        out[1, j] = c[p, 0, 1] + t * (c[p, 1, 1] + t * (c[p, 2, 1] + t * c[p, 3, 1]))
        if full:
            k, _, _, ax, ay = curv_at(c, p, t)
            out[2, j] = math.atan2(ay, ax)
            out[3, j] = vj
            out[4, j] = k * vj
    return out
