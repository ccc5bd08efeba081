"""Cubic-spline smoothing of a piecewise-linear path, with certified collision checking.

The paper (Roy, Harchowdhury & Vachhani, "Anytime Planning: A Motion Planner for Dynamic
Environment", §4) turns BIT*'s polyline into a smooth curve with a cubic spline. Here the spline
interpolates the path's points with ``scipy.interpolate.CubicSpline``, parameterised by (very
nearly) arc length: the knots start at the cumulative chord lengths and are then replaced, a few
times, by the arc lengths of the previous fit. The exact arc length s(u) is tabulated by
Gauss-Legendre quadrature, so nothing downstream depends on the parameter being exactly s.

End conditions: natural (zero curvature) at the end; at the start either natural, or a clamped
unit tangent when a start heading is given (the curve leaves the start along that heading).

Certified collision check (:func:`curve_clearance_ok`): the curve is cut into pieces
[u_j, u_{j+1}] that never straddle a knot. On such a piece r''(u) is linear in u, so
M_j = max(|r''(u_j)|, |r''(u_{j+1})|) bounds |r''| on it, and the curve stays within
M_j h_j^2 / 8 of its chord (h_j = u_{j+1} - u_j). The disc robot of radius R is therefore free
along the piece if the chord's *exact* clearance (:meth:`ObstacleSet.segments_clearance`) is at
least R + M_j h_j^2 / 8. Pieces that fail are subdivided a few times before they are declared
in collision, so the test is sufficient (never misses a contact) and nearly tight.

Repair (:func:`smooth_path`): where a spline interval (between two consecutive interpolation
points) is not certified, the midpoints of that polyline segment and of its neighbours are added
to the interpolation points. The new points lie on the polyline, so the geometric route is
unchanged while the spline is pulled toward the segments; as the points get denser the spline
converges to the polyline, which is free, so a few rounds suffice in practice. If they do not,
the caller falls back to the polyline (see :mod:`anyplan.trajectory.motion`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet

__all__ = ["SmoothCurve", "SmoothingResult", "clean_path", "curve_clearance_ok", "smooth_path"]

# Gauss-Legendre nodes/weights on [0, 1] (5 points: exact for polynomials of degree 9).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(5)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


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
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(p) == 0:
        raise ValueError("path must contain at least one point")
    keep = [p[0]]
    for q in p[1:]:
        if math.hypot(q[0] - keep[-1][0], q[1] - keep[-1][1]) > tol:
            keep.append(q)
    if len(keep) > 1 and math.hypot(*(p[-1] - keep[-1])) > 0.0:
        keep[-1] = p[-1]
    out = [keep[0]]
    for i in range(1, len(keep) - 1):
        a, b, c = out[-1], keep[i], keep[i + 1]
        ab, ac = b - a, c - a
        lac = math.hypot(*ac)
        cross = abs(ab[0] * ac[1] - ab[1] * ac[0]) / max(lac, 1e-300)
        t = float(ab @ ac) / max(lac * lac, 1e-300)
        if cross < collinear_tol and 0.0 < t < 1.0:
            continue
        out.append(b)
    if len(keep) > 1:
        out.append(keep[-1])
    return np.array(out)


class SmoothCurve:
    """A planar cubic spline r(u) through ``points``, with u close to arc length.

    Args:
        points: Interpolation points (N >= 2, 2) [m], consecutive points distinct.
        start_heading: If given, the curve leaves ``points[0]`` along this heading [rad]
            (clamped unit tangent); otherwise the start is natural (zero curvature).
        grid_step: Target spacing [m] of the evaluation grid used for arc length tables,
            speed profiles and collision certification.
        reparam_iters: Number of knot updates toward arc length.

    Attributes:
        points: The interpolation points (N, 2).
        knots: Spline parameters of the points (N,).
        u_grid: Evaluation grid in u, containing every knot (M,).
        s_grid: Exact arc length [m] at ``u_grid`` (M,).
        length: Total arc length [m].
    """

    def __init__(self, points: np.ndarray, start_heading: float | None = None,
                 grid_step: float = 0.02, reparam_iters: int = 3) -> None:
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        if len(pts) < 2:
            raise ValueError("a curve needs at least two points")
        chords = np.hypot(*np.diff(pts, axis=0).T)
        if np.any(chords <= 0.0):
            raise ValueError("consecutive curve points must be distinct")
        self.points = pts
        self.start_heading = start_heading
        if start_heading is None:
            bc: object = "natural"
        else:
            tan = np.array([math.cos(start_heading), math.sin(start_heading)])
            bc = ((1, tan), (2, np.zeros(2)))
        u = np.concatenate([[0.0], np.cumsum(chords)])
        for _ in range(max(reparam_iters, 0)):
            cs = CubicSpline(u, pts, axis=0, bc_type=bc)
            u = np.concatenate([[0.0], np.cumsum(self._piece_lengths(cs, u))])
        self.knots = u
        self._cs = CubicSpline(u, pts, axis=0, bc_type=bc)
        self._d1 = self._cs.derivative(1)
        self._d2 = self._cs.derivative(2)
        self._d3 = self._cs.derivative(3)
        # Evaluation grid: every knot, each piece cut into equal parts of about grid_step.
        parts = [np.linspace(u[k], u[k + 1], max(1, math.ceil((u[k + 1] - u[k]) / grid_step)) + 1)[:-1]
                 for k in range(len(u) - 1)]
        self.u_grid = np.concatenate(parts + [u[-1:]])
        ds = self._sub_lengths(self.u_grid)
        self.s_grid = np.concatenate([[0.0], np.cumsum(ds)])
        self.length = float(self.s_grid[-1])

    # --- evaluation -------------------------------------------------------------------------
    @staticmethod
    def _piece_lengths(cs: CubicSpline, u: np.ndarray) -> np.ndarray:
        d1 = cs.derivative(1)
        out = np.zeros(len(u) - 1)
        # 4 sub-intervals x 5 Gauss points per piece: relative error far below 1e-9 here.
        for j in range(4):
            a = u[:-1] + (u[1:] - u[:-1]) * j / 4.0
            h = (u[1:] - u[:-1]) / 4.0
            for x, w in zip(_GL_X, _GL_W, strict=True):
                out += w * h * np.hypot(*d1(a + x * h).T)
        return out

    def _sub_lengths(self, ug: np.ndarray) -> np.ndarray:
        a, h = ug[:-1], np.diff(ug)
        out = np.zeros(len(h))
        for x, w in zip(_GL_X, _GL_W, strict=True):
            out += w * h * np.hypot(*self._d1(a + x * h).T)
        return out

    def position(self, u: np.ndarray) -> np.ndarray:
        """Points r(u) [m], shape (N, 2), for parameters ``u`` (N,)."""
        return self._cs(np.clip(np.asarray(u, dtype=float), 0.0, self.knots[-1]))

    def derivatives(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(r', r'', r''') at ``u``, each of shape (N, 2)."""
        uu = np.clip(np.asarray(u, dtype=float), 0.0, self.knots[-1])
        return self._d1(uu), self._d2(uu), self._d3(uu)

    def heading(self, u: np.ndarray) -> np.ndarray:
        """Tangent direction [rad] at ``u``."""
        d1 = self._d1(np.clip(np.asarray(u, dtype=float), 0.0, self.knots[-1]))
        return np.arctan2(d1[..., 1], d1[..., 0])

    def curvature(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed curvature kappa [1/m] and its arc-length derivative dkappa/ds [1/m^2] at ``u``."""
        d1, d2, d3 = self.derivatives(u)
        sp = np.hypot(d1[..., 0], d1[..., 1])
        cr = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        kappa = cr / sp**3
        dcr = d1[..., 0] * d3[..., 1] - d1[..., 1] * d3[..., 0]
        dot = d1[..., 0] * d2[..., 0] + d1[..., 1] * d2[..., 1]
        dk_du = dcr / sp**3 - 3.0 * cr * dot / sp**5
        return kappa, dk_du / sp

    def u_of_s(self, s: np.ndarray) -> np.ndarray:
        """Parameter u at arc length ``s`` [m] (linear in the grid table; error << 1 mm)."""
        return np.interp(np.asarray(s, dtype=float), self.s_grid, self.u_grid)

    def knot_index(self, u: np.ndarray) -> np.ndarray:
        """Index k of the spline interval [knots[k], knots[k+1]] containing each ``u``."""
        k = np.searchsorted(self.knots, np.asarray(u, dtype=float), side="right") - 1
        return np.clip(k, 0, len(self.knots) - 2)

    def samples(self, step: float = 0.05) -> np.ndarray:
        """Points (M, 2) [m] along the curve about ``step`` apart, endpoints included."""
        n = max(2, math.ceil(self.length / step) + 1)
        return self.position(self.u_of_s(np.linspace(0.0, self.length, n)))


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
        ``(free, bad, margin)``: whether the whole curve is certified free; the sorted spline
        interval indices (into ``curve.knots``) that could not be certified; and a certified
        lower bound [m] of the clearance minus ``radius`` over the certified pieces.
    """
    u = curve.u_grid
    limit = radius - COLLISION_EPS
    a_u, b_u = u[:-1], u[1:]
    bad_idx: list[int] = []
    margin = math.inf
    for depth in range(max_depth + 1):
        if len(a_u) == 0:
            break
        pa, pb = curve.position(a_u), curve.position(b_u)
        _, d2a, _ = curve.derivatives(a_u)
        # r'' at b from the left: evaluate slightly inside the piece to stay on the same cubic.
        _, d2b, _ = curve.derivatives(b_u - 1e-12 * np.maximum(1.0, np.abs(b_u)))
        m = np.maximum(np.hypot(*d2a.T), np.hypot(*d2b.T))
        dev = m * (b_u - a_u) ** 2 / 8.0
        clr = obstacles.segments_clearance(pa, pb) - dev
        ok = clr >= limit
        if np.any(ok):
            margin = min(margin, float(np.min(clr[ok])) - radius)
        fail = ~ok
        if not np.any(fail):
            a_u = b_u = np.zeros(0)
            break
        if depth == max_depth:
            bad_idx.extend(curve.knot_index(0.5 * (a_u[fail] + b_u[fail])).tolist())
            break
        fa, fb = a_u[fail], b_u[fail]
        parts = np.linspace(0.0, 1.0, 5)
        sub = fa[:, None] + (fb - fa)[:, None] * parts[None, :]
        a_u, b_u = sub[:, :-1].ravel(), sub[:, 1:].ravel()
    bad = np.unique(np.array(bad_idx, dtype=int))
    return len(bad) == 0, bad, margin


@dataclass
class SmoothingResult:
    """Outcome of :func:`smooth_path`.

    Attributes:
        curve: The certified collision-free curve, or None if repair failed.
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
                grid_step: float = 0.02, min_segment: float = 0.02) -> SmoothingResult:
    """Fit a cubic spline through ``path`` and repair it until it is certified collision-free.

    Args:
        path: Polyline (N, 2) [m]; its first and last points are kept exactly.
        obstacles: Static obstacles (including any virtual ones) and walls.
        radius: Required clearance [m] of the curve.
        start_heading: Heading [rad] the curve must start with, or None.
        max_rounds: Repair rounds before giving up.
        grid_step: Evaluation grid spacing [m] (see :class:`SmoothCurve`).
        min_segment: Polyline segments shorter than this [m] are not split further.

    Returns:
        A :class:`SmoothingResult`; ``curve`` is None when no certified curve was found.
    """
    pts = clean_path(path)
    if len(pts) < 2:
        raise ValueError("path must contain two distinct points")
    n0 = len(pts)
    for rnd in range(max_rounds + 1):
        curve = SmoothCurve(pts, start_heading=start_heading, grid_step=grid_step)
        free, bad, margin = curve_clearance_ok(curve, obstacles, radius)
        if free:
            return SmoothingResult(curve, rnd, len(pts) - n0, margin)
        if rnd == max_rounds:
            break
        # Split the offending polyline segments and their neighbours at their midpoints.
        split = set()
        for k in bad.tolist():
            for j in (k - 1, k, k + 1):
                if 0 <= j < len(pts) - 1:
                    split.add(j)
        new = [pts[0]]
        added = 0
        for j in range(len(pts) - 1):
            a, b = pts[j], pts[j + 1]
            if j in split and math.hypot(*(b - a)) > min_segment:
                new.append(0.5 * (a + b))
                added += 1
            new.append(b)
        if added == 0:
            break
        pts = np.array(new)
    return SmoothingResult(None, max_rounds, len(pts) - n0, float("nan"))
