"""A fast proof that the goal cannot be reached, for large maps: connectivity of a cell cover.

Cover the arena with square cells of side h. A cell whose centre has clearance below
``r - h sqrt(2) / 2`` lies wholly in collision for a disc robot of radius r (clearance is
1-Lipschitz), so it is *blocked*. Any collision-free path passes through a chain of unblocked
cells, each sharing at least a point with the next (8-neighbours). Hence, if the cells of the
start and of the goal are not 8-connected through unblocked cells, no collision-free path
exists: the answer ``True`` is a proof, ``False`` proves nothing. When the cover cannot tell,
the cells near the obstacles (centre clearance below ``r + h sqrt(2) / 2``: neither blocked nor
wholly free) are split into finer cells and the fill runs again, so passages narrower than the
robot by less than the coarse cells' loss (``h sqrt(2) / 2``) are proven closed too, at the
cost of a fine cover only along the obstacles. The cost is clearance queries and compiled
flood fills, whatever the number of obstacles, unlike the visibility graph's lower bound
(quadratic in the obstacle corners).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.planning._connectivity_kernels import connected8
from anyplan.planning.problem import Problem
from anyplan.planning.visgraph import lower_bound

__all__ = ["exactly_unsolvable", "provably_disconnected"]

#: Most cells of the cover (the cell side grows beyond it).
MAX_CELLS = 120_000
#: Most fine cells whose clearance the refinement queries (beyond it, no refinement).
MAX_REFINED = 400_000
#: Fine cells the refinement may always query (beyond it and beyond four per coarse cell, the
#: fine cells are half the coarse side, not a quarter).
MIN_REFINED = 8192
#: Most polygon corners (a circle counts as :data:`CIRCLE_CORNERS`) for which
#: :func:`exactly_unsolvable` asks the visibility graph (its cost grows with the square
#: of the corners: about 6 ms for 16 here).
MAX_EXACT_CORNERS = 48
CIRCLE_CORNERS = 8


def exactly_unsolvable(problem: Problem) -> bool:
    """True only if no collision-free path joins the problem's start and goal, by the visibility
    graph's relaxation (:func:`anyplan.planning.visgraph.lower_bound` infinite), among few
    obstacles (:data:`MAX_EXACT_CORNERS`; False beyond). Unlike the cell cover it also proves
    passages closed by less than a cell (a square beside a wall's gap, 2 cm too close)."""
    arrays = problem.obstacles.arrays
    if len(arrays.vx) + CIRCLE_CORNERS * len(arrays.circles) > MAX_EXACT_CORNERS:
        return False
    return math.isinf(lower_bound(problem))


def provably_disconnected(obstacles: ObstacleSet, start: np.ndarray | tuple[float, float],
                          goal: np.ndarray | tuple[float, float], radius: float,
                          cell: float | None = None, refine: int = 4) -> bool:
    """True only if no collision-free path of the disc robot joins ``start`` and ``goal``.

    Args:
        obstacles: The static obstacles; their ``bounds`` (the arena) are required.
        start: Start position (x, y) [m].
        goal: Goal position (x, y) [m].
        radius: Robot radius [m], > 0.
        cell: Cell side [m]; default max(radius, the side giving :data:`MAX_CELLS` cells).
        refine: When the cover proves nothing, split the cells near the obstacles into
            ``refine`` x ``refine`` finer ones and try again (1: never). Halved down to 2
            while that queries more than four fine cells per coarse cell and more than
            :data:`MIN_REFINED` (along a map's many walls); no refinement beyond
            :data:`MAX_REFINED` fine cells.
    """
    if obstacles.bounds is None or not radius > 0.0:
        return False
    x0, y0, x1, y1 = obstacles.bounds
    w, h_ = x1 - x0, y1 - y0
    h = cell if cell is not None else max(radius, math.sqrt(w * h_ / MAX_CELLS))
    half = h * math.sqrt(2.0) / 2.0
    limit = radius - half - 1e-9
    if limit <= 0.0:
        return False  # no cell can be proven blocked
    nx, ny = max(1, math.ceil(w / h)), max(1, math.ceil(h_ / h))
    centres = _centres(x0, y0, h, nx, ny)
    # one exact clearance per cell when the set is small; on an indexed map, pass/fail
    # queries, which stop early, are cheaper even twice, and the map's own part is kept
    # across the calls of a replanning loop (_Cover: about 12 ms a call to 2 ms in the office)
    cover = _Cover(obstacles, x0, y0, h, nx, ny, centres) if obstacles.indexed else None
    if cover is None:
        dist = obstacles.clearances(centres).reshape(ny, nx)
        clear: Callable[[float], np.ndarray] = lambda lim: dist >= lim  # noqa: E731
    else:
        clear = cover.clear
    open_ = np.ascontiguousarray(clear(limit))
    a, b = _cell_of(start, x0, y0, h, nx, ny), _cell_of(goal, x0, y0, h, nx, ny)
    # a point on a cell border also belongs to the neighbour: only conclude when the
    # endpoints' own cells are open and not joined
    if not (open_[a] and open_[b]):
        return False
    if not connected8(open_, a[0], a[1], b[0], b[1]):
        return True
    k = int(refine)
    if k <= 1:
        return False
    # the cells neither blocked nor wholly free (centre clearance below radius + half) are
    # split; on the nested finer grid every cell the coarse cover would block stays blocked
    free = np.ascontiguousarray(clear(radius + half))
    if connected8(free, a[0], a[1], b[0], b[1]):
        return False  # a chain of wholly free cells joins them: a path exists
    near = open_ & ~free
    n_near = int(np.count_nonzero(near))
    # at most as many fine queries as a cover of half-size cells (4 per cell) would make, or
    # MIN_REFINED: along many walls (a map) the fine cells are half as wide
    while k > 2 and n_near * k * k > max(4 * nx * ny, MIN_REFINED):
        k //= 2
    if k <= 1 or n_near == 0 or n_near * k * k > MAX_REFINED:
        return False
    hf = h / k
    fine_limit = radius - hf * math.sqrt(2.0) / 2.0 - 1e-9
    fine = np.repeat(np.repeat(open_, k, axis=0), k, axis=1)
    if cover is None:
        fi, fj = _fine_cells(near, k)
        pts = _fine_centres(x0, y0, hf, fi, fj)
        fine[fi, fj] = obstacles.points_clear(pts, fine_limit)
    else:
        cover.refine(fine, near, k, fine_limit)
    fine = np.ascontiguousarray(fine)
    fa = _cell_of(start, x0, y0, hf, nx * k, ny * k)
    fb = _cell_of(goal, x0, y0, hf, nx * k, ny * k)
    return bool(fine[fa] and fine[fb] and not connected8(fine, fa[0], fa[1], fb[0], fb[1]))


def _fine_cells(near: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows, columns) of the k x k fine cells of each coarse cell marked in ``near``."""
    rows, cols = np.nonzero(near)
    di, dj = np.divmod(np.arange(k * k), k)
    return (rows[:, None] * k + di[None, :]).ravel(), (cols[:, None] * k + dj[None, :]).ravel()


def _fine_centres(x0: float, y0: float, hf: float, fi: np.ndarray, fj: np.ndarray) -> np.ndarray:
    """Centres (N, 2) [m] of the fine cells (rows ``fi``, columns ``fj``) of side ``hf``."""
    return np.column_stack([x0 + (fj + 0.5) * hf, y0 + (fi + 0.5) * hf])


#: Recent pass/fail masks of a map's boxes and walls (:class:`_Cover`), by cover and limit.
_MASKS: dict[tuple[object, ...], np.ndarray] = {}
#: Recent fine masks of a map's boxes and walls, and which coarse cells they hold (_Cover.refine).
_FINE: dict[tuple[object, ...], tuple[np.ndarray, np.ndarray]] = {}
_MEMO_SIZE = 4


def _remember(memo: dict[tuple[object, ...], Any], key: tuple[object, ...], value: Any) -> None:
    memo[key] = value
    while len(memo) > _MEMO_SIZE:
        del memo[next(iter(memo))]


class _Cover:
    """The pass/fail clearance tests of a cover on an indexed map. A map's boxes and walls are
    the same in every call of a replanning loop, only its virtual squares change: their cells'
    tests are kept (by the boxes' fingerprint) and combined with those of the shapes, the few
    squares, which are scanned linearly (clearance is the least over the parts, so a point is
    clear of the whole set iff it is clear of both: the same answers as testing the whole)."""

    def __init__(self, obstacles: ObstacleSet, x0: float, y0: float, h: float, nx: int, ny: int,
                 centres: np.ndarray) -> None:
        self.base, self.shapes = obstacles.split_boxes()
        self.key = (self.base.fingerprint, x0, y0, h, nx, ny)
        self.x0, self.y0, self.h, self.nx, self.ny = x0, y0, h, nx, ny
        self.centres = centres

    def clear(self, limit: float) -> np.ndarray:
        """(ny, nx): the cells whose centre has clearance >= ``limit`` [m]."""
        key = (*self.key, limit)
        mask = _MASKS.get(key)
        if mask is None:
            mask = self.base.points_clear(self.centres, limit).reshape(self.ny, self.nx)
            _remember(_MASKS, key, mask)
        out = mask.copy()
        at = np.flatnonzero(out)
        out.ravel()[at] = self._clear_of_shapes(self.centres[at], limit)
        return out

    def _clear_of_shapes(self, pts: np.ndarray, limit: float) -> np.ndarray:
        """Mask (N,): clearance from the shapes >= ``limit`` [m]. A point farther than
        ``limit`` from every shape's bounding box is clear of it (the box holds the shape);
        the others get the exact test."""
        out = np.ones(len(pts), dtype=bool)
        c = self.shapes.circles
        boxes = np.vstack([self.shapes.pbox, np.column_stack([c[:, :2] - c[:, 2:], c[:, :2] + c[:, 2:]])])
        if len(boxes) == 0 or len(pts) == 0:
            return out
        x, y = pts[:, 0:1], pts[:, 1:2]
        near = ((x >= boxes[:, 0] - limit) & (x <= boxes[:, 2] + limit)
                & (y >= boxes[:, 1] - limit) & (y <= boxes[:, 3] + limit)).any(axis=1)
        at = np.flatnonzero(near)
        if len(at):
            out[at] = self.shapes.points_clear(pts[at], limit)
        return out

    def refine(self, fine: np.ndarray, near: np.ndarray, k: int, limit: float) -> None:
        """Set the k x k fine cells of each ``near`` coarse cell in ``fine`` to their centres'
        test at ``limit`` [m] (clearance >= limit)."""
        key = (*self.key, k, limit)
        got = _FINE.get(key)
        if got is None:
            got = (np.zeros((self.ny * k, self.nx * k), dtype=bool),
                   np.zeros((self.ny, self.nx), dtype=bool))
            _remember(_FINE, key, got)
        base, done = got
        hf = self.h / k
        todo = near & ~done
        if todo.any():
            fi, fj = _fine_cells(todo, k)
            pts = _fine_centres(self.x0, self.y0, hf, fi, fj)
            base[fi, fj] = self.base.points_clear(pts, limit)
            done |= todo
        fi, fj = _fine_cells(near, k)
        vals = base[fi, fj]
        at = np.flatnonzero(vals)
        pts = _fine_centres(self.x0, self.y0, hf, fi[at], fj[at])
        vals[at] = self._clear_of_shapes(pts, limit)
        fine[fi, fj] = vals


def _centres(x0: float, y0: float, h: float, nx: int, ny: int) -> np.ndarray:
    """Centres (nx * ny, 2) of the cells, row by row (y), each row along x."""
    gx, gy = np.meshgrid(x0 + (np.arange(nx) + 0.5) * h, y0 + (np.arange(ny) + 0.5) * h)
    return np.column_stack([gx.ravel(), gy.ravel()])


def _cell_of(p: np.ndarray | tuple[float, float], x0: float, y0: float, h: float, nx: int,
             ny: int) -> tuple[int, int]:
    """(row, column) of the cell holding point ``p``, clamped to the cover."""
    return (min(max(int((p[1] - y0) // h), 0), ny - 1), min(max(int((p[0] - x0) // h), 0), nx - 1))
