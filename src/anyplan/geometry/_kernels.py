"""Compiled (numba) kernels for exact planar distance queries.

All functions work on plain floats and flat arrays so that numba compiles them once and caches
the machine code on disk (``cache=True``). The public, documented API is
:class:`anyplan.geometry.collision.ObstacleSet`.

Data layout of an obstacle set:
    vx, vy: polygon vertex coordinates [m], all polygons concatenated, shape (V,).
    starts: offsets of each polygon's first vertex, shape (P + 1,); polygon k owns
        vertices ``starts[k]:starts[k + 1]``.
    pbox: polygon bounding boxes (xmin, ymin, xmax, ymax), shape (P, 4).
    circles: (cx, cy, radius), shape (C, 3).
    bounds: arena (xmin, ymin, xmax, ymax); the robot must stay inside. ``bounds[0] > bounds[2]``
        disables the walls.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

INF = math.inf


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
def point_clearance(px: float, py: float, vx: np.ndarray, vy: np.ndarray, starts: np.ndarray,
                    pbox: np.ndarray, circles: np.ndarray, bounds: np.ndarray) -> float:
    """Distance [m] from point p to the nearest obstacle or wall; 0 inside an obstacle."""
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
    for k in range(starts.shape[0] - 1):
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
    return best


@njit(cache=True)
def segment_clearance(ax: float, ay: float, bx: float, by: float, vx: np.ndarray, vy: np.ndarray,
                      starts: np.ndarray, pbox: np.ndarray, circles: np.ndarray,
                      bounds: np.ndarray, stop_below: float) -> float:
    """Minimum distance [m] from segment ab to any obstacle or wall (0 on contact).

    Returns early, with some value below ``stop_below``, as soon as the clearance is known to
    be smaller than ``stop_below`` (pass ``-1`` for the exact minimum).
    """
    best = INF
    if bounds[0] <= bounds[2]:
        # The distance to the boundary of a convex region is concave along a segment inside
        # it, so its minimum is at an endpoint.
        dwa = min(ax - bounds[0], bounds[2] - ax, ay - bounds[1], bounds[3] - ay)
        dwb = min(bx - bounds[0], bounds[2] - bx, by - bounds[1], bounds[3] - by)
        dw = min(dwa, dwb)
        if dw <= 0.0:
            return 0.0
        best = dw
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
    for k in range(starts.shape[0] - 1):
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
    return best


@njit(cache=True)
def points_clearance(px: np.ndarray, py: np.ndarray, vx: np.ndarray, vy: np.ndarray,
                     starts: np.ndarray, pbox: np.ndarray, circles: np.ndarray,
                     bounds: np.ndarray) -> np.ndarray:
    """Vectorised :func:`point_clearance`, shape (N,)."""
    out = np.empty(px.shape[0])
    for n in range(px.shape[0]):
        out[n] = point_clearance(px[n], py[n], vx, vy, starts, pbox, circles, bounds)
    return out


@njit(cache=True)
def segments_clearance(ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray,
                       vx: np.ndarray, vy: np.ndarray, starts: np.ndarray, pbox: np.ndarray,
                       circles: np.ndarray, bounds: np.ndarray, stop_below: float) -> np.ndarray:
    """Vectorised :func:`segment_clearance`, shape (N,)."""
    out = np.empty(ax.shape[0])
    for n in range(ax.shape[0]):
        out[n] = segment_clearance(ax[n], ay[n], bx[n], by[n], vx, vy, starts, pbox, circles,
                                   bounds, stop_below)
    return out
