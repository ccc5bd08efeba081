"""Closest approach and first contact of two moving points (discs) over a time interval.

Two discs of radii r1, r2 collide at time t iff the distance between their centres is
``<= r1 + r2``. For two straight, constant-velocity motions the squared distance is a quadratic
in t and everything is closed form. For any other pair of motions (a circular arc, a spline
reference) :func:`first_contact` and :func:`closest_approach` are *certified*: they use a bound
``L`` on the relative speed (|d'(t)| <= L), so no contact can be missed between evaluation
points, whatever their spacing. Results are exact up to ``tol`` in time.

Examples:
    >>> import numpy as np
    >>> t, d = closest_approach_straight(np.array([0.0, 0.0]), np.array([1.0, 0.0]),
    ...                                  np.array([5.0, 1.0]), np.array([0.0, 0.0]), 0.0, 10.0)
    >>> round(t, 9), round(d, 9)
    (5.0, 1.0)
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from anyplan.geometry.se2 import dot2

__all__ = [
    "closest_approach_straight",
    "first_contact_straight",
    "closest_approach",
    "first_contact",
    "first_contact_growing",
]

PositionFn = Callable[[np.ndarray], np.ndarray]
"""Maps times, shape (N,) [s], to positions, shape (N, 2) [m]."""


def closest_approach_straight(p: np.ndarray, u: np.ndarray, q: np.ndarray, w: np.ndarray,
                              t0: float, t1: float) -> tuple[float, float]:
    """Closest approach of ``p + u t`` and ``q + w t`` for t in [t0, t1].

    Args:
        p: First position at t = 0 [m], shape (2,).
        u: First constant velocity [m/s], shape (2,).
        q: Second position at t = 0 [m], shape (2,).
        w: Second constant velocity [m/s], shape (2,).
        t0: Interval start [s].
        t1: Interval end [s], t1 >= t0.

    Returns:
        (time [s], distance [m]) of the minimum distance on the interval.
    """
    d0 = np.asarray(p, float) - np.asarray(q, float)
    dv = np.asarray(u, float) - np.asarray(w, float)
    vv = dot2(dv, dv)
    t = t0 if vv <= 0.0 else min(max(-dot2(d0, dv) / vv, t0), t1)
    d = d0 + dv * t
    return t, float(math.hypot(d[0], d[1]))


def first_contact_straight(p: np.ndarray, u: np.ndarray, q: np.ndarray, w: np.ndarray,
                           radius: float, t0: float, t1: float) -> float | None:
    """First time in [t0, t1] at which ``|p + u t - (q + w t)| <= radius``, or None."""
    d0 = np.asarray(p, float) - np.asarray(q, float)
    dv = np.asarray(u, float) - np.asarray(w, float)
    a = dot2(dv, dv)
    b = 2.0 * dot2(d0, dv)
    c = dot2(d0, d0) - radius * radius
    # distance^2 - radius^2 = a t^2 + b t + c
    at_t0 = a * t0 * t0 + b * t0 + c
    if at_t0 <= 0.0:
        return t0
    if a <= 0.0:
        return None
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return None
    sq = math.sqrt(disc)
    # Numerically stable smaller root.
    qv = -0.5 * (b + math.copysign(sq, b)) if b != 0.0 else -0.5 * sq
    r1, _r2 = sorted((qv / a, c / qv if qv != 0.0 else qv / a))
    if r1 >= t0 and r1 <= t1:
        return r1
    return None


#: Evaluation budget of one certified search. A distance that stays within a hair of the contact
#: distance for a long time (e.g. an obstacle circling the robot) needs about T L / gap
#: evaluations to be certified free; past the budget the search answers conservatively.
MAX_EVALUATIONS = 50_000


def _certified_scan(fn: Callable[[np.ndarray], np.ndarray], lipschitz: float, t0: float,
                    t1: float, level: float, tol: float, n_init: int = 64) -> float | None:
    """First t in [t0, t1] with fn(t) <= level, for an L-Lipschitz scalar fn, or None.

    Intervals [a, b] are discarded when the Lipschitz lower bound
    ``(f(a) + f(b) - L (b - a)) / 2`` is above ``level``; the rest are split, earliest first.
    After :data:`MAX_EVALUATIONS` evaluations the earliest interval not yet certified free is
    reported as the contact (never later than a true contact; possibly a false alarm).
    """
    if t1 < t0:
        return None
    ts = np.linspace(t0, t1, n_init + 1)
    fs = fn(ts)
    if fs[0] <= level:
        return float(t0)
    L = max(lipschitz, 1e-12)
    stack: list[tuple[float, float, float, float]] = []
    for i in range(n_init - 1, -1, -1):
        stack.append((ts[i], ts[i + 1], fs[i], fs[i + 1]))
    evals = n_init + 1
    while stack:
        a, b, fa, fb = stack.pop()
        if 0.5 * (fa + fb - L * (b - a)) > level:
            continue  # certified free on [a, b]
        if b - a <= tol or evals >= MAX_EVALUATIONS:
            # Cannot be certified free at this resolution: report the contact conservatively.
            return float(a)
        evals += 7
        mids = np.linspace(a, b, 9)
        fm = fn(mids[1:-1])
        vals = np.concatenate([[fa], fm, [fb]])
        for j in range(7, -1, -1):
            stack.append((mids[j], mids[j + 1], vals[j], vals[j + 1]))
    return None


def first_contact(pos_a: PositionFn, pos_b: PositionFn, rel_speed_bound: float, radius: float,
                  t0: float, t1: float, tol: float = 1e-6) -> float | None:
    """First time in [t0, t1] at which two moving points come within ``radius``, or None.

    Args:
        pos_a: Position function, times (N,) [s] -> positions (N, 2) [m].
        pos_b: The other one, likewise.
        rel_speed_bound: An upper bound on |d/dt (pos_a - pos_b)| [m/s] over the interval
            (e.g. the sum of both maximum speeds).
        radius: Contact distance [m] (sum of the disc radii).
        t0: Interval start [s].
        t1: Interval end [s].
        tol: Time accuracy [s]. A grazing approach that cannot be told from a contact at
            this accuracy is reported as a contact (conservative).

    Returns:
        The first contact time [s], within ``tol`` and never later than the true one, or None
        if the distance stays above ``radius`` on the whole interval.
    """
    def dist(t: np.ndarray) -> np.ndarray:
        d = pos_a(t) - pos_b(t)
        return np.hypot(d[:, 0], d[:, 1])

    return _certified_scan(dist, rel_speed_bound, t0, t1, radius, tol)


def first_contact_growing(pos_a: PositionFn, pos_b: PositionFn, rel_speed_bound: float,
                          radius: float, extra_fn: Callable[[np.ndarray], np.ndarray],
                          extra_rate_bound: float, t0: float, t1: float,
                          tol: float = 1e-6) -> float | None:
    """First time in [t0, t1] at which two moving points come within ``radius + extra_fn(t)``
    (a contact distance that changes with time, e.g. an uncertain disc growing with the horizon),
    or None.

    The search scans ``dist(t) - extra_fn(t)``, whose slope is bounded by
    ``rel_speed_bound + extra_rate_bound`` (a bound on |d extra / dt| [m/s]); otherwise as
    :func:`first_contact`: within ``tol`` and never later than the true first contact.
    """
    def gap(t: np.ndarray) -> np.ndarray:
        d = pos_a(t) - pos_b(t)
        return np.hypot(d[:, 0], d[:, 1]) - extra_fn(t)

    return _certified_scan(gap, rel_speed_bound + extra_rate_bound, t0, t1, radius, tol)


def closest_approach(pos_a: PositionFn, pos_b: PositionFn, rel_speed_bound: float, t0: float,
                     t1: float, tol: float = 1e-6) -> tuple[float, float]:
    """Certified minimum distance between two moving points over [t0, t1].

    Returns (time [s], distance [m]); the distance is within ``rel_speed_bound * tol`` of the
    true minimum, unless the distance is nearly constant for a long time (a plateau needs about
    T / tol evaluations to certify): after :data:`MAX_EVALUATIONS` the best distance found is
    returned, which is then only an upper bound on the minimum.
    """
    L = max(rel_speed_bound, 1e-12)

    def dist(t: np.ndarray) -> np.ndarray:
        d = pos_a(t) - pos_b(t)
        return np.hypot(d[:, 0], d[:, 1])

    n = 128
    ts = np.linspace(t0, t1, n + 1)
    fs = dist(ts)
    i = int(np.argmin(fs))
    best_t, best = float(ts[i]), float(fs[i])
    # the intervals of a level as arrays: starts, ends, distances at both
    a, b, fa, fb = ts[:-1], ts[1:], fs[:-1], fs[1:]
    evals = n + 1
    steps = np.arange(1, 4, dtype=float)
    while len(a) and evals < MAX_EVALUATIONS:
        # An interval is settled when it cannot hold a distance below the best by more than
        # L tol, or is fine enough. The level's points are evaluated in one call for the
        # intervals not settled by the best at the level's start (the best only decreases);
        # the scan below then takes the same decisions, in the same order, with the same values
        # as refining interval by interval with the best as it goes.
        lbs = 0.5 * (fa + fb - L * (b - a))
        live = np.flatnonzero(~((lbs >= best - L * tol) | (b - a <= tol)))
        if not len(live):
            break
        la, lb, lfa, lfb, llbs = a[live], b[live], fa[live], fb[live], lbs[live]
        # np.linspace(a, b, 5)'s interior points, bit for bit: k * ((b - a) / 4) + a
        mids = steps[None, :] * ((lb - la) / 4.0)[:, None] + la[:, None]
        fm = dist(mids.ravel()).reshape(-1, 3)
        jm = np.argmin(fm, axis=1)
        fmin = fm[np.arange(len(live)), jm].tolist()
        keep = []
        for k, lo in enumerate(llbs.tolist()):
            if lo >= best - L * tol:
                continue  # settled by a better distance found earlier in this level
            keep.append(k)
            evals += 3
            if fmin[k] < best:
                best, best_t = fmin[k], float(mids[k, jm[k]])
        kk = np.asarray(keep, dtype=np.int64)
        # each refined interval's four parts, in time order
        pts = np.column_stack([la[kk], mids[kk], lb[kk]])
        vals = np.column_stack([lfa[kk], fm[kk], lfb[kk]])
        a, b = pts[:, :-1].ravel(), pts[:, 1:].ravel()
        fa, fb = vals[:, :-1].ravel(), vals[:, 1:].ravel()
    return best_t, best
