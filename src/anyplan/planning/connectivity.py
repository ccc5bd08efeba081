"""A fast proof that the goal cannot be reached, for large maps: connectivity of a cell cover.

Cover the arena with square cells of side h. A cell whose centre has clearance below
``r - h sqrt(2) / 2`` lies wholly in collision for a disc robot of radius r (clearance is
1-Lipschitz), so it is *blocked*. Any collision-free path passes through a chain of unblocked
cells, each sharing at least a point with the next (8-neighbours). Hence, if the cells of the
start and of the goal are not 8-connected through unblocked cells, no collision-free path
exists: the answer ``True`` is a proof, ``False`` proves nothing. The cost is one pass/fail
clearance query per cell and a compiled flood fill, whatever the number of obstacles,
unlike the visibility graph's lower bound (quadratic in the obstacle corners).
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.planning._connectivity_kernels import connected8

__all__ = ["provably_disconnected"]

#: Most cells of the cover (the cell side grows beyond it).
MAX_CELLS = 120_000


def provably_disconnected(obstacles: ObstacleSet, start: np.ndarray | tuple[float, float],
                          goal: np.ndarray | tuple[float, float], radius: float,
                          cell: float | None = None) -> bool:
    """True only if no collision-free path of the disc robot joins ``start`` and ``goal``.

    Args:
        obstacles: The static obstacles; their ``bounds`` (the arena) are required.
        start: Start position (x, y) [m].
        goal: Goal position (x, y) [m].
        radius: Robot radius [m], > 0.
        cell: Cell side [m]; default max(radius / 2, the side giving :data:`MAX_CELLS` cells).
    """
    if obstacles.bounds is None or not radius > 0.0:
        return False
    x0, y0, x1, y1 = obstacles.bounds
    w, h_ = x1 - x0, y1 - y0
    h = cell if cell is not None else max(radius / 2.0, math.sqrt(w * h_ / MAX_CELLS))
    limit = radius - h * math.sqrt(2.0) / 2.0 - 1e-9
    if limit <= 0.0:
        return False  # no cell can be proven blocked
    nx, ny = max(1, math.ceil(w / h)), max(1, math.ceil(h_ / h))
    xs = x0 + (np.arange(nx) + 0.5) * h
    ys = y0 + (np.arange(ny) + 0.5) * h
    gx, gy = np.meshgrid(xs, ys)
    open_ = obstacles.points_clear(np.column_stack([gx.ravel(), gy.ravel()]), limit)
    open_ = np.ascontiguousarray(open_.reshape(ny, nx), dtype=np.bool_)

    def cell_of(p: np.ndarray | tuple[float, float]) -> tuple[int, int]:
        return (min(max(int((p[1] - y0) // h), 0), ny - 1), min(max(int((p[0] - x0) // h), 0), nx - 1))

    (a0, a1), (b0, b1) = cell_of(start), cell_of(goal)
    # a point on a cell border also belongs to the neighbour: only conclude when the
    # endpoints' own cells are open and not joined
    return bool(open_[a0, a1] and open_[b0, b1] and not connected8(open_, a0, a1, b0, b1))
