"""The piece of reference motion that a :class:`~anyplan.trajectory.Trajectory` is made of.

A :class:`Segment` covers absolute times [t0, t1] [s] and samples the reference state
(x [m], y [m], theta [rad], v [m/s], omega [rad/s]) at any times, clamped to itself. The
segments of the trajectory package: driving along a curve (``CurveSegment``,
:mod:`anyplan.trajectory.trajectory`), turning in place (``TurnSegment``,
:mod:`anyplan.trajectory.turn`) and braking (``BrakeSegment``, :mod:`anyplan.trajectory.brake`).
See ``docs/motion.md`` ("``plan_motion`` and ``Trajectory``").
"""

from __future__ import annotations

import numpy as np

__all__ = ["Sample", "Segment"]

#: Arrays x, y, theta, v, omega of one shape.
Sample = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class Segment:
    """A piece of reference motion on [t0, t1] (absolute times [s])."""

    #: What the segment does (a :class:`~anyplan.trajectory.kinds.SegmentKind` value).
    kind: str
    t0: float
    t1: float
    #: Bound on the speed of the reference position [m/s].
    max_speed: float = 0.0
    #: Distance driven [m].
    length: float = 0.0

    def sample(self, t: np.ndarray) -> Sample:
        """(x, y, theta, v, omega) at times ``t`` (clamped to the segment)."""
        raise NotImplementedError

    def xy(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """x, y [m] at times ``t`` (N,) [s], as :meth:`sample` gives them (a segment may
        compute them alone, faster)."""
        out = self.sample(t)
        return out[0], out[1]

    def path_points(self, step: float) -> np.ndarray:
        """Geometric points (M, 2) [m] visited by the segment."""
        raise NotImplementedError
