"""Compiled arc length of the piecewise cubic: Gauss-Legendre lengths and the inverse u(s).

Lengths of parameter intervals by ``nsub`` equal parts times 5-point Gauss-Legendre quadrature
(exact for polynomials of degree 9); u(s) by cubic Hermite interpolation of the tabulated
(s_grid, u_grid) with the exact slopes du/ds = 1 / |r'(u)| (error O(ds^4)).
See ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from anyplan.trajectory.spline._pp import locate

# Gauss-Legendre nodes/weights on [0, 1] (5 points: exact for polynomials of degree 9).
_X, _W = np.polynomial.legendre.leggauss(5)
GL_X = 0.5 * (_X + 1.0)
GL_W = 0.5 * _W


@njit(cache=True)
def cumsum0(a: np.ndarray) -> np.ndarray:
    out = np.empty(a.shape[0] + 1)
    out[0] = 0.0
    acc = 0.0
    for j in range(a.shape[0]):
        acc += a[j]
        out[j + 1] = acc
    return out


@njit(cache=True)
def gl_lengths(x: np.ndarray, c: np.ndarray, u: np.ndarray, nsub: int, gx: np.ndarray,
               gw: np.ndarray) -> np.ndarray:
    """Arc length of each interval [u_k, u_{k+1}]: ``nsub`` equal parts x 5-point Gauss."""
    m = u.shape[0] - 1
    out = np.empty(m)
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for k in range(m):
        h = (u[k + 1] - u[k]) / nsub
        acc = 0.0
        for q in range(nsub):
            for g in range(gx.shape[0]):
                uu = u[k] + h * (q + gx[g])
                i = locate(x, uu, i)
                t = uu - x[i]
                ax = c[i, 1, 0] + t * (2.0 * c[i, 2, 0] + 3.0 * t * c[i, 3, 0])
                ay = c[i, 1, 1] + t * (2.0 * c[i, 2, 1] + 3.0 * t * c[i, 3, 1])
                acc += math.sqrt(ax * ax + ay * ay) * gw[g]
        out[k] = acc * h
    return out


@njit(cache=True)
def subdivide(u: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Cut each interval [u[k], u[k+1]] into n[k] equal parts; all breakpoints, in order."""
    out = np.empty(n.sum() + 1)
    q = 0
    for k in range(n.shape[0]):
        a = u[k]
        w = u[k + 1] - a
        nk = n[k]
        for j in range(nk):
            out[q] = a + w * j / nk
            q += 1
    out[q] = u[-1]
    return out


@njit(cache=True)
def hermite_one(s_grid: np.ndarray, u_grid: np.ndarray, dus: np.ndarray, length: float,
                 s: float, hint: int) -> tuple[float, int]:
    """u(s) as in :func:`hermite_u_of_s` and the grid interval used (``hint``: a guess)."""
    sj = min(max(s, 0.0), length)
    i = locate(s_grid, sj, hint)
    h = s_grid[i + 1] - s_grid[i]
    xx = (sj - s_grid[i]) / h
    m0 = dus[i] * h
    m1 = dus[i + 1] * h
    x2 = xx * xx
    x3 = x2 * xx
    return ((2 * x3 - 3 * x2 + 1) * u_grid[i] + (x3 - 2 * x2 + xx) * m0
            + (-2 * x3 + 3 * x2) * u_grid[i + 1] + (x3 - x2) * m1), i


@njit(cache=True)
def hermite_u_of_s(s_grid: np.ndarray, u_grid: np.ndarray, dus: np.ndarray, length: float,
                   s: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation of u(s) on the grid with slopes ``dus`` (s clipped)."""
    n = s.shape[0]
    out = np.empty(n)
    ih = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(n):
        out[j], ih = hermite_one(s_grid, u_grid, dus, length, s[j], ih)
    return out
