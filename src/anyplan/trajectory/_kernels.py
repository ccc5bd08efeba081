"""Numba kernels of the trajectory layer: planar cubic splines and their evaluation.

A planar piecewise cubic is stored as breakpoints ``x`` (P+1,) and coefficients ``c`` (P, 4, 2)
in ascending powers of (u - x[i]) on piece i. Piece lookup follows scipy's ``PPoly``: u belongs to
the piece i with x[i] <= u < x[i+1]; u below x[0] or at/after x[-1] extrapolates the first/last
piece.

The interpolating C2 cubic (:func:`cubic_spline`) is solved in Hermite form: the unknowns are the
slopes m_j at the breakpoints; C2 continuity at an interior breakpoint j reads
``h_j m_{j-1} + 2 (h_{j-1} + h_j) m_j + h_{j-1} m_{j+1} = 3 (h_j d_{j-1} + h_{j-1} d_j)`` with
h the piece lengths and d the chord slopes (de Boor, "A Practical Guide to Splines", ch. IV). The
system is strictly diagonally dominant, so elimination without pivoting (Thomas) is stable.

With ``extra`` (a start curvature besides the start tangent) the spline gets one more breakpoint
e in the first interval whose value y_e is unknown; the prescribed r''(x_0) gives
``y_e = y_0 + h_0^2 r''_0 / 6 + 2 h_0 r'_0 / 3 + h_0 m_1 / 3``, affine in m_1, so the system stays
tridiagonal (and dominant because h_0 <= h_1). It is the same C2 piecewise cubic as the B-spline
with knots (x_0 x4, e, x_1, ..., x_{n-2}, x_{n-1} x4) that ``scipy.interpolate.make_interp_spline``
would build.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Gauss-Legendre nodes/weights on [0, 1] (5 points: exact for polynomials of degree 9).
_X, _W = np.polynomial.legendre.leggauss(5)
GL_X = 0.5 * (_X + 1.0)
GL_W = 0.5 * _W


@njit(cache=True)
def cubic_spline(x: np.ndarray, y: np.ndarray, mode: int, tan: np.ndarray, nrm: np.ndarray,
                 extra: float) -> tuple[np.ndarray, np.ndarray]:
    """Interpolating C2 cubic through (x[i], y[i]) (y: (n, 2)); returns (breakpoints, coeffs).

    ``mode`` 0: natural at both ends; 1: r'(x0) = tan, natural end; 2: r'(x0) = tan,
    r''(x0) = nrm, natural end, with an extra breakpoint at ``extra`` in (x[0], x[1]).
    """
    n = x.shape[0]
    if mode == 2:
        npt = n + 1
        xi = np.empty(npt)
        xi[0] = x[0]
        xi[1] = extra
        xi[2:] = x[1:]
        yi = np.empty((npt, 2))
        yi[0] = y[0]
        yi[1] = 0.0
        yi[2:] = y[1:]
    else:
        npt = n
        xi = x.copy()
        yi = y.copy()
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
def _piece(x: np.ndarray, u: float) -> int:
    i = np.searchsorted(x, u, side="right") - 1
    if i < 0:
        return 0
    if i > x.shape[0] - 2:
        return x.shape[0] - 2
    return i


@njit(cache=True)
def pp_eval(x: np.ndarray, c: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
    """Derivative ``nu`` (0-3) of the curve at ``u`` (N,); shape (N, 2)."""
    n = u.shape[0]
    out = np.empty((n, 2))
    for k in range(n):
        i = _piece(x, u[k])
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
    for k in range(n):
        uk = min(max(u[k], 0.0), xe)
        i = _piece(x, uk)
        t = uk - x[i]
        for d in range(2):
            c1, c2, c3 = c[i, 1, d], c[i, 2, d], c[i, 3, d]
            d1[k, d] = c1 + t * (2.0 * c2 + 3.0 * t * c3)
            d2[k, d] = 2.0 * c2 + 6.0 * t * c3
            d3[k, d] = 6.0 * c3
    return d1, d2, d3


@njit(cache=True)
def _curv_at(c: np.ndarray, i: int, t: float) -> tuple[float, float, float, float]:
    """(kappa, dkappa/ds, heading, speed) on piece i at offset t."""
    ax = c[i, 1, 0] + t * (2.0 * c[i, 2, 0] + 3.0 * t * c[i, 3, 0])
    ay = c[i, 1, 1] + t * (2.0 * c[i, 2, 1] + 3.0 * t * c[i, 3, 1])
    bx = 2.0 * c[i, 2, 0] + 6.0 * t * c[i, 3, 0]
    by = 2.0 * c[i, 2, 1] + 6.0 * t * c[i, 3, 1]
    gx = 6.0 * c[i, 3, 0]
    gy = 6.0 * c[i, 3, 1]
    sp = math.hypot(ax, ay)
    cr = ax * by - ay * bx
    sp3 = sp ** 3
    kappa = cr / sp3
    dcr = ax * gy - ay * gx
    dot = ax * bx + ay * by
    dk_du = dcr / sp3 - 3.0 * cr * dot / sp ** 5
    return kappa, dk_du / sp, math.atan2(ay, ax), sp


@njit(cache=True)
def pp_curvature(x: np.ndarray, c: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed curvature and dkappa/ds at ``u`` clipped to [0, x[-1]]."""
    n = u.shape[0]
    k = np.empty(n)
    dk = np.empty(n)
    xe = x[-1]
    for j in range(n):
        uj = min(max(u[j], 0.0), xe)
        i = _piece(x, uj)
        k[j], dk[j], _, _ = _curv_at(c, i, uj - x[i])
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
    for j in range(m):
        a = u[j]
        h = u[j + 1] - a
        km = 0.0
        dmx = 0.0
        for f in range(fr.shape[0]):
            uj = min(max(a + h * fr[f], 0.0), xe)
            i = _piece(x, uj)
            k, dk, _, _ = _curv_at(c, i, uj - x[i])
            km = max(km, abs(k))
            dmx = max(dmx, abs(dk))
        kk[j] = km
        dd[j] = dmx
    if with_ends:
        prev = 0.0
        for j in range(m + 1):
            uj = min(max(u[j], 0.0), xe)
            i = _piece(x, uj)
            k, _, _, _ = _curv_at(c, i, uj - x[i])
            k = abs(k)
            if j > 0:
                kk[j - 1] = max(kk[j - 1], max(prev, k))
            prev = k
    return kk, dd


@njit(cache=True)
def gl_lengths(x: np.ndarray, c: np.ndarray, u: np.ndarray, nsub: int, gx: np.ndarray,
               gw: np.ndarray) -> np.ndarray:
    """Arc length of each interval [u_k, u_{k+1}]: ``nsub`` equal parts x 5-point Gauss."""
    m = u.shape[0] - 1
    out = np.empty(m)
    for k in range(m):
        h = (u[k + 1] - u[k]) / nsub
        acc = 0.0
        for q in range(nsub):
            for g in range(gx.shape[0]):
                uu = u[k] + h * (q + gx[g])
                i = _piece(x, uu)
                t = uu - x[i]
                ax = c[i, 1, 0] + t * (2.0 * c[i, 2, 0] + 3.0 * t * c[i, 3, 0])
                ay = c[i, 1, 1] + t * (2.0 * c[i, 2, 1] + 3.0 * t * c[i, 3, 1])
                acc += math.hypot(ax, ay) * gw[g]
        out[k] = acc * h
    return out


@njit(cache=True)
def hermite_u_of_s(s_grid: np.ndarray, u_grid: np.ndarray, dus: np.ndarray, length: float,
                   s: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation of u(s) on the grid with slopes ``dus`` (s clipped)."""
    n = s.shape[0]
    out = np.empty(n)
    last = s_grid.shape[0] - 2
    for j in range(n):
        sj = min(max(s[j], 0.0), length)
        i = np.searchsorted(s_grid, sj, side="right") - 1
        i = min(max(i, 0), last)
        h = s_grid[i + 1] - s_grid[i]
        xx = (sj - s_grid[i]) / h
        m0 = dus[i] * h
        m1 = dus[i + 1] * h
        x2 = xx * xx
        x3 = x2 * xx
        out[j] = ((2 * x3 - 3 * x2 + 1) * u_grid[i] + (x3 - 2 * x2 + xx) * m0
                  + (-2 * x3 + 3 * x2) * u_grid[i + 1] + (x3 - x2) * m1)
    return out
