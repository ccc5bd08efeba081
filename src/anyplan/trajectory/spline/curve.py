"""The smooth curve: a planar C2 cubic spline through a path's points, parameterised by arc length.

The paper (Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic
Environment", §4) turns BIT*'s polyline into a smooth curve with a cubic spline. Here it
interpolates the path's points (the curve ``scipy.interpolate.CubicSpline`` would give), natural
at the end and natural or clamped to a start heading (and curvature) at the start, and is refitted
at the exact arc lengths of its samples so that u is arc length to ~1e-4.
Notation: u the curve parameter, s arc length [m], r(u) the point, kappa the signed curvature.
The curve's arrays travel as one :class:`CurveArrays` record (compiled kernels in ``_pp``,
``_arclength``, ``_fit``, ``_drive``).
Construction and error bounds: ``docs/motion.md`` ("Smoothing and collision certification").
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.trajectory.spline import _drive, _fit, _pp
from anyplan.trajectory.spline._arclength import GL_W, GL_X, hermite_u_of_s
from anyplan.trajectory.spline.arrays import CurveArrays, ProfileArrays

__all__ = ["CurveArrays", "ProfileArrays", "SmoothCurve", "START_KNOT", "MAX_TURN"]

# Sub-sample fractions of a piece used to estimate its tangent turn.
_FR9 = np.linspace(0.0, 1.0, 9)

#: Distance [m] of the extra knot from the start when a start curvature is imposed.
START_KNOT = 0.5

#: Largest tangent turn [rad] across one evaluation-grid interval.
MAX_TURN = 0.05


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
        arrays: The curve as one :class:`CurveArrays` record (for compiled kernels).
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

        # One compiled pass (_fit.build_curve):
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
        self.arrays = CurveArrays._make(_fit.build_curve(
            pts, mode, tan, nrm, START_KNOT, int(reparam_iters), float(resample_step),
            float(grid_step), MAX_TURN, _FR9, GL_X, GL_W))
        a = self.arrays
        self.knots, self.point_u, self.u_grid, self.s_grid = a.x, a.point_u, a.u_grid, a.s_grid
        self.length = float(self.s_grid[-1])

    # --- evaluation -------------------------------------------------------------------------
    @staticmethod
    def _u_array(u: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(u, dtype=float).ravel())

    def position(self, u: np.ndarray) -> np.ndarray:
        """Points r(u) [m], shape (N, 2), for parameters ``u`` (N,)."""
        u = np.asarray(u, dtype=float)
        out = _pp.pp_eval_clipped(self.arrays.x, self.arrays.c, self._u_array(u), 0)
        return out.reshape(u.shape + (2,))

    def derivatives(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(r', r'', r''') at ``u``, each of shape (N, 2)."""
        u = np.asarray(u, dtype=float)
        d1, d2, d3 = _pp.pp_derivs(self.arrays.x, self.arrays.c, self._u_array(u))
        shp = u.shape + (2,)
        return d1.reshape(shp), d2.reshape(shp), d3.reshape(shp)

    def heading(self, u: np.ndarray) -> np.ndarray:
        """Tangent direction [rad] at ``u``."""
        u = np.asarray(u, dtype=float)
        d1 = _pp.pp_eval_clipped(self.arrays.x, self.arrays.c, self._u_array(u), 1)
        return np.arctan2(d1[:, 1], d1[:, 0]).reshape(u.shape)

    def curvature(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed curvature kappa [1/m] and its arc-length derivative dkappa/ds [1/m^2] at ``u``."""
        u = np.asarray(u, dtype=float)
        k, dk = _pp.pp_curvature(self.arrays.x, self.arrays.c, self._u_array(u))
        return k.reshape(u.shape), dk.reshape(u.shape)

    def u_of_s(self, s: np.ndarray) -> np.ndarray:
        """Parameter u at arc length ``s`` [m].

        Cubic Hermite interpolation of u(s) on the grid, with the exact slopes du/ds = 1/|r'(u)|
        at the grid points: error O(ds^4), so the speed along the curve is 1 to ~1e-6.
        """
        s = np.asarray(s, dtype=float)
        out = hermite_u_of_s(self.s_grid, self.u_grid, self.arrays.dus, self.length, self._u_array(s))
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
        return bool(_pp.regular(self.arrays, float(min_speed)))

    def samples(self, step: float = 0.05) -> np.ndarray:
        """Points (M, 2) [m] along the curve about ``step`` apart, endpoints included."""
        n = max(2, math.ceil(self.length / step) + 1)
        return self.position(self.u_of_s(np.linspace(0.0, self.length, n)))

    def curvature_bounds(self, u: np.ndarray, fractions: np.ndarray,
                         with_ends: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Per interval [u_i, u_{i+1}] of the increasing ``u``: max |kappa| and max |dkappa/ds|
        over the points u_i + f (u_{i+1} - u_i), f in ``fractions``; with ``with_ends`` |kappa|
        exactly at both ends also counts."""
        return _pp.abs_curvature_max(self.arrays.x, self.arrays.c,
                                     np.ascontiguousarray(u, dtype=float),
                                     np.ascontiguousarray(fractions, dtype=float), bool(with_ends))

    def sample_profile(self, profile: ProfileArrays, tau: np.ndarray,
                       full: bool = True) -> np.ndarray:
        """(x, y, theta, v, omega) (5, N) of driving along the curve with ``profile`` (its arc
        lengths, speeds and times), at profile times ``tau`` (N,) [s] (clamped); (x, y) (2, N)
        alone when not ``full``."""
        a = self.arrays
        return _drive.curve_sample(a.x, a.c, a.s_grid, a.u_grid, a.dus, profile.s, profile.v,
                                   profile.t, tau, bool(full))

    def profile_speed_bound(self, profile: ProfileArrays, nsub: int = 8) -> float:
        """Bound on |d position / dt| [m/s] when driving with ``profile``, before any inflation:
        per profile interval the largest chord rate |dr|/ds over ``nsub`` equal parts times the
        interval's larger end speed."""
        return float(_drive.speed_bound(self.arrays, profile, nsub))
