"""Compiled (numba) clearance kernels: exact distances from points and segments to obstacles.

Every kernel takes the obstacle set as one record, :class:`ObstacleArrays` (defined here beside
its kernels, public as ``anyplan.geometry.collision.ObstacleArrays``; it documents the layout), and
plain floats, so numba compiles it once and caches the machine code (``cache=True``). Flags are
passed as ``np.bool_(True)``, not ``True``: numba types a constant argument as a literal and would
compile one specialisation per value. The public entry points for other packages' compiled code
are re-exported by :mod:`anyplan.geometry.collision` (``segment_clearance_kernel``,
``segment_blocked_kernel``); Python code uses :class:`~anyplan.geometry.collision.ObstacleSet`.

A query against the grid index is exact: it scans the cells within a distance R of the query
(a conservative, padded cover of the capsule), and R grows until the best distance found is
<= R, so no polygon nearer than the answer can be skipped.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

INF = math.inf


class ObstacleArrays(NamedTuple):
    """An obstacle set as flat arrays, one argument of the compiled kernels (numba accepts a
    NamedTuple of arrays). Produced only by :attr:`ObstacleSet.arrays`.

    P polygons (the map's boxes first), V vertices in all, C circles.
    """

    #: Polygon vertex x coordinates [m], all polygons concatenated, shape (V,).
    vx: np.ndarray
    #: Polygon vertex y coordinates [m], shape (V,).
    vy: np.ndarray
    #: int64 offsets, shape (P + 1,): polygon k owns vertices ``starts[k]:starts[k + 1]``.
    starts: np.ndarray
    #: Polygon bounding boxes (xmin, ymin, xmax, ymax) [m], shape (P, 4).
    pbox: np.ndarray
    #: Circles (cx, cy, radius) [m], shape (C, 3).
    circles: np.ndarray
    #: Arena (xmin, ymin, xmax, ymax) [m], shape (4,); the robot must stay inside.
    #: ``bounds[0] > bounds[2]`` disables the walls.
    bounds: np.ndarray
    #: Uniform-grid index over the first polygons, (x0, y0, cell [m], nx, ny, n_indexed,
    #: n_boxes); ``nx == 0`` means no index (every polygon is scanned). The first ``n_boxes``
    #: polygons are axis-aligned boxes equal to their ``pbox`` rows (a cheaper exact test);
    #: polygons ``n_indexed:`` are always scanned linearly (e.g. a few added to a map).
    gmeta: np.ndarray
    #: The grid's cells in CSR form, int64: ``gcsr[c]:gcsr[c + 1]`` (c = row * nx + col) are
    #: positions in ``gcsr`` holding the indices of the polygons whose bounding box meets the
    #: cell (:mod:`anyplan.geometry.index`).
    gcsr: np.ndarray


@njit(cache=True, inline="always")
def pt_seg_d2(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Squared distance from point p to segment ab."""
    dx = bx - ax
    dy = by - ay
    l2 = dx * dx + dy * dy
    t = 0.0
    if l2 > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / l2
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
    ex = ax + t * dx - px
    ey = ay + t * dy - py
    return ex * ex + ey * ey


@njit(cache=True, inline="always")
def _orient(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> float:
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(cache=True)
def seg_seg_d2(ax: float, ay: float, bx: float, by: float,
               cx: float, cy: float, dx: float, dy: float) -> float:
    """Squared distance between segments ab and cd (0 if they cross or touch)."""
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if o1 * o2 < 0.0 and o3 * o4 < 0.0:
        return 0.0
    # Not properly crossing: the minimum is attained at an endpoint of one of the segments.
    d = pt_seg_d2(ax, ay, cx, cy, dx, dy)
    d = min(d, pt_seg_d2(bx, by, cx, cy, dx, dy))
    d = min(d, pt_seg_d2(cx, cy, ax, ay, bx, by))
    return min(d, pt_seg_d2(dx, dy, ax, ay, bx, by))


@njit(cache=True)
def point_in_polygon(px: float, py: float, vx: np.ndarray, vy: np.ndarray, i0: int, i1: int) -> bool:
    """Even-odd rule: True if p is strictly inside polygon vertices ``i0:i1``."""
    inside = False
    j = i1 - 1
    for i in range(i0, i1):
        xi = vx[i]
        yi = vy[i]
        xj = vx[j]
        yj = vy[j]
        if (yi > py) != (yj > py):
            xc = xi + (py - yi) * (xj - xi) / (yj - yi)
            if px < xc:
                inside = not inside
        j = i
    return inside


@njit(cache=True)
def _poly_d2(ax: float, ay: float, bx: float, by: float, vx: np.ndarray, vy: np.ndarray,
             i0: int, i1: int) -> float:
    """Squared distance from segment ab (a point if a == b) to polygon ``i0:i1`` (0 on contact)."""
    if point_in_polygon(ax, ay, vx, vy, i0, i1):
        return 0.0
    best = INF
    j = i1 - 1
    pt = ax == bx and ay == by
    for i in range(i0, i1):
        if pt:
            d2 = pt_seg_d2(ax, ay, vx[j], vy[j], vx[i], vy[i])
        else:
            d2 = seg_seg_d2(ax, ay, bx, by, vx[j], vy[j], vx[i], vy[i])
        if d2 < best:
            best = d2
            if best <= 0.0:
                return 0.0
        j = i
    return best


@njit(cache=True, inline="always")
def _pt_box_d2(px: float, py: float, x0: float, y0: float, x1: float, y1: float) -> float:
    gx = max(x0 - px, 0.0, px - x1)
    gy = max(y0 - py, 0.0, py - y1)
    return gx * gx + gy * gy


@njit(cache=True)
def _box_d2(ax: float, ay: float, bx: float, by: float, x0: float, y0: float, x1: float,
            y1: float) -> float:
    """Squared distance from segment ab (a point if a == b) to the closed box [x0, x1] x
    [y0, y1] (0 if they meet): the clipped segment is empty or not; if empty, the distance of
    two disjoint convex sets is attained at a vertex of one of them."""
    if ax == bx and ay == by:
        return _pt_box_d2(ax, ay, x0, y0, x1, y1)
    dx = bx - ax
    dy = by - ay
    t0 = 0.0
    t1 = 1.0
    meet = True
    if dx == 0.0:
        if ax < x0 or ax > x1:
            meet = False
    else:
        u = (x0 - ax) / dx
        v = (x1 - ax) / dx
        t0 = max(t0, min(u, v))
        t1 = min(t1, max(u, v))
    if dy == 0.0:
        if ay < y0 or ay > y1:
            meet = False
    else:
        u = (y0 - ay) / dy
        v = (y1 - ay) / dy
        t0 = max(t0, min(u, v))
        t1 = min(t1, max(u, v))
    if meet and t0 <= t1:
        return 0.0
    d = min(_pt_box_d2(ax, ay, x0, y0, x1, y1), _pt_box_d2(bx, by, x0, y0, x1, y1))
    d = min(d, pt_seg_d2(x0, y0, ax, ay, bx, by), pt_seg_d2(x1, y0, ax, ay, bx, by))
    return min(d, pt_seg_d2(x1, y1, ax, ay, bx, by), pt_seg_d2(x0, y1, ax, ay, bx, by))


@njit(cache=True)
def _grid_scan(ax: float, ay: float, bx: float, by: float, rad: float, best: float,
               stop_below: float, exact: bool, obs: ObstacleArrays) -> float:
    """min(best, distance to the indexed polygons met by the cells within ``rad`` of ab).

    Every polygon at distance <= ``rad`` from ab is tested (the cover is padded against
    rounding); returns early once the distance is 0 or below ``stop_below``. With ``exact``
    False only polygons nearer than ``stop_below`` matter (the others are skipped by the lower
    bounds of their boxes)."""
    vx = obs.vx
    vy = obs.vy
    starts = obs.starts
    pbox = obs.pbox
    gmeta = obs.gmeta
    gcsr = obs.gcsr
    x0 = gmeta[0]
    y0 = gmeta[1]
    h = gmeta[2]
    nx = int(gmeta[3])
    ny = int(gmeta[4])
    pad = rad + 1e-9 * (1.0 + abs(ax) + abs(ay) + abs(bx) + abs(by) + abs(x0) + abs(y0))
    j0 = int(math.floor((min(ay, by) - pad - y0) / h))
    j1 = int(math.floor((max(ay, by) + pad - y0) / h))
    if j1 < 0 or j0 >= ny:
        return best
    j0 = max(j0, 0)
    j1 = min(j1, ny - 1)
    dx = bx - ax
    dy = by - ay
    sx0 = min(ax, bx)
    sx1 = max(ax, bx)
    sy0 = min(ay, by)
    sy1 = max(ay, by)
    cut = best if exact else min(best, stop_below)
    nbox = int(gmeta[6])
    for j in range(j0, j1 + 1):
        lo = y0 + j * h - pad
        hi = y0 + (j + 1) * h + pad
        if dy == 0.0:
            if ay < lo or ay > hi:
                continue
            t0 = 0.0
            t1 = 1.0
        else:
            ta = (lo - ay) / dy
            tb = (hi - ay) / dy
            t0 = max(min(ta, tb), 0.0)
            t1 = min(max(ta, tb), 1.0)
            if t0 > t1:
                continue
        xa = ax + t0 * dx
        xb = ax + t1 * dx
        i0 = int(math.floor((min(xa, xb) - pad - x0) / h))
        i1 = int(math.floor((max(xa, xb) + pad - x0) / h))
        if i1 < 0 or i0 >= nx:
            continue
        i0 = max(i0, 0)
        i1 = min(i1, nx - 1)
        for i in range(i0, i1 + 1):
            c = j * nx + i
            for q in range(gcsr[c], gcsr[c + 1]):
                k = gcsr[q]
                gx = max(pbox[k, 0] - sx1, 0.0, sx0 - pbox[k, 2])
                gy = max(pbox[k, 1] - sy1, 0.0, sy0 - pbox[k, 3])
                if gx * gx + gy * gy >= cut * cut:
                    continue
                # the polygon lies in the disc around its box: a second lower bound
                hx = 0.5 * (pbox[k, 2] - pbox[k, 0])
                hy = 0.5 * (pbox[k, 3] - pbox[k, 1])
                dc = math.sqrt(pt_seg_d2(pbox[k, 0] + hx, pbox[k, 1] + hy, ax, ay, bx, by))
                if dc - math.sqrt(hx * hx + hy * hy) >= cut:
                    continue
                if k < nbox:  # an axis-aligned box (a map's cells): the cheaper exact test
                    d2 = _box_d2(ax, ay, bx, by, pbox[k, 0], pbox[k, 1], pbox[k, 2], pbox[k, 3])
                else:
                    d2 = _poly_d2(ax, ay, bx, by, vx, vy, starts[k], starts[k + 1])
                if d2 < best * best:
                    best = math.sqrt(d2)
                    if best <= 0.0 or best < stop_below:
                        return best
                    if exact:
                        cut = best
    return best


@njit(cache=True)
def _grid_clearance(ax: float, ay: float, bx: float, by: float, best: float, stop_below: float,
                    exact: bool, obs: ObstacleArrays) -> float:
    """min(best, distance from ab to the indexed polygons), by scans of growing radius.

    Exact unless the result is below ``stop_below`` (then some value below it) or, with
    ``exact`` False, unless it is >= ``stop_below`` (then some value >= it: pass/fail only)."""
    gmeta = obs.gmeta
    h = gmeta[2]
    gx0 = gmeta[0]
    gy0 = gmeta[1]
    gx1 = gx0 + gmeta[3] * h
    gy1 = gy0 + gmeta[4] * h
    # a radius this large covers the whole grid (its farthest corner from a)
    rmax = math.sqrt(max(abs(ax - gx0), abs(ax - gx1)) ** 2 + max(abs(ay - gy0), abs(ay - gy1)) ** 2)
    rad = stop_below if stop_below > 0.0 else h
    if rad > best:
        rad = best
    while True:
        best = _grid_scan(ax, ay, bx, by, rad, best, stop_below, exact, obs)
        if best <= 0.0 or best < stop_below or not exact:
            return best
        if best <= rad or rad >= rmax:
            return best
        rad = min(2.0 * rad, best)


@njit(cache=True)
def point_clearance(px: float, py: float, obs: ObstacleArrays) -> float:
    """Distance [m] from point p to the nearest obstacle or wall; 0 inside an obstacle."""
    vx = obs.vx
    vy = obs.vy
    starts = obs.starts
    pbox = obs.pbox
    circles = obs.circles
    bounds = obs.bounds
    gmeta = obs.gmeta
    best = INF
    if bounds[0] <= bounds[2]:
        dw = min(px - bounds[0], bounds[2] - px, py - bounds[1], bounds[3] - py)
        if dw <= 0.0:
            return 0.0
        best = dw
    for k in range(circles.shape[0]):
        d = math.hypot(px - circles[k, 0], py - circles[k, 1]) - circles[k, 2]
        if d <= 0.0:
            return 0.0
        if d < best:
            best = d
    for k in range(int(gmeta[5]), starts.shape[0] - 1):
        # Lower bound from the bounding box first.
        gx = max(pbox[k, 0] - px, 0.0, px - pbox[k, 2])
        gy = max(pbox[k, 1] - py, 0.0, py - pbox[k, 3])
        if gx * gx + gy * gy >= best * best:
            continue
        i0 = starts[k]
        i1 = starts[k + 1]
        if point_in_polygon(px, py, vx, vy, i0, i1):
            return 0.0
        j = i1 - 1
        for i in range(i0, i1):
            d2 = pt_seg_d2(px, py, vx[j], vy[j], vx[i], vy[i])
            if d2 < best * best:
                best = math.sqrt(d2)
            j = i
    if gmeta[3] > 0.0:
        best = _grid_clearance(px, py, px, py, best, 0.0, np.bool_(True), obs)
    return best


@njit(cache=True)
def _segment_clearance(ax: float, ay: float, bx: float, by: float, obs: ObstacleArrays,
                       stop_below: float, exact: bool, cap: float) -> float:
    vx = obs.vx
    vy = obs.vy
    starts = obs.starts
    pbox = obs.pbox
    circles = obs.circles
    bounds = obs.bounds
    gmeta = obs.gmeta
    best = cap
    if bounds[0] <= bounds[2]:
        # The distance to the boundary of a convex region is concave along a segment inside
        # it, so its minimum is at an endpoint.
        dwa = min(ax - bounds[0], bounds[2] - ax, ay - bounds[1], bounds[3] - ay)
        dwb = min(bx - bounds[0], bounds[2] - bx, by - bounds[1], bounds[3] - by)
        dw = min(dwa, dwb)
        if dw <= 0.0:
            return 0.0
        best = min(dw, cap)
        if best < stop_below:
            return best
    for k in range(circles.shape[0]):
        d = math.sqrt(pt_seg_d2(circles[k, 0], circles[k, 1], ax, ay, bx, by)) - circles[k, 2]
        if d <= 0.0:
            return 0.0
        if d < best:
            best = d
            if best < stop_below:
                return best
    sx0 = min(ax, bx)
    sx1 = max(ax, bx)
    sy0 = min(ay, by)
    sy1 = max(ay, by)
    for k in range(int(gmeta[5]), starts.shape[0] - 1):
        gx = max(pbox[k, 0] - sx1, 0.0, sx0 - pbox[k, 2])
        gy = max(pbox[k, 1] - sy1, 0.0, sy0 - pbox[k, 3])
        if gx * gx + gy * gy >= best * best:
            continue
        i0 = starts[k]
        i1 = starts[k + 1]
        if point_in_polygon(ax, ay, vx, vy, i0, i1):
            return 0.0
        j = i1 - 1
        for i in range(i0, i1):
            d2 = seg_seg_d2(ax, ay, bx, by, vx[j], vy[j], vx[i], vy[i])
            if d2 < best * best:
                best = math.sqrt(d2)
                if best <= 0.0:
                    return 0.0
                if best < stop_below:
                    return best
            j = i
    if gmeta[3] > 0.0:
        best = _grid_clearance(ax, ay, bx, by, best, stop_below, exact, obs)
    return best


@njit(cache=True)
def segment_clearance(ax: float, ay: float, bx: float, by: float, obs: ObstacleArrays,
                      stop_below: float) -> float:
    """Minimum distance [m] from segment ab to any obstacle or wall (0 on contact).

    Returns early, with some value below ``stop_below``, as soon as the clearance is known to
    be smaller than ``stop_below`` (pass ``-1`` for the exact minimum); otherwise exact.
    """
    return _segment_clearance(ax, ay, bx, by, obs, stop_below, np.bool_(True), INF)


@njit(cache=True)
def segment_blocked(ax: float, ay: float, bx: float, by: float, obs: ObstacleArrays,
                    limit: float) -> bool:
    """True iff the exact clearance of segment ab is < ``limit`` [m] (pass/fail only: on a map
    it scans only the cells within ``limit`` of the segment)."""
    return _segment_clearance(ax, ay, bx, by, obs, limit, np.bool_(False), INF) < limit


@njit(cache=True)
def segment_clearance_below(ax: float, ay: float, bx: float, by: float, obs: ObstacleArrays,
                            cap: float) -> float:
    """The exact clearance [m] of segment ab when it is below ``cap``, otherwise ``cap``
    (i.e. ``min(clearance, cap)``): on a map only the cells within ``cap`` of ab are scanned, so
    a far-away answer costs what a pass/fail test at ``cap`` costs."""
    return _segment_clearance(ax, ay, bx, by, obs, -1.0, np.bool_(True), cap)


@njit(cache=True)
def capsule_buried(ax: float, ay: float, bx: float, by: float, pad: float,
                   obs: ObstacleArrays) -> bool:
    """True if every point within ``pad`` [m] of segment ab (the capsule) is inside one circle,
    one of the map's boxes (``n_boxes`` > 0, with the index) or beyond one of the arena's walls,
    by more than 1e-9 m: then every segment in the capsule has clearance exactly 0 (a
    conservative test: False says nothing)."""
    pad = pad + 1e-9
    sx0 = min(ax, bx) - pad
    sx1 = max(ax, bx) + pad
    sy0 = min(ay, by) - pad
    sy1 = max(ay, by) + pad
    bounds = obs.bounds
    if bounds[0] <= bounds[2] and (sx1 < bounds[0] or sx0 > bounds[2] or sy1 < bounds[1]
                                   or sy0 > bounds[3]):
        return True
    circles = obs.circles
    for k in range(circles.shape[0]):
        r = circles[k, 2] - pad
        if r > 0.0 and (math.hypot(ax - circles[k, 0], ay - circles[k, 1]) < r
                        and math.hypot(bx - circles[k, 0], by - circles[k, 1]) < r):
            return True
    gmeta = obs.gmeta
    nbox = int(gmeta[6])
    if gmeta[3] <= 0.0 or nbox == 0:
        return False
    h = gmeta[2]
    nx = int(gmeta[3])
    ny = int(gmeta[4])
    i = int(math.floor((ax - gmeta[0]) / h))
    j = int(math.floor((ay - gmeta[1]) / h))
    if i < 0 or j < 0 or i >= nx or j >= ny:
        return False
    pbox = obs.pbox
    gcsr = obs.gcsr
    c = j * nx + i
    for q in range(gcsr[c], gcsr[c + 1]):
        k = gcsr[q]
        if k < nbox and (pbox[k, 0] < sx0 and sx1 < pbox[k, 2] and pbox[k, 1] < sy0
                         and sy1 < pbox[k, 3]):
            return True
    return False


# --- entries for calls from Python ---------------------------------------------------------
# numba types a NamedTuple argument from Python on its slow path (about 2 us per call more
# than eight arrays), so ObstacleSet's methods pass the record's fields and the record is
# rebuilt here, in compiled code, for free. Compiled callers pass the record itself. Two
# entries serve every query kind: numba links the whole clearance chain into each entry and
# generates its machine code again there, so each entry more costs a cold start about 0.4 s.

#: Query kinds of :func:`py_query` and :func:`py_queries`: the clearance of point a; the
#: clearance of segment ab (early exit below ``arg``, as :func:`segment_clearance`); the
#: pass/fail value of ab at the limit ``arg`` (compare it with ``arg``: ``< arg`` iff
#: :func:`segment_blocked`; for a point, a == b, ``>= arg`` iff the point is clear).
POINT, SEGMENT, PASS_FAIL = 0, 1, 2


@njit(cache=True, inline="always")
def _query(kind: int, ax: float, ay: float, bx: float, by: float, obs: ObstacleArrays,
           arg: float) -> float:
    if kind == POINT:
        return point_clearance(ax, ay, obs)
    return _segment_clearance(ax, ay, bx, by, obs, arg, kind == SEGMENT, INF)


@njit(cache=True)
def py_query(kind: int, ax: float, ay: float, bx: float, by: float, vx: np.ndarray,
             vy: np.ndarray, starts: np.ndarray, pbox: np.ndarray, circles: np.ndarray,
             bounds: np.ndarray, gmeta: np.ndarray, gcsr: np.ndarray, arg: float) -> float:
    """One query of kind ``kind`` (:data:`POINT`, :data:`SEGMENT`, :data:`PASS_FAIL`) against
    the record made of the given fields."""
    return _query(kind, ax, ay, bx, by,
                  ObstacleArrays(vx, vy, starts, pbox, circles, bounds, gmeta, gcsr), arg)


@njit(cache=True)
def py_queries(kind: int, ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray,
               vx: np.ndarray, vy: np.ndarray, starts: np.ndarray, pbox: np.ndarray,
               circles: np.ndarray, bounds: np.ndarray, gmeta: np.ndarray, gcsr: np.ndarray,
               arg: float) -> np.ndarray:
    """:func:`py_query` of each (a[n], b[n]), shape (N,)."""
    obs = ObstacleArrays(vx, vy, starts, pbox, circles, bounds, gmeta, gcsr)
    out = np.empty(ax.shape[0])
    for n in range(ax.shape[0]):
        out[n] = _query(kind, ax[n], ay[n], bx[n], by[n], obs, arg)
    return out
