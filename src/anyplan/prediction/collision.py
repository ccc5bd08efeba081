"""Predicted collisions between the robot's timed reference motion and moving obstacles.

The robot's motion is any object with ``positions(t)`` (absolute times [s] -> (N, 2) [m]),
``t_start``, ``t_end`` and ``max_speed`` (a bound on its speed [m/s]), such as
:class:`anyplan.trajectory.Trajectory`. Each obstacle is a
:class:`~anyplan.prediction.base.PredictedObstacle`. The first contact time is found by the
certified search of :func:`anyplan.geometry.first_contact`, which uses the bound on the relative
speed so that no contact can slip between evaluation points: the time returned is exact up to
``tol`` and never later than the true first contact. An obstacle whose radius grows with the
horizon (``PredictedObstacle.growth``, an uncertain prediction) is searched with its growing
radius and the growth rate added to the speed bound
(:func:`anyplan.geometry.moving.first_contact_growing`): exact for the growing disc too. On a
resampled motion, a disc on a straight line needs no search: its first contact is a
quadratic's first root (:mod:`anyplan.prediction._contact_kernels`). A prediction with a
horizon (``PredictedObstacle.until``) is checked up to it only.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from anyplan.geometry.moving import first_contact, first_contact_growing
from anyplan.prediction._contact_kernels import (
    LoopingTracks,
    StraightDiscs,
    track_contacts,
    track_start_bounds,
)
from anyplan.prediction.base import PredictedObstacle, RadiusGrowth
from anyplan.world.motion import TrackMotion, UnicycleMotion, WaypointMotion

__all__ = ["TimedMotion", "SampledMotion", "PredictedCollision", "first_collision",
           "predict_collisions", "min_separation"]


class TimedMotion(Protocol):
    """A robot reference motion over absolute time."""

    @property
    def t_start(self) -> float:
        """Start time [s]."""
        ...

    @property
    def t_end(self) -> float:
        """End time [s]; the motion rests at its end position afterwards."""
        ...

    @property
    def max_speed(self) -> float:
        """Upper bound on the speed of the reference position [m/s]."""
        ...

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Positions (N, 2) [m] at absolute times ``t`` (N,) [s]."""
        ...


class SampledMotion:
    """A motion resampled every ``dt`` seconds and interpolated linearly: cheap to evaluate.

    Between two samples the true position is within ``error_bound = max_speed * dt / 2`` [m] of
    the interpolation (with the speed bounded by V, |p(t) - q(t)| <= 2 l (1 - l) V dt for the
    fraction l of the interval), so a contact test on the samples with the contact distance
    enlarged by ``error_bound`` never misses a contact of the true motion.

    Args:
        motion: The motion to sample.
        t0, t1: Interval [s] to cover; outside it positions are clamped.
        dt: Sample spacing [s].
        stop: Only the samples up to the first at or after ``stop`` [s] are made (the same
            times as without it): nothing after ``stop`` is asked (every prediction has ended).
    """

    def __init__(self, motion: TimedMotion, t0: float, t1: float, dt: float = 0.02,
                 stop: float = math.inf) -> None:
        n = max(2, int(math.ceil((t1 - t0) / dt)) + 1)
        self._t = np.linspace(t0, t0 + (n - 1) * dt, n)
        if stop < self._t[-2]:
            self._t = self._t[:max(2, int(np.searchsorted(self._t, stop, side="left")) + 1)]
        p = motion.positions(self._t)
        self._x = np.ascontiguousarray(p[:, 0])
        self._y = np.ascontiguousarray(p[:, 1])
        self.t_start = float(t0)
        self.t_end = float(self._t[-1])
        self.max_speed = float(motion.max_speed)
        self.error_bound = 0.5 * self.max_speed * dt

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Interpolated positions (N, 2) [m] at times ``t`` (N,) [s]."""
        t = np.asarray(t, dtype=float)
        return np.column_stack([np.interp(t, self._t, self._x), np.interp(t, self._t, self._y)])


@dataclass(frozen=True)
class PredictedCollision:
    """The first predicted contact with one obstacle.

    Attributes:
        obstacle: Obstacle name.
        t: Time of first contact [s] (distance = robot radius + obstacle radius + margin).
        robot_position: Robot reference position at ``t`` [m], shape (2,).
        obstacle_position: Obstacle centre at ``t`` [m], shape (2,).
        obstacle_radius: [m], at ``t`` (an uncertain prediction's disc grows with the horizon).
    """

    obstacle: str
    t: float
    robot_position: np.ndarray
    obstacle_position: np.ndarray
    obstacle_radius: float


def predict_collisions(motion: TimedMotion, obstacles: Sequence[PredictedObstacle],
                       robot_radius: float, *, t_from: float | None = None,
                       t_until: float | None = None, margin: float = 0.0,
                       tol: float = 1e-4, sample_dt: float | None = None) -> list[PredictedCollision]:
    """First contact with each obstacle over [t_from, t_until], earliest first.

    Args:
        motion: The robot's timed reference motion.
        obstacles: Predicted moving obstacles.
        robot_radius: [m].
        t_from: Start of the checked interval [s] (default ``motion.t_start``).
        t_until: End of the checked interval [s] (default ``motion.t_end``).
        margin: Extra clearance [m] required between the discs (for tracking error).
        tol: Time accuracy [s] of the contact time.
        sample_dt: If given, the robot's motion is first resampled every ``sample_dt`` seconds
            (:class:`SampledMotion`) and the contact distance enlarged by its error bound: much
            faster, still never missing a contact, but possibly reporting one up to
            ``max_speed * sample_dt / 2`` [m] early.

    Returns:
        One :class:`PredictedCollision` per obstacle that is met, sorted by time.
    """
    return _predict(motion, obstacles, robot_radius, t_from, t_until, margin, tol, sample_dt, False)


#: The last few answers of :func:`_predict`, newest last: (motion, obstacles, settings, answer).
#: A planner often checks the same motion against the same predictions twice in a row (the
#: candidate's own check, then the loop's); the entries hold their motion and obstacles, so an
#: ``id`` seen here is the same live object, and motions and predictions do not change once built.
_MEMO: list[tuple[object, tuple[object, ...], tuple[float | bool | None, ...],
                  list[PredictedCollision]]] = []
_MEMO_SIZE = 8
#: Grid points per interval of the coarse certificate of :func:`_predict_uncached`.
_COARSE = 16


#: Per motion (by identity; the entry keeps it alive): a box (xmin, ymin, xmax, ymax) [m] that
#: holds its position at every time (inf if none is known), and its max_speed.
_TRACKS: dict[int, tuple[object, np.ndarray, float]] = {}


def _track(o: PredictedObstacle) -> tuple[np.ndarray, float]:
    m = o.motion
    hit = _TRACKS.get(id(m))
    if hit is not None and hit[0] is m:
        return hit[1], hit[2]
    box = np.array([-math.inf, -math.inf, math.inf, math.inf])
    if isinstance(m, WaypointMotion | TrackMotion):  # interpolated (looping) keyframes
        k = m.keyframes if isinstance(m, WaypointMotion) else m.samples
        box = np.array([k[:, 1].min(), k[:, 2].min(), k[:, 1].max(), k[:, 2].max()])
    elif isinstance(m, UnicycleMotion) and m.omega != 0.0:  # on its circle at all times
        c, r = m.circle_center, abs(m.v / m.omega)
        assert c is not None
        box = np.array([c[0] - r, c[1] - r, c[0] + r, c[1] + r])
    if len(_TRACKS) >= 4096:
        _TRACKS.clear()
    _TRACKS[id(m)] = (m, box, float(m.max_speed))
    return box, float(m.max_speed)


def _predict(motion: TimedMotion, obstacles: Sequence[PredictedObstacle], robot_radius: float,
             t_from: float | None, t_until: float | None, margin: float, tol: float,
             sample_dt: float | None, first_only: bool) -> list[PredictedCollision]:
    t0 = motion.t_start if t_from is None else float(t_from)
    t1 = motion.t_end if t_until is None else float(t_until)
    key = (float(robot_radius), t0, t1, float(margin), float(tol), sample_dt, first_only)
    obs = tuple(obstacles)
    for m, o, k, hits in _MEMO:
        if m is motion and k == key and len(o) == len(obs) and all(
                a is b for a, b in zip(o, obs, strict=True)):
            return list(hits)
    out = _predict_uncached(motion, obs, float(robot_radius), t0, t1, margin, tol, sample_dt,
                            first_only)
    _MEMO.append((motion, obs, key, list(out)))
    del _MEMO[:-_MEMO_SIZE]
    return out


def _predict_uncached(motion: TimedMotion, obstacles: Sequence[PredictedObstacle],
                      robot_radius: float, t0: float, t1: float, margin: float, tol: float,
                      sample_dt: float | None, first_only: bool) -> list[PredictedCollision]:
    """Straight discs and looping tracks in closed form on the robot's samples, the others by
    the certified search (:func:`_certified_hits`); merged, earliest first."""
    if t1 < t0 or not obstacles:
        return []
    if sample_dt is None:
        return _certified_hits(motion, obstacles, robot_radius, t0, t1, margin, tol, None,
                               first_only)
    lines, tracks, rest = _closed(obstacles)
    if not len(lines.index) and not len(tracks.index):
        return _certified_hits(motion, obstacles, robot_radius, t0, t1, margin, tol, sample_dt,
                               first_only)
    # every obstacle in closed form: the robot is not sampled after the last prediction's end
    stop = max(float(lines.until.max(initial=-math.inf)),
               float(tracks.until.max(initial=-math.inf))) if not rest else math.inf
    sampled = SampledMotion(motion, t0, t1, sample_dt, stop)
    reach0 = robot_radius + margin
    out = []
    if len(lines.index):
        out += _straight_hits(motion, sampled, obstacles, lines, reach0, t0, t1, first_only)
    if len(tracks.index):
        out += _track_hits(motion, sampled, obstacles, tracks, reach0, t0, t1, first_only)
    if rest:  # each obstacle's contact is its own: the same answer with or without the others
        out += _certified_hits(motion, [obstacles[k] for k in rest], robot_radius, t0, t1,
                               margin, tol, sample_dt, first_only, sampled)
    out.sort(key=lambda c: c.t)
    return out[:1] if first_only else out


_Closed = tuple[StraightDiscs, LoopingTracks, tuple[int, ...]]
_LINES: dict[tuple[int, ...], tuple[tuple[object, ...], Any]] = {}  # recent _closed, by identity


def _closed(obstacles: Sequence[PredictedObstacle]) -> _Closed:
    """The straight discs and the looping tracks of a prediction set, and the indices of the
    others (memoised by the set's identity: a planner asks one set many times)."""
    def build() -> _Closed:
        lines, tracks = StraightDiscs.of(obstacles), LoopingTracks.of(obstacles)
        return lines, tracks, tuple(sorted(set(lines.rest) - set(tracks.index.tolist())))

    return _by_identity(_LINES, obstacles, build)


def _straight_hits(motion: TimedMotion, sampled: SampledMotion,
                   obstacles: Sequence[PredictedObstacle], lines: StraightDiscs, reach0: float,
                   t0: float, t1: float, first_only: bool) -> list[PredictedCollision]:
    """First contacts with the obstacles ``lines`` (straight, shared growth knots), exact on the
    robot's samples with the contact distance enlarged by their error bound (so never later
    than the true motion's), by :meth:`StraightDiscs.first_contacts`."""
    times = lines.first_contacts(sampled._t, sampled._x, sampled._y,
                                 reach0 + sampled.error_bound, t0, min(t1, sampled.t_end),
                                 first_only)
    return _hits(motion, obstacles, lines.index, times, first_only)


def _track_hits(motion: TimedMotion, sampled: SampledMotion,
                obstacles: Sequence[PredictedObstacle], tracks: LoopingTracks, reach0: float, t0: float,
                t1: float, first_only: bool) -> list[PredictedCollision]:
    """First contacts with the looping ``tracks``, exact on the robot's samples with the contact
    distance enlarged by their error bound (so never later than the true motion's), jumps of
    open tracks included, by :func:`track_contacts`."""
    times = track_contacts(sampled._t, sampled._x, sampled._y, float(t0),
                           float(min(t1, sampled.t_end)), tracks.kf, tracks.lens, tracks.speed,
                           reach0 + sampled.error_bound + tracks.radius, tracks.until,
                           float(sampled.max_speed), bool(first_only))
    return _hits(motion, obstacles, tracks.index, times, first_only)


def _hits(motion: TimedMotion, obstacles: Sequence[PredictedObstacle], index: np.ndarray,
          times: np.ndarray, first_only: bool) -> list[PredictedCollision]:
    """The contacts ``times`` [s] (inf: none) of the obstacles ``index`` as records (with
    ``first_only``, the earliest alone; the first in ``index`` order on a tie)."""
    out = []
    found = np.flatnonzero(times < math.inf)
    if first_only and len(found):
        found = found[np.argmin(times[found]):][:1]
    for j in found:
        o, tc = obstacles[int(index[j])], float(times[j])
        ta = np.array([tc])
        out.append(PredictedCollision(o.name, tc, motion.positions(ta)[0], o.positions(ta)[0],
                                      float(o.radius_at(tc))))
    return out


def _certified_hits(motion: TimedMotion, obstacles: Sequence[PredictedObstacle],
                    robot_radius: float, t0: float, t1: float, margin: float, tol: float,
                    sample_dt: float | None, first_only: bool,
                    sampled: SampledMotion | None = None) -> list[PredictedCollision]:
    """The certified search for any predicted motion (``sampled``: the robot's samples, if
    already made)."""
    out: list[PredictedCollision] = []
    if t1 < t0 or not obstacles:
        return out
    extra = 0.0
    true_motion = motion  # the contact's robot position is the motion's, not the samples'
    if sample_dt is not None:
        motion = sampled if sampled is not None else SampledMotion(motion, t0, t1, sample_dt)
        extra = motion.error_bound
        grid = motion._t
    else:
        grid = np.linspace(t0, t1, max(2, int(math.ceil((t1 - t0) / 0.05)) + 1))
    # Vectorised certificate on a grid: with the relative speed bounded by L, the distance on
    # [t_i, t_i+1] is at least (d_i + d_i+1 - L dt) / 2. Obstacles certified clear on every
    # interval are done; the others are searched from their first uncertified interval on.
    p = motion.positions(grid)
    vr = float(motion.max_speed)
    # The same certificate on every _COARSE-th grid point first: an obstacle certified clear
    # there is clear (the bound holds on any interval), and is never sampled finely.
    ic = np.unique(np.r_[np.arange(0, len(grid), _COARSE), len(grid) - 1])
    gc, pc = grid[ic], p[ic]
    far = _far_from_tracks(obstacles, gc, pc, vr, robot_radius + margin + extra)

    def gap_bounds(o: PredictedObstacle, ts: np.ndarray, ps: np.ndarray) -> np.ndarray:
        """Lower bounds of the gap between the robot (at ``ps``) and ``o`` on each interval
        of ``ts``; with growth, the gap to the grown disc, its slope adding the growth rate."""
        d = np.hypot(*(ps - o.positions(ts)).T)
        rate = 0.0
        if o.growth is not None:
            d = d - o.growth.at(ts)
            rate = o.growth.rate
        return 0.5 * (d[:-1] + d[1:] - (vr + o.max_speed + rate) * np.diff(ts))

    def start(k: int) -> float | None:
        """The obstacle's first uncertified grid time, or None if it is certified clear."""
        o = obstacles[k]
        if o.until < t0 or far[k]:
            return None  # predicted only before the interval, or never near the robot
        reach = robot_radius + o.radius + margin + extra
        jumps = [j.time for j in o.motion.jumps(grid[0], grid[-1])]
        if not len(jumps) and len(ic) < len(grid) and np.all(gap_bounds(o, gc, pc) > reach):
            return None
        low = gap_bounds(o, grid, p) <= reach
        # the speed bound does not hold across a jump: an interval that holds one is uncertified
        low[np.clip(np.searchsorted(grid, jumps) - 1, 0, len(low) - 1)] = True
        bad = np.flatnonzero(low)
        if o.until < t1:  # intervals that start after the prediction's horizon do not count
            bad = bad[grid[bad] <= o.until]
        return float(grid[bad[0]]) if len(bad) else None

    # Candidates in order of their start (ties by index). For the first contact only, an
    # obstacle's start is computed when a lower bound of it comes up (_start_bounds): one that
    # cannot start before the contact found is never sampled finely; the same candidates are
    # searched in the same order as with every start computed first.
    if first_only:
        heap = [(b, 0, k) for k, b in enumerate(_start_bounds(obstacles, far, grid, gc, pc, vr,
                                                              robot_radius + margin + extra))
                if b < math.inf]
    else:
        heap = [(b, 1, k) for k in range(len(obstacles)) if (b := start(k)) is not None]
    heapq.heapify(heap)
    while heap:
        ts, exact, k = heapq.heappop(heap)
        if first_only and out and out[0].t <= ts:
            break  # no later candidate can come before the contact already found
        if not exact:
            st = start(k)
            if st is not None:
                heapq.heappush(heap, (st, 1, k))
            continue
        o = obstacles[k]
        reach = robot_radius + o.radius + margin + extra
        t1o = min(t1, o.until)
        tc = None
        for a, b in o.motion.continuous_pieces(ts, t1o):  # the speed bound holds between jumps
            if o.growth is None:
                tc = first_contact(motion.positions, o.positions, vr + o.max_speed, reach, a, b,
                                   tol=tol)
            else:
                tc = first_contact_growing(motion.positions, o.positions, vr + o.max_speed,
                                           reach, o.growth.at, o.growth.rate, a, b, tol=tol)
            if tc is not None:
                break
        if tc is None:
            continue
        ta = np.array([tc])
        hit = PredictedCollision(o.name, float(tc), true_motion.positions(ta)[0],
                                 o.positions(ta)[0], float(o.radius_at(float(tc))))
        out.append(hit)
        out.sort(key=lambda c: c.t)
    return out


def _far_from_tracks(obstacles: Sequence[PredictedObstacle], gc: np.ndarray, pc: np.ndarray,
                     vr: float, reach0: float) -> np.ndarray:
    """Broad phase, for all obstacles at once: True where an obstacle is certified clear by the
    coarse certificate below without sampling it. An obstacle stays in its track's box B at
    all times, so its gap to the robot is >= dist(robot, B) - max growth; that distance is
    vr-Lipschitz in time, so >= (F_j + F_j+1 - vr dT_j) / 2 between coarse times. Where this
    exceeds reach + L dT_max / 2 (L the gap's Lipschitz bound), every coarse (and fine)
    interval's bound (>= min gap - L dT / 2) is above reach: the loop would skip it too."""
    n = len(obstacles)
    if n < 8 or len(gc) < 2:
        return np.zeros(n, dtype=bool)
    stack = _stack(obstacles)
    boxes = stack.boxes
    lip = vr + stack.speed + stack.rate
    need = reach0 + stack.radius + stack.grown
    dx = np.maximum(np.maximum(boxes[None, :, 0] - pc[:, 0, None], pc[:, 0, None] - boxes[None, :, 2]), 0.0)
    dy = np.maximum(np.maximum(boxes[None, :, 1] - pc[:, 1, None], pc[:, 1, None] - boxes[None, :, 3]), 0.0)
    f = np.hypot(dx, dy)  # (coarse times, obstacles); 0 for an unbounded track
    dt = np.diff(gc)
    lb = (0.5 * (f[:-1] + f[1:] - vr * dt[:, None])).min(axis=0)
    with np.errstate(invalid="ignore"):
        return lb > need + 0.5 * lip * float(dt.max()) + 1e-9 * (1.0 + need + lip)


def _by_identity(cache: dict[tuple[int, ...], tuple[tuple[object, ...], Any]],
                 items: Sequence[object], build: Callable[[], Any]) -> Any:
    """``build()``, memoised in ``cache`` by the identity of ``items`` (the entry keeps them
    alive, so that an id seen is the same object); at most 64 entries."""
    key = tuple(id(x) for x in items)
    hit = cache.get(key)
    if hit is not None and all(a is b for a, b in zip(hit[0], items, strict=True)):
        return hit[1]
    out = build()
    if len(cache) >= 64:
        cache.clear()
    cache[key] = (tuple(items), out)
    return out


def _start_bounds(obstacles: Sequence[PredictedObstacle], far: np.ndarray, grid: np.ndarray,
                  gc: np.ndarray, pc: np.ndarray, vr: float, reach0: float) -> np.ndarray:
    """A lower bound of each obstacle's first uncertified grid time in :func:`_predict_uncached`
    (inf: it has none), for the pacing (waypoints) discs of fixed size from one interpolation of
    all their tracks at the coarse times, -inf for the others. Before the first coarse interval
    whose bound is <= reach + L dt_max / 2 (+ 1e-9 m, far above the interpolations' rounding),
    the gap exceeds reach + L dt_max / 2, so no fine interval there is uncertified. The tracks
    (keyframes padded in the set's :class:`_Stack`) are interpolated by a compiled kernel that
    stops each at its first such interval (:func:`track_start_bounds`)."""
    n = len(obstacles)
    out = np.full(n, -math.inf)
    out[far] = math.inf
    if len(gc) < 2:
        return out
    half_fine = 0.5 * float(np.diff(grid).max())
    _straight_bounds(obstacles, far, out, gc, pc, half_fine, vr, reach0)
    tracks = _closed(obstacles)[1]
    rows = np.flatnonzero(~far[tracks.index])  # rows of the pacing tracks, not far
    if len(rows):
        out[tracks.index[rows]] = track_start_bounds(
            tracks.kf, tracks.lens, rows, tracks.speed, tracks.radius, tracks.opened, gc,
            np.ascontiguousarray(pc), float(vr), half_fine, float(reach0))
    return out


def _first_uncertified(d: np.ndarray, lip: np.ndarray, radii: np.ndarray, gc: np.ndarray,
                       half_fine: float, reach0: float) -> np.ndarray:
    """Per obstacle (a row of gaps ``d`` [m] at the coarse times ``gc``, its gap's Lipschitz
    bound ``lip`` [m/s] and radius [m]), the start of the first coarse interval whose bound is
    <= reach + L dt_max / 2 (+ 1e-9 m, far above the gaps' rounding), inf if none: before it
    no fine interval is uncertified (:func:`_start_bounds`)."""
    need = reach0 + radii + lip * half_fine + 1e-9 * (1.0 + reach0 + lip)
    low = 0.5 * (d[:, :-1] + d[:, 1:] - lip[:, None] * np.diff(gc)[None, :]) <= need[:, None]
    first = np.argmax(low, axis=1)
    return np.where(low.any(axis=1), gc[first], math.inf)


def first_collision(motion: TimedMotion, obstacles: Sequence[PredictedObstacle], robot_radius: float,
                    **kwargs: float | None) -> PredictedCollision | None:
    """The earliest of :func:`predict_collisions`, or None if the motion is collision-free."""
    hits = _predict(motion, obstacles, robot_radius, kwargs.get("t_from"), kwargs.get("t_until"),
                    float(kwargs.get("margin") or 0.0), float(kwargs.get("tol") or 1e-4),
                    kwargs.get("sample_dt"), True)
    return hits[0] if hits else None


def min_separation(motion: TimedMotion, obstacles: Sequence[PredictedObstacle], robot_radius: float,
                   t_from: float, t_until: float, step: float = 0.05) -> float:
    """Sampled minimum clearance [m] between the motion and the obstacles (for diagnostics)."""
    if not obstacles or t_until <= t_from:
        return math.inf
    t = np.arange(t_from, t_until + step, step)
    p = motion.positions(t)
    best = math.inf
    for o in obstacles:
        d = np.hypot(*(p - o.positions(t)).T) - robot_radius - o.radius_at(t)
        best = min(best, float(d.min()))
    return best


def _straight_bounds(obstacles: Sequence[PredictedObstacle], far: np.ndarray, out: np.ndarray,
                     gc: np.ndarray, pc: np.ndarray, half_fine: float, vr: float,
                     reach0: float) -> None:
    """:func:`_start_bounds` for the discs moving on straight lines at constant speed (the
    ``twist`` and ``tracked`` predictions, :class:`UnicycleMotion` with omega = 0), growing or
    not, all at once; written into ``out``. The same certificate: the gap to a grown disc,
    d(t) - extra(t), is (vr + v + rate)-Lipschitz (the extra radius never shrinks and grows at
    most at ``rate``), so a coarse interval whose bound exceeds reach + L dt_max / 2 holds no
    uncertified fine interval. Positions are computed here in one pass (a few ulp off
    ``positions``, far below the 1e-9 m allowance); a prediction's horizon (``until``) is
    ignored, which only lowers the bound."""
    stack = _stack(obstacles)
    sel = np.flatnonzero(~far[stack.straight])  # rows of the straight ones, not far
    if not len(sel):
        return
    ls = stack.straight[sel]
    x0, y0, th, sp, t_s = (a[sel] for a in stack.line)
    tau = np.maximum(gc[None, :] - t_s[:, None], 0.0)  # (obstacles, coarse times)
    ox = x0[:, None] + sp[:, None] * tau * np.cos(th)[:, None]
    oy = y0[:, None] + sp[:, None] * tau * np.sin(th)[:, None]
    d = np.hypot(pc[None, :, 0] - ox, pc[None, :, 1] - oy)
    d -= _growth_rows(stack, ls, gc)
    lip = vr + np.abs(sp) + stack.rate[ls]
    out[ls] = _first_uncertified(d, lip, stack.radius[ls], gc, half_fine, reach0)


@dataclass(frozen=True)
class _Stack:
    """One set of predictions as arrays (per obstacle, in order), for the broad phases.

    Attributes:
        boxes: (n, 4) a box holding each obstacle's centre at all times (:func:`_track`).
        speed: (n,) the obstacles' speed bounds [m/s].
        rate: (n,) their growth rates [m/s] (0 without growth).
        grown: (n,) their largest extra radii [m] (0 without growth).
        radius: (n,) their radii [m] (without growth).
        straight: indices of the discs on straight lines (constant twist, omega = 0).
        line: x0 [m], y0 [m], theta0 [rad], v [m/s], start_time [s] of those, one array each.
        taus: the growth knots [s] shared by every growing one among them (None when they
            differ: each is then interpolated on its own).
        t0: (n,) each growth's t0 [s] (nan without growth).
        values: (n, K) each growth's values [m] on ``taus`` (when shared; else K = 0).
        growths: each obstacle's growth (None without), for the interpolation one by one.
    """

    boxes: np.ndarray
    speed: np.ndarray
    rate: np.ndarray
    grown: np.ndarray
    radius: np.ndarray
    straight: np.ndarray
    line: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    taus: np.ndarray | None
    t0: np.ndarray
    values: np.ndarray
    growths: tuple[RadiusGrowth | None, ...]


#: Recent :class:`_Stack` records (``_stack``). A fallback ranking checks some twenty
#: candidates against one list of predictions.
_STACKS: dict[tuple[int, ...], tuple[tuple[object, ...], Any]] = {}


def _stack(obstacles: Sequence[PredictedObstacle]) -> _Stack:
    """The :class:`_Stack` of ``obstacles`` (memoised by their identity)."""
    return _by_identity(_STACKS, obstacles, lambda: _build_stack(obstacles))


def _build_stack(obstacles: Sequence[PredictedObstacle]) -> _Stack:
    n = len(obstacles)
    boxes, speed = np.empty((n, 4)), np.empty(n)
    for k, o in enumerate(obstacles):
        boxes[k], speed[k] = _track(o)
    growths = [o.growth for o in obstacles]
    rate = np.array([0.0 if g is None else g.rate for g in growths])
    grown = np.array([0.0 if g is None else g.max_extra for g in growths])
    straight = np.array([k for k, o in enumerate(obstacles)
                         if isinstance(o.motion, UnicycleMotion) and o.motion.omega == 0.0],
                        dtype=np.int64)
    ms = [obstacles[k].motion for k in straight]
    line = tuple(np.array([getattr(m, a) for m in ms], dtype=float)
                 for a in ("x0", "y0", "theta0", "v", "start_time"))
    knots = [g.taus for g in growths if g is not None]
    taus = knots[0] if knots and all(np.array_equal(k, knots[0]) for k in knots) else None
    t0 = np.array([math.nan if g is None else g.t0 for g in growths])
    values = np.zeros((n, 0 if taus is None else len(taus)))
    if taus is not None:
        for k, g in enumerate(growths):
            if g is not None:
                values[k] = g.values
    return _Stack(boxes, speed, rate, grown, np.array([o.radius for o in obstacles], dtype=float),
                  straight, line, taus, t0, values, tuple(growths))  # type: ignore[arg-type]


def _growth_rows(stack: _Stack, rows: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The extra radii (len(rows), len(t)) [m] of the obstacles ``rows`` at times ``t`` [s]
    (0 without growth): ``RadiusGrowth.at`` row by row, as one interpolation when the knots
    are shared (the same formula as ``np.interp``: exact but for rounding, far below the
    bounds' 1e-9 m allowance)."""
    out = np.zeros((len(rows), len(t)))
    has = np.flatnonzero(~np.isnan(stack.t0[rows]))
    if not len(has):
        return out
    taus = stack.taus
    if taus is None or len(taus) < 2:
        for i in has:
            out[i] = stack.growths[int(rows[i])].at(t)  # type: ignore[union-attr]
        return out
    r = rows[has]
    tau = t[None, :] - stack.t0[r][:, None]
    j = np.clip(np.searchsorted(taus, tau.ravel(), side="right") - 1, 0,
                len(taus) - 2).reshape(tau.shape)
    v = stack.values[r]
    ri = np.arange(len(r))[:, None]
    y0, y1 = v[ri, j], v[ri, j + 1]
    val = (y1 - y0) / (taus[j + 1] - taus[j]) * (tau - taus[j]) + y0
    val = np.where(tau <= taus[0], v[:, :1], val)
    out[has] = np.where(tau >= taus[-1], v[:, -1:], val)
    return out
