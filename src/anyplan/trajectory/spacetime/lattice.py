"""Time-optimal, acceleration-bounded velocity planning along a fixed path among s-t obstacles.

The robot moves along a path of arc length s in [0, L]; moving obstacles forbid regions of the
(s, t) plane (:mod:`~anyplan.trajectory.spacetime.stmap`). We look for the earliest arrival at
rest at the end with 0 <= v <= v_max(s) (a cap on v^2 per path cell), |a| <= a_max, waits
allowed, and no point of the s-t curve in a forbidden cell: the problem of Johnson & Hauser
("Optimal acceleration-bounded trajectory planning in dynamic environments along a specified
path", ICRA 2012), solved here on an exact bang-bang lattice: steps of ``dt`` at acceleration
in {-a, 0, +a}, v = k a dt, s = s_A + m a dt^2 / 2, so a step maps integers (m, k) to
(m + 2k + u, k + u); A* over (step n, m, k), each step checked continuously against the map.
Kernels are numba; :func:`plan_velocity` handles a start speed off the lattice.
Design and measurements: ``docs/spacetime.md`` ("Design: path-velocity decomposition ...").
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np
from numba import njit

__all__ = ["VelocityPlan", "plan_velocity", "lattice_dt", "edge_ok", "goal_times"]


@dataclass(frozen=True)
class VelocityPlan:
    """A piecewise constant-acceleration motion along the path.

    Attributes:
        t: Knot times [s] (absolute), (n+1,).
        s: Arc length [m] at the knots (n+1,).
        v: Speed [m/s] at the knots (n+1,); v[-1] == 0.
        a: Acceleration [m/s^2] on each step (n,).
    """

    t: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray

    @property
    def arrival_s(self) -> float:
        """Time [s] at which the robot is at rest at the end."""
        return float(self.t[-1])

    @property
    def wait_s(self) -> float:
        """Total time [s] spent at rest (v = 0 at both ends of a step)."""
        rest = (self.v[:-1] <= 1e-12) & (self.v[1:] <= 1e-12)
        return float(np.sum(np.diff(self.t)[rest]))

    def at_time(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s [m], v [m/s], a [m/s^2]) at absolute times ``t`` [s] (clamped to the plan)."""
        t = np.clip(np.asarray(t, dtype=float), self.t[0], self.t[-1])
        i = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.a) - 1)
        tau = t - self.t[i]
        a = self.a[i]
        v = np.maximum(self.v[i] + a * tau, 0.0)
        s = self.s[i] + self.v[i] * tau + 0.5 * a * tau * tau
        return np.minimum(s, self.s[i + 1] if len(self.s) > 1 else s), v, a


def lattice_dt(v_max: float, a_max: float, target_dt: float = 0.25) -> tuple[float, int]:
    """Step ``dt`` [s] and number of speed levels K so that v_max = K a_max dt exactly."""
    k = max(2, int(round(v_max / (a_max * target_dt))))
    return v_max / (a_max * k), k


@njit(cache=True)
def edge_ok(forbidden: np.ndarray, t_map: float, h: float, ds: float, xcap0: np.ndarray,
            xcap1: np.ndarray, t_a: float, s_a: float, v_a: float, acc: float, dur: float) -> bool:
    """True if the step from (t_a, s_a, v_a) with acceleration ``acc`` for ``dur`` seconds keeps
    the speed limit and touches no forbidden cell (rows beyond the map count as forbidden)."""
    ncell = forbidden.shape[1]
    nrow = forbidden.shape[0]
    s_b = s_a + v_a * dur + 0.5 * acc * dur * dur
    v_b = v_a + acc * dur
    if v_b < -1e-9:
        return False
    x_hi = max(v_a * v_a, v_b * v_b)
    c0 = min(max(int(s_a / ds), 0), ncell - 1)
    c1 = min(max(int(s_b / ds), 0), ncell - 1)
    if x_hi > 1e-12:
        for c in range(c0, c1 + 1):
            cap = xcap1[c] if acc != 0.0 else xcap0[c]
            if x_hi > cap * (1.0 + 1e-9) + 1e-12:
                return False
    j0 = int(math.floor((t_a - t_map) / h + 1e-9))
    j1 = int(math.floor((t_a + dur - t_map) / h - 1e-9))
    if j0 < 0:
        j0 = 0
    if j1 >= nrow:
        return False
    for j in range(j0, j1 + 1):
        ta = max(t_a, t_map + j * h) - t_a
        tb = min(t_a + dur, t_map + (j + 1) * h) - t_a
        sa = s_a + v_a * ta + 0.5 * acc * ta * ta
        sb = s_a + v_a * tb + 0.5 * acc * tb * tb
        ca = min(max(int(sa / ds), 0), ncell - 1)
        cb = min(max(int(sb / ds), 0), ncell - 1)
        for c in range(ca, cb + 1):
            if forbidden[j, c]:
                return False
    return True


@njit(cache=True)
def _to_go(d: float, v: float, a: float, v_max: float) -> float:
    """Least time [s] to cover ``d`` [m] from speed ``v`` and stop, ignoring obstacles."""
    if d <= 0.0:
        return v / a
    if v * v >= 2.0 * a * d:
        return v / a
    vp = math.sqrt(a * d + 0.5 * v * v)
    if vp <= v_max:
        return (vp - v) / a + vp / a
    cruise = d - (v_max * v_max - v * v) / (2.0 * a) - v_max * v_max / (2.0 * a)
    return (v_max - v) / a + v_max / a + cruise / v_max


@njit(cache=True)
def goal_times(forbidden: np.ndarray, t_map: float, h: float, c_goal: int, reach: int,
               ds: float, v_max: float) -> np.ndarray:
    """Lower bounds G[j, c] [s] on the arrival at the goal cell from cell c at time t_map + j h.

    The relaxation of every lattice motion: within a row the robot advances by at most ``reach``
    cells (v_max h / ds, rounded up, plus one), through free cells of that row, with unbounded
    acceleration; each bound is also raised to the distance bound t + (c_goal - c - 1) ds / v_max
    (the max of two lower bounds is one). Backward over the rows; inf marks cells from which the
    goal cannot be reached within the map (the search drops them).
    """
    nrow, ncell = forbidden.shape
    g = np.full((nrow + 1, ncell), np.inf)
    for c in range(c_goal, ncell):
        g[nrow, c] = t_map + nrow * h
    for j in range(nrow - 1, -1, -1):
        tj = t_map + j * h
        for c in range(ncell):
            if c >= c_goal:
                g[j, c] = tj
                continue
            if forbidden[j, c]:
                continue
            best = np.inf
            for c2 in range(c, min(c + reach, ncell - 1) + 1):
                if forbidden[j, c2]:
                    break
                if c2 >= c_goal:
                    best = tj
                    break
                if g[j + 1, c2] < best:
                    best = g[j + 1, c2]
            g[j, c] = max(best, tj + (c_goal - c - 1) * ds / v_max)
    return g


@njit(cache=True)
def _search(forbidden: np.ndarray, t_map: float, h: float, ds: float, xcap0: np.ndarray,
            xcap1: np.ndarray, t_a: float, s_a: float, k_a: int, a: float, dt: float, kmax: int,
            m_goal: int, n_max: int, key_cells: int, gt: np.ndarray) -> np.ndarray:
    """A* over lattice nodes (step n, m, k), cost = time, heuristic = the larger of the
    obstacle-free time to go and the relaxed bound ``gt`` of :func:`goal_times` (both admissible);
    returns the accelerations (-1, 0, 1) of the earliest motion from
    (m=0, k=k_a) at t_a to (m_goal, 0), or [-9] if none within n_max steps."""
    delta = 0.5 * a * dt * dt
    vstep = a * dt
    nm = m_goal + 1
    s_goal = s_a + m_goal * delta
    parent = np.zeros((n_max + 1, nm, kmax + 1), dtype=np.int8)
    parent[0, 0, k_a] = 4
    # One node per (step, map cell, speed): two lattice points in one cell at one speed and
    # time differ by less than a cell; keeping the first (best f) bounds the search by the map.
    ncell = forbidden.shape[1]
    seen = np.zeros((n_max + 1, ncell, kmax + 1), dtype=np.bool_)
    heap = [(_to_go(s_goal - s_a, k_a * vstep, a, kmax * vstep), 0, 0, 0, k_a)]
    found = -1
    while len(heap) > 0:
        _, _, n, m, k = heapq.heappop(heap)
        if m == m_goal and k == 0:
            found = n
            break
        if n >= n_max:
            continue
        s = s_a + m * delta
        v = k * vstep
        t = t_a + n * dt
        for u in (1, 0, -1):
            k2 = k + u
            if k2 < 0 or k2 > kmax:
                continue
            m2 = m + 2 * k + u
            if m2 > m_goal or parent[n + 1, m2, k2] != 0:
                continue
            key = min(int((s_a + m2 * delta) / (max(key_cells, 1) * ds)), ncell - 1)
            if key_cells > 0 and seen[n + 1, key, k2] and m2 != m_goal:
                continue
            if not edge_ok(forbidden, t_map, h, ds, xcap0, xcap1, t, s, v, u * a, dt):
                continue
            s2 = s_a + m2 * delta
            t2 = t + dt
            j2 = min(max(int((t2 - t_map) / h + 1e-9), 0), gt.shape[0] - 1)
            g2 = gt[j2, min(max(int(s2 / ds), 0), ncell - 1)]
            if g2 == np.inf:
                continue  # the goal cannot be reached from there within the map
            parent[n + 1, m2, k2] = u + 2
            seen[n + 1, key, k2] = True
            f = t2 + max(_to_go(s_goal - s2, k2 * vstep, a, kmax * vstep), g2 - t2)
            heapq.heappush(heap, (f, -m2, n + 1, m2, k2))
    if found < 0:
        return np.full(1, -9, dtype=np.int64)
    acts = np.empty(found, dtype=np.int64)
    m, k = m_goal, 0
    for n in range(found, 0, -1):
        u = int(parent[n, m, k]) - 2
        acts[n - 1] = u
        k_prev = k - u
        m = m - 2 * k_prev - u
        k = k_prev
    return acts


def plan_velocity(forbidden: np.ndarray, t_map: float, h: float, ds: float, xcap0: np.ndarray,
                  xcap1: np.ndarray, length: float, t0: float, v0: float, a_max: float,
                  v_max: float, *, target_dt: float = 0.25, horizon_s: float = 60.0,
                  key_cells: int = 4) -> VelocityPlan | None:
    """The earliest lattice motion from (t0, s=0, v0) to rest at (about) the path's end.

    Args:
        forbidden: s-t map (rows of ``h`` seconds from ``t_map``, columns of ``ds`` metres).
        t_map: Map origin [s].
        h: Row duration [s].
        ds: Column width [m].
        xcap0: Cap on v^2 [m^2/s^2] per column when cruising.
        xcap1: Cap on v^2 [m^2/s^2] per column when accelerating at +-a_max.
        length: Path length L [m]; the motion ends at rest within ``a dt^2`` [m] before L.
        t0: Start time [s].
        v0: Start speed [m/s] (0 <= v0 <= v_max).
        a_max: Acceleration limit [m/s^2].
        v_max: Speed limit [m/s].
        target_dt: Approximate lattice step [s] (see :func:`lattice_dt`).
        horizon_s: Latest arrival considered, counted from t0 [s].
        key_cells: The search keeps one node per (step, speed, ``key_cells`` map cells): the
            first reached, which has the best estimate. Coarser keys search faster; the motion
            found is collision-free either way, but it may arrive a step or two later than the
            lattice optimum, and a gap narrower than the key may be missed. 0 keeps every node
            (the exact lattice optimum).

    Returns:
        The :class:`VelocityPlan`, or None if no lattice motion reaches the end in the horizon.
    """
    dt, kmax = lattice_dt(v_max, a_max, target_dt)
    vstep = a_max * dt
    delta = 0.5 * a_max * dt * dt
    v0 = min(max(float(v0), 0.0), v_max)
    n_max = int(math.ceil(horizon_s / dt))
    # Start options: (time, s, k) of the lattice origin and the first step (or none).
    starts: list[tuple[float, float, int, float, float]] = []
    kf = v0 / vstep
    if abs(kf - round(kf)) < 1e-9:
        starts.append((t0, 0.0, int(round(kf)), 0.0, 0.0))
    else:
        lo, hi = int(math.floor(kf)), int(math.ceil(kf))
        for k, acc in ((hi, a_max), (lo, -a_max)):
            if k > kmax:
                continue
            tau = abs(k * vstep - v0) / a_max
            if not edge_ok(forbidden, t_map, h, ds, xcap0, xcap1, t0, 0.0, v0, acc, tau):
                continue
            starts.append((t0 + tau, v0 * tau + 0.5 * acc * tau * tau, k, acc, tau))
    ncell = forbidden.shape[1]
    c_goal = min(int(math.floor((length - 2.0 * delta) / ds)), ncell - 1)
    reach = int(math.ceil(v_max * h / ds)) + 1
    gt = goal_times(forbidden, float(t_map), float(h), max(c_goal, 0), reach, float(ds),
                    float(v_max))
    best: VelocityPlan | None = None
    for t_a, s_a, k_a, acc0, tau0 in starts:
        m_goal = int(math.floor((length - s_a) / delta + 1e-9))
        if (m_goal - k_a) % 2:
            m_goal -= 1  # m + k keeps its parity on the lattice; at rest k = 0
        if m_goal < 0:
            continue
        acts = _search(forbidden, float(t_map), float(h), float(ds), xcap0, xcap1, float(t_a),
                       float(s_a), int(k_a), float(a_max), float(dt), int(kmax), int(m_goal), n_max,
                       int(key_cells), gt)
        if len(acts) == 1 and acts[0] == -9:
            continue
        ks = np.concatenate([[k_a], k_a + np.cumsum(acts)])
        ms = np.concatenate([[0], np.cumsum(2 * ks[:-1] + acts)])
        ts = t_a + dt * np.arange(len(ks))
        ss = s_a + delta * ms
        vs = vstep * ks
        accs = a_max * acts.astype(float)
        if tau0 > 0.0:
            ts = np.concatenate([[t0], ts])
            ss = np.concatenate([[0.0], ss])
            vs = np.concatenate([[v0], vs])
            accs = np.concatenate([[acc0], accs])
        if len(accs) == 0:  # already at rest at the end
            ts, ss, vs, accs = np.array([t0, t0]), np.array([s_a, s_a]), np.zeros(2), np.zeros(1)
        plan = VelocityPlan(ts, ss, vs, accs)
        if best is None or plan.arrival_s < best.arrival_s:
            best = plan
    return best
