"""Cleaning a planned polyline before it is smoothed: repeated, collinear and skippable vertices;
long segments split (:func:`split_long_segments`); the rest of a path from a point on the way
(:func:`remaining_path`).

Sampling planners return many jittery vertices (BIT* at a fixed budget: one every few
centimetres, off the straight line by millimetres), and a spline through all of them wiggles.
:func:`clean_path` drops repeated points and interior points on the line through their
neighbours; :func:`shortcut_path` jumps greedily from each kept vertex to the farthest one whose
straight segment keeps a given clearance (exact test), so the result is never longer and stays
free. Compiled loops in ``_path``. See ``docs/motion.md`` ("Smoothing and collision
certification").
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.trajectory import _path

__all__ = ["clean_path", "polyline_length", "remaining_path", "shortcut_path", "split_long_segments"]


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


def polyline_length(path: np.ndarray) -> float:
    """Length [m] of the polyline through ``path`` (N, 2) [m] (0 for fewer than two points).

    Examples:
        >>> polyline_length(np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 5.0]]))
        6.0
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    return float(np.sum(np.hypot(*np.diff(p, axis=0).T))) if len(p) >= 2 else 0.0


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


def remaining_path(path: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The part of ``path`` (N, 2) [m] after its point nearest to ``p`` (2,) [m], starting at
    ``p``: the path still ahead of a robot at ``p`` (at least ``p`` and the path's end)."""
    a, b = path[:-1], path[1:]
    ab = b - a
    den = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-18)
    u = np.clip(np.einsum("ij,ij->i", p - a, ab) / den, 0.0, 1.0)
    d = np.hypot(*(a + u[:, None] * ab - p).T)
    k = int(np.argmin(d))
    rest = path[k + 1:]
    if len(rest) and float(np.hypot(*(rest[0] - p))) < 1e-6:
        rest = rest[1:]
    return np.vstack([p, rest]) if len(rest) else np.vstack([p, path[-1:]])


def split_long_segments(pts: np.ndarray, max_len: float) -> np.ndarray:
    """``pts`` (N, 2) [m] with every segment longer than ``max_len`` [m] split into equal parts
    of at most ``max_len`` (points on the segment: the route is unchanged).

    Examples:
        >>> split_long_segments(np.array([[0.0, 0.0], [60.0, 0.0], [60.0, 10.0]]), 25.0)[:, 0]
        array([ 0., 20., 40., 60., 60.])
    """
    d = np.hypot(*np.diff(pts, axis=0).T)
    if not (d > max_len).any():
        return pts
    out = [pts[:1]]
    for j, dj in enumerate(d.tolist()):
        n = int(math.ceil(dj / max_len)) if dj > max_len else 1
        f = np.arange(1, n + 1)[:, None] / n
        out.append(pts[j] + f * (pts[j + 1] - pts[j]))
    return np.concatenate(out)
