"""Names of how a reference motion was built and of its segments, as string-valued enums.

A :class:`MotionKind` is a :class:`~anyplan.trajectory.Trajectory`'s ``kind``; a
:class:`SegmentKind` is a segment's. Both are :class:`enum.StrEnum`, so each member *is* its
string: it compares equal to it, formats and serialises (``json``) as it, and ``result.json``
keeps exactly the strings it had. Layers above compose kinds by prefixing a base kind (the
space-time re-timing :data:`ST_PREFIX`, an agent's delayed departure ``"wait+"``); such
composites are plain strings. See ``docs/motion.md`` ("``plan_motion`` and
``Trajectory``").
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["MotionKind", "SegmentKind", "ST_PREFIX"]


class MotionKind(StrEnum):
    """How :func:`~anyplan.trajectory.plan_motion` (or a fallback) built a trajectory."""

    #: Drive off along a spline from the current heading, speed and curvature.
    SMOOTH = "smooth"
    #: Turn in place toward the path, then drive a spline tangent to it.
    TURN_SMOOTH = "turn+smooth"
    #: Brake to rest, turn in place, then drive a spline.
    BRAKE_TURN_SMOOTH = "brake+turn+smooth"
    #: Fallback: per segment, turn in place and drive straight from rest to rest.
    POLYLINE = "polyline"
    #: Nothing to drive: brake (if moving) and stay.
    HOLD = "hold"
    #: An agent's fallback: brake and hold until a new plan.
    FALLBACK_HOLD = "fallback-hold"
    #: An agent's fallback: an arc at a target twist entered without stopping, then brake.
    SWERVE = "swerve"


class SegmentKind(StrEnum):
    """What a :class:`~anyplan.trajectory.Segment` does."""

    #: Driving along a curve with a speed profile.
    CURVE = "curve"
    #: Turning in place.
    TURN = "turn"
    #: Braking to rest.
    BRAKE = "brake"
    #: Standing still.
    HOLD = "hold"
    #: Ramping to a target twist and holding it (an arc entered without stopping).
    SWERVE = "swerve"
    #: Driving along a curve with a space-time velocity plan.
    ST_CURVE = "st-curve"


#: Prefix of a trajectory re-timed by the space-time planner (:mod:`anyplan.trajectory.spacetime`).
ST_PREFIX = "st+"

