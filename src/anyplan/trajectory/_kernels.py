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

from anyplan.geometry.collision import ObstacleArrays, segment_blocked_kernel, segment_clearance_kernel

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
def _piece(x: np.ndarray, u: float) -> int:
    i = np.searchsorted(x, u, side="right") - 1
    if i < 0:
        return 0
    if i > x.shape[0] - 2:
        return x.shape[0] - 2
    return i


@njit(cache=True)
def _locate(x: np.ndarray, u: float, i: int) -> int:
    """:func:`_piece` with a guess ``i`` (the previous piece of an increasing sequence)."""
    last = x.shape[0] - 2
    if 0 <= i <= last and (i == 0 or u >= x[i]):
        if i == last or u < x[i + 1]:
            return i
        j = i + 1
        if u >= x[j] and (j == last or u < x[j + 1]):
            return j
    return _piece(x, u)


@njit(cache=True)
def pp_eval(x: np.ndarray, c: np.ndarray, u: np.ndarray, nu: int) -> np.ndarray:
    """Derivative ``nu`` (0-3) of the curve at ``u`` (N,); shape (N, 2)."""
    n = u.shape[0]
    out = np.empty((n, 2))
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for k in range(n):
        i = _locate(x, u[k], i)
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
        i = _locate(x, uk, i)
        t = uk - x[i]
        for d in range(2):
            c1, c2, c3 = c[i, 1, d], c[i, 2, d], c[i, 3, d]
            d1[k, d] = c1 + t * (2.0 * c2 + 3.0 * t * c3)
            d2[k, d] = 2.0 * c2 + 6.0 * t * c3
            d3[k, d] = 6.0 * c3
    return d1, d2, d3


@njit(cache=True)
def _curv_at(c: np.ndarray, i: int, t: float) -> tuple[float, float, float, float, float]:
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
        i = _locate(x, uj, i)
        k[j], dk[j], _, _, _ = _curv_at(c, i, uj - x[i])
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
            i = _locate(x, uj, i)
            k, dk, _, _, _ = _curv_at(c, i, uj - x[i])
            km = max(km, abs(k))
            dmx = max(dmx, abs(dk))
        kk[j] = km
        dd[j] = dmx
    if with_ends:
        prev = 0.0
        i = np.int64(0)  # not a literal: one specialisation of the callee
        for j in range(m + 1):
            uj = min(max(u[j], 0.0), xe)
            i = _locate(x, uj, i)
            k, _, _, _, _ = _curv_at(c, i, uj - x[i])
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
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for k in range(m):
        h = (u[k + 1] - u[k]) / nsub
        acc = 0.0
        for q in range(nsub):
            for g in range(gx.shape[0]):
                uu = u[k] + h * (q + gx[g])
                i = _locate(x, uu, i)
                t = uu - x[i]
                ax = c[i, 1, 0] + t * (2.0 * c[i, 2, 0] + 3.0 * t * c[i, 3, 0])
                ay = c[i, 1, 1] + t * (2.0 * c[i, 2, 1] + 3.0 * t * c[i, 3, 1])
                acc += math.sqrt(ax * ax + ay * ay) * gw[g]
        out[k] = acc * h
    return out


@njit(cache=True)
def hermite_u_of_s(s_grid: np.ndarray, u_grid: np.ndarray, dus: np.ndarray, length: float,
                   s: np.ndarray) -> np.ndarray:
    """Cubic Hermite interpolation of u(s) on the grid with slopes ``dus`` (s clipped)."""
    n = s.shape[0]
    out = np.empty(n)
    ih = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(n):
        out[j], ih = _hermite_one(s_grid, u_grid, dus, length, s[j], ih)
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
def _chord_dev_one(x: np.ndarray, c: np.ndarray, a_u: float, b_u: float,
                   i: int) -> tuple[float, float, float, float, float, int]:
    """(r(a), r(b), M h^2 / 8) for one piece [a_u, b_u]; ``i``: piece guess for a_u (returned
    updated)."""
    xe = x[-1]
    a = min(max(a_u, 0.0), xe)
    b = min(max(b_u, 0.0), xe)
    bi = min(max(b_u - 1e-12 * max(1.0, abs(b_u)), 0.0), xe)
    i = _locate(x, a, i)
    ia = i
    t = a - x[i]
    pax = c[i, 0, 0] + t * (c[i, 1, 0] + t * (c[i, 2, 0] + t * c[i, 3, 0]))
    pay = c[i, 0, 1] + t * (c[i, 1, 1] + t * (c[i, 2, 1] + t * c[i, 3, 1]))
    m2 = math.hypot(2.0 * c[i, 2, 0] + 6.0 * t * c[i, 3, 0], 2.0 * c[i, 2, 1] + 6.0 * t * c[i, 3, 1])
    i = _locate(x, b, ia)
    t = b - x[i]
    pbx = c[i, 0, 0] + t * (c[i, 1, 0] + t * (c[i, 2, 0] + t * c[i, 3, 0]))
    pby = c[i, 0, 1] + t * (c[i, 1, 1] + t * (c[i, 2, 1] + t * c[i, 3, 1]))
    i = _locate(x, bi, ia)
    t = bi - x[i]
    m2b = math.hypot(2.0 * c[i, 2, 0] + 6.0 * t * c[i, 3, 0], 2.0 * c[i, 2, 1] + 6.0 * t * c[i, 3, 1])
    h = b_u - a_u
    return pax, pay, pbx, pby, max(m2, m2b) * h * h / 8.0, ia


@njit(cache=True)
def chord_deviation(x: np.ndarray, c: np.ndarray, a_u: np.ndarray,
                    b_u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For pieces [a_u, b_u] (within one cubic): end points (N, 2) each and the bound
    M h^2 / 8 on the curve's distance from its chord, M = max |r''| at both ends (r'' at b_u
    taken just inside the piece)."""
    n = a_u.shape[0]
    pa = np.empty((n, 2))
    pb = np.empty((n, 2))
    dev = np.empty(n)
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(n):
        pa[j, 0], pa[j, 1], pb[j, 0], pb[j, 1], dev[j], i = _chord_dev_one(x, c, a_u[j], b_u[j], i)
    return pa, pb, dev


@njit(cache=True)
def regular(x: np.ndarray, c: np.ndarray, u: np.ndarray, s: np.ndarray, min_speed: float) -> bool:
    """The test of ``SmoothCurve.is_regular`` on the grid ``u`` (arc lengths ``s``)."""
    n = u.shape[0]
    xe = x[-1]
    th_prev = 0.0
    k_prev = 0.0
    ok = True
    i = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(n):
        ip = i
        uj = min(max(u[j], 0.0), xe)
        i = _locate(x, uj, i)
        k, _, sp, ax, ay = _curv_at(c, i, uj - x[i])
        th = math.atan2(ay, ax)
        if sp < min_speed:
            return False
        if j > 0:
            um = 0.5 * (u[j - 1] + u[j])
            um = min(max(um, 0.0), xe)
            im = _locate(x, um, ip)
            km, _, spm, _, _ = _curv_at(c, im, um - x[im])
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


@njit(cache=True)
def _hermite_one(s_grid: np.ndarray, u_grid: np.ndarray, dus: np.ndarray, length: float,
                 s: float, hint: int) -> tuple[float, int]:
    """u(s) as in :func:`hermite_u_of_s` and the grid interval used (``hint``: a guess)."""
    sj = min(max(s, 0.0), length)
    i = _locate(s_grid, sj, hint)
    h = s_grid[i + 1] - s_grid[i]
    xx = (sj - s_grid[i]) / h
    m0 = dus[i] * h
    m1 = dus[i + 1] * h
    x2 = xx * xx
    x3 = x2 * xx
    return ((2 * x3 - 3 * x2 + 1) * u_grid[i] + (x3 - 2 * x2 + xx) * m0
            + (-2 * x3 + 3 * x2) * u_grid[i + 1] + (x3 - x2) * m1), i


@njit(cache=True)
def speed_bound(x: np.ndarray, c: np.ndarray, s_grid: np.ndarray, u_grid: np.ndarray,
                dus: np.ndarray, length: float, s: np.ndarray, v: np.ndarray, nsub: int) -> float:
    """max over profile intervals of (largest chord rate |dr|/ds over ``nsub`` equal parts)
    times the interval's larger end speed."""
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
            uq, ih = _hermite_one(s_grid, u_grid, dus, length, sq, ih)
            uq = min(max(uq, 0.0), xe)
            i = _locate(x, uq, i)
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
                 dus: np.ndarray, length: float, ps: np.ndarray, pv: np.ndarray, pt: np.ndarray,
                 tau: np.ndarray) -> np.ndarray:
    """Reference (x, y, theta, v, omega) at profile times ``tau`` (clamped); shape (5, N)."""
    n = tau.shape[0]
    out = np.empty((5, n))
    t_end = pt[-1]
    last = pt.shape[0] - 2
    xe = x[-1]
    for j in range(n):
        tj = min(max(tau[j], 0.0), t_end)
        i = np.searchsorted(pt, tj, side="right") - 1
        i = min(max(i, 0), last)
        a = (pv[i + 1] ** 2 - pv[i] ** 2) / (2.0 * (ps[i + 1] - ps[i]))
        dt = tj - pt[i]
        vj = max(pv[i] + a * dt, 0.0)
        sj = min(ps[i] + pv[i] * dt + 0.5 * a * dt * dt, ps[i + 1])
        uj, _ = _hermite_one(s_grid, u_grid, dus, length, sj, np.int64(0))
        uj = min(max(uj, 0.0), xe)
        p = _piece(x, uj)
        t = uj - x[p]
        out[0, j] = c[p, 0, 0] + t * (c[p, 1, 0] + t * (c[p, 2, 0] + t * c[p, 3, 0]))
        out[1, j] = c[p, 0, 1] + t * (c[p, 1, 1] + t * (c[p, 2, 1] + t * c[p, 3, 1]))
        k, _, _, ax, ay = _curv_at(c, p, t)
        out[2, j] = math.atan2(ay, ax)
        out[3, j] = vj
        out[4, j] = k * vj
    return out


@njit(cache=True)
def certify(x: np.ndarray, c: np.ndarray, u: np.ndarray, limit: float, radius: float,
            max_depth: int, obs: ObstacleArrays) -> tuple[np.ndarray, np.ndarray, float]:
    """Certified chord test of the pieces [u_j, u_{j+1}] with up to ``max_depth`` 4-way splits.

    A piece is certified when (exact chord clearance) - M h^2 / 8 >= ``limit``
    (:func:`chord_deviation`). Returns the midpoints and certified clearances of the pieces that
    still fail at ``max_depth`` (in order of u) and min(certified clearance) - ``radius`` over
    the certified pieces (inf if none). Before the last level only pass/fail matters, so the
    clearance query may stop early once it is known to be below the threshold (minus 1e-9 m,
    far beyond rounding, so pass/fail is exactly that of the exact clearance).
    """
    a_u = np.empty(u.shape[0] - 1)
    b_u = np.empty(u.shape[0] - 1)
    for j in range(u.shape[0] - 1):
        a_u[j] = u[j]
        b_u[j] = u[j + 1]
    margin = np.inf
    fail_u = np.zeros(0)
    fail_c = np.zeros(0)
    for depth in range(max_depth + 1):
        n = a_u.shape[0]
        if n == 0:
            break
        pa, pb, dev = chord_deviation(x, c, a_u, b_u)
        fail = np.zeros(n, dtype=np.bool_)
        clr = np.empty(n)
        nf = 0
        last = depth == max_depth
        for j in range(n):
            stop = -1.0 if last else limit + dev[j] - 1e-9
            cl = segment_clearance_kernel(pa[j, 0], pa[j, 1], pb[j, 0], pb[j, 1], obs, stop)
            if cl < stop:
                fail[j] = True
                nf += 1
                continue
            cj = cl - dev[j]
            clr[j] = cj
            if cj >= limit:
                margin = min(margin, cj - radius)
            else:
                fail[j] = True
                nf += 1
        if nf == 0:
            break
        if last:
            fail_u = np.empty(nf)
            fail_c = np.empty(nf)
            q = 0
            for j in range(n):
                if fail[j]:
                    fail_u[q] = 0.5 * (a_u[j] + b_u[j])
                    fail_c[q] = clr[j]
                    q += 1
            break
        na = np.empty(4 * nf)
        nb = np.empty(4 * nf)
        q = 0
        for j in range(n):
            if fail[j]:
                fa = a_u[j]
                w = b_u[j] - fa
                for p in range(4):
                    na[q + p] = fa + w * (p / 4.0)
                    nb[q + p] = fa + w * ((p + 1) / 4.0)
                q += 4
        a_u = na
        b_u = nb
    return fail_u, fail_c, margin


@njit(cache=True)
def worst_per_group(k: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For a non-decreasing ``k``: each distinct value and the index of the first minimum of ``v``
    among its entries."""
    n = k.shape[0]
    keys = np.empty(n, dtype=np.int64)
    idx = np.empty(n, dtype=np.int64)
    g = -1
    for j in range(n):
        if g < 0 or k[j] != keys[g]:
            g += 1
            keys[g] = k[j]
            idx[g] = j
        elif v[j] < v[idx[g]]:
            idx[g] = j
    return keys[:g + 1], idx[:g + 1]


@njit(cache=True)
def _cumsum0(a: np.ndarray) -> np.ndarray:
    out = np.empty(a.shape[0] + 1)
    out[0] = 0.0
    acc = 0.0
    for j in range(a.shape[0]):
        acc += a[j]
        out[j + 1] = acc
    return out


@njit(cache=True)
def _fit(x: np.ndarray, y: np.ndarray, mode: int, tan: np.ndarray, nrm: np.ndarray,
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
    u = _cumsum0(chords)
    for _ in range(max(reparam_iters, 0)):
        bx, bc = _fit(u, pts, mode, tan, nrm, start_knot)
        u = _cumsum0(gl_lengths(bx, bc, u, np.int64(4), gx, gw))
    bx, bc = _fit(u, pts, mode, tan, nrm, start_knot)
    n_us = np.empty(n - 1, dtype=np.int64)
    for j in range(n - 1):
        n_us[j] = max(4, int(math.ceil((u[j + 1] - u[j]) / resample_step)))
    us = subdivide(u, n_us)
    s_of_us = _cumsum0(gl_lengths(bx, bc, us, np.int64(4), gx, gw))
    point_u = np.empty(n)
    ii = np.searchsorted(us, u)
    for j in range(n):
        point_u[j] = s_of_us[ii[j]]
    x, c = _fit(s_of_us, pp_eval(bx, bc, us, np.int64(0)), mode, tan, nrm, start_knot)
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
    s_grid = _cumsum0(gl_lengths(x, c, u_grid, np.int64(1), gx, gw))
    d1 = pp_eval(x, c, u_grid, np.int64(1))
    dus = np.empty(u_grid.shape[0])
    for j in range(u_grid.shape[0]):
        dus[j] = 1.0 / math.hypot(d1[j, 0], d1[j, 1])
    return x, c, point_u, u_grid, s_grid, dus


@njit(cache=True)
def clean_points(p: np.ndarray, tol: float, collinear_tol: float) -> np.ndarray:
    """The loop of ``spline.clean_path`` (p: (N >= 1, 2))."""
    n = p.shape[0]
    keep = np.empty((n, 2))
    keep[0, 0] = p[0, 0]
    keep[0, 1] = p[0, 1]
    nk = 1
    for j in range(1, n):
        if math.hypot(p[j, 0] - keep[nk - 1, 0], p[j, 1] - keep[nk - 1, 1]) > tol:
            keep[nk, 0] = p[j, 0]
            keep[nk, 1] = p[j, 1]
            nk += 1
    if nk > 1 and math.hypot(p[n - 1, 0] - keep[nk - 1, 0], p[n - 1, 1] - keep[nk - 1, 1]) > 0.0:
        keep[nk - 1, 0] = p[n - 1, 0]
        keep[nk - 1, 1] = p[n - 1, 1]
    out = np.empty((nk, 2))
    out[0, 0] = keep[0, 0]
    out[0, 1] = keep[0, 1]
    no = 1
    for i in range(1, nk - 1):
        abx = keep[i, 0] - out[no - 1, 0]
        aby = keep[i, 1] - out[no - 1, 1]
        acx = keep[i + 1, 0] - out[no - 1, 0]
        acy = keep[i + 1, 1] - out[no - 1, 1]
        lac = math.hypot(acx, acy)
        cross = abs(abx * acy - aby * acx) / max(lac, 1e-300)
        t = (abx * acx + aby * acy) / max(lac * lac, 1e-300)
        if cross < collinear_tol and 0.0 < t < 1.0:
            continue
        out[no, 0] = keep[i, 0]
        out[no, 1] = keep[i, 1]
        no += 1
    if nk > 1:
        out[no, 0] = keep[nk - 1, 0]
        out[no, 1] = keep[nk - 1, 1]
        no += 1
    res = np.empty((no, 2))
    for j in range(no):
        res[j, 0] = out[j, 0]
        res[j, 1] = out[j, 1]
    return res


@njit(cache=True)
def shortcut_indices(p: np.ndarray, limit: float, obs: ObstacleArrays) -> np.ndarray:
    """Indices kept by ``spline.shortcut_path``: from each kept vertex, the farthest one whose
    straight segment has clearance >= ``limit`` (else the next vertex). Scanning from the far end
    with the query stopping early below ``limit`` gives exactly the pass/fail of the exact
    clearance."""
    n = p.shape[0]
    keep = np.empty(n, dtype=np.int64)
    keep[0] = 0
    nk = 1
    i = 0
    while i < n - 1:
        nxt = i + 1
        for j in range(n - 1, i + 1, -1):
            if not segment_blocked_kernel(p[i, 0], p[i, 1], p[j, 0], p[j, 1], obs, limit):
                nxt = j
                break
        keep[nk] = nxt
        nk += 1
        i = nxt
    res = np.empty(nk, dtype=np.int64)
    for j in range(nk):
        res[j] = keep[j]
    return res


@njit(cache=True)
def rotation_eval(tau: np.ndarray, theta0: float, omega0: float, durations: np.ndarray,
                  alphas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(heading, turn rate) of constant angular-acceleration phases at times ``tau`` (the last
    phase started by tau applies, its elapsed time clamped to its duration)."""
    n = tau.shape[0]
    th = np.empty(n)
    w = np.empty(n)
    for j in range(n):
        tj = tau[j]
        thj = theta0
        wj = omega0
        t0 = 0.0
        th0 = theta0
        w0 = omega0
        for k in range(durations.shape[0]):
            d = durations[k]
            a = alphas[k]
            if tj >= t0:
                dt = min(max(tj - t0, 0.0), d)
                thj = th0 + w0 * dt + 0.5 * a * dt * dt
                wj = w0 + a * dt
            th0 += w0 * d + 0.5 * a * d * d
            w0 += a * d
            t0 += d
        th[j] = thj
        w[j] = wj
    return th, w


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


@njit(cache=True)
def _argsort_stable(v: np.ndarray) -> np.ndarray:
    """Indices that sort ``v`` ascending, equal values in their original order (bottom-up
    merge sort; cheaper to compile than numpy's argsort)."""
    n = v.shape[0]
    idx = np.arange(n)
    tmp = np.empty(n, dtype=np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            i = lo
            j = mid
            q = lo
            while i < mid and j < hi:
                if v[idx[j]] < v[idx[i]]:
                    tmp[q] = idx[j]
                    j += 1
                else:
                    tmp[q] = idx[i]
                    i += 1
                q += 1
            while i < mid:
                tmp[q] = idx[i]
                i += 1
                q += 1
            while j < hi:
                tmp[q] = idx[j]
                j += 1
                q += 1
        idx, tmp = tmp, idx
        width *= 2
    return idx


@njit(cache=True)
def certify_worst(x: np.ndarray, c: np.ndarray, u: np.ndarray, point_u: np.ndarray, limit: float,
                  radius: float, max_depth: int,
                  obs: ObstacleArrays) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """:func:`certify` reduced to what the repair uses, by branch and bound.

    Returns, for each interpolation interval k (``point_u[k:k+2]``) that has a piece failing at
    ``max_depth``, the failing piece of least certified clearance, the first in u among equal
    ones: (k, its midpoint, its clearance), in order of k; and the margin, equal to
    :func:`certify`'s when nothing fails (nothing is pruned then).

    Bound: the curve on a piece P = [a, b] stays within dev(P) = M h^2 / 8 of P's chord, so the
    chord of any sub-piece P' (its ends are curve points, and the dev(P)-neighbourhood of a
    segment is convex) has an exact clearance >= clr(P) + dev(P) - dev(P) and >= 0, i.e. a
    certified clearance >= max(clr(P), 0) - dev(P'), with dev(P') <= dev(P) / 16^(levels between
    them) (|r''| is linear on P, so its maximum over P' is at most M). A piece whose bound, minus
    a rounding allowance of 1e-11 times the size of the coordinates (the computed distances are
    off by a few ulp of it), is not below its interval's best so far holds only strictly larger
    values and is skipped. Every grid piece is tested first; the failing ones are then searched from the
    lowest certified clearance up, and each piece's failing children likewise, so that the best
    is found early.
    """
    m = u.shape[0] - 1
    nk = point_u.shape[0] - 1
    has = np.zeros(nk, dtype=np.bool_)
    best_c = np.empty(nk)
    best_u = np.empty(nk)
    margin = np.inf
    # Rounding allowance of the bound: distances here are computed from coordinates of size
    # <= scale with absolute errors of a few ulp(scale) ~ 1e-15 scale; allow 1e-11 scale.
    bounds = obs.bounds
    vx = obs.vx
    vy = obs.vy
    circles = obs.circles
    scale = 1.0
    for j in range(c.shape[0]):
        scale = max(scale, abs(c[j, 0, 0]), abs(c[j, 0, 1]))
    for j in range(bounds.shape[0]):
        scale = max(scale, abs(bounds[j]))
    for j in range(vx.shape[0]):
        scale = max(scale, abs(vx[j]), abs(vy[j]))
    for j in range(circles.shape[0]):
        scale = max(scale, abs(circles[j, 0]) + abs(circles[j, 2]), abs(circles[j, 1]) + abs(circles[j, 2]))
    slack = 1e-11 * scale
    # 1. every grid piece
    fa = np.empty(m)
    fb = np.empty(m)
    fc = np.empty(m)
    fd = np.empty(m)
    nf = 0
    hint = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(m):
        pax, pay, pbx, pby, dev, hint = _chord_dev_one(x, c, u[j], u[j + 1], hint)
        cl = segment_clearance_kernel(pax, pay, pbx, pby, obs, -1.0)
        cj = cl - dev
        if cj >= limit:
            margin = min(margin, cj - radius)
        else:
            fa[nf] = u[j]
            fb[nf] = u[j + 1]
            fc[nf] = cj
            fd[nf] = dev
            nf += 1
    # 2. depth-first search below the failing ones, lowest certified clearance first
    cap = 4 * max_depth + 4
    sa = np.empty(cap)
    sb = np.empty(cap)
    sd = np.empty(cap, dtype=np.int64)
    sc = np.empty(cap)
    sv = np.empty(cap)
    ca = np.empty(4)
    cb = np.empty(4)
    cc = np.empty(4)
    cd = np.empty(4)
    order = _argsort_stable(fc[:nf])
    for r in range(nf):
        j = order[r]
        kj = np.searchsorted(point_u, 0.5 * (fa[j] + fb[j]), side="right") - 1
        kj = min(max(kj, 0), nk - 1)
        sa[0] = fa[j]
        sb[0] = fb[j]
        sd[0] = 0
        sc[0] = fc[j]
        sv[0] = fd[j]
        top = 1
        while top > 0:
            top -= 1
            a = sa[top]
            b = sb[top]
            depth = sd[top]
            cj = sc[top]
            if depth == max_depth:
                mid = 0.5 * (a + b)
                k = np.searchsorted(point_u, mid, side="right") - 1
                k = min(max(k, 0), nk - 1)
                if not has[k] or cj < best_c[k] or (cj == best_c[k] and mid < best_u[k]):
                    has[k] = True
                    best_c[k] = cj
                    best_u[k] = mid
                continue
            # chord clearances are >= 0: the sub-pieces' certified clearances are
            # >= max(clr(P), 0) - dev(P) / 16^levels
            if has[kj] and max(cj, 0.0) - sv[top] / 16.0 ** (max_depth - depth) - slack >= best_c[kj]:
                continue
            w = b - a
            n_c = 0
            h2 = np.int64(0)  # not a literal: one specialisation of the callee
            for p in range(4):
                a2 = a + w * (p / 4.0)
                b2 = a + w * ((p + 1) / 4.0)
                pax, pay, pbx, pby, dev, h2 = _chord_dev_one(x, c, a2, b2, h2)
                cl = segment_clearance_kernel(pax, pay, pbx, pby, obs, -1.0)
                c2 = cl - dev
                if c2 >= limit:
                    margin = min(margin, c2 - radius)
                    continue
                ca[n_c] = a2
                cb[n_c] = b2
                cc[n_c] = c2
                cd[n_c] = dev
                n_c += 1
            # push the failing children so that the lowest (then the first in u) pops first
            for _ in range(n_c):
                worst = -1
                for q in range(n_c):
                    if cd[q] < 0.0:
                        continue
                    if worst < 0 or cc[q] > cc[worst] or (cc[q] == cc[worst] and ca[q] > ca[worst]):
                        worst = q
                sa[top] = ca[worst]
                sb[top] = cb[worst]
                sd[top] = depth + 1
                sc[top] = cc[worst]
                sv[top] = cd[worst]
                top += 1
                cd[worst] = -1.0
    n = 0
    for k in range(nk):
        if has[k]:
            n += 1
    ks = np.empty(n, dtype=np.int64)
    fu = np.empty(n)
    fcl = np.empty(n)
    q = 0
    for k in range(nk):
        if has[k]:
            ks[q] = k
            fu[q] = best_u[k]
            fcl[q] = best_c[k]
            q += 1
    return ks, fu, fcl, margin
