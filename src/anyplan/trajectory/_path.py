"""Compiled path cleaning: dropping repeated and collinear points, greedy shortcutting.

See :mod:`anyplan.trajectory.path` for the contracts and ``docs/motion.md``
("Smoothing and collision certification").
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from anyplan.geometry.collision import ObstacleArrays, segment_blocked_kernel


@njit(cache=True)
def clean_points(p: np.ndarray, tol: float, collinear_tol: float) -> np.ndarray:
    """The loop of ``spline.clean_path`` (p: (N >= 1, 2))."""
    n = p.shape[0]
    keep = np.empty((n, 2))
    keep[0, 0] = p[0, 0]
    keep[0, 1] = p[0, 1]
    nk = 1
    for j in range(1, n):
        if math.hypot(p[j, 0] - keep[nk - 1, 0], p[j, 1] - keep[nk - 1, 1]) > tol:
            keep[nk, 0] = p[j, 0]
            keep[nk, 1] = p[j, 1]
            nk += 1
    if nk > 1 and math.hypot(p[n - 1, 0] - keep[nk - 1, 0], p[n - 1, 1] - keep[nk - 1, 1]) > 0.0:
        keep[nk - 1, 0] = p[n - 1, 0]
        keep[nk - 1, 1] = p[n - 1, 1]
    out = np.empty((nk, 2))
    out[0, 0] = keep[0, 0]
    out[0, 1] = keep[0, 1]
    no = 1
    for i in range(1, nk - 1):
        abx = keep[i, 0] - out[no - 1, 0]
        aby = keep[i, 1] - out[no - 1, 1]
        acx = keep[i + 1, 0] - out[no - 1, 0]
        acy = keep[i + 1, 1] - out[no - 1, 1]
        lac = math.hypot(acx, acy)
        cross = abs(abx * acy - aby * acx) / max(lac, 1e-300)
        t = (abx * acx + aby * acy) / max(lac * lac, 1e-300)
        if cross < collinear_tol and 0.0 < t < 1.0:
            continue
        out[no, 0] = keep[i, 0]
        out[no, 1] = keep[i, 1]
        no += 1
    if nk > 1:
        out[no, 0] = keep[nk - 1, 0]
        out[no, 1] = keep[nk - 1, 1]
        no += 1
    res = np.empty((no, 2))
    for j in range(no):
        res[j, 0] = out[j, 0]
        res[j, 1] = out[j, 1]
    return res


@njit(cache=True)
def shortcut_indices(p: np.ndarray, limit: float, obs: ObstacleArrays) -> np.ndarray:
    """Indices kept by ``spline.shortcut_path``: from each kept vertex, the farthest one whose
    straight segment has clearance >= ``limit`` (else the next vertex). Scanning from the far end
    with the query stopping early below ``limit`` gives exactly the pass/fail of the exact
    clearance."""
    n = p.shape[0]
    keep = np.empty(n, dtype=np.int64)
    keep[0] = 0
    nk = 1
    i = 0
    while i < n - 1:
        nxt = i + 1
        for j in range(n - 1, i + 1, -1):
            if not segment_blocked_kernel(p[i, 0], p[i, 1], p[j, 0], p[j, 1], obs, limit):
                nxt = j
                break
        keep[nk] = nxt
        nk += 1
        i = nxt
    res = np.empty(nk, dtype=np.int64)
    for j in range(nk):
        res[j] = keep[j]
    return res
