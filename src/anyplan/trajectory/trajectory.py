"""The reference motion of the robot over absolute time: a sequence of timed segments.

A :class:`Trajectory` is what the tracking controller follows and what Sequential BIT* uses to
predict, continuously in time, whether the robot will meet a moving obstacle. Its segments are

* :class:`CurveSegment`: driving along a :class:`~anyplan.trajectory.spline.SmoothCurve` with a
  :class:`~anyplan.trajectory.profile.SpeedProfile`;
* :class:`~anyplan.trajectory.turn.TurnSegment`: turning in place;
* :class:`~anyplan.trajectory.brake.BrakeSegment`: braking to rest from the current twist.

Times are absolute simulation times [s]. Before ``t_start`` the trajectory is held at its start
state, after ``t_end`` at its end pose with zero twist. See ``docs/motion.md``
("``plan_motion`` and ``Trajectory``").
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

import numpy as np

from anyplan.trajectory.brake import BrakeSegment, SwerveSegment
from anyplan.trajectory.kinds import MotionKind, SegmentKind
from anyplan.trajectory.profile import SpeedProfile
from anyplan.trajectory.segment import Sample, Segment
from anyplan.trajectory.spline import SmoothCurve
from anyplan.trajectory.turn import TurnSegment
from anyplan.world.robot import RobotState

__all__ = ["Segment", "CurveSegment", "TurnSegment", "BrakeSegment", "Trajectory"]


class CurveSegment(Segment):
    """Driving along ``curve`` with ``profile``, starting at absolute time ``t0`` [s]."""

    kind = SegmentKind.CURVE

    def __init__(self, curve: SmoothCurve, profile: SpeedProfile, t0: float) -> None:
        self.curve, self.profile = curve, profile
        self.t0 = float(t0)
        self.t1 = self.t0 + profile.duration
        self.length = curve.length
        self._prof = profile.arrays
        self._max_speed: float | None = None

    @property
    def max_speed(self) -> float:
        """Bound on the speed of the reference position [m/s] (computed on first use)."""
        # |d position/dt| = |r'(u(s))| u'(s) v: measure the first factor (1 to ~1e-6) finely,
        # as chord lengths over 8 equal parts of each profile interval, times the larger end
        # speed of the interval, plus 1 %.
        if self._max_speed is None:
            self._max_speed = ((self.curve.profile_speed_bound(self._prof, 8) * 1.01)
                               if len(self.profile.s) > 1 else 0.0)
        return self._max_speed

    @max_speed.setter
    def max_speed(self, value: float) -> None:
        self._max_speed = float(value)

    def sample(self, t: np.ndarray) -> Sample:
        t = np.asarray(t, dtype=float)
        out = self.curve.sample_profile(self._prof, t.ravel() - self.t0)
        if t.ndim == 1:
            return out[0], out[1], out[2], out[3], out[4]
        return tuple(o.reshape(t.shape) for o in out)

    def xy(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """x, y [m] at times ``t`` (N,) [s]: :meth:`sample`'s first two, without the others."""
        out = self.curve.sample_profile(self._prof, np.asarray(t, dtype=float) - self.t0, False)
        return out[0], out[1]

    def path_points(self, step: float) -> np.ndarray:
        return self.curve.samples(step)


def _span(flat: np.ndarray) -> tuple[float, float] | None:
    """The earliest and the latest of the times ``flat`` [s], or None when there are none or
    one is NaN (a few times in Python: cheaper than numpy's reductions)."""
    if flat.size <= 16:
        ts = flat.tolist()
        if not ts or any(math.isnan(x) for x in ts):
            return None
        return min(ts), max(ts)
    lo, hi = float(flat.min()), float(flat.max())
    return None if math.isnan(lo) or math.isnan(hi) else (lo, hi)


def _ascending(flat: np.ndarray) -> bool:
    """Whether the times ``flat`` [s] (no NaN) are in nondecreasing order."""
    if flat.size <= 16:
        ts = flat.tolist()
        return all(a <= b for a, b in zip(ts, ts[1:], strict=False))
    return bool(np.all(flat[1:] >= flat[:-1]))


#: Segment types whose ``sample`` returns new arrays that share no memory.
_FRESH = (CurveSegment, TurnSegment, BrakeSegment, SwerveSegment)


class Trajectory:
    """A reference motion over absolute time [s]: consecutive segments.

    Attributes:
        segments: The segments, contiguous in time.
        kind: How it was built: a :class:`~anyplan.trajectory.kinds.MotionKind` (``"smooth"``,
            ``"turn+smooth"``, ``"polyline"``, ...) or a prefixed one (``"st+smooth"``, ...).
        feasible: False when the robot's current state could not be followed within its limits
            (the trajectory is then a best effort).
        lower_bound_s: Time lower bound [s] for driving :attr:`length` from the start speed to
            rest under v_max and a_max only (no curvature, no turning).
        polyline: The input path after cleaning (N, 2) [m].
        certified_free: True when the whole motion was certified collision-free against the
            obstacles given to :func:`~anyplan.trajectory.plan_motion` (False only for a polyline
            fallback whose own segments, or braking path, are not free).
        info: Diagnostics (repair rounds, candidate times, ...).
        departs_s: For a motion that brakes, stands still and then departs (a late departure,
            :class:`~anyplan.trajectory.reference.Departure`): the time [s] it leaves the point
            where it stood; before it the motion is the same for every later departure. None
            otherwise.
    """

    def __init__(self, segments: Sequence[Segment], kind: str = MotionKind.SMOOTH,
                 feasible: bool = True,
                 lower_bound_s: float = float("nan"), polyline: np.ndarray | None = None,
                 info: dict | None = None, certified_free: bool = True,
                 departs_s: float | None = None) -> None:
        if not segments:
            raise ValueError("a trajectory needs at least one segment")
        self.segments = list(segments)
        self.kind = kind
        self.feasible = feasible
        self.lower_bound_s = lower_bound_s
        self.polyline = polyline
        self.certified_free = certified_free
        self.info = dict(info or {})
        self.departs_s = departs_s
        self._starts = np.array([s.t0 for s in self.segments])
        self._starts_list: list[float] = self._starts.tolist()
        self._path: np.ndarray | None = None  # built on first use (see path)
        self._max_speed: float | None = None  # taken on first use (see max_speed)

    @property
    def t_start(self) -> float:
        """Absolute start time [s]."""
        return self.segments[0].t0

    @property
    def t_end(self) -> float:
        """Absolute time [s] at which the robot is at rest at the end of the path."""
        return self.segments[-1].t1

    @property
    def duration(self) -> float:
        """t_end - t_start [s]."""
        return self.t_end - self.t_start

    @property
    def max_speed(self) -> float:
        """Upper bound on |d position / dt| [m/s] over all time (for certified contact tests);
        the segments' bound, taken on first use (segments do not change once built)."""
        if self._max_speed is None:
            self._max_speed = max(s.max_speed for s in self.segments)
        return self._max_speed

    @property
    def length(self) -> float:
        """Distance driven along the path [m]."""
        return float(sum(s.length for s in self.segments))

    @property
    def path(self) -> np.ndarray:
        """The geometric curve followed, as points (M, 2) [m] about 5 cm apart."""
        if self._path is None:
            path = np.vstack([s.path_points(0.05) for s in self.segments])
            keep = np.concatenate([[True], np.hypot(*np.diff(path, axis=0).T) > 1e-12])
            self._path = path[keep]
        return self._path

    def sample(self, t: np.ndarray | float) -> Sample:
        """Reference state at absolute times ``t`` [s].

        Returns:
            Arrays x [m], y [m], theta [rad], v [m/s], omega [rad/s] of the shape of ``t``.
        """
        t = np.asarray(t, dtype=float)
        out = self._evaluate(t.ravel(), True)
        if t.ndim == 1:
            return out[0], out[1], out[2], out[3], out[4]
        return tuple(o.reshape(t.shape) for o in out)  # type: ignore[return-value]

    def _evaluate(self, flat: np.ndarray, full: bool) -> list[np.ndarray]:
        """The five arrays of :meth:`sample` at the times ``flat`` (N,) [s], or x and y alone
        when not ``full`` (each segment's :meth:`~Segment.xy`)."""
        segs = self.segments
        nseg = len(segs)
        nout = 5 if full else 2
        span = _span(flat)
        cuts: list[int] | None = None
        if span is None:  # no times, or a NaN among them: every segment found time by time
            idx = np.clip(np.searchsorted(self._starts, flat, side="right") - 1, 0, nseg - 1)
            k0 = int(idx[0]) if flat.size else 0
            single = flat.size > 0 and bool(np.all(idx == k0))
        else:
            # the segment index is monotone in time: one segment serves all when it serves the
            # earliest and the latest (the index searchsorted(starts, t, "right") - 1, clipped)
            k0 = min(max(bisect.bisect_right(self._starts_list, span[0]) - 1, 0), nseg - 1)
            single = nseg == 1 or k0 == min(max(bisect.bisect_right(self._starts_list, span[1])
                                                - 1, 0), nseg - 1)
            cuts = None if single or not _ascending(flat) else \
                [0, *np.searchsorted(flat, self._starts[1:], side="left").tolist(), flat.size]
            if not single and cuts is None:
                idx = np.clip(np.searchsorted(self._starts, flat, side="right") - 1, 0, nseg - 1)

        def at(seg: Segment, times: np.ndarray) -> tuple[np.ndarray, ...]:
            return seg.sample(times) if full else seg.xy(times)

        if single:
            # one segment serves every time (the common case: a control step or one query)
            seg = segs[k0]
            vals = at(seg, flat)
            # our segments return fresh, separate arrays; copy others' (they may share memory)
            if type(seg) in _FRESH:
                out = [np.asarray(v, dtype=float).reshape(flat.shape) for v in vals]
            else:
                out = [np.array(v, dtype=float).reshape(flat.shape) for v in vals]
        elif cuts is not None:
            # times in order: segment k serves the slice from the first time at or after its
            # start to the first at or after the next one's (searchsorted(starts, t, "right") - 1)
            out = [np.empty(flat.shape) for _ in range(nout)]
            for k in range(nseg):
                lo, hi = cuts[k], cuts[k + 1]
                if lo < hi:
                    vals = at(segs[k], flat[lo:hi])
                    for o, val in zip(out, vals, strict=True):
                        o[lo:hi] = val
        else:
            out = [np.empty(flat.shape) for _ in range(nout)]
            for k in np.unique(idx):
                m = idx == k
                vals = at(segs[k], flat[m])
                for o, val in zip(out, vals, strict=True):
                    o[m] = val
        if full and (span is None or span[1] >= segs[-1].t1):  # at rest after the end
            after = flat >= segs[-1].t1
            if after.any():
                out[3][after] = 0.0
                out[4][after] = 0.0
        return out

    def positions(self, t: np.ndarray | float) -> np.ndarray:
        """Reference positions (N, 2) [m] at absolute times ``t`` (N,) [s]: :meth:`sample`'s
        x and y, bit for bit, without computing the rest."""
        x, y = self._evaluate(np.atleast_1d(np.asarray(t, dtype=float)).ravel(), False)
        p = np.empty((x.size, 2))
        p[:, 0] = x
        p[:, 1] = y
        return p

    def state(self, t: float) -> RobotState:
        """The reference pose and twist at absolute time ``t`` [s]."""
        x, y, th, v, w = self.sample(np.array([float(t)]))
        return RobotState(float(x[0]), float(y[0]), float(th[0]), float(v[0]), float(w[0]))

    @property
    def end_pose(self) -> tuple[float, float, float]:
        """(x [m], y [m], theta [rad]) at the end."""
        st = self.state(self.t_end)
        return st.x, st.y, st.theta
