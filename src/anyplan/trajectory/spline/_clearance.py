"""Compiled certified clearance of the curve: chord bounds, 4-way refinement, branch and bound.

On a piece [a, b] inside one cubic, r'' is linear, so the curve stays within
dev = M h^2 / 8 of its chord (M = max |r''| at both ends, h = b - a); the piece is certified
for a clearance ``limit`` when the chord's exact clearance (geometry's
``segment_clearance_kernel``) minus dev is at least ``limit``. :func:`certify` refines failing
pieces level by level; :func:`certify_worst` finds, per interpolation interval, only the worst
failing piece (what the repair uses) by branch and bound. Curves arrive as one
:class:`~anyplan.trajectory.spline.CurveArrays` record, obstacles as geometry's record.
See ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from anyplan.geometry.collision import (
    ObstacleArrays,
    capsule_buried_kernel,
    segment_clearance_below_kernel,
    segment_clearance_kernel,
)
from anyplan.trajectory.spline._pp import locate

if TYPE_CHECKING:
    from anyplan.trajectory.spline.arrays import CurveArrays


#: Deferral distance [m] of :func:`certify_worst`: a piece whose chord clears the limit by more
#: than this (plus its deviation bound) is not measured exactly unless the margin needs it.
CAP_DELTA = 0.05


@njit(cache=True)
def _grown(a: np.ndarray, n: int) -> np.ndarray:
    """``a`` with twice the room, its first ``n`` entries kept."""
    out = np.empty(2 * max(a.shape[0], 1))
    for i in range(n):  # not out[:n] = a[:n]: that compiles numba's error-message formatting
        out[i] = a[i]
    return out


@njit(cache=True)
def chord_dev_one(x: np.ndarray, c: np.ndarray, a_u: float, b_u: float,
                   i: int) -> tuple[float, float, float, float, float, int]:
    """(r(a), r(b), M h^2 / 8) for one piece [a_u, b_u]; ``i``: piece guess for a_u (returned
    updated)."""
    xe = x[-1]
    a = min(max(a_u, 0.0), xe)
    b = min(max(b_u, 0.0), xe)
    bi = min(max(b_u - 1e-12 * max(1.0, abs(b_u)), 0.0), xe)
    i = locate(x, a, i)
    ia = i
    t = a - x[i]
    pax = c[i, 0, 0] + t * (c[i, 1, 0] + t * (c[i, 2, 0] + t * c[i, 3, 0]))
    pay = c[i, 0, 1] + t * (c[i, 1, 1] + t * (c[i, 2, 1] + t * c[i, 3, 1]))
    m2 = math.hypot(2.0 * c[i, 2, 0] + 6.0 * t * c[i, 3, 0], 2.0 * c[i, 2, 1] + 6.0 * t * c[i, 3, 1])
    i = locate(x, b, ia)
    t = b - x[i]
    pbx = c[i, 0, 0] + t * (c[i, 1, 0] + t * (c[i, 2, 0] + t * c[i, 3, 0]))
    pby = c[i, 0, 1] + t * (c[i, 1, 1] + t * (c[i, 2, 1] + t * c[i, 3, 1]))
    i = locate(x, bi, ia)
    t = bi - x[i]
    m2b = math.hypot(2.0 * c[i, 2, 0] + 6.0 * t * c[i, 3, 0], 2.0 * c[i, 2, 1] + 6.0 * t * c[i, 3, 1])
    h = b_u - a_u
    return pax, pay, pbx, pby, max(m2, m2b) * h * h / 8.0, ia


@njit(cache=True)
def leaf_dev_bound(x: np.ndarray, c: np.ndarray, a_u: float, b_u: float, levels: int) -> float:
    """An upper bound [m] on the deviation bound :func:`chord_dev_one` computes for each piece
    that ``levels`` 4-way splits of [a_u, b_u] make, its rounding included (inf when the piece
    is not inside one cubic).

    r'' is affine on a cubic, so |r''| is convex and at most its larger end value on the whole
    piece; a sub-piece is 4^-levels as long. Allowed for: the sub-pieces' ends and their t off
    by a few ulp a split (and the last one's end just past b_u), r'' evaluated to a few ulp of
    its terms' size, the products to a few ulp: each by far more than rounding can give."""
    xe = x[-1]
    a = min(max(a_u, 0.0), xe)
    b = min(max(b_u, 0.0), xe)
    bi = min(max(b_u - 1e-12 * max(1.0, abs(b_u)), 0.0), xe)
    i = locate(x, a, np.int64(0))
    if locate(x, bi, i) != i:
        return np.inf
    ta = a - x[i]
    tb = b - x[i]
    c2x = c[i, 2, 0]
    c2y = c[i, 2, 1]
    c3x = c[i, 3, 0]
    c3y = c[i, 3, 1]
    ma = math.hypot(2.0 * c2x + 6.0 * ta * c3x, 2.0 * c2y + 6.0 * ta * c3y)
    mb = math.hypot(2.0 * c2x + 6.0 * tb * c3x, 2.0 * c2y + 6.0 * tb * c3y)
    g3 = 6.0 * math.hypot(c3x, c3y)  # the third derivative's size: how fast |r''| can change
    size = 2.0 * math.hypot(c2x, c2y) + g3 * max(abs(ta), abs(tb))
    stray = 4.0 * (levels + 2) * 2.3e-16 * max(1.0, abs(a_u), abs(b_u), abs(xe))
    m = max(ma, mb) + 1e-12 * size + g3 * stray
    h = (b_u - a_u) / 4.0 ** levels * (1.0 + 1e-12) + stray
    return m * h * h / 8.0 * (1.0 + 1e-12)


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
        pa[j, 0], pa[j, 1], pb[j, 0], pb[j, 1], dev[j], i = chord_dev_one(x, c, a_u[j], b_u[j], i)
    return pa, pb, dev


@njit(cache=True)
def certify(cv: CurveArrays, limit: float, radius: float, max_depth: int,
            obs: ObstacleArrays) -> tuple[np.ndarray, np.ndarray, float]:
    """Certified chord test of the pieces [u_j, u_{j+1}] with up to ``max_depth`` 4-way splits.

    A piece is certified when (exact chord clearance) - M h^2 / 8 >= ``limit``
    (:func:`chord_deviation`). Returns the midpoints and certified clearances of the pieces that
    still fail at ``max_depth`` (in order of u) and min(certified clearance) - ``radius`` over
    the certified pieces (inf if none). Before the last level only pass/fail matters, so the
    clearance query may stop early once it is known to be below the threshold (minus 1e-9 m,
    far beyond rounding, so pass/fail is exactly that of the exact clearance). The pieces are
    the intervals of the curve's evaluation grid ``u_grid``.
    """
    x, c, u = cv.x, cv.c, cv.u_grid
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
def argsort_stable(v: np.ndarray) -> np.ndarray:
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
def certify_worst(cv: CurveArrays, limit: float, radius: float, max_depth: int,
                  obs: ObstacleArrays, tight: bool = True
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
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

    With ``tight`` False the deferred pieces are never measured: the margin is then
    min(the margin of the measured pieces, limit + CAP_DELTA - radius), still a certified lower
    bound (every deferred piece clears limit + CAP_DELTA), and the failures are the same.

    Fewer and cheaper queries, same answers: the chord clearance is capped at limit + dev +
    :data:`CAP_DELTA` (a piece clearing that is certified; it is measured, capped by the margin
    so far, only if the margin needs it), and below a failing piece whose dev-neighbourhood is
    buried in one obstacle (``capsule_buried_kernel``) every chord's clearance is 0, unqueried.
    """
    x, c, u, point_u = cv.x, cv.c, cv.u_grid, cv.point_u
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
    # Clearance queries are capped (segment_clearance_below): a piece needs its exact chord
    # clearance only when it fails (cl < limit + dev) or when it may lower the margin. A piece
    # whose chord is >= limit + dev + CAP_DELTA away is certified and deferred (its certified
    # clearance is >= limit + CAP_DELTA); the deferred pieces are measured, capped by the margin
    # found so far, only if the curve turns out free and its margin is not already below them.
    # 1. every grid piece
    fa = np.empty(m)
    fb = np.empty(m)
    fc = np.empty(m)
    fd = np.empty(m)
    fz = np.empty(m, dtype=np.bool_)
    nf = 0
    dfa = np.empty(m)
    dfb = np.empty(m)
    nd = 0
    hint = np.int64(0)  # not a literal: one specialisation of the callee
    for j in range(m):
        pax, pay, pbx, pby, dev, hint = chord_dev_one(x, c, u[j], u[j + 1], hint)
        cap = limit + dev + CAP_DELTA
        cl = segment_clearance_below_kernel(pax, pay, pbx, pby, obs, cap)
        if cl >= cap:
            dfa[nd] = u[j]
            dfb[nd] = u[j + 1]
            nd += 1
            continue
        cj = cl - dev
        if cj >= limit:
            margin = min(margin, cj - radius)
        else:
            fa[nf] = u[j]
            fb[nf] = u[j + 1]
            fc[nf] = cj
            fd[nf] = dev
            fz[nf] = cl == 0.0 and capsule_buried_kernel(pax, pay, pbx, pby, dev, obs)
            nf += 1
    # 2. depth-first search below the failing ones, lowest certified clearance first
    cap_stack = 4 * max_depth + 4
    sa = np.empty(cap_stack)
    sb = np.empty(cap_stack)
    sd = np.empty(cap_stack, dtype=np.int64)
    sc = np.empty(cap_stack)
    sv = np.empty(cap_stack)
    sz = np.empty(cap_stack, dtype=np.bool_)
    ca = np.empty(4)
    cb = np.empty(4)
    cc = np.empty(4)
    cd = np.empty(4)
    order = argsort_stable(fc[:nf])
    for r in range(nf):
        j = order[r]
        kj = np.searchsorted(point_u, 0.5 * (fa[j] + fb[j]), side="right") - 1
        kj = min(max(kj, 0), nk - 1)
        sa[0] = fa[j]
        sb[0] = fb[j]
        sd[0] = 0
        sc[0] = fc[j]
        sv[0] = fd[j]
        sz[0] = fz[j]
        top = 1
        while top > 0:
            top -= 1
            a = sa[top]
            b = sb[top]
            depth = sd[top]
            cj = sc[top]
            buried = sz[top]
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
            # every leaf's chord clearance is >= 0, so its value is >= -(its dev): a bound with
            # no computed distance in it, so no slack of the coordinates' size. The bound above
            # cannot prune pieces inside an obstacle or beyond a wall (each leaf -dev, about
            # -1e-10 m, below that slack): 4^depth leaves each, on a curve far out of its arena
            # or through a map's walls; this one prunes them once a leaf below them is found
            if has[kj] and best_c[kj] < 0.0 and -leaf_dev_bound(x, c, a, b, max_depth - depth) > best_c[kj]:
                continue
            w = b - a
            n_c = 0
            h2 = np.int64(0)  # not a literal: one specialisation of the callee
            for p in range(4):
                a2 = a + w * (p / 4.0)
                b2 = a + w * ((p + 1) / 4.0)
                pax, pay, pbx, pby, dev, h2 = chord_dev_one(x, c, a2, b2, h2)
                cap = limit + dev + CAP_DELTA
                # inside a buried parent's capsule the clearance is 0: no query
                cl = 0.0 if buried else segment_clearance_below_kernel(pax, pay, pbx, pby, obs,
                                                                       cap)
                if cl >= cap:
                    if nd == dfa.shape[0]:
                        dfa = _grown(dfa, nd)
                        dfb = _grown(dfb, nd)
                    dfa[nd] = a2
                    dfb[nd] = b2
                    nd += 1
                    continue
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
                sz[top] = buried
                top += 1
                cd[worst] = -1.0
    # 3. the deferred pieces, when the margin is wanted and they may lower it: each is
    # certified (its certified clearance is >= limit + CAP_DELTA), and one whose chord is
    # >= margin + radius + dev + 1e-9 away cannot lower the margin found so far
    free = True
    for k in range(nk):
        if has[k]:
            free = False
            break
    if not tight:
        margin = min(margin, limit + CAP_DELTA - radius)
    elif free and nd > 0 and margin > limit + CAP_DELTA - radius - 1e-9:
        hint = np.int64(0)
        for j in range(nd):
            pax, pay, pbx, pby, dev, hint = chord_dev_one(x, c, dfa[j], dfb[j], hint)
            cap = margin + radius + dev + 1e-9
            cl = segment_clearance_below_kernel(pax, pay, pbx, pby, obs, cap)
            if cl < cap:
                margin = min(margin, cl - dev - radius)
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
