"""Cubic-spline smoothing of a piecewise-linear path, with certified collision checking.

* :mod:`.curve`: :class:`SmoothCurve`, the arc-length C2 cubic through the path's points;
* :mod:`.arrays`: :class:`CurveArrays` and :class:`ProfileArrays`, the curve's arrays and a speed
  profile's grid as records for the compiled kernels;
* :mod:`.clearance`: :func:`curve_clearance_ok`, the certified sweep test of a disc robot;
* :mod:`.smooth`: :func:`smooth_path`, fit and repair until certified.

Compiled kernels live beside them: ``_fit`` (fitting), ``_arclength`` (arc length and u(s)),
``_pp`` (evaluation), ``_clearance`` (certification), ``_drive`` (driving along the curve with a
speed profile). :func:`clean_path` and :func:`shortcut_path` (:mod:`anyplan.trajectory.path`)
are re-exported here, where they used to live. See ``docs/motion.md`` ("Smoothing and collision
certification").
"""

from anyplan.trajectory.path import clean_path, shortcut_path
from anyplan.trajectory.spline.clearance import curve_clearance_ok
from anyplan.trajectory.spline.curve import MAX_TURN, START_KNOT, CurveArrays, ProfileArrays, SmoothCurve
from anyplan.trajectory.spline.smooth import SmoothingResult, smooth_path

__all__ = [
    "MAX_TURN",
    "START_KNOT",
    "CurveArrays",
    "ProfileArrays",
    "SmoothCurve",
    "SmoothingResult",
    "clean_path",
    "curve_clearance_ok",
    "shortcut_path",
    "smooth_path",
]
