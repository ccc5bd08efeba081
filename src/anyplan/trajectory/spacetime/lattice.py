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

import math
from dataclasses import dataclass

import numpy as np

from anyplan.trajectory.spacetime._lattice_kernels import (
    DENSE_CELLS,
    LatticeMap,
    edge_ok,
    goal_times,
    search,
)

__all__ = ["VelocityPlan", "plan_velocity", "lattice_dt", "bounded_lattice", "lattice_cells",
           "edge_ok", "goal_times", "MAX_LATTICE_CELLS"]

#: Largest velocity lattice searched, in cells (:func:`lattice_cells`). The robots of the
#: built-in, generated and benchmark scenarios need below 10^7 (the paper's robot on a 30 m
#: path: 6 x 10^6); a robot at the schema's limits (a_max 0.001 or 1000 m/s^2) or a path of
#: hundreds of metres asked for 10^9 to 10^11 and failed with MemoryError when the search kept
#: its marks in dense arrays of this size (:func:`bounded_lattice`). Above ``DENSE_CELLS`` it
#: keeps them in hash tables, whose size follows the nodes reached; the bound still caps what
#: a search that finds no motion can reach.
MAX_LATTICE_CELLS = 2 ** 27


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


def lattice_cells(dt: float, kmax: int, a: float, horizon_s: float, length: float,
                  ncell: int) -> int:
    """Cells of a lattice of step ``dt`` [s], ``kmax`` speed levels and acceleration ``a``
    [m/s^2] over ``horizon_s`` [s] on a path of ``length`` [m] and ``ncell`` map columns:
    (steps + 1) x (kmax + 1) x (positions + map columns), the search's nodes and key cells."""
    n = int(math.ceil(horizon_s / dt)) + 1
    m = int(math.floor(length / (0.5 * a * dt * dt))) + 2
    return n * (kmax + 1) * (m + ncell)


def bounded_lattice(v_max: float, a_max: float, target_dt: float, horizon_s: float, length: float,
                    ncell: int) -> tuple[float, int, float]:
    """Step ``dt`` [s], speed levels K and acceleration ``a`` <= ``a_max`` [m/s^2] of the
    lattice (v_max = K a dt): :func:`lattice_dt`'s, unless its cells would exceed
    :data:`MAX_LATTICE_CELLS`; then the step is doubled until they fit (fewer speed levels,
    and, once there are two, a smaller acceleration than the robot's: a motion of the coarser
    lattice is as feasible, it may only arrive later). A tiny ``a_max`` makes thousands of speed
    levels, a huge one a step of microseconds, and a long path or horizon many positions and
    steps: all are the product of the three sizes.
    """
    a = a_max
    dt, kmax = lattice_dt(v_max, a, target_dt)
    while lattice_cells(dt, kmax, a, horizon_s, length, ncell) > MAX_LATTICE_CELLS \
            and dt < horizon_s:
        target_dt = 2.0 * dt
        a = min(a_max, v_max / (2.0 * target_dt))
        dt, kmax = lattice_dt(v_max, a, target_dt)
    return dt, kmax, a


def plan_velocity(forbidden: np.ndarray, t_map: float, h: float, ds: float, xcap0: np.ndarray,
                  xcap1: np.ndarray, length: float, t0: float, v0: float, a_max: float,
                  v_max: float, *, target_dt: float = 0.25, horizon_s: float = 60.0,
                  key_cells: int = 4, cap: bool = True, frontier: bool = True,
                  rows: int | None = None, dense_cells: int | None = None) -> VelocityPlan | None:
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
        target_dt: Approximate lattice step [s] (see :func:`lattice_dt`; coarser when the
            lattice would be too large, :func:`bounded_lattice`).
        horizon_s: Latest arrival considered, counted from t0 [s].
        key_cells: The search keeps one node per (step, speed, ``key_cells`` map cells): the
            first reached, which has the best estimate. Coarser keys search faster; the motion
            found is collision-free either way, but it may arrive a step or two later than the
            lattice optimum, and a gap narrower than the key may be missed. 0 keeps every node
            (the exact lattice optimum).
        cap: End a search once no node left can arrive within the horizon (the same answer,
            sooner; False runs it to exhaustion, for tests).
        frontier: Compute the goal-time bounds only on the cells a motion from the start can
            reach (the same answer, sooner; False computes every cell, for tests).
        rows: The map's rows, of which ``forbidden`` holds the first (the rows after them are
            free: :class:`~anyplan.trajectory.spacetime.STMap` keeps only the rows its
            predictions reach); None: ``forbidden`` holds them all.
        dense_cells: The lattice size above which the search keeps its marks in hash tables
            rather than dense arrays (the same answer; None: ``DENSE_CELLS`` of the kernels,
            2^22; tests pass 0 for the tables always).

    Returns:
        The :class:`VelocityPlan`, or None if no lattice motion reaches the end in the horizon.
    """
    ncell = forbidden.shape[1]
    nrow = forbidden.shape[0] if rows is None else int(rows)
    if nrow < forbidden.shape[0]:
        raise ValueError(f"rows: {nrow} is fewer than the map's {forbidden.shape[0]}")
    dt, kmax, a_max = bounded_lattice(v_max, a_max, target_dt, horizon_s, length, ncell)
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
            if not edge_ok(forbidden, t_map, h, ds, xcap0, xcap1, t0, 0.0, v0, acc, tau, nrow):
                continue
            starts.append((t0 + tau, v0 * tau + 0.5 * acc * tau * tau, k, acc, tau))
    c_goal = min(int(math.floor((length - 2.0 * delta) / ds)), ncell - 1)
    reach = int(math.ceil(v_max * h / ds)) + 1
    lm = LatticeMap(forbidden, float(t_map), float(h), float(ds), xcap0, xcap1, nrow)
    # A motion from (t0, s = 0) is at s <= v_max (t - t0): during row j (t < t_map + (j+1) h)
    # in a cell <= c_first + j (v_max h / ds) (2 cells to spare for rounding); goal_times
    # computes only the cells the search can read (the same values there).
    c_first = max(int(v_max * (t_map + h - t0) / ds) + 2, 0) if frontier else -1
    gt = goal_times(forbidden, float(t_map), float(h), max(c_goal, 0), reach, float(ds),
                    float(v_max), c_first, nrow)
    best: VelocityPlan | None = None
    for t_a, s_a, k_a, acc0, tau0 in starts:
        m_goal = int(math.floor((length - s_a) / delta + 1e-9))
        if (m_goal - k_a) % 2:
            m_goal -= 1  # m + k keeps its parity on the lattice; at rest k = 0
        if m_goal < 0:
            continue
        # No motion found by the search arrives after t_a + n_max dt: the cap (1e-6 s for
        # rounding) ends a search that cannot succeed, with the same answer (see search).
        acts = search(lm, gt, float(t_a), float(s_a), int(k_a), float(a_max), float(dt),
                      int(kmax), int(m_goal), n_max, int(key_cells),
                      float(t_a) + n_max * float(dt) + 1e-6 if cap else math.inf,
                      max(c_goal, 0), reach, float(v_max),
                      DENSE_CELLS if dense_cells is None else int(dense_cells))
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
