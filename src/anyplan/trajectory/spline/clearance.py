"""Certified collision check of a smooth curve for a disc robot (:func:`curve_clearance_ok`).

The curve is cut into the pieces of its evaluation grid, which never straddle a knot; on such a
piece r'' is linear, so M = max |r''| at both ends bounds it and the curve stays within
M h^2 / 8 of its chord (h the piece's parameter length). The disc of radius R is free along the
piece if the chord's exact clearance is at least R + M h^2 / 8; pieces that fail are split in 4
a few times before they count as colliding, so the test never misses a contact and is nearly
tight. Notation: u curve parameter, k the interpolation interval ``point_u[k:k+2]``.
Compiled kernels in ``_clearance``; the curve and the obstacles arrive there as one record each.
See ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import numpy as np

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.trajectory.spline import _clearance
from anyplan.trajectory.spline.curve import SmoothCurve

__all__ = ["curve_clearance_ok", "failing_pieces", "worst_failures", "worst_per_group"]


def failing_pieces(curve: SmoothCurve, obstacles: ObstacleSet, radius: float,
             max_depth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Failing pieces: (interval index k, piece midpoint u, certified clearance), and the margin."""
    # Each grid piece, then each failing piece split in 4 (up to max_depth times): certified
    # when (exact chord clearance) - max(|r''(a)|, |r''(b-)|) (b - a)^2 / 8 >= radius - eps,
    # with r'' at b taken slightly inside the piece to stay on the same cubic.
    fail_u, fail_c, margin = _clearance.certify(curve.arrays, radius - COLLISION_EPS,
                                        float(radius), int(max_depth), obstacles.arrays)
    return curve.point_index(fail_u), fail_u, fail_c, margin


def worst_failures(curve: SmoothCurve, obstacles: ObstacleSet, radius: float, max_depth: int,
                   tight: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """What the repair uses of :func:`failing_pieces`: per interpolation interval with failing pieces,
    its first failing piece of least certified clearance (k, midpoint u, clearance), found by
    branch and bound (see ``_clearance.certify_worst``); the margin is valid when nothing fails
    (with ``tight`` False a certified lower bound of it, at most ``CAP_DELTA`` (5 cm), cheaper on
    a curve far from every obstacle).
    Not memoised: :func:`~anyplan.trajectory.spline.smooth.smooth_path` memoises whole
    smoothings, and a curve certified twice outside that memo is rare (1-2 % of the calls)."""
    return _clearance.certify_worst(curve.arrays, radius - COLLISION_EPS, float(radius),
                                    int(max_depth), obstacles.arrays, bool(tight))


def curve_clearance_ok(curve: SmoothCurve, obstacles: ObstacleSet, radius: float,
                       max_depth: int = 4) -> tuple[bool, np.ndarray, float]:
    """Certified check that a disc of ``radius`` [m] swept along ``curve`` touches nothing.

    Args:
        curve: The curve.
        obstacles: Static obstacles and walls.
        radius: Required clearance [m] of the curve (robot radius plus any margin).
        max_depth: Each failing grid piece is split in 4, at most this many times, before it
            is reported as colliding.

    Returns:
        ``(free, bad, margin)``: whether the whole curve is certified free; the sorted indices k
        of the interpolation intervals (``curve.point_u[k:k+2]``) that could not be certified;
        and a certified lower bound [m] of the clearance minus ``radius`` over the certified
        pieces.
    """
    k, _, _, margin = failing_pieces(curve, obstacles, radius, max_depth)
    bad = np.unique(k.astype(int))
    return len(bad) == 0, bad, margin


def worst_per_group(k: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For a non-decreasing ``k``: each distinct value and the index of the first minimum of
    ``v`` among its entries."""
    return _clearance.worst_per_group(np.ascontiguousarray(k, dtype=np.int64),
                                      np.ascontiguousarray(v, dtype=float))
