"""Motions of moving obstacles: positions as functions of time [s].

A moving obstacle follows its motion whatever is in its way (it is not reactive).

* :class:`UnicycleMotion`: constant speed v [m/s] and turn rate omega [rad/s] from a start
  pose; a straight line if omega == 0, otherwise a circle of radius |v / omega|.
  Straight: ``(x0 + v t cos th0, y0 + v t sin th0)``. Circular:
  ``(x0 + v/w (sin(th0 + w t) - sin th0), y0 - v/w (cos(th0 + w t) - cos th0))``.
  Before ``start_time`` the obstacle waits at its start pose; ``t`` above is measured from it.
* :class:`WaypointMotion`: a looping, time-stamped, piecewise-linear track (DynaBARN).
* :class:`TrackMotion`: a recorded, time-stamped track (e.g. a pedestrian), not looping, linear
  in between; the obstacle exists only between its first and last sample (:attr:`Motion.span`).
"""

from __future__ import annotations

import bisect
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

__all__ = ["Jump", "Motion", "UnicycleMotion", "WaypointMotion", "TrackMotion", "positions_of",
           "JUMP_SLACK_S"]


#: Tolerance [s] on a jump's time (:meth:`Motion.jumps`).
_JUMP_EPS = 1e-9
#: [s] how far from a jump's reported time the positions may still be on its other side
#: (rounding): pieces between jumps keep this far from them (:meth:`Motion.continuous_pieces`).
JUMP_SLACK_S = 1e-9


class Jump(NamedTuple):
    """A discontinuity of a motion: at ``time`` [s] the position jumps from ``before`` to
    ``after`` (both [m], shape (2,)); :meth:`Motion.position` gives ``after`` at ``time``."""

    time: float
    before: np.ndarray
    after: np.ndarray


class Motion:
    """Base class: the trajectory of a point over time."""

    #: Upper bound on the speed [m/s], used by certified contact tests.
    max_speed: float = 0.0
    #: Times [s] between which the obstacle exists (outside, it is neither an obstacle nor
    #: observed); every motion but :class:`TrackMotion` exists at all times.
    span: tuple[float, float] = (-math.inf, math.inf)

    def exists(self, t: float) -> bool:
        """True if the obstacle exists at time ``t`` [s]."""
        return self.span[0] <= t <= self.span[1]

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Positions at times ``t`` (N,) [s], shape (N, 2) [m]."""
        raise NotImplementedError

    def position(self, t: float) -> np.ndarray:
        """Position at time ``t`` [s], shape (2,) [m]."""
        return self.positions(np.array([float(t)]))[0]

    def state(self, t: float) -> tuple[float, float, float, float, float]:
        """Pose and twist at time ``t`` [s]: (x [m], y [m], heading [rad], v [m/s], omega [rad/s])."""
        raise NotImplementedError

    #: False when the position never jumps (:meth:`jumps` is then always empty).
    may_jump: bool = False

    def jumps(self, t0: float, t1: float) -> tuple[Jump, ...]:
        """The jumps (teleports, not motions) of the position at times in (t0, t1] [s] (each
        end moved 1 ns later, so that a jump at t1 is reported once, not again from t0 = t1),
        in time order; none for a continuous motion."""
        return ()

    def jump_times(self, t0: float, t1: float) -> list[float]:
        """The times [s] of the jumps in (t0, t1] exactly (:meth:`jumps` reports up to 1 ns past
        t1); empty at once for a motion that never jumps."""
        if not self.may_jump:
            return []
        return [j.time for j in self.jumps(t0, t1) if t0 < j.time <= t1]

    def continuous_pieces(self, t0: float, t1: float) -> list[tuple[float, float]]:
        """[t0, t1] [s] cut at the jumps into pieces on which the position is continuous (so a
        bound on the speed holds on each): each jump starts a piece (which may be a single
        instant). A jump's time (n times a period) and the wrap of the positions (t mod the
        period) may differ by rounding, so a piece starts :data:`JUMP_SLACK_S` after its jump
        and the one before ends as long before it."""
        js = self.jump_times(t0, t1)
        if not js:
            return [(t0, max(t0, t1))]
        starts = [t0, *(min(j + JUMP_SLACK_S, t1) for j in js)]
        ends = [*(j - JUMP_SLACK_S for j in js), t1]
        return [(a, max(a, b)) for a, b in zip(starts, ends, strict=True)]


_EPS = float(np.finfo(float).eps)


def _sinc(x: np.ndarray) -> np.ndarray:
    """``np.sinc(x)`` for a float array, by the same operations (without its per-call set-up)."""
    y = math.pi * x
    y = np.where(y, y, _EPS)
    return np.sin(y) / y


@functools.lru_cache(maxsize=256)
def _straight_factors(theta0: float) -> tuple[float, float, float]:
    """cos(theta0), sin(theta0) and sinc(0) as the array operations of the chord form give them."""
    th = np.full(1, theta0) + np.zeros(1)
    return float(np.cos(th)[0]), float(np.sin(th)[0]), float(_sinc(np.zeros(1))[0])


@dataclass(frozen=True)
class UnicycleMotion(Motion):
    """Constant (v, omega) motion from pose (x0, y0, theta0), starting at ``start_time``."""

    x0: float
    y0: float
    theta0: float
    v: float
    omega: float = 0.0
    start_time: float = 0.0

    @property
    def max_speed(self) -> float:  # type: ignore[override]
        return abs(self.v)

    @property
    def is_straight(self) -> bool:
        """True if the motion is a straight line (omega == 0)."""
        return self.omega == 0.0

    def positions(self, t: np.ndarray) -> np.ndarray:
        tau = np.maximum(np.asarray(t, dtype=float) - self.start_time, 0.0)
        out = np.empty((tau.size, 2))
        if self.omega == 0.0:
            # The chord form below with w = 0: half = 0, sinc = sin(eps) / eps (= 1) and the
            # heading constant, so both are computed once (the same operations, the same bits).
            c, sn, one = _straight_factors(self.theta0)
            chord = self.v * tau * one
            out[:, 0] = (self.x0 + chord * c).ravel()
            out[:, 1] = (self.y0 + chord * sn).ravel()
            return out
        # sin(th0 + w t) - sin(th0) = 2 cos(th0 + w t / 2) sin(w t / 2), and likewise for cos:
        # the chord form below equals the contract's formulas and stays exact as w -> 0.
        half = 0.5 * self.omega * tau
        chord = self.v * tau * _sinc(half / math.pi)
        th = self.theta0 + half
        out[:, 0] = (self.x0 + chord * np.cos(th)).ravel()
        out[:, 1] = (self.y0 + chord * np.sin(th)).ravel()
        return out

    def position(self, t: float) -> np.ndarray:
        if self.omega != 0.0:
            return super().position(t)
        # a straight motion in scalars: the operations of positions(), the same bits, without
        # its arrays (one position per step and mover in the simulator, per disc in filters)
        c, sn, one = _straight_factors(self.theta0)
        chord = self.v * max(float(t) - self.start_time, 0.0) * one
        return np.array([self.x0 + chord * c, self.y0 + chord * sn])

    def state(self, t: float) -> tuple[float, float, float, float, float]:
        moving = t >= self.start_time
        tau = max(t - self.start_time, 0.0)
        x, y = self.position(t)
        th = self.theta0 + self.omega * tau
        return (float(x), float(y), float(th), self.v if moving else 0.0,
                self.omega if moving else 0.0)

    @property
    def circle_center(self) -> np.ndarray | None:
        """Centre of the circular path [m], or None for a straight motion."""
        if self.omega == 0.0:
            return None
        r = self.v / self.omega
        return np.array([self.x0 - r * math.sin(self.theta0), self.y0 + r * math.cos(self.theta0)])


def positions_of(motions: Sequence[Any], t: np.ndarray) -> np.ndarray:
    """Every motion's positions (len(motions), len(t), 2) [m] at times ``t`` (T,) [s]: each
    row is ``motions[k].positions(t)``, bit for bit (any object with ``positions`` may stand
    in for a motion). The straight :class:`UnicycleMotion` rows are computed at once, element
    by element the operations of its ``positions`` (a planner asks 40-60 tracked people
    where they are, many times per replanning)."""
    t = np.asarray(t, dtype=float).ravel()
    out = np.empty((len(motions), t.size, 2))
    lines = [k for k, m in enumerate(motions)
             if type(m) is UnicycleMotion and m.omega == 0.0]
    if lines:
        ms: list[UnicycleMotion] = [motions[k] for k in lines]
        f = np.array([_straight_factors(m.theta0) for m in ms])
        x0, y0, v, t0 = (np.array([getattr(m, a) for m in ms], dtype=float)
                         for a in ("x0", "y0", "v", "start_time"))
        tau = np.maximum(t[None, :] - t0[:, None], 0.0)
        chord = v[:, None] * tau * f[:, 2:3]
        out[lines, :, 0] = x0[:, None] + chord * f[:, 0:1]
        out[lines, :, 1] = y0[:, None] + chord * f[:, 1:2]
    if len(lines) < len(motions):
        done = set(lines)
        for k, m in enumerate(motions):
            if k not in done:
                out[k] = np.asarray(m.positions(t), dtype=float).reshape(t.size, 2)
    return out


def _interp1(x: float, ts: tuple[float, ...], vs: tuple[float, ...]) -> float:
    """``np.interp(x, ts, vs)`` for one time ``x`` [s], by the same operations in the same order
    (the same bits), without numpy's per-call set-up: the simulator asks every obstacle for its
    position and twist at every step, one time at a time."""
    if x != x:
        return x  # nan
    if x < ts[0]:
        return vs[0]
    if x >= ts[-1]:
        return vs[-1]
    j = bisect.bisect_right(ts, x) - 1
    if ts[j] == x:
        return vs[j]
    slope = (vs[j + 1] - vs[j]) / (ts[j + 1] - ts[j])
    out = slope * (x - ts[j]) + vs[j]
    if out != out:  # as numpy: from the other end, then the constant piece
        out = slope * (x - ts[j + 1]) + vs[j + 1]
        if out != out and vs[j] == vs[j + 1]:
            out = vs[j]
    return out


class _Keyframes(NamedTuple):
    """A track's columns as tuples of floats, for :func:`_interp1`."""

    t: tuple[float, ...]
    x: tuple[float, ...]
    y: tuple[float, ...]


def _columns(k: np.ndarray) -> _Keyframes:
    return _Keyframes(*(tuple(float(v) for v in k[:, c]) for c in range(3)))


def _point(kf: _Keyframes, t: float) -> tuple[float, float]:
    """The track's position (x, y) [m] at time ``t`` [s], as ``np.interp`` of its columns."""
    return _interp1(t, kf.t, kf.x), _interp1(t, kf.t, kf.y)


def _segment_twist(kf: _Keyframes, t: float) -> tuple[float, float]:
    """The velocity (vx, vy) [m/s] of the track's segment at time ``t`` [s] (the first before
    the track, the last after it)."""
    i = min(max(bisect.bisect_right(kf.t, t) - 1, 0), len(kf.t) - 2)
    dt = kf.t[i + 1] - kf.t[i]
    return (kf.x[i + 1] - kf.x[i]) / dt, (kf.y[i + 1] - kf.y[i]) / dt


def _track_speed(k: np.ndarray) -> float:
    """Largest speed [m/s] of a piecewise-linear track, rows (t, x, y)."""
    seg = np.hypot(np.diff(k[:, 1]), np.diff(k[:, 2])) / np.diff(k[:, 0])
    return float(seg.max())


@dataclass(frozen=True)
class WaypointMotion(Motion):
    """A looping piecewise-linear track: ``keyframes`` rows (t [s], x [m], y [m]).

    The first keyframe time is 0 and the last is ``period``; the position at time t is the
    linear interpolation at ``t mod period`` (a closed track repeats its first point at the end,
    an open one jumps back, as in DynaBARN's Gazebo animations).
    """

    keyframes: np.ndarray

    def __post_init__(self) -> None:
        k = np.asarray(self.keyframes, dtype=float)
        if k.ndim != 2 or k.shape[1] != 3 or len(k) < 2:
            raise ValueError("keyframes must have shape (N >= 2, 3) as rows (t, x, y)")
        if abs(k[0, 0]) > 1e-12 or np.any(np.diff(k[:, 0]) <= 0.0):
            raise ValueError("keyframe times must start at 0 and increase strictly")
        k.setflags(write=False)
        object.__setattr__(self, "keyframes", k)
        object.__setattr__(self, "_vmax", _track_speed(k))  # asked for by every prediction check
        object.__setattr__(self, "_kf", _columns(k))
        object.__setattr__(self, "_open", bool(k[-1, 1] != k[0, 1] or k[-1, 2] != k[0, 2]))

    @property
    def period(self) -> float:
        """Loop period [s]."""
        return float(self.keyframes[-1, 0])

    @property
    def max_speed(self) -> float:  # type: ignore[override]
        return self._vmax  # type: ignore[attr-defined]  # set in __post_init__ (frozen)

    @property
    def is_open(self) -> bool:
        """True if the track does not end where it starts: it jumps back at every period."""
        return self._open  # type: ignore[attr-defined]  # set in __post_init__

    @property
    def may_jump(self) -> bool:  # type: ignore[override]
        return self.is_open

    def jumps(self, t0: float, t1: float) -> tuple[Jump, ...]:
        """An open track jumps from its last keyframe back to its first at every multiple of
        the period."""
        if not self.is_open:
            return ()
        p, k = self.period, self.keyframes
        n0, n1 = math.floor((t0 + _JUMP_EPS) / p) + 1, math.floor((t1 + _JUMP_EPS) / p)
        return tuple(Jump(n * p, k[-1, 1:].copy(), k[0, 1:].copy()) for n in range(max(n0, 1), n1 + 1))

    def positions(self, t: np.ndarray) -> np.ndarray:
        tm = np.mod(np.asarray(t, dtype=float), self.period)
        k = self.keyframes
        return np.column_stack([np.interp(tm, k[:, 0], k[:, 1]), np.interp(tm, k[:, 0], k[:, 2])])

    def position(self, t: float) -> np.ndarray:
        kf: _Keyframes = self._kf  # type: ignore[attr-defined]  # set in __post_init__ (frozen)
        return np.array(_point(kf, float(t) % kf.t[-1]))

    def state(self, t: float) -> tuple[float, float, float, float, float]:
        kf: _Keyframes = self._kf  # type: ignore[attr-defined]
        tm = float(t) % kf.t[-1]
        vx, vy = _segment_twist(kf, tm)
        x, y = _point(kf, tm)
        return x, y, math.atan2(vy, vx), math.hypot(vx, vy), 0.0


@dataclass(frozen=True)
class TrackMotion(Motion):
    """A recorded track: ``samples`` rows (t [s], x [m], y [m]), times strictly increasing.

    Not looping: the position is the linear interpolation of the samples, exact at every sample;
    the obstacle exists only on ``[t_first, t_last]`` (:attr:`span`). Outside the span
    :meth:`positions` returns the first or last sample (callers test :meth:`exists`).
    """

    samples: np.ndarray

    def __post_init__(self) -> None:
        k = np.asarray(self.samples, dtype=float)
        if k.ndim != 2 or k.shape[1] != 3 or len(k) < 2:
            raise ValueError("samples must have shape (N >= 2, 3) as rows (t, x, y)")
        if np.any(np.diff(k[:, 0]) <= 0.0):
            raise ValueError("sample times must increase strictly")
        k.setflags(write=False)
        object.__setattr__(self, "samples", k)
        object.__setattr__(self, "span", (float(k[0, 0]), float(k[-1, 0])))
        object.__setattr__(self, "_vmax", _track_speed(k))
        object.__setattr__(self, "_kf", _columns(k))

    @property
    def max_speed(self) -> float:  # type: ignore[override]
        return self._vmax  # type: ignore[attr-defined]  # set in __post_init__ (frozen)

    def positions(self, t: np.ndarray) -> np.ndarray:
        tt = np.asarray(t, dtype=float)
        k = self.samples
        return np.column_stack([np.interp(tt, k[:, 0], k[:, 1]), np.interp(tt, k[:, 0], k[:, 2])])

    def position(self, t: float) -> np.ndarray:
        kf: _Keyframes = self._kf  # type: ignore[attr-defined]  # set in __post_init__ (frozen)
        return np.array(_point(kf, float(t)))

    def state(self, t: float) -> tuple[float, float, float, float, float]:
        kf: _Keyframes = self._kf  # type: ignore[attr-defined]
        t = float(t)
        vx, vy = _segment_twist(kf, t)
        x, y = _point(kf, t)
        if not self.span[0] <= t < self.span[1]:
            return x, y, math.atan2(vy, vx), 0.0, 0.0
        return x, y, math.atan2(vy, vx), math.hypot(vx, vy), 0.0
