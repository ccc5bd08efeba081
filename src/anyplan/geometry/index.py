"""A uniform-grid spatial index over polygon bounding boxes, for many static obstacles.

Each polygon is listed in every grid cell its (closed) bounding box meets. The compiled
clearance kernels (:mod:`anyplan.geometry.collision`) then visit only the cells near a query
and grow the searched radius until the answer is certain, so a query costs what the obstacles
*near it* cost, not what all of them cost, and stays exact.

The grid is built only for sets of at least :data:`MIN_INDEXED` polygons: below that a plain
scan with bounding-box rejection is as fast, and the few-obstacle case is left untouched.

Examples:
    >>> import numpy as np
    >>> boxes = np.array([[0.0, 0.0, 1.0, 1.0], [3.0, 0.0, 4.0, 0.5]])
    >>> meta, csr = build_grid(boxes, cell=1.0)
    >>> meta.tolist()
    [0.0, 0.0, 1.0, 5.0, 2.0, 2.0, 0.0]
    >>> cell_items(meta, csr, 0, 3).tolist()   # row 0, column 3: the second box
    [1]
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["MIN_INDEXED", "NO_GRID", "build_grid", "cell_items"]

#: Polygon count from which an :class:`~anyplan.geometry.collision.ObstacleSet` builds a grid.
MIN_INDEXED = 48

#: The "no index" metadata: every polygon is scanned linearly.
NO_GRID = (np.zeros(7), np.zeros(1, dtype=np.int64))


def build_grid(pbox: np.ndarray, cell: float | None = None,
               max_cells: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Index the boxes ``pbox`` (P, 4) = (xmin, ymin, xmax, ymax) [m] in a uniform grid.

    Args:
        pbox: Bounding boxes of the polygons to index (all of them: ``n_indexed = P``).
        cell: Cell side [m]; default sqrt(extent area / P), about one box per cell, but never
            smaller than the median box side (so that a box spans few cells).
        max_cells: Cap on nx * ny (default 4 P + 64); the cell grows to respect it.

    Returns:
        ``gmeta`` (7,) = (x0, y0, cell, nx, ny, P, 0) and ``gcsr`` (int64), see
        :class:`anyplan.geometry.collision.ObstacleArrays`.
    """
    b = np.asarray(pbox, dtype=float).reshape(-1, 4)
    n = len(b)
    if n == 0:
        return NO_GRID[0].copy(), NO_GRID[1].copy()
    x0, y0 = float(b[:, 0].min()), float(b[:, 1].min())
    w = max(float(b[:, 2].max()) - x0, 1e-9)
    hgt = max(float(b[:, 3].max()) - y0, 1e-9)
    if cell is None:
        side = np.maximum(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1])
        cell = max(math.sqrt(w * hgt / n), float(np.median(side)), 1e-6)
    cap = 4 * n + 64 if max_cells is None else int(max_cells)
    h = float(cell)
    while (math.floor(w / h) + 1) * (math.floor(hgt / h) + 1) > cap:
        h *= 1.25
    nx = int(math.floor(w / h)) + 1
    ny = int(math.floor(hgt / h)) + 1
    ix0 = np.clip(np.floor((b[:, 0] - x0) / h).astype(np.int64), 0, nx - 1)
    ix1 = np.clip(np.floor((b[:, 2] - x0) / h).astype(np.int64), 0, nx - 1)
    iy0 = np.clip(np.floor((b[:, 1] - y0) / h).astype(np.int64), 0, ny - 1)
    iy1 = np.clip(np.floor((b[:, 3] - y0) / h).astype(np.int64), 0, ny - 1)
    wx = ix1 - ix0 + 1
    counts = wx * (iy1 - iy0 + 1)
    item = np.repeat(np.arange(n, dtype=np.int64), counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    local = np.arange(len(item), dtype=np.int64) - first
    col = ix0[item] + local % wx[item]
    row = iy0[item] + local // wx[item]
    cid = row * nx + col
    order = np.argsort(cid, kind="stable")
    ncell = nx * ny
    offsets = np.zeros(ncell + 1, dtype=np.int64)
    np.cumsum(np.bincount(cid, minlength=ncell), out=offsets[1:])
    gcsr = np.concatenate([offsets + (ncell + 1), item[order]]).astype(np.int64)
    gmeta = np.array([x0, y0, h, nx, ny, n, 0.0], dtype=float)
    return gmeta, gcsr


def cell_items(gmeta: np.ndarray, gcsr: np.ndarray, row: int, col: int) -> np.ndarray:
    """Indices of the polygons listed in grid cell (``row``, ``col``)."""
    nx = int(gmeta[3])
    c = row * nx + col
    return gcsr[gcsr[c]:gcsr[c + 1]]
