"""The visibility graph's compiled kernels: interior tests of the convex components and the
visible bitangent edges (:mod:`anyplan.planning.visgraph`, which builds the graph).

:func:`edges` checks the edges exactly against an obstacle record (the feasible variant) or
against the components, and a map's boxes; :func:`edges_relaxed` is its interior test alone
(the lower variant without a map: the feasibility check before every run and the time lower
bound), which links none of geometry's clearance kernels and so compiles in less time.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from anyplan.geometry.collision import ObstacleArrays, segment_blocked_kernel


class Components(NamedTuple):
    """Convex polygons whose union is the (relaxed) inflated obstacles, for the interior
    tests; K components, E edges in all. Produced by :mod:`~anyplan.planning.visgraph`
    (``_pack``) only."""

    #: Vertex x [m], shape (E,).
    vx: np.ndarray
    #: Vertex y [m], shape (E,).
    vy: np.ndarray
    #: int64 offsets, shape (K + 1,): component k owns vertices and edges
    #: ``starts[k]:starts[k + 1]``.
    starts: np.ndarray
    #: Bounding boxes (xmin, ymin, xmax, ymax) [m], shape (K, 4).
    box: np.ndarray
    #: Outward unit normal x of each edge, shape (E,).
    nx: np.ndarray
    #: Outward unit normal y of each edge, shape (E,).
    ny: np.ndarray
    #: Offset of each edge's line, ``nx * x + ny * y = off`` [m], shape (E,).
    off: np.ndarray



@njit(cache=True)
def point_in_any(px: float, py: float, c: Components, eps: float) -> bool:
    """True if p is in the open interior (shrunk by eps) of any convex component."""
    starts = c.starts
    box = c.box
    nx = c.nx
    ny = c.ny
    off = c.off
    for k in range(starts.shape[0] - 1):
        if px <= box[k, 0] or px >= box[k, 2] or py <= box[k, 1] or py >= box[k, 3]:
            continue
        inside = True
        for e in range(starts[k], starts[k + 1]):
            if nx[e] * px + ny[e] * py >= off[e] - eps:
                inside = False
                break
        if inside:
            return True
    return False


@njit(cache=True)
def points_in_any(px: np.ndarray, py: np.ndarray, c: Components, eps: float) -> np.ndarray:
    """Mask (N,): :func:`point_in_any` of each point."""
    out = np.zeros(px.shape[0], np.bool_)
    for i in range(px.shape[0]):
        out[i] = point_in_any(px[i], py[i], c, eps)
    return out


@njit(cache=True)
def segment_hits_any(ax: float, ay: float, bx: float, by: float, c: Components,
                      eps: float) -> bool:
    """True if segment ab meets the open interior (shrunk by eps) of any convex component."""
    starts = c.starts
    box = c.box
    nx = c.nx
    ny = c.ny
    off = c.off
    x0 = min(ax, bx)
    x1 = max(ax, bx)
    y0 = min(ay, by)
    y1 = max(ay, by)
    dx = bx - ax
    dy = by - ay
    for k in range(starts.shape[0] - 1):
        if x1 <= box[k, 0] or x0 >= box[k, 2] or y1 <= box[k, 1] or y0 >= box[k, 3]:
            continue
        lo = 0.0
        hi = 1.0
        for e in range(starts[k], starts[k + 1]):
            den = nx[e] * dx + ny[e] * dy
            num = off[e] - eps - (nx[e] * ax + ny[e] * ay)
            if den == 0.0:
                if num <= 0.0:
                    lo = 2.0
                    break
            elif den > 0.0:
                hi = min(hi, num / den)
            else:
                lo = max(lo, num / den)
            if lo >= hi:
                break
        if lo < hi:
            return True
    return False


@njit(cache=True, inline="always")
def _tangent(ux: float, uy: float, px: float, py: float, qx: float, qy: float, vx: float,
             vy: float) -> bool:
    """True unless the line u->v separates u's boundary neighbours p and q (bitangent test)."""
    dx = vx - ux
    dy = vy - uy
    s1 = dx * (py - uy) - dy * (px - ux)
    s2 = dx * (qy - uy) - dy * (qx - ux)
    tol = 1e-12 * (abs(dx) + abs(dy) + 1.0)
    return not ((s1 > tol and s2 < -tol) or (s1 < -tol and s2 > tol))


@njit(cache=True, inline="always")
def _bitangent(i: int, j: int, px: np.ndarray, py: np.ndarray, prv: np.ndarray, nxt: np.ndarray,
               n_free: int) -> bool:
    """The tangent test of edge ij at both ends; nodes ``[0, n_free)`` (start, goal) skip it."""
    if i >= n_free and not _tangent(px[i], py[i], prv[i, 0], prv[i, 1], nxt[i, 0], nxt[i, 1],
                                    px[j], py[j]):
        return False
    return not (j >= n_free and not _tangent(px[j], py[j], prv[j, 0], prv[j, 1], nxt[j, 0],
                                             nxt[j, 1], px[i], py[i]))


@njit(cache=True, inline="always")
def _append(ei: np.ndarray, ej: np.ndarray, m: int, i: int,
            j: int) -> tuple[np.ndarray, np.ndarray]:
    """Edge ij as the m-th, in arrays that double when full."""
    if m == ei.shape[0]:
        ei2 = np.empty(2 * m, np.int64)
        ej2 = np.empty(2 * m, np.int64)
        for q in range(m):  # not a slice copy: that compiles numba's error formatting
            ei2[q] = ei[q]
            ej2[q] = ej[q]
        ei = ei2
        ej = ej2
    ei[m] = i
    ej[m] = j
    return ei, ej


@njit(cache=True, inline="always")
def _weighted(px: np.ndarray, py: np.ndarray, ei: np.ndarray, ej: np.ndarray,
              m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The m edges and their lengths."""
    w = np.empty(m)
    for e in range(m):
        w[e] = math.hypot(px[ei[e]] - px[ej[e]], py[ei[e]] - py[ej[e]])
    return ei[:m], ej[:m], w


@njit(cache=True)
def edges(px: np.ndarray, py: np.ndarray, prv: np.ndarray, nxt: np.ndarray, n_free: int,
           exact: bool, radius: float, comps: Components, obs: ObstacleArrays,
           box_limit: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Visible bitangent edges; nodes ``[0, n_free)`` (start, goal) skip the tangent test.

    ``exact``: the exact test at ``radius`` against the obstacle record ``obs``; else the
    interior test of the components and, if ``box_limit`` > 0, the exact test at
    ``box_limit`` against ``obs`` (then a map's boxes alone)."""
    n = px.shape[0]
    ei = np.empty(1024, np.int64)
    ej = np.empty(1024, np.int64)
    m = 0
    limit = radius - 1e-9
    for i in range(n):
        for j in range(i + 1, n):
            if not _bitangent(i, j, px, py, prv, nxt, n_free):
                continue
            if exact:
                if segment_blocked_kernel(px[i], py[i], px[j], py[j], obs, limit):
                    continue
            else:
                if segment_hits_any(px[i], py[i], px[j], py[j], comps, 1e-9):
                    continue
                if box_limit > 0.0 and segment_blocked_kernel(px[i], py[i], px[j], py[j], obs,
                                                              box_limit):
                    continue
            ei, ej = _append(ei, ej, m, i, j)
            m += 1
    return _weighted(px, py, ei, ej, m)


@njit(cache=True)
def edges_relaxed(px: np.ndarray, py: np.ndarray, prv: np.ndarray, nxt: np.ndarray,
                   n_free: int, comps: Components) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`edges` with the interior test alone (``exact`` False, ``box_limit`` 0: the lower
    variant without a map), the same edges; it links none of the clearance kernels, so it
    compiles faster (about 1.1 s of CPU against 1.6 s here)."""
    n = px.shape[0]
    ei = np.empty(1024, np.int64)
    ej = np.empty(1024, np.int64)
    m = 0
    for i in range(n):
        for j in range(i + 1, n):
            if not _bitangent(i, j, px, py, prv, nxt, n_free):
                continue
            if segment_hits_any(px[i], py[i], px[j], py[j], comps, 1e-9):
                continue
            ei, ej = _append(ei, ej, m, i, j)
            m += 1
    return _weighted(px, py, ei, ej, m)
