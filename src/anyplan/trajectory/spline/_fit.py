"""Compiled fitting of the smooth curve: the C2 interpolating cubic and its arc-length refit.

:func:`cubic_spline` solves the C2 interpolating cubic in Hermite form (slopes m_j at the
breakpoints; a strictly diagonally dominant tridiagonal system, Thomas elimination; de Boor,
"A Practical Guide to Splines", ch. IV), optionally with a clamped start tangent and start
curvature (one extra breakpoint). :func:`fit_curve` runs the whole construction of
:class:`~anyplan.trajectory.spline.SmoothCurve` and is the only producer of its
:class:`~anyplan.trajectory.spline.CurveArrays`.
Notation: breakpoints x (P+1,), coefficients c (P, 4, 2) as in :mod:`._pp`.
The derivation is in ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from anyplan.trajectory.spline._arclength import cumsum0, gl_lengths, subdivide
from anyplan.trajectory.spline._pp import abs_curvature_max, pp_eval


@njit(cache=True)
def cubic_spline(x: np.ndarray, y: np.ndarray, mode: int, tan: np.ndarray, nrm: np.ndarray,
                 extra: float) -> tuple[np.ndarray, np.ndarray]:
    """Interpolating C2 cubic through (x[i], y[i]) (y: (n, 2)); returns (breakpoints, coeffs).

    ``mode`` 0: natural at both ends; 1: r'(x0) = tan, natural end; 2: r'(x0) = tan,
    r''(x0) = nrm, natural end, with an extra breakpoint at ``extra`` in (x[0], x[1]).
    """
    n = x.shape[0]
    off = 1 if mode == 2 else 0
    npt = n + off
    xi = np.empty(npt)
    yi = np.zeros((npt, 2))
    for j in range(n):
        q = j + off if j > 0 else 0
        xi[q] = x[j]
        yi[q, 0] = y[j, 0]
        yi[q, 1] = y[j, 1]
    if mode == 2:
        xi[1] = extra
    P = npt - 1
    h = np.empty(P)
    for j in range(P):
        h[j] = xi[j + 1] - xi[j]
    # chord slopes d_j = dc_j + dm_j * m_1 (dm non-zero only next to the extra breakpoint)
    dc = np.empty((P, 2))
    dm = np.zeros(P)
    ya = np.zeros(2)
    bb = 0.0
    if mode == 2:
        h0 = h[0]
        for d in range(2):
            ya[d] = yi[0, d] + h0 * h0 * nrm[d] / 6.0 + 2.0 * h0 * tan[d] / 3.0
        bb = h0 / 3.0
        for d in range(2):
            dc[0, d] = (ya[d] - yi[0, d]) / h0
            dc[1, d] = (yi[2, d] - ya[d]) / h[1]
        dm[0] = bb / h0
        dm[1] = -bb / h[1]
        for j in range(2, P):
            for d in range(2):
                dc[j, d] = (yi[j + 1, d] - yi[j, d]) / h[j]
    else:
        for j in range(P):
            for d in range(2):
                dc[j, d] = (yi[j + 1, d] - yi[j, d]) / h[j]
    # tridiagonal system: lo[j] m_{j-1} + di[j] m_j + up[j] m_{j+1} = rhs[j]
    lo = np.zeros(npt)
    di = np.zeros(npt)
    up = np.zeros(npt)
    rhs = np.zeros((npt, 2))
    if mode == 0:
        # r''(x0) = 0: 2 m_0 + m_1 = 3 d_0
        di[0] = 2.0
        up[0] = 1.0
        for d in range(2):
            rhs[0, d] = 3.0 * dc[0, d]
    else:
        di[0] = 1.0
        for d in range(2):
            rhs[0, d] = tan[d]
    for j in range(1, P):
        lo[j] = h[j]
        di[j] = 2.0 * (h[j - 1] + h[j])
        up[j] = h[j - 1]
        for d in range(2):
            rhs[j, d] = 3.0 * (h[j] * dc[j - 1, d] + h[j - 1] * dc[j, d])
        c1 = 3.0 * (h[j] * dm[j - 1] + h[j - 1] * dm[j])
        if c1 != 0.0:  # the m_1 term: diagonal of row 1, sub-diagonal of row 2
            if j == 1:
                di[j] -= c1
            else:
                lo[j] -= c1
    # natural end r''(x_P) = 0: m_{P-1} + 2 m_P = 3 d_{P-1}
    lo[P] = 1.0
    di[P] = 2.0
    for d in range(2):
        rhs[P, d] = 3.0 * dc[P - 1, d]
    if dm[P - 1] != 0.0:
        lo[P] -= 3.0 * dm[P - 1]
    # Thomas elimination
    for j in range(1, npt):
        w = lo[j] / di[j - 1]
        di[j] -= w * up[j - 1]
        for d in range(2):
            rhs[j, d] -= w * rhs[j - 1, d]
    m = np.empty((npt, 2))
    for d in range(2):
        m[P, d] = rhs[P, d] / di[P]
    for j in range(P - 1, -1, -1):
        for d in range(2):
            m[j, d] = (rhs[j, d] - up[j] * m[j + 1, d]) / di[j]
    if mode == 2:
        for d in range(2):
            yi[1, d] = ya[d] + bb * m[1, d]
    c = np.empty((P, 4, 2))
    for j in range(P):
        hj = h[j]
        for d in range(2):
            s = (yi[j + 1, d] - yi[j, d]) / hj
            t = (m[j, d] + m[j + 1, d] - 2.0 * s) / hj
            c[j, 0, d] = yi[j, d]
            c[j, 1, d] = m[j, d]
            c[j, 2, d] = (s - m[j, d]) / hj - t
            c[j, 3, d] = t / hj
    return xi, c


@njit(cache=True)
def fit(x: np.ndarray, y: np.ndarray, mode: int, tan: np.ndarray, nrm: np.ndarray,
         start_knot: float) -> tuple[np.ndarray, np.ndarray]:
    extra = x[0] + min(0.5 * (x[1] - x[0]), start_knot)
    return cubic_spline(x, y, mode, tan, nrm, extra)


@njit(cache=True)
def build_curve(pts: np.ndarray, mode: int, tan: np.ndarray, nrm: np.ndarray, start_knot: float,
                reparam_iters: int, resample_step: float, grid_step: float, max_turn: float,
                fr: np.ndarray, gx: np.ndarray, gw: np.ndarray):  # noqa: ANN201
    """The construction of ``SmoothCurve`` (see its docstring): returns breakpoints, coefficients,
    point_u, u_grid, s_grid and du/ds on the grid."""
    n = pts.shape[0]
    chords = np.empty(n - 1)
    for j in range(n - 1):
        chords[j] = math.hypot(pts[j + 1, 0] - pts[j, 0], pts[j + 1, 1] - pts[j, 1])
    u = cumsum0(chords)
    for _ in range(max(reparam_iters, 0)):
        bx, bc = fit(u, pts, mode, tan, nrm, start_knot)
        u = cumsum0(gl_lengths(bx, bc, u, np.int64(4), gx, gw))
    bx, bc = fit(u, pts, mode, tan, nrm, start_knot)
    n_us = np.empty(n - 1, dtype=np.int64)
    for j in range(n - 1):
        n_us[j] = max(4, int(math.ceil((u[j + 1] - u[j]) / resample_step)))
    us = subdivide(u, n_us)
    s_of_us = cumsum0(gl_lengths(bx, bc, us, np.int64(4), gx, gw))
    point_u = np.empty(n)
    ii = np.searchsorted(us, u)
    for j in range(n):
        point_u[j] = s_of_us[ii[j]]
    x, c = fit(s_of_us, pp_eval(bx, bc, us, np.int64(0)), mode, tan, nrm, start_knot)
    k_est, _ = abs_curvature_max(x, c, x, fr, np.bool_(False))
    m = x.shape[0] - 1
    n_parts = np.empty(m, dtype=np.int64)
    for j in range(m):
        du = x[j + 1] - x[j]
        p = max(math.ceil(du / grid_step), math.ceil(k_est[j] * du / max_turn))
        if not p >= 1.0:  # also NaN
            p = 1.0 if p < 1.0 else 400.0
        n_parts[j] = int(min(p, 400.0))
    u_grid = subdivide(x, n_parts)
    s_grid = cumsum0(gl_lengths(x, c, u_grid, np.int64(1), gx, gw))
    d1 = pp_eval(x, c, u_grid, np.int64(1))
    dus = np.empty(u_grid.shape[0])
    for j in range(u_grid.shape[0]):
        dus[j] = 1.0 / math.hypot(d1[j, 0], d1[j, 1])
    return x, c, point_u, u_grid, s_grid, dus
