"""The records that carry a smooth curve and a speed profile into the compiled kernels.

:class:`CurveArrays` (a :class:`~anyplan.trajectory.spline.curve.SmoothCurve` as flat arrays)
and :class:`ProfileArrays` (a speed profile's grid) are the only form in which their arrays
cross into ``_fit``, ``_pp``, ``_clearance`` and ``_drive``. They sit below both the curve and
the kernels, so that neither imports the other for them.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["CurveArrays", "ProfileArrays"]


class CurveArrays(NamedTuple):
    """A :class:`~anyplan.trajectory.spline.curve.SmoothCurve` as flat arrays, one argument of
    the compiled kernels. Produced only by the curve (from ``_fit.build_curve``).

    P cubic pieces, N interpolation points, M evaluation-grid points.
    """

    #: Breakpoints (knots) of the piecewise cubic [m], shape (P + 1,).
    x: np.ndarray
    #: Coefficients in ascending powers of (u - x[i]) on piece i, shape (P, 4, 2).
    c: np.ndarray
    #: Curve parameter of each interpolation point, shape (N,).
    point_u: np.ndarray
    #: Evaluation grid in u, containing every knot, shape (M,).
    u_grid: np.ndarray
    #: Exact arc length [m] at ``u_grid``, shape (M,).
    s_grid: np.ndarray
    #: du/ds = 1 / |r'(u)| at ``u_grid``, shape (M,).
    dus: np.ndarray


class ProfileArrays(NamedTuple):
    """The grid of a speed profile driven along a smooth curve, as contiguous float
    arrays, one argument of the driving kernels (``_drive``). Produced only by
    :attr:`anyplan.trajectory.profile.SpeedProfile.arrays`."""

    #: Arc length [m] at the grid, shape (M,).
    s: np.ndarray
    #: Speed [m/s] at the grid, shape (M,).
    v: np.ndarray
    #: Time [s] since the profile's start at the grid, shape (M,).
    t: np.ndarray
