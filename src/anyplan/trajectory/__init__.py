"""From path to motion: cubic-spline smoothing, speed profiles, turning in place, trajectories.

The entry point is :func:`plan_motion` (polyline -> :class:`Trajectory`). One module per concept:
``path`` (cleaning, shortcutting), ``spline`` (the curve, its certification and repair),
``profile`` (speed profile), ``turn`` and ``brake`` (their segments), ``trajectory`` (the timed
motion), ``kinds`` (string-valued enums of how motions are built), ``motion`` (the chain) and
``spacetime`` (timing among moving obstacles); compiled kernels beside each concept.
See ``docs/motion.md``.
"""

from anyplan.trajectory.kinds import ST_PREFIX, MotionKind, SegmentKind
from anyplan.trajectory.motion import plan_motion, polyline_trajectory, turn_segment
from anyplan.trajectory.path import clean_path, shortcut_path
from anyplan.trajectory.profile import ProfileArrays, SpeedProfile, time_lower_bound, time_parameterize
from anyplan.trajectory.spline import (
    CurveArrays,
    SmoothCurve,
    SmoothingResult,
    curve_clearance_ok,
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
    "ST_PREFIX",
    "CurveArrays",
    "MotionKind",
    "ProfileArrays",
    "SegmentKind",
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
