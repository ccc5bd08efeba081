"""Compiled first contacts of a sampled robot motion with discs on straight lines and on
looping tracks.

The robot's motion is given by samples (``SampledMotion``: linear between them). A straight
disc moves at constant velocity from its start time (at rest before it) and its radius grows
piecewise linearly with the horizon (``RadiusGrowth`` on knots shared by all); a looping track
(``WaypointMotion``) is piecewise linear and repeats every period, an open one jumping back to
its first keyframe. Between consecutive breakpoints (samples, start time, growth knots,
keyframes, periods' starts) the relative position and the contact distance are both affine in
time, so the squared gap ``|d(s)|^2 - c(s)^2`` is a quadratic and its first root is closed
form: the first contact is exact up to rounding, with no time tolerance.
:class:`StraightDiscs` and :class:`LoopingTracks` hold one prediction set's discs and tracks as
the kernels' arrays (``anyplan.prediction.collision`` uses them); :func:`track_start_bounds` is
the certified search's broad phase for tracks (where each may first come near the robot).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit

from anyplan.prediction.base import PredictedObstacle
from anyplan.world.motion import UnicycleMotion, WaypointMotion

#: [m] added to the contact distance: a gap this close to zero counts as contact (rounding).
CONTACT_EPS = 1e-12


@njit(cache=True)
def _extra(t: float, t0: float, taus: np.ndarray, vals: np.ndarray) -> float:
    """``np.interp(t - t0, taus, vals)`` (constant outside the knots)."""
    x = t - t0
    n = taus.shape[0]
    if n == 0:
        return 0.0
    if x <= taus[0]:
        return vals[0]
    if x >= taus[n - 1]:
        return vals[n - 1]
    j = np.searchsorted(taus, x, side="right") - 1
    return (vals[j + 1] - vals[j]) / (taus[j + 1] - taus[j]) * (x - taus[j]) + vals[j]


@njit(cache=True)
def _first_root(d0x: float, d0y: float, dvx: float, dvy: float, c0: float, cr: float,
                h: float) -> float:
    """The first s in [0, h] with |d0 + dv s| <= c0 + cr s (c0 + cr s >= 0 on it), or -1."""
    c = d0x * d0x + d0y * d0y - c0 * c0
    if c <= 0.0:
        return 0.0
    a = dvx * dvx + dvy * dvy - cr * cr
    b = 2.0 * (d0x * dvx + d0y * dvy - c0 * cr)
    if a > 0.0:
        if b >= 0.0:
            return -1.0  # both roots negative: the gap only opens
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            return -1.0
        r = 2.0 * c / (-b + math.sqrt(disc))  # the smaller root, without cancellation
    elif a < 0.0:
        # concave: positive at 0, below zero past its positive root
        sq = math.sqrt(b * b - 4.0 * a * c)
        r = 2.0 * c / (sq - b) if b <= 0.0 else (b + sq) / (-2.0 * a)
    else:
        if b >= 0.0:
            return -1.0
        r = -c / b
    return r if r <= h else -1.0


@njit(cache=True)
def straight_contacts(ts: np.ndarray, xs: np.ndarray, ys: np.ndarray, t0: float, t1: float,
                      x0: np.ndarray, y0: np.ndarray, vx: np.ndarray, vy: np.ndarray,
                      t_s: np.ndarray, reach: np.ndarray, until: np.ndarray, g_t0: np.ndarray,
                      taus: np.ndarray, g_vals: np.ndarray, first_only: bool) -> np.ndarray:
    """First contact time [s] in [t0, t1] of the robot (samples ``ts``, ``xs``, ``ys`` [s, m],
    ``ts`` increasing, [t0, t1] within them) with each obstacle k (centre ``(x0, y0) + (vx, vy)
    max(t - t_s, 0)`` [m], contact distance ``reach[k] + interp(t - g_t0[k], taus, g_vals[k])``
    [m], checked up to ``until[k]`` [s]); inf where there is none. ``first_only``: only the
    earliest is exact, every later one may be reported as inf (the scan of an obstacle stops at
    the earliest contact found so far)."""
    n_obs = x0.shape[0]
    n = ts.shape[0]
    nk = taus.shape[0]
    out = np.full(n_obs, np.inf)
    best = np.inf
    # broad phase: the robot stays in its samples' box (linear in between)
    bx0, bx1, by0, by1 = xs.min(), xs.max(), ys.min(), ys.max()
    for k in range(n_obs):
        t_end = min(t1, until[k])
        if t_end < t0:
            continue
        # the obstacle's centre stays on the segment between its positions at t0 and t_end
        sa, sb = max(t0 - t_s[k], 0.0), max(t_end - t_s[k], 0.0)
        ax, bx = x0[k] + vx[k] * sa, x0[k] + vx[k] * sb
        ay, by = y0[k] + vy[k] * sa, y0[k] + vy[k] * sb
        gx = max(0.0, min(ax, bx) - bx1, bx0 - max(ax, bx))
        gy = max(0.0, min(ay, by) - by1, by0 - max(ay, by))
        grown = 0.0
        for j in range(nk):
            grown = max(grown, g_vals[k, j])
        if gx * gx + gy * gy > (reach[k] + CONTACT_EPS + grown) ** 2:
            continue  # farther than its largest disc at every time: no contact
        i = min(max(int(np.searchsorted(ts, t0, side="right")) - 1, 0), n - 2)
        a = t0
        found = False
        while not found and a <= t_end:
            if first_only and a >= best:
                break
            b = min(ts[i + 1], t_end)
            # one sub-interval per piece on which everything is affine
            p = a
            while True:
                q = b
                if p < t_s[k] < q:
                    q = t_s[k]
                for j in range(nk):
                    tk = g_t0[k] + taus[j]
                    if p < tk < q:
                        q = tk
                # robot on its sample interval i (np.interp's formula), obstacle, growth
                w = (xs[i + 1] - xs[i]) / (ts[i + 1] - ts[i])
                u = (ys[i + 1] - ys[i]) / (ts[i + 1] - ts[i])
                rpx, rpy = w * (p - ts[i]) + xs[i], u * (p - ts[i]) + ys[i]
                rqx, rqy = w * (q - ts[i]) + xs[i], u * (q - ts[i]) + ys[i]
                sp, sq = max(p - t_s[k], 0.0), max(q - t_s[k], 0.0)
                dpx, dpy = rpx - (x0[k] + vx[k] * sp), rpy - (y0[k] + vy[k] * sp)
                dqx, dqy = rqx - (x0[k] + vx[k] * sq), rqy - (y0[k] + vy[k] * sq)
                cp = reach[k] + CONTACT_EPS + _extra(p, g_t0[k], taus, g_vals[k])
                cq = reach[k] + CONTACT_EPS + _extra(q, g_t0[k], taus, g_vals[k])
                h = q - p
                if h > 0.0:
                    r = _first_root(dpx, dpy, (dqx - dpx) / h, (dqy - dpy) / h, cp, (cq - cp) / h, h)
                else:
                    r = 0.0 if dpx * dpx + dpy * dpy <= cp * cp else -1.0
                if r >= 0.0:
                    out[k] = min(p + r, t_end)
                    found = True
                    break
                if q >= b:
                    break
                p = q
            if b >= t_end:
                break
            a = b
            i += 1
        if out[k] < best:
            best = out[k]
    return out


@njit(cache=True)
def track_start_bounds(kf: np.ndarray, lens: np.ndarray, rows: np.ndarray, speed: np.ndarray,
                       radius: np.ndarray, opened: np.ndarray, gc: np.ndarray, pc: np.ndarray,
                       vr: float, half_fine: float, reach0: float) -> np.ndarray:
    """For each looping track ``rows[j]`` (keyframes ``kf[k, :lens[k]]``, rows (t, x, y), the
    position at ``t mod period`` interpolated as ``np.interp`` does; speed bound ``speed[k]``
    [m/s], radius ``radius[k]`` [m]), the start [s] of the first interval of the coarse times
    ``gc`` whose gap bound, (d_c + d_c+1 - L dt) / 2 with L = ``vr`` + the track's speed, is at
    most reach0 + radius + L ``half_fine`` + 1e-9 (1 + reach0 + L) [m]; inf if none. ``pc``
    (len(gc), 2): the robot's positions [m]. Each track stops at its first such interval; an
    interval that holds a period's start of an open track (``opened[k]``: it jumps back there)
    counts as one, since the speed bound does not hold across the jump."""
    m = gc.shape[0]
    out = np.full(rows.shape[0], np.inf)
    for j in range(rows.shape[0]):
        k = rows[j]
        nk = lens[k]
        period = kf[k, nk - 1, 0]
        lip = vr + speed[k]
        need = reach0 + radius[k] + lip * half_fine + 1e-9 * (1.0 + reach0 + lip)
        prev = 0.0
        for c in range(m):
            tm = gc[c] % period
            i = 0
            while i < nk and kf[k, i, 0] <= tm:
                i += 1
            i = min(max(i - 1, 0), nk - 2)
            w = min(max((tm - kf[k, i, 0]) / (kf[k, i + 1, 0] - kf[k, i, 0]), 0.0), 1.0)
            d = math.hypot(pc[c, 0] - (kf[k, i, 1] + w * (kf[k, i + 1, 1] - kf[k, i, 1])),
                           pc[c, 1] - (kf[k, i, 2] + w * (kf[k, i + 1, 2] - kf[k, i, 2])))
            if c > 0 and (0.5 * (prev + d - lip * (gc[c] - gc[c - 1])) <= need or (
                    opened[k] and (tm == 0.0 or math.floor(gc[c] / period)
                                   != math.floor(gc[c - 1] / period)))):
                out[j] = gc[c - 1]
                break
            prev = d
    return out


@njit(cache=True)
def _track_at(kf: np.ndarray, k: int, nk: int, t: float) -> tuple[int, float]:
    """The segment of track ``k`` at absolute time ``t`` [s] (as ``np.interp`` at ``t mod
    period`` picks it) and the index of the period that holds ``t``."""
    period = kf[k, nk - 1, 0]
    m = math.floor(t / period)
    tm = t - m * period
    if tm >= period:  # rounding: t is the next period's start
        m += 1.0
        tm = t - m * period
    elif tm < 0.0:
        m -= 1.0
        tm = t - m * period
    s = 0
    while s + 2 < nk and kf[k, s + 1, 0] <= tm:
        s += 1
    return s, m


@njit(cache=True)
def track_contacts(ts: np.ndarray, xs: np.ndarray, ys: np.ndarray, t0: float, t1: float,
                   kf: np.ndarray, lens: np.ndarray, speed: np.ndarray, reach: np.ndarray,
                   until: np.ndarray, vr: float, first_only: bool) -> np.ndarray:
    """First contact time [s] in [t0, t1] of the robot (samples ``ts``, ``xs``, ``ys``, linear
    between them, speed at most ``vr`` [m/s], [t0, t1] within them) with each looping track
    ``k`` (keyframes ``kf[k, :lens[k]]``, rows (t, x, y), repeated every period; an
    open track jumps back to its first keyframe at each period's start; speed at most
    ``speed[k]`` [m/s]), contact distance ``reach[k]`` [m], checked up to ``until[k]`` [s];
    inf where there is none.

    Between breakpoints (the samples, the keyframes, the periods' starts) both motions are
    affine, so the first root of the squared gap is closed form (:func:`_first_root`). Where
    the gap g [m] is wide the scan moves on by g / (vr + speed) at once (the gap cannot close
    faster), never past a period's start. ``first_only``: as in :func:`straight_contacts`."""
    n = ts.shape[0]
    out = np.full(kf.shape[0], np.inf)
    best = np.inf
    for k in range(kf.shape[0]):
        nk = lens[k]
        period = kf[k, nk - 1, 0]
        t_end = min(t1, until[k])
        if t_end < t0:
            continue
        rk = reach[k] + CONTACT_EPS
        lip = vr + speed[k]
        p = t0
        i = min(max(int(np.searchsorted(ts, p, side="right")) - 1, 0), n - 2)
        s, m = _track_at(kf, k, nk, p)
        while True:
            if first_only and p >= best:
                break
            base = m * period
            ta, tb = base + kf[k, s, 0], base + kf[k, s + 1, 0]
            q = min(ts[i + 1], tb, t_end)
            # the robot on its sample interval i (np.interp's formula), the track on segment s
            w = (xs[i + 1] - xs[i]) / (ts[i + 1] - ts[i])
            u = (ys[i + 1] - ys[i]) / (ts[i + 1] - ts[i])
            ox = (kf[k, s + 1, 1] - kf[k, s, 1]) / (kf[k, s + 1, 0] - kf[k, s, 0])
            oy = (kf[k, s + 1, 2] - kf[k, s, 2]) / (kf[k, s + 1, 0] - kf[k, s, 0])
            dpx = w * (p - ts[i]) + xs[i] - (ox * (p - ta) + kf[k, s, 1])
            dpy = u * (p - ts[i]) + ys[i] - (oy * (p - ta) + kf[k, s, 2])
            gap = math.sqrt(dpx * dpx + dpy * dpy) - rk
            if gap > 0.0 and lip > 0.0 and p + gap / lip > q:
                nxt = min(p + gap / lip, base + period)  # no contact before it
                if nxt >= t_end:
                    break
                p = nxt
            else:
                h = q - p
                r = -1.0
                if h > 0.0:
                    dqx = w * (q - ts[i]) + xs[i] - (ox * (q - ta) + kf[k, s, 1])
                    dqy = u * (q - ts[i]) + ys[i] - (oy * (q - ta) + kf[k, s, 2])
                    r = _first_root(dpx, dpy, (dqx - dpx) / h, (dqy - dpy) / h, rk, 0.0, h)
                elif gap <= 0.0:
                    r = 0.0
                if r >= 0.0:
                    out[k] = min(p + r, t_end)
                    break
                if q >= t_end:
                    break
                p = q
            while i < n - 2 and ts[i + 1] <= p:
                i += 1
            while p >= m * period + kf[k, s + 1, 0]:  # the segment's end: the next one
                s += 1
                if s == nk - 1:  # the period's end: the next period's first segment
                    s = 0
                    m += 1.0
        if out[k] < best:
            best = out[k]
    return out


@dataclass(frozen=True)
class StraightDiscs:
    """The discs of one prediction set on straight lines (without growth, or with one on the
    knots every growing one shares) as the arrays of :func:`straight_contacts` (C-contiguous:
    one specialisation), their indices in the set (``index``) and those of the others
    (``rest``)."""

    index: np.ndarray
    rest: tuple[int, ...]
    x0: np.ndarray
    y0: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    t_s: np.ndarray
    radius: np.ndarray
    until: np.ndarray
    g_t0: np.ndarray
    taus: np.ndarray
    g_vals: np.ndarray

    @classmethod
    def of(cls, obstacles: Sequence[PredictedObstacle]) -> StraightDiscs:
        straight = [k for k, o in enumerate(obstacles)
                    if isinstance(o.motion, UnicycleMotion) and o.motion.omega == 0.0]
        knots = [obstacles[k].growth.taus for k in straight  # type: ignore[union-attr]
                 if obstacles[k].growth is not None]
        shared = not knots or all(np.array_equal(t, knots[0]) for t in knots)
        index = [k for k in straight if shared or obstacles[k].growth is None]
        ms = [obstacles[k].motion for k in index]
        x0, y0, th, sp, t_s = (np.array([getattr(m, a) for m in ms], dtype=float)
                               for a in ("x0", "y0", "theta0", "v", "start_time"))
        gs = [obstacles[k].growth for k in index]
        taus = np.ascontiguousarray(knots[0], dtype=float) if knots and shared else np.zeros(0)
        vals = np.zeros((len(index), len(taus)))
        for j, g in enumerate(gs):
            if g is not None:
                vals[j] = g.values
        return cls(np.array(index, dtype=np.int64),
                   tuple(sorted(set(range(len(obstacles))) - set(index))), x0, y0,
                   sp * np.cos(th), sp * np.sin(th), t_s,
                   np.array([obstacles[k].radius for k in index], dtype=float),
                   np.array([obstacles[k].until for k in index], dtype=float),
                   np.array([0.0 if g is None else g.t0 for g in gs], dtype=float), taus, vals)

    def first_contacts(self, ts: np.ndarray, xs: np.ndarray, ys: np.ndarray, reach0: float,
                       t0: float, t1: float, first_only: bool) -> np.ndarray:
        """First contact time [s] in [t0, t1] of the robot's samples (``ts``, ``xs``, ``ys``)
        with each disc (inf: none), the contact distance ``reach0`` [m] plus each disc's radius
        and growth (:func:`straight_contacts`)."""
        return straight_contacts(ts, xs, ys, float(t0), float(t1), self.x0, self.y0, self.vx,
                                 self.vy, self.t_s, reach0 + self.radius, self.until, self.g_t0,
                                 self.taus, self.g_vals, bool(first_only))


@dataclass(frozen=True)
class LoopingTracks:
    """The looping tracks (``WaypointMotion`` without growth) of one prediction set as the
    kernels' arrays, one row per track: their indices in the set (``index``), keyframes
    (``kf``, padded to the longest with rows at time +inf) and keyframe counts (``lens``),
    whether each is open (``opened``: it jumps back at each period's start), speed bounds
    [m/s], radii [m] and horizons (``until``) [s]."""

    index: np.ndarray
    kf: np.ndarray
    lens: np.ndarray
    opened: np.ndarray
    speed: np.ndarray
    radius: np.ndarray
    until: np.ndarray

    @classmethod
    def of(cls, obstacles: Sequence[PredictedObstacle]) -> LoopingTracks:
        index = [k for k, o in enumerate(obstacles)
                 if o.growth is None and isinstance(o.motion, WaypointMotion)]
        ms: list[WaypointMotion] = [obstacles[k].motion for k in index]  # type: ignore[misc]
        lens = np.array([len(m.keyframes) for m in ms], dtype=np.int64)
        kf = np.zeros((len(ms), int(lens.max()) if len(ms) else 2, 3))
        kf[:, :, 0] = math.inf
        for j, m in enumerate(ms):
            kf[j, :lens[j]] = m.keyframes
        return cls(np.array(index, dtype=np.int64), kf, lens,
                   np.array([m.is_open for m in ms], dtype=np.bool_),
                   np.array([m.max_speed for m in ms], dtype=float),
                   np.array([obstacles[k].radius for k in index], dtype=float),
                   np.array([obstacles[k].until for k in index], dtype=float))
