"""Compiled flood fill of :mod:`anyplan.planning.connectivity` (its only importer)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def connected8(open_: np.ndarray, a0: int, a1: int, b0: int, b1: int) -> bool:
    """True if cells (a0, a1) and (b0, b1) of the boolean grid ``open_`` are joined by a chain of
    open cells, each an 8-neighbour of the next (both cells open); breadth-first from a."""
    ny, nx = open_.shape
    if not (open_[a0, a1] and open_[b0, b1]):
        return False
    seen = np.zeros((ny, nx), dtype=np.bool_)
    queue = np.empty(ny * nx, dtype=np.int64)
    seen[a0, a1] = True
    queue[0] = a0 * nx + a1
    head, tail = 0, 1
    while head < tail:
        k = queue[head]
        head += 1
        i, j = k // nx, k % nx
        if i == b0 and j == b1:
            return True
        for di in range(-1, 2):
            for dj in range(-1, 2):
                u, w = i + di, j + dj
                if 0 <= u < ny and 0 <= w < nx and open_[u, w] and not seen[u, w]:
                    seen[u, w] = True
                    queue[tail] = u * nx + w
                    tail += 1
    return False
