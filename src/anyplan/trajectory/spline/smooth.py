"""Smoothing a path into a certified collision-free curve (:func:`smooth_path`).

A :class:`~anyplan.trajectory.spline.SmoothCurve` is fitted through the cleaned path and repaired
until :mod:`~anyplan.trajectory.spline.clearance` certifies it: in every interpolation interval
that is not certified, the worst point is projected onto the interval's polyline segment and
that projection (kept to the middle 60 % of the segment) becomes a new interpolation point. New
points lie on the polyline, so the route is unchanged while the spline is pulled back toward the
segments where it strayed (``repair="midpoint"`` splits the segment and its neighbours instead).
If repair fails, the caller falls back to the polyline (:mod:`anyplan.trajectory.motion`).
Paper: Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic
Environment", §4. Measurements: ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.se2 import dot2
from anyplan.trajectory.path import clean_path, split_long_segments
from anyplan.trajectory.spline.clearance import worst_failures, worst_per_group
from anyplan.trajectory.spline.curve import SmoothCurve

__all__ = ["MAX_SEGMENT_M", "SmoothingResult", "smooth_path"]


@dataclass
class SmoothingResult:
    """Outcome of :func:`smooth_path`.

    Attributes:
        curve: The certified collision-free curve, or None if repair failed or the curve has a
            cusp (see :meth:`SmoothCurve.is_regular`).
        rounds: Repair rounds used (0: the first spline was free).
        points_added: Interpolation points inserted by the repair.
        margin: Certified clearance above the required radius [m] (nan if no curve); with
            ``tight_margin`` False a certified lower bound of it, at most 5 cm.
    """

    curve: SmoothCurve | None
    rounds: int
    points_added: int
    margin: float


#: Recent answers of :func:`smooth_path`, newest last: (key, answer). A planner smooths the same
#: path among the same obstacles several times (one path timed with several departure delays);
#: the key is the content of every input, so a hit is the same computation. The answer's curve
#: is shared (a :class:`SmoothCurve` is not changed once built).
_MEMO: list[tuple[bytes, SmoothingResult]] = []
_MEMO_SIZE = 16
#: The repair gives up once the number of failing intervals has grown this many rounds in a
#: row: each inserted point then makes more failures than it removes (the curve is forced
#: through an obstacle, e.g. by its start heading and curvature), and the rounds left only
#: cost more and more. Measured on 2221 smoothings of st-bitstar and seq-bitstar runs
#: (DynaBARN 20-59, paper-1..3, 6 random and 21 gap worlds): no successful repair ever grew
#: twice in a row (3 grew once; all succeeded within 5 rounds), 53 of the 75 failures grew
#: 1, 2, 4, 8, ... intervals and ran all 10 rounds, 2.6 s of the 4.3 s spent smoothing.
_DIVERGING_ROUNDS = 3

#: Longest polyline segment [m] the spline is fitted over: longer ones are split evenly first
#: (:func:`~anyplan.trajectory.path.split_long_segments`).
#: A C2 spline through points hundreds of metres apart swings metres off its polyline after a
#: turn (14 m out of a 12 m corridor on a 600 m path), and the repair then certifies the whole
#: curve round after round. Above the segments of the benchmarks' arenas (the longest smoothed
#: on DynaBARN's 23 m x 21 m worlds is 20.3 m), but for the 40 m x 30 m hall of many obstacles.
MAX_SEGMENT_M = 25.0


def smooth_path(path: np.ndarray, obstacles: ObstacleSet, radius: float,
                start_heading: float | None = None, max_rounds: int = 10,
                grid_step: float = 0.02, min_segment: float = 0.02,
                repair: str = "project", start_curvature: float | None = None,
                tight_margin: bool = True) -> SmoothingResult:
    """Fit a cubic spline through ``path`` and repair it until it is certified collision-free.

    Args:
        path: Polyline (N, 2) [m]; its first and last points are kept exactly.
        obstacles: Static obstacles (including any virtual ones) and walls.
        radius: Required clearance [m] of the curve.
        start_heading: Heading [rad] the curve must start with, or None.
        max_rounds: Repair rounds before giving up (earlier when the repair diverges: the
            failing intervals grew three rounds in a row).
        grid_step: Evaluation grid spacing [m] (see :class:`SmoothCurve`).
        min_segment: Polyline segments shorter than this [m] are not split further.
        start_curvature: Curvature [1/m] at the start (with ``start_heading``), see
            :class:`SmoothCurve`.
        repair: ``"project"`` (default): in each interval that is not certified, insert the
            projection of its worst point onto the polyline segment (clamped to the middle 60 %
            of the segment); ``"midpoint"``: split that segment and both neighbours in half.
        tight_margin: False: the result's margin is a certified lower bound, at most 5 cm
            (``worst_failures``), instead of the tightest one; the curve is the same.

    Returns:
        A :class:`SmoothingResult`; ``curve`` is None when no certified curve was found.
    """
    h = hashlib.blake2b(np.ascontiguousarray(path, dtype=float).tobytes(), digest_size=16)
    h.update(obstacles.fingerprint)
    h.update(repr((np.shape(path), float(radius), None if start_heading is None else float(start_heading),
                   int(max_rounds), float(grid_step), float(min_segment), repair,
                   None if start_curvature is None else float(start_curvature),
                   bool(tight_margin))).encode())
    key = h.digest()
    for k, ans in _MEMO:
        if k == key:
            return SmoothingResult(ans.curve, ans.rounds, ans.points_added, ans.margin)
    out = _smooth_path(path, obstacles, radius, start_heading, max_rounds, grid_step, min_segment,
                       repair, start_curvature, tight_margin)
    _MEMO.append((key, out))
    del _MEMO[:-_MEMO_SIZE]
    return SmoothingResult(out.curve, out.rounds, out.points_added, out.margin)


def _smooth_path(path: np.ndarray, obstacles: ObstacleSet, radius: float,
                 start_heading: float | None, max_rounds: int, grid_step: float,
                 min_segment: float, repair: str, start_curvature: float | None,
                 tight_margin: bool = True) -> SmoothingResult:
    pts = clean_path(path)
    if len(pts) < 2:
        raise ValueError("path must contain two distinct points")
    pts = split_long_segments(pts, MAX_SEGMENT_M)
    n0 = len(pts)
    failing = -1
    grew = 0
    for rnd in range(max_rounds + 1):
        curve = SmoothCurve(pts, start_heading=start_heading, grid_step=grid_step,
                            start_curvature=start_curvature)
        if not curve.is_regular():
            # a cusp comes from the start heading, which no repair changes
            return SmoothingResult(None, rnd, len(pts) - n0, float("nan"))
        kk, fu, fc, margin = worst_failures(curve, obstacles, radius, 4, tight_margin)
        if len(kk) == 0:
            return SmoothingResult(curve, rnd, len(pts) - n0, margin)
        grew = grew + 1 if failing >= 0 and len(kk) > failing else 0
        failing = len(kk)
        if rnd == max_rounds or grew >= _DIVERGING_ROUNDS:
            break
        if repair == "midpoint":
            # Split the offending polyline segments and their neighbours at their midpoints.
            split = {j: 0.5 for k in np.unique(kk).tolist() for j in (k - 1, k, k + 1)
                     if 0 <= j < len(pts) - 1}
        else:
            # Project the worst point of each offending interval onto its polyline segment and
            # insert it there (kept away from the ends so that segments shrink geometrically).
            split = {}
            for k, j in zip(*worst_per_group(kk, fc), strict=True):
                k = int(k)
                q = curve.position(fu[j:j + 1])[0]
                a, b = pts[k], pts[k + 1]
                ab = b - a
                lam = dot2(q - a, ab) / dot2(ab, ab)
                split[k] = min(max(lam, 0.2), 0.8)
        new = [pts[0]]
        added = 0
        for j in range(len(pts) - 1):
            a, b = pts[j], pts[j + 1]
            if j in split and math.hypot(*(b - a)) > min_segment:
                new.append(a + split[j] * (b - a))
                added += 1
            new.append(b)
        if added == 0:
            break
        pts = np.array(new)
    return SmoothingResult(None, rnd, len(pts) - n0, float("nan"))
