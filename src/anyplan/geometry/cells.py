"""Occupied grid cells merged into disjoint axis-aligned rectangles, without loss or excess.

A grid is a boolean array ``occ`` of shape (ny, nx), row 0 at the *bottom* (smallest y). Cell
(j, i) is the closed box [x0 + i h, x0 + (i + 1) h] x [y0 + j h, y0 + (j + 1) h]. The merge:

1. each row is cut into maximal runs of occupied cells;
2. a run continues the rectangle of the row below when that rectangle spans exactly the same
   columns (and was extended up to the row below), else it starts a new one.

The rectangles partition the occupied cells exactly (each cell in exactly one rectangle), so
their union is the occupied area, their areas sum to it, and their corners are computed from
integer cell indices, so that neighbouring rectangles share bit-identical coordinates.

Examples:
    >>> import numpy as np
    >>> occ = np.array([[1, 1, 0], [1, 1, 0], [0, 0, 1]], dtype=bool)
    >>> merge_cells(occ).tolist()      # (col0, row0, col1, row1), half-open
    [[0, 0, 2, 2], [2, 2, 3, 3]]
"""

from __future__ import annotations

import numpy as np

__all__ = ["merge_cells", "cell_boxes", "convex_corners", "paint"]


def merge_cells(occ: np.ndarray) -> np.ndarray:
    """Disjoint rectangles covering exactly the true cells of ``occ`` (ny, nx).

    Returns:
        int64 array (M, 4) of half-open cell ranges (col0, row0, col1, row1), ordered by row0
        then col0.
    """
    a = np.asarray(occ, dtype=bool)
    if a.ndim != 2:
        raise ValueError(f"occupancy must be a 2-D array, got shape {a.shape}")
    ny, nx = a.shape
    pad = np.zeros((ny, nx + 2), dtype=np.int8)
    pad[:, 1:-1] = a
    d = np.diff(pad, axis=1)
    rs, cs = np.nonzero(d == 1)     # run starts: (row, col)
    _, ce = np.nonzero(d == -1)     # run ends (exclusive), same order (row-major)
    out: list[list[int]] = []
    open_: dict[tuple[int, int], int] = {}   # (col0, col1) -> index into out, open at row-1
    k = 0
    n = len(rs)
    for row in range(ny):
        nxt: dict[tuple[int, int], int] = {}
        while k < n and rs[k] == row:
            key = (int(cs[k]), int(ce[k]))
            idx = open_.get(key)
            if idx is None:
                idx = len(out)
                out.append([key[0], row, key[1], row + 1])
            else:
                out[idx][3] = row + 1
            nxt[key] = idx
            k += 1
        open_ = nxt
    res = np.array(out, dtype=np.int64).reshape(-1, 4)
    order = np.lexsort((res[:, 0], res[:, 1]))
    return res[order]


def cell_boxes(rects: np.ndarray, origin: tuple[float, float], resolution: float) -> np.ndarray:
    """Cell ranges (M, 4) from :func:`merge_cells` as boxes (xmin, ymin, xmax, ymax) [m]."""
    r = np.asarray(rects, dtype=np.int64).reshape(-1, 4)
    x0, y0 = float(origin[0]), float(origin[1])
    h = float(resolution)
    return np.column_stack([x0 + r[:, 0] * h, y0 + r[:, 1] * h,
                            x0 + r[:, 2] * h, y0 + r[:, 3] * h]).astype(float)


def paint(rects: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """How many rectangles cover each cell, int array of ``shape`` (ny, nx) (for checks)."""
    cnt = np.zeros(shape, dtype=np.int64)
    for c0, r0, c1, r1 in np.asarray(rects, dtype=np.int64).reshape(-1, 4):
        cnt[r0:r1, c0:c1] += 1
    return cnt


def convex_corners(occ: np.ndarray) -> np.ndarray:
    """Grid vertices (col, row) that are convex corners of the occupied region, (K, 2) int.

    A grid vertex is a convex corner of the union of the occupied cells when exactly one of
    the four cells around it is occupied. (With two diagonal cells occupied it is a pinch
    point of two convex corners: it is listed too.) The shortest paths of a disc robot among
    the cells bend only around such corners.
    """
    a = np.asarray(occ, dtype=bool)
    ny, nx = a.shape
    pad = np.zeros((ny + 2, nx + 2), dtype=np.int8)
    pad[1:-1, 1:-1] = a
    # vertex (i, j) (col i in 0..nx, row j in 0..ny) touches cells (j-1..j, i-1..i)
    ll = pad[:-1, :-1]
    lr = pad[:-1, 1:]
    ul = pad[1:, :-1]
    ur = pad[1:, 1:]
    s = ll + lr + ul + ur
    diag = (s == 2) & (ll == ur)
    rows, cols = np.nonzero((s == 1) | diag)
    return np.column_stack([cols, rows]).astype(np.int64)
