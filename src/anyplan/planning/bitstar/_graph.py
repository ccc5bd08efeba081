"""BIT*'s implicit graph (OMPL ``BITstar::ImplicitGraph``): samples, batches and neighbours.

The points (start, goal, samples and vertices alike) and their heuristics live in one record,
:class:`Points`; each batch has its own immutable record, :class:`Batch`: the connection radius
``r`` (or ``k``) and uniform grids of cell size r over all points and over the batch's new
samples, which answer the neighbour queries of the random geometric graph. New samples come
from the informed set (:class:`InformedSampler`); :func:`compact` prunes and recycles points.
Notation of :mod:`anyplan.planning.bitstar`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.se2 import transform_points
from anyplan.planning.bitstar import _tree
from anyplan.planning.bitstar._tree import Tree


class Points(NamedTuple):
    """The graph's points in C slots (0 the start, 1 the goal). Produced by :func:`new_points`
    and :func:`with_capacity` only."""

    #: Positions [m], shape (C, 2).
    xy: np.ndarray
    #: ``g_hat``, the distance to the start [m], shape (C,).
    g_hat: np.ndarray
    #: ``h_hat``, the distance to the goal [m], shape (C,).
    h_hat: np.ndarray
    #: Batch in which the point became a sample (new samples are the current batch's), int64,
    #: shape (C,).
    batch: np.ndarray
    #: Number of points in use, int64, shape (1,).
    n: np.ndarray


class Batch(NamedTuple):
    """One batch's random geometric graph (fixed while the batch is searched). Produced by
    :func:`first_batch` and :func:`next_batch` only."""

    #: Batch number (0 before the first batch).
    number: int
    #: Connection radius ``r`` [m].
    radius: float
    #: ``k`` of the k-nearest graph (0: the r-disc graph).
    k: int
    #: Grid origin x [m].
    x0: float
    #: Grid origin y [m].
    y0: float
    #: Grid cell side [m] (>= r).
    cell: float
    #: Grid columns.
    ncx: int
    #: Grid rows.
    ncy: int
    #: All points by cell (CSR): ``items[start[c]:start[c + 1]]`` lie in cell c, int64.
    start: np.ndarray
    #: See ``start``.
    items: np.ndarray
    #: The batch's new samples by cell (CSR), int64.
    new_start: np.ndarray
    #: See ``new_start``.
    new_items: np.ndarray
    #: The batch's new samples, int64.
    new: np.ndarray


def new_points(cap: int, start: np.ndarray, goal: np.ndarray) -> Points:
    """Room for ``cap`` points, holding the start (0) and the goal (1)."""
    p = Points(np.zeros((cap, 2)), np.full(cap, math.inf), np.full(cap, math.inf),
               np.full(cap, -1, np.int64), np.array([2], np.int64))
    for i, x in enumerate((start, goal)):
        p.xy[i] = x
        p.g_hat[i] = np.hypot(*(x - start))
        p.h_hat[i] = np.hypot(*(goal - x))
    return p


def with_capacity(p: Points, cap: int) -> Points:
    """``p`` with ``cap`` slots (contents kept)."""
    old = p.xy.shape[0]
    if cap <= old:
        return p
    extra = cap - old
    return Points(np.vstack([p.xy, np.zeros((extra, 2))]),
                  np.concatenate([p.g_hat, np.full(extra, math.inf)]),
                  np.concatenate([p.h_hat, np.full(extra, math.inf)]),
                  np.concatenate([p.batch, np.full(extra, -1, np.int64)]), p.n)


def append_samples(p: Points, pts: np.ndarray, start: np.ndarray, goal: np.ndarray,
                   batch: int) -> None:
    """Add the samples ``pts`` (K, 2) of batch ``batch`` (the capacity must suffice)."""
    n = int(p.n[0])
    k = len(pts)
    p.xy[n:n + k] = pts
    p.g_hat[n:n + k] = np.hypot(*(pts - start).T)
    p.h_hat[n:n + k] = np.hypot(*(goal - pts).T)
    p.batch[n:n + k] = batch
    p.n[0] = n + k


def first_batch() -> Batch:
    """The record before the first batch (no radius, empty grids)."""
    empty = np.zeros(0, np.int64)
    return Batch(0, 0.0, 0, 0.0, 0.0, 0.0, 0, 0, np.zeros(2, np.int64), empty,
                 np.zeros(2, np.int64), empty, empty)


def next_batch(p: Points, vertex: np.ndarray, number: int, measure: float,
               rewire_factor: float, use_k_nearest: bool,
               box: tuple[float, float, float, float]) -> Batch:
    """Batch ``number`` over the points ``p``, whose vertices are ``vertex`` (mask): radius
    ``r`` (and ``k``) from the informed-set ``measure`` [m^2], and the neighbour grids."""
    n = int(p.n[0])
    q = max(n, 2)
    eta = rewire_factor
    # r = eta * 2 * sqrt((1 + 1/d) * (lambda / zeta_d) * log(q) / q), d = 2
    r = eta * 2.0 * math.sqrt(1.5 * (measure / math.pi) * math.log(q) / q) if q > 1 else math.inf
    xmin, ymin, xmax, ymax = box
    r = min(r, math.hypot(xmax - xmin, ymax - ymin))
    # k = eta * e * (1 + 1/d) * log(q)
    k = max(1, math.ceil(eta * math.e * 1.5 * math.log(q))) if use_k_nearest else 0
    cell = max(r, 1e-9)
    ncx = max(1, min(int(math.ceil((xmax - xmin) / cell)), 4096))
    ncy = max(1, min(int(math.ceil((ymax - ymin) / cell)), 4096))
    cell = max(cell, (xmax - xmin) / ncx, (ymax - ymin) / ncy)
    start, items = build_grid(p.xy, np.arange(n), xmin, ymin, cell, ncx, ncy)
    new = np.flatnonzero((p.batch[:n] == number) & ~vertex[:n])
    new_start, new_items = build_grid(p.xy, new, xmin, ymin, cell, ncx, ncy)
    return Batch(number, r, k, xmin, ymin, cell, ncx, ncy, start, items, new_start, new_items,
                 new)


class InformedSampler:
    """Uniform samples of the informed set: the points of the arena whose ``g_hat + h_hat``
    is below the best cost (an ellipse with foci start and goal), or the whole arena.

    Args:
        start: Start (2,) [m].
        goal: Goal (2,) [m].
        box: Arena (xmin, ymin, xmax, ymax) [m].
    """

    def __init__(self, start: np.ndarray, goal: np.ndarray,
                 box: tuple[float, float, float, float]) -> None:
        self.start = start
        self.goal = goal
        self.box = box
        self.c_min = float(np.hypot(*(goal - start)))
        self.center = (start + goal) / 2.0
        d = goal - start
        ang = math.atan2(d[1], d[0]) if self.c_min > 0.0 else 0.0
        self.rot = np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]])

    def measure(self, c_best: float) -> float:
        """Area [m^2] of the informed set for the cost ``c_best`` (capped by the arena's)."""
        xmin, ymin, xmax, ymax = self.box
        box = (xmax - xmin) * (ymax - ymin)
        if not math.isfinite(c_best):
            return box
        a = c_best / 2.0
        b = math.sqrt(max(c_best * c_best - self.c_min * self.c_min, 0.0)) / 2.0
        return min(math.pi * a * b, box)

    def sample(self, rng: np.random.Generator, m: int, c_best: float, obs: ObstacleSet,
               limit: float) -> np.ndarray:
        """``m`` samples (fewer if the set is nearly all blocked) whose clearance in ``obs``
        is at least ``limit`` [m]."""
        xmin, ymin, xmax, ymax = self.box
        box_area = (xmax - xmin) * (ymax - ymin)
        out: list[np.ndarray] = []
        got = 0
        for _ in range(64):
            need = m - got
            if need <= 0:
                break
            k = int(need * 1.3) + 8
            if math.isfinite(c_best) and self.measure(c_best) < box_area:
                # Direct sampling of the ellipse: uniform in the unit disc, scaled and rotated.
                a = c_best / 2.0
                b = math.sqrt(max(c_best * c_best - self.c_min * self.c_min, 0.0)) / 2.0
                u = rng.random((k, 2))
                rho = np.sqrt(u[:, 0])
                th = 2.0 * math.pi * u[:, 1]
                local = np.column_stack([a * rho * np.cos(th), b * rho * np.sin(th)])
                pts = transform_points(local, self.rot) + self.center
                inside = ((pts[:, 0] > xmin) & (pts[:, 0] < xmax)
                          & (pts[:, 1] > ymin) & (pts[:, 1] < ymax))
                pts = pts[inside]
            else:
                u = rng.random((k, 2))
                pts = np.column_stack([xmin + u[:, 0] * (xmax - xmin),
                                       ymin + u[:, 1] * (ymax - ymin)])
                if math.isfinite(c_best):
                    f = (np.hypot(*(pts - self.start).T) + np.hypot(*(pts - self.goal).T))
                    pts = pts[f < c_best]
            if len(pts):
                pts = pts[obs.points_clear(pts, limit)]
            pts = pts[:need]
            out.append(pts)
            got += len(pts)
        return np.vstack(out) if out else np.zeros((0, 2))


# --- neighbour grids -----------------------------------------------------------------------
@njit(cache=True, inline="always")
def _cell_of(x: float, y: float, x0: float, y0: float, cell: float, ncx: int,
             ncy: int) -> tuple[int, int]:
    """Grid cell (column, row) of the point (x, y), clamped to the grid."""
    return (min(max(int((x - x0) / cell), 0), ncx - 1), min(max(int((y - y0) / cell), 0), ncy - 1))


@njit(cache=True)
def build_grid(xy: np.ndarray, idx: np.ndarray, x0: float, y0: float, cell: float, ncx: int,
               ncy: int) -> tuple[np.ndarray, np.ndarray]:
    """Counting sort of the points ``idx`` into ncx x ncy cells of side ``cell`` (CSR)."""
    n = idx.shape[0]
    cstart = np.zeros(ncx * ncy + 1, np.int64)
    cid = np.empty(n, np.int64)
    for t in range(n):
        i = idx[t]
        cx, cy = _cell_of(xy[i, 0], xy[i, 1], x0, y0, cell, ncx, ncy)
        cid[t] = cy * ncx + cx
        cstart[cid[t] + 1] += 1
    for c in range(ncx * ncy):
        cstart[c + 1] += cstart[c]
    fill = cstart[:-1].copy()
    citems = np.empty(n, np.int64)
    for t in range(n):
        citems[fill[cid[t]]] = idx[t]
        fill[cid[t]] += 1
    return cstart, citems


@njit(cache=True, inline="always")
def near(v: int, p: Points, b: Batch, rad: float, cstart: np.ndarray, citems: np.ndarray,
         out: np.ndarray, dout: np.ndarray) -> int:
    """Points of the grid (cstart, citems) within ``rad`` of point v (v excluded) into
    ``out`` (ids) and ``dout`` (distances [m]), scratch of at least ``p.n[0]`` slots; returns
    their number. ``rad`` must not exceed ``b.cell``."""
    xy = p.xy
    ncx = b.ncx
    ncy = b.ncy
    px = xy[v, 0]
    py = xy[v, 1]
    cx, cy = _cell_of(px, py, b.x0, b.y0, b.cell, ncx, ncy)
    r2 = rad * rad
    m = 0
    for yy in range(max(cy - 1, 0), min(cy + 2, ncy)):
        for xx in range(max(cx - 1, 0), min(cx + 2, ncx)):
            c = yy * ncx + xx
            for t in range(cstart[c], cstart[c + 1]):
                j = citems[t]
                if j == v:
                    continue
                dx = xy[j, 0] - px
                dy = xy[j, 1] - py
                d2 = dx * dx + dy * dy
                if d2 <= r2:
                    out[m] = j
                    dout[m] = math.sqrt(d2)
                    m += 1
    return m


@njit(cache=True)
def k_nearest(v: int, p: Points, b: Batch, out: np.ndarray, dout: np.ndarray) -> int:
    """The ``b.k`` nearest points to v (v excluded) into ``out``/``dout`` (as :func:`near`),
    nearest first, searching grid rings outwards; returns their number.

    Points outside the (2 ring + 1)^2 block of cells around v's cell are farther than
    ``ring * cell``, so the search stops once k candidates lie within that distance.
    """
    xy = p.xy
    cstart = b.start
    citems = b.items
    cell = b.cell
    ncx = b.ncx
    ncy = b.ncy
    px = xy[v, 0]
    py = xy[v, 1]
    cx, cy = _cell_of(px, py, b.x0, b.y0, cell, ncx, ncy)
    ring = 1
    n_total = p.n[0] - 1
    kk = min(b.k, n_total)
    while True:
        m = 0
        for yy in range(max(cy - ring, 0), min(cy + ring + 1, ncy)):
            for xx in range(max(cx - ring, 0), min(cx + ring + 1, ncx)):
                c = yy * ncx + xx
                for t in range(cstart[c], cstart[c + 1]):
                    j = citems[t]
                    if j == v:
                        continue
                    out[m] = j
                    dout[m] = math.hypot(xy[j, 0] - px, xy[j, 1] - py)
                    m += 1
        covers_all = (cx - ring <= 0 and cy - ring <= 0 and cx + ring >= ncx - 1
                      and cy + ring >= ncy - 1)
        if m >= kk:
            # The kk nearest first, ascending, ties in candidate order (a partial stable
            # selection sort, in place: out and dout are refilled if the ring grows; far
            # cheaper to compile than np.argsort).
            for i in range(kk):
                j = i
                for t in range(i + 1, m):
                    if dout[t] < dout[j]:
                        j = t
                dj = dout[j]
                oj = out[j]
                for t in range(j, i, -1):
                    dout[t] = dout[t - 1]
                    out[t] = out[t - 1]
                dout[i] = dj
                out[i] = oj
            if dout[kk - 1] <= ring * cell or covers_all:
                return kk
        elif covers_all:
            return m
        ring += 1


# --- pruning --------------------------------------------------------------------------------
def compact(p: Points, t: Tree, state: np.ndarray, next_batch_number: int) -> np.ndarray:
    """Drop, recycle and keep points, keeping the tree consistent (see :func:`_compact`)."""
    return _compact(tuple(p), tuple(t), state, next_batch_number)


@njit(cache=True)
def _compact(p_fields: tuple, t_fields: tuple, state: np.ndarray,
             next_batch_number: int) -> np.ndarray:
    """Drop, recycle and keep points, keeping the tree consistent.

    ``state[i]``: 0 drop, 1 keep as a sample, 2 keep as a vertex if still a vertex. A vertex
    keeps its place in the tree only if its parent does; otherwise it (and its subtree) becomes
    a sample (new in batch ``next_batch_number``), or is dropped if its state is 0. Start and
    goal are never dropped. Returns the old-to-new index map (-1 for dropped points). Takes
    the records as plain tuples (see :mod:`anyplan.planning.bitstar._search`).
    """
    p = Points(*p_fields)
    t = Tree(*t_fields)
    n = p.n[0]
    state[0] = 2
    if state[1] == 0:
        state[1] = 1
    # Top-down pass from the root: a vertex survives only below a surviving vertex.
    keepv = _tree.surviving_vertices(t, n, state)
    new = np.full(n, -1, np.int64)
    m = 0
    for i in range(n):
        if state[i] > 0 or keepv[i]:
            new[i] = m
            m += 1
    for i in range(n):
        j = new[i]
        if j < 0:
            continue
        p.xy[j, 0] = p.xy[i, 0]
        p.xy[j, 1] = p.xy[i, 1]
        p.g_hat[j] = p.g_hat[i]
        p.h_hat[j] = p.h_hat[i]
        if keepv[i]:
            t.g[j] = t.g[i]
            t.parent[j] = new[t.parent[i]] if i != 0 else -1
            t.old[j] = t.old[i]
            t.vertex[j] = True
            t.expanded[j] = t.expanded[i]
        else:
            if t.vertex[i]:
                p.batch[j] = next_batch_number  # a recycled vertex is a new sample next batch
            else:
                p.batch[j] = p.batch[i]
            t.g[j] = math.inf
            t.parent[j] = -1
            t.vertex[j] = False
            t.old[j] = False
            t.expanded[j] = -1
    for j in range(m):
        t.child[j] = -1
        t.next_sibling[j] = -1
        t.prev_sibling[j] = -1
    for j in range(m - 1, -1, -1):
        q = t.parent[j]
        if q >= 0:
            _tree.attach(t, j, q)
    t.g[0] = 0.0
    p.n[0] = m
    return new
