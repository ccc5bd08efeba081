"""Cleaning a planned polyline before it is smoothed: repeated, collinear and skippable vertices.

Sampling planners return many jittery vertices (BIT* at a fixed budget: one every few
centimetres, off the straight line by millimetres), and a spline through all of them wiggles.
:func:`clean_path` drops repeated points and interior points on the line through their
neighbours; :func:`shortcut_path` jumps greedily from each kept vertex to the farthest one whose
straight segment keeps a given clearance (exact test), so the result is never longer and stays
free. Compiled loops in ``_path``. See ``docs/motion.md`` ("Smoothing and collision
certification").
"""

from __future__ import annotations

import numpy as np

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.trajectory import _path

__all__ = ["clean_path", "shortcut_path"]


def clean_path(path: np.ndarray, tol: float = 1e-9, collinear_tol: float = 1e-9) -> np.ndarray:
    """Drop repeated points and interior points lying on the straight line through neighbours.

    Args:
        path: Points (N, 2) [m].
        tol: Points closer than this [m] to the previous kept point are dropped.
        collinear_tol: An interior point is dropped when it deviates from the chord of its
            neighbours by less than this [m] and lies between them.

    Returns:
        The cleaned points (M, 2), first and last kept.
    """
    p = np.ascontiguousarray(np.asarray(path, dtype=float).reshape(-1, 2))
    if len(p) == 0:
        raise ValueError("path must contain at least one point")
    # Compiled loop: drop points within tol of the last kept one (the last input point always
    # replaces the last kept one), then interior points off the chord of their kept predecessor
    # and next point by less than collinear_tol and strictly between them.
    return _path.clean_points(p, float(tol), float(collinear_tol))


def shortcut_path(path: np.ndarray, obstacles: ObstacleSet, radius: float) -> np.ndarray:
    """Drop vertices greedily: from each kept vertex jump to the farthest one in straight sight.

    Sampling planners return many jittery vertices (BIT* at a fixed budget: one every few
    centimetres, off the straight line by millimetres); a spline through all of them wiggles
    with a curvature that forces the robot to crawl. A vertex is skipped only when the straight
    segment that replaces it keeps a clearance of at least ``radius`` [m] (exact test), so the
    result is never longer and stays free for a disc of ``radius``. Segments of the input that
    are not free at ``radius`` are kept as they are.

    Args:
        path: Polyline (N, 2) [m].
        obstacles: Obstacles (all that the path must avoid, virtual ones included).
        radius: Clearance [m] every new segment must keep.

    Returns:
        A subsequence of ``path`` with the same first and last points.
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(p) <= 2:
        return p.copy()
    keep = _path.shortcut_indices(np.ascontiguousarray(p), radius - COLLISION_EPS, obstacles.arrays)
    return p[keep]
