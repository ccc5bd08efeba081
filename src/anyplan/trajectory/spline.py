"""Cubic-spline smoothing of a piecewise-linear path, with certified collision checking.

The paper (Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic
Environment", §4) turns BIT*'s polyline into a smooth curve with a cubic spline. Here the spline
interpolates the path's points (the C2 interpolating cubic that ``scipy.interpolate.CubicSpline``
would give, solved by our own tridiagonal numba kernel in :mod:`anyplan.trajectory._kernels` and
evaluated there from its piecewise-polynomial coefficients) and is parameterised by arc
length: a first fit uses chord lengths as knots, which are then replaced (twice) by the arc
lengths of the previous fit; finally the fit is resampled at short parameter steps, every sample
(the interpolation points among them) gets its exact arc length (Gauss-Legendre quadrature) as
its parameter, and the spline is fitted again through these samples. The arc length s(u) is also
tabulated exactly on the evaluation grid, so nothing downstream depends on |r'(u)| being 1.

End conditions: natural (zero curvature) at the end; at the start either natural, or a clamped
unit tangent when a start heading is given (the curve leaves the start along that heading).

Certified collision check (:func:`curve_clearance_ok`): the curve is cut into pieces
[u_j, u_{j+1}] that never straddle a knot. On such a piece r''(u) is linear in u, so
M_j = max(|r''(u_j)|, |r''(u_{j+1})|) bounds |r''| on it, and the curve stays within
M_j h_j^2 / 8 of its chord (h_j = u_{j+1} - u_j). The disc robot of radius R is therefore free
along the piece if the chord's *exact* clearance (:meth:`ObstacleSet.segments_clearance`) is at
least R + M_j h_j^2 / 8. Pieces that fail are subdivided a few times before they are declared
in collision, so the test is sufficient (never misses a contact) and nearly tight.

Repair (:func:`smooth_path`): in every interpolation interval where the curve is not certified,
the worst point is projected onto the interval's polyline segment and that projection (kept to
the middle 60 % of the segment) becomes a new interpolation point. New points lie on the
polyline, so the geometric route is unchanged while the spline is pulled back toward the
segments exactly where it strayed; as points accumulate the spline converges to the polyline,
which is free, so a few rounds suffice whenever the polyline has some slack. (The alternative
``repair="midpoint"`` splits the offending segment and its neighbours in half; it tightens more
corners than needed: on 24 random worlds with 20 obstacles its worst duration / lower bound was
1.088 against 1.054.) If repair fails, the caller falls back to the polyline
(see :mod:`anyplan.trajectory.motion`).

Path shortcutting (:func:`shortcut_path`) runs first: sampling planners return many jittery
vertices, and a spline through all of them wiggles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.trajectory import _kernels as _k

__all__ = [
    "SmoothCurve",
    "SmoothingResult",
    "clean_path",
    "curve_clearance_ok",
    "shortcut_path",
    "smooth_path",
]

# Gauss-Legendre nodes/weights on [0, 1] (5 points: exact for polynomials of degree 9).
_GL_X, _GL_W = _k.GL_X, _k.GL_W
# Sub-sample fractions of a piece used to estimate its tangent turn.
_FR9 = np.linspace(0.0, 1.0, 9)

#: Distance [m] of the extra knot from the start when a start curvature is imposed.
START_KNOT = 0.5

#: Largest tangent turn [rad] across one evaluation-grid interval.
MAX_TURN = 0.05


def _subdivide(u: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Cut each interval [u[k], u[k+1]] into n[k] equal parts; all breakpoints, in order."""
    return _k.subdivide(np.ascontiguousarray(u, dtype=float), np.ascontiguousarray(n, dtype=np.int64))


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
    return _k.clean_points(p, float(tol), float(collinear_tol))


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
    keep = _k.shortcut_indices(np.ascontiguousarray(p), radius - COLLISION_EPS, obstacles.arrays)
    return p[keep]


class SmoothCurve:
    """A planar cubic spline r(u) through ``points``, parameterised by arc length u.

    Args:
        points: Interpolation points (N >= 2, 2) [m], consecutive points distinct.
        start_heading: If given, the curve leaves ``points[0]`` along this heading [rad]
            (clamped unit tangent); otherwise the start is natural (zero curvature).
        start_curvature: With ``start_heading``, also the signed curvature [1/m] at the start,
            so that a robot already turning at omega = kappa v can take up the curve without a
            jump in its turn rate. This needs one more degree of freedom than a cubic spline
            through the points has: the C2 cubic gets one extra knot in the first interval (the
            curve ``scipy.interpolate.make_interp_spline`` builds with that knot vector).
        grid_step: Target spacing [m] of the evaluation grid used for arc length tables,
            speed profiles and collision certification (finer where the tangent turns by more
            than ``MAX_TURN`` across a step).
        reparam_iters: Number of knot updates toward arc length before the final refit.
        resample_step: Parameter step [m] of the arc-length refit.

    Attributes:
        points: The interpolation points (N, 2).
        point_u: Curve parameter (= arc length) of each interpolation point (N,).
        knots: Knots of the final spline (every interpolation point and the resampled points).
        u_grid: Evaluation grid in u, containing every knot (M,).
        s_grid: Exact arc length [m] at ``u_grid`` (M,).
        length: Total arc length [m].
    """

    def __init__(self, points: np.ndarray, start_heading: float | None = None,
                 grid_step: float = 0.02, reparam_iters: int = 2,
                 resample_step: float = 0.05, start_curvature: float | None = None) -> None:
        pts = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 2))
        if len(pts) < 2:
            raise ValueError("a curve needs at least two points")
        chords = np.hypot(*np.diff(pts, axis=0).T)
        if np.any(chords <= 0.0):
            raise ValueError("consecutive curve points must be distinct")
        self.points = pts
        self.start_heading = start_heading
        self.start_curvature = start_curvature if start_heading is not None else None
        tan = np.zeros(2)
        nrm = np.zeros(2)
        mode = 0
        if start_heading is not None:
            tan = np.array([math.cos(start_heading), math.sin(start_heading)])
            mode = 1
            if self.start_curvature is not None:
                nrm = np.array([-tan[1], tan[0]]) * float(self.start_curvature)
                mode = 2

        # One compiled pass (anyplan.trajectory._kernels.build_curve):
        # 1. knots u = chord lengths, then ``reparam_iters`` times the arc lengths of the fit;
        # 2. arc-length refit: every piece resampled at equal parameter steps of at most
        #    ``resample_step`` (at least 4 per piece), each sample's exact arc length (4 x 5-point
        #    Gauss-Legendre per step) becomes its parameter, and the spline is fitted through
        #    the samples (they include the interpolation points, so those and the end conditions
        #    are kept; the refit is unit speed to within ~1e-4); with a start curvature an extra
        #    knot min(half the first interval, START_KNOT) in sets how far it reaches;
        # 3. evaluation grid: every knot, each piece cut into equal parts of about grid_step, and
        #    finely enough that the tangent turns by at most MAX_TURN per part (|kappa| sampled at
        #    9 points per piece), at most 400 parts;
        # 4. exact arc length at the grid (5-point Gauss per part) and du/ds = 1 / |r'| there.
        (self._x, self._c, self.point_u, self.u_grid, self.s_grid,
         self._dus) = _k.build_curve(pts, mode, tan, nrm, START_KNOT, int(reparam_iters),
                                     float(resample_step), float(grid_step), MAX_TURN, _FR9,
                                     _GL_X, _GL_W)
        self.knots = self._x
        self.length = float(self.s_grid[-1])

    # --- evaluation -------------------------------------------------------------------------
    @staticmethod
    def _u_array(u: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(u, dtype=float).ravel())

    def position(self, u: np.ndarray) -> np.ndarray:
        """Points r(u) [m], shape (N, 2), for parameters ``u`` (N,)."""
        u = np.asarray(u, dtype=float)
        out = _k.pp_eval_clipped(self._x, self._c, self._u_array(u), 0)
        return out.reshape(u.shape + (2,))

    def derivatives(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(r', r'', r''') at ``u``, each of shape (N, 2)."""
        u = np.asarray(u, dtype=float)
        d1, d2, d3 = _k.pp_derivs(self._x, self._c, self._u_array(u))
        shp = u.shape + (2,)
        return d1.reshape(shp), d2.reshape(shp), d3.reshape(shp)

    def heading(self, u: np.ndarray) -> np.ndarray:
        """Tangent direction [rad] at ``u``."""
        u = np.asarray(u, dtype=float)
        d1 = _k.pp_eval_clipped(self._x, self._c, self._u_array(u), 1)
        return np.arctan2(d1[:, 1], d1[:, 0]).reshape(u.shape)

    def curvature(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed curvature kappa [1/m] and its arc-length derivative dkappa/ds [1/m^2] at ``u``."""
        u = np.asarray(u, dtype=float)
        k, dk = _k.pp_curvature(self._x, self._c, self._u_array(u))
        return k.reshape(u.shape), dk.reshape(u.shape)

    def u_of_s(self, s: np.ndarray) -> np.ndarray:
        """Parameter u at arc length ``s`` [m].

        Cubic Hermite interpolation of u(s) on the grid, with the exact slopes du/ds = 1/|r'(u)|
        at the grid points: error O(ds^4), so the speed along the curve is 1 to ~1e-6.
        """
        s = np.asarray(s, dtype=float)
        out = _k.hermite_u_of_s(self.s_grid, self.u_grid, self._dus, self.length, self._u_array(s))
        return out.reshape(s.shape)

    def point_index(self, u: np.ndarray) -> np.ndarray:
        """Index k of the interpolation interval [point_u[k], point_u[k+1]] containing each ``u``."""
        k = np.searchsorted(self.point_u, np.asarray(u, dtype=float), side="right") - 1
        return np.clip(k, 0, len(self.point_u) - 2)

    def is_regular(self, min_speed: float = 0.2) -> bool:
        """True if the curve has no cusp: |r'(u)| stays near 1 and the heading turns no faster
        than the curvature allows between grid points.

        A clamped start heading opposite to the path can fold the spline back on itself (a cusp,
        where the heading flips by pi at zero speed); such a curve cannot be driven.
        """
        # On the grid u and its midpoints: |r'| >= min_speed, and the wrapped heading change
        # across each grid interval <= 1.5 max(|kappa| at both ends and the middle) ds + 1e-6.
        return bool(_k.regular(self._x, self._c, self.u_grid, self.s_grid, float(min_speed)))

    def samples(self, step: float = 0.05) -> np.ndarray:
        """Points (M, 2) [m] along the curve about ``step`` apart, endpoints included."""
        n = max(2, math.ceil(self.length / step) + 1)
        return self.position(self.u_of_s(np.linspace(0.0, self.length, n)))


def _certify(curve: SmoothCurve, obstacles: ObstacleSet, radius: float,
             max_depth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Failing pieces: (interval index k, piece midpoint u, certified clearance), and the margin."""
    # Each grid piece, then each failing piece split in 4 (up to max_depth times): certified
    # when (exact chord clearance) - max(|r''(a)|, |r''(b-)|) (b - a)^2 / 8 >= radius - eps,
    # with r'' at b taken slightly inside the piece to stay on the same cubic.
    fail_u, fail_c, margin = _k.certify(curve._x, curve._c, curve.u_grid, radius - COLLISION_EPS,
                                        float(radius), int(max_depth), obstacles.arrays)
    return curve.point_index(fail_u), fail_u, fail_c, margin


def _worst_failures(curve: SmoothCurve, obstacles: ObstacleSet, radius: float,
                    max_depth: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """What the repair uses of :func:`_certify`: per interpolation interval with failing pieces,
    its first failing piece of least certified clearance (k, midpoint u, clearance), found by
    branch and bound (see ``_kernels.certify_worst``); the margin is valid when nothing fails."""
    return _k.certify_worst(curve._x, curve._c, curve.u_grid, curve.point_u, radius - COLLISION_EPS,
                            float(radius), int(max_depth), obstacles.arrays)


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
    k, _, _, margin = _certify(curve, obstacles, radius, max_depth)
    bad = np.unique(k.astype(int))
    return len(bad) == 0, bad, margin


@dataclass
class SmoothingResult:
    """Outcome of :func:`smooth_path`.

    Attributes:
        curve: The certified collision-free curve, or None if repair failed or the curve has a
            cusp (see :meth:`SmoothCurve.is_regular`).
        rounds: Repair rounds used (0: the first spline was free).
        points_added: Interpolation points inserted by the repair.
        margin: Certified clearance above the required radius [m] (nan if no curve).
    """

    curve: SmoothCurve | None
    rounds: int
    points_added: int
    margin: float


def smooth_path(path: np.ndarray, obstacles: ObstacleSet, radius: float,
                start_heading: float | None = None, max_rounds: int = 10,
                grid_step: float = 0.02, min_segment: float = 0.02,
                repair: str = "project", start_curvature: float | None = None) -> SmoothingResult:
    """Fit a cubic spline through ``path`` and repair it until it is certified collision-free.

    Args:
        path: Polyline (N, 2) [m]; its first and last points are kept exactly.
        obstacles: Static obstacles (including any virtual ones) and walls.
        radius: Required clearance [m] of the curve.
        start_heading: Heading [rad] the curve must start with, or None.
        max_rounds: Repair rounds before giving up.
        grid_step: Evaluation grid spacing [m] (see :class:`SmoothCurve`).
        min_segment: Polyline segments shorter than this [m] are not split further.
        start_curvature: Curvature [1/m] at the start (with ``start_heading``), see
            :class:`SmoothCurve`.
        repair: ``"project"`` (default): in each interval that is not certified, insert the
            projection of its worst point onto the polyline segment (clamped to the middle 60 %
            of the segment); ``"midpoint"``: split that segment and both neighbours in half.

    Returns:
        A :class:`SmoothingResult`; ``curve`` is None when no certified curve was found.
    """
    pts = clean_path(path)
    if len(pts) < 2:
        raise ValueError("path must contain two distinct points")
    n0 = len(pts)
    for rnd in range(max_rounds + 1):
        curve = SmoothCurve(pts, start_heading=start_heading, grid_step=grid_step,
                            start_curvature=start_curvature)
        if not curve.is_regular():
            # a cusp comes from the start heading, which no repair changes
            return SmoothingResult(None, rnd, len(pts) - n0, float("nan"))
        kk, fu, fc, margin = _worst_failures(curve, obstacles, radius, 4)
        if len(kk) == 0:
            return SmoothingResult(curve, rnd, len(pts) - n0, margin)
        if rnd == max_rounds:
            break
        if repair == "midpoint":
            # Split the offending polyline segments and their neighbours at their midpoints.
            split = {j: 0.5 for k in np.unique(kk).tolist() for j in (k - 1, k, k + 1)
                     if 0 <= j < len(pts) - 1}
        else:
            # Project the worst point of each offending interval onto its polyline segment and
            # insert it there (kept away from the ends so that segments shrink geometrically).
            split = {}
            for k, j in zip(*_k.worst_per_group(kk.astype(np.int64), fc), strict=True):
                k = int(k)
                q = curve.position(fu[j:j + 1])[0]
                a, b = pts[k], pts[k + 1]
                ab = b - a
                lam = float((q - a) @ ab) / float(ab @ ab)
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
    return SmoothingResult(None, max_rounds, len(pts) - n0, float("nan"))
