"""Compiled evaluation of a planar piecewise cubic (the curve of :mod:`.curve`).

The curve is stored as breakpoints ``x`` (P+1,) and coefficients ``c`` (P, 4, 2) in ascending
powers of (u - x[i]) on piece i. Piece lookup follows scipy's ``PPoly``: u belongs to the piece i
with x[i] <= u < x[i+1]; u below x[0] or at/after x[-1] extrapolates the first/last piece.
These kernels take the polynomial as the two arrays (x, c): they are also called on the
intermediate fits inside :mod:`._fit`, and from Python once per query, where numba types a
NamedTuple argument about ten times slower than two arrays (~3 us a call).
See ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

if TYPE_CHECKING:
    from anyplan.trajectory.spline.arrays import CurveArrays


@njit(cache=True)
def piece(x: np.ndarray, u: float) -> int:
    i = np.searchsorted(x, u, side="right") - 1
    if i < 0:
        return 0
    if i > x.shape[0] - 2:
        return x.shape[0] - 2
    return int(i)


@njit(cache=True)
def locate(x: np.ndarray, u: float, i: int) -> int:
    """:func:`piece` with a guess ``i`` (the previous piece of an increasing sequence)."""
    last = x.shape[0] - 2
    if 0 <= i <= last and (i == 0 or u >= x[i]):
        if i == last or u < x[i + 1]:
            return i
        j = i + 1
        if u >= x[j] and (j == last or u < x[j + 1]):
            return j
    return piece(x, u)


@njit(cache=True)
def pp_eval(x: np.ndarray, c: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
    """Derivative ``nu`` (0-3) of the curve at ``u`` (N,); shape (N, 2)."""
    n = u.shape[0]
    out = np.empty((n, 2))
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for k in range(n):
        i = locate(x, u[k], i)
        t = u[k] - x[i]
        for d in range(2):
            c0, c1, c2, c3 = c[i, 0, d], c[i, 1, d], c[i, 2, d], c[i, 3, d]
            if nu == 0:
                out[k, d] = c0 + t * (c1 + t * (c2 + t * c3))
            elif nu == 1:
                out[k, d] = c1 + t * (2.0 * c2 + 3.0 * t * c3)
            elif nu == 2:
                out[k, d] = 2.0 * c2 + 6.0 * t * c3
            else:
                out[k, d] = 6.0 * c3
    return out


@njit(cache=True)
def pp_eval_clipped(x: np.ndarray, c: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
    """:func:`pp_eval` with ``u`` clipped to [0, x[-1]]."""
    uu = np.minimum(np.maximum(u, 0.0), x[-1])
    return pp_eval(x, c, uu, nu)


@njit(cache=True)
def pp_derivs(x: np.ndarray, c: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(r', r'', r''') at ``u`` clipped to [0, x[-1]], each (N, 2)."""
    n = u.shape[0]
    d1 = np.empty((n, 2))
    d2 = np.empty((n, 2))
    d3 = np.empty((n, 2))
    xe = x[-1]
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for k in range(n):
        uk = min(max(u[k], 0.0), xe)
        i = locate(x, uk, i)
        t = uk - x[i]
        for d in range(2):
            c1, c2, c3 = c[i, 1, d], c[i, 2, d], c[i, 3, d]
            d1[k, d] = c1 + t * (2.0 * c2 + 3.0 * t * c3)
            d2[k, d] = 2.0 * c2 + 6.0 * t * c3
            d3[k, d] = 6.0 * c3
    return d1, d2, d3


@njit(cache=True)
def curv_at(c: np.ndarray, i: int, t: float) -> tuple[float, float, float, float, float]:
    """(kappa, dkappa/ds, speed |r'|, r'_x, r'_y) on piece i at offset t."""
    ax = c[i, 1, 0] + t * (2.0 * c[i, 2, 0] + 3.0 * t * c[i, 3, 0])
    ay = c[i, 1, 1] + t * (2.0 * c[i, 2, 1] + 3.0 * t * c[i, 3, 1])
    bx = 2.0 * c[i, 2, 0] + 6.0 * t * c[i, 3, 0]
    by = 2.0 * c[i, 2, 1] + 6.0 * t * c[i, 3, 1]
    gx = 6.0 * c[i, 3, 0]
    gy = 6.0 * c[i, 3, 1]
    sp2 = ax * ax + ay * ay
    sp = math.sqrt(sp2)
    sp3 = sp2 * sp
    cr = ax * by - ay * bx
    kappa = cr / sp3
    dcr = ax * gy - ay * gx
    dot = ax * bx + ay * by
    dk_du = dcr / sp3 - 3.0 * cr * dot / (sp3 * sp2)
    return kappa, dk_du / sp, sp, ax, ay


@njit(cache=True)
def pp_curvature(x: np.ndarray, c: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed curvature and dkappa/ds at ``u`` clipped to [0, x[-1]]."""
    n = u.shape[0]
    k = np.empty(n)
    dk = np.empty(n)
    xe = x[-1]
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(n):
        uj = min(max(u[j], 0.0), xe)
        i = locate(x, uj, i)
        k[j], dk[j], _, _, _ = curv_at(c, i, uj - x[i])
    return k, dk


@njit(cache=True)
def abs_curvature_max(x: np.ndarray, c: np.ndarray, u: np.ndarray, fr: np.ndarray,
                      with_ends: bool) -> tuple[np.ndarray, np.ndarray]:
    """Per interval [u_i, u_{i+1}]: max |kappa| and max |dkappa/ds| at u_i + fr (u_{i+1} - u_i);
    with ``with_ends`` |kappa| at both grid points exactly also counts."""
    m = u.shape[0] - 1
    kk = np.empty(m)
    dd = np.empty(m)
    xe = x[-1]
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(m):
        a = u[j]
        h = u[j + 1] - a
        km = 0.0
        dmx = 0.0
        for f in range(fr.shape[0]):
            uj = min(max(a + h * fr[f], 0.0), xe)
            i = locate(x, uj, i)
            k, dk, _, _, _ = curv_at(c, i, uj - x[i])
            km = max(km, abs(k))
            dmx = max(dmx, abs(dk))
        kk[j] = km
        dd[j] = dmx
    if with_ends:
        prev = 0.0
        i = np.int64(0)  # not a literal: one specialisation of the callee
        for j in range(m + 1):
            uj = min(max(u[j], 0.0), xe)
            i = locate(x, uj, i)
            k, _, _, _, _ = curv_at(c, i, uj - x[i])
            k = abs(k)
            if j > 0:
                kk[j - 1] = max(kk[j - 1], max(prev, k))
            prev = k
    return kk, dd


@njit(cache=True)
def regular(cv: CurveArrays, min_speed: float) -> bool:
    """The test of ``SmoothCurve.is_regular`` on the curve's grid ``u_grid`` (arc lengths
    ``s_grid``)."""
    x, c, u, s = cv.x, cv.c, cv.u_grid, cv.s_grid
    n = u.shape[0]
    xe = x[-1]
    th_prev = 0.0
    k_prev = 0.0
    ok = True
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(n):
        ip = i
        uj = min(max(u[j], 0.0), xe)
        i = locate(x, uj, i)
        k, _, sp, ax, ay = curv_at(c, i, uj - x[i])
        th = math.atan2(ay, ax)
        if sp < min_speed:
            return False
        if j > 0:
            um = 0.5 * (u[j - 1] + u[j])
            um = min(max(um, 0.0), xe)
            im = locate(x, um, ip)
            km, _, spm, _, _ = curv_at(c, im, um - x[im])
            if spm < min_speed:
                return False
            d = th - th_prev
            dth = abs(math.atan2(math.sin(d), math.cos(d)))
            kb = max(abs(k_prev), abs(k), abs(km))
            if not dth <= 1.5 * kb * (s[j] - s[j - 1]) + 1e-6:
                ok = False
        th_prev = th
        k_prev = k
    return ok
