"""From path to motion: cubic-spline smoothing, speed profiles, turning in place, trajectories.

The entry point is :func:`plan_motion` (polyline -> :class:`Trajectory`).
"""

from anyplan.trajectory.motion import plan_motion, polyline_trajectory, turn_segment
from anyplan.trajectory.profile import SpeedProfile, time_lower_bound, time_parameterize
from anyplan.trajectory.spline import (
    SmoothCurve,
    SmoothingResult,
    clean_path,
    curve_clearance_ok,
    shortcut_path,
    smooth_path,
)
from anyplan.trajectory.trajectory import (
    BrakeSegment,
    CurveSegment,
    Segment,
    Trajectory,
    TurnSegment,
)
from anyplan.trajectory.turn import RotationProfile, rotation_profile

__all__ = [
    "BrakeSegment",
    "CurveSegment",
    "RotationProfile",
    "Segment",
    "SmoothCurve",
    "SmoothingResult",
    "SpeedProfile",
    "Trajectory",
    "TurnSegment",
    "clean_path",
    "curve_clearance_ok",
    "plan_motion",
    "polyline_trajectory",
    "rotation_profile",
    "shortcut_path",
    "smooth_path",
    "time_lower_bound",
    "time_parameterize",
    "turn_segment",
]
