"""Compiled kernels of the s-t velocity lattice (:mod:`~anyplan.trajectory.spacetime.lattice`).

The lattice, the relaxed goal-time bound and the A* search are described in that module and in
``docs/spacetime.md``; :func:`~anyplan.trajectory.spacetime.lattice.plan_velocity` is the only
caller of :func:`search` and :func:`goal_times`, and builds the :class:`LatticeMap` record.
"""

from __future__ import annotations

import heapq
import math
from typing import NamedTuple

import numpy as np
from numba import njit

__all__ = ["DENSE_CELLS", "LatticeMap", "edge_ok", "free_goal_time", "goal_times", "search", "to_go"]


class LatticeMap(NamedTuple):
    """The s-t map and speed caps one search runs on (fields as in ``plan_velocity``):
    ``forbidden`` holds the map's first rows, ``nrow`` >= its row count is the map's length in
    rows; the rows beyond ``forbidden``'s are free."""

    forbidden: np.ndarray
    t_map: float
    h: float
    ds: float
    xcap0: np.ndarray
    xcap1: np.ndarray
    nrow: int


@njit(cache=True)
def edge_ok(forbidden: np.ndarray, t_map: float, h: float, ds: float, xcap0: np.ndarray,
            xcap1: np.ndarray, t_a: float, s_a: float, v_a: float, acc: float, dur: float,
            nrow: int = -1) -> bool:
    """True if the step from (t_a, s_a, v_a) with acceleration ``acc`` for ``dur`` seconds keeps
    the speed limit and touches no forbidden cell (rows beyond the map count as forbidden).
    ``nrow``: the map's rows, of which ``forbidden`` holds the first (the others are free);
    -1: ``forbidden`` holds them all."""
    ncell = forbidden.shape[1]
    n_dense = forbidden.shape[0]
    if nrow < 0:
        nrow = n_dense
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
    for j in range(j0, min(j1 + 1, n_dense)):
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
def to_go(d: float, v: float, a: float, v_max: float) -> float:
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
def free_goal_time(j: int, c: int, t_map: float, h: float, c_goal: int, reach: int, ds: float,
                   v_max: float, nrow: int) -> float:
    """:func:`goal_times`' bound G[j, c] when every row from j on is free (j <= ``nrow``, the
    map's rows; row ``nrow`` is the one after the map): its recurrence in closed form.

    From c < c_goal the relaxed robot advances ``reach`` cells a row, so the goal is reached in
    the row k - 1 rows on, k = ceil((c_goal - c) / reach), if the map has it (else inf); the
    bound is the largest of the rows' distance bounds t_{j+i} + (c_goal - c_i - 1) ds / v_max
    along the way, at its first row when a row's advance outruns its time (reach ds / v_max > h,
    as :func:`~anyplan.trajectory.spacetime.lattice.plan_velocity`'s reach does), else each term
    is computed: bit for bit the recurrence's value, each term computed as it does."""
    tj = t_map + j * h
    if c >= c_goal:
        return tj
    k = (c_goal - c + reach - 1) // reach
    if j + k - 1 >= nrow:
        return np.inf
    best = tj + (c_goal - c - 1) * ds / v_max
    slope = reach * ds / v_max - h  # how much faster each next term falls than time grows
    if slope > 1e-9 * (1.0 + abs(t_map) + nrow * h):
        return best
    for i in range(1, k):
        ci = c + i * reach
        best = max(best, (t_map + (j + i) * h) + (c_goal - ci - 1) * ds / v_max)
    return best


@njit(cache=True)
def goal_times(forbidden: np.ndarray, t_map: float, h: float, c_goal: int, reach: int,
               ds: float, v_max: float, c_first: int = -1, nrow: int = -1) -> np.ndarray:
    """Lower bounds G[j, c] [s] on the arrival at the goal cell from cell c at time t_map + j h.

    The relaxation of every lattice motion: within a row the robot advances by at most ``reach``
    cells (v_max h / ds, rounded up, plus one), through free cells of that row, with unbounded
    acceleration; each bound is also raised to the distance bound t + (c_goal - c - 1) ds / v_max
    (the max of two lower bounds is one). Backward over the rows; inf marks cells from which the
    goal cannot be reached within the map (the search drops them).

    ``nrow``: the map's rows, of which ``forbidden`` holds the first R (the others are free; -1:
    it holds them all). The table returned has R + 1 rows: the bounds of rows 0 .. R - 1, then
    those of row R (the row after the map when R = ``nrow``); the rows after R are
    :func:`free_goal_time`'s. A long path's map, whose predictions end within seconds, so costs
    what the rows of the predictions cost, not its whole duration.

    With ``c_first >= 0`` only the cells c <= c_first + j reach of row j are computed (the others
    stay inf): row j reads row j + 1 up to c + reach only, so the computed cells get the same
    values; :func:`~anyplan.trajectory.spacetime.lattice.plan_velocity` passes a c_first beyond
    every cell a motion from the start can be in during row 0 (then during row j too, as
    v_max h / ds < reach): the search reads no other cell.
    """
    n_dense, ncell = forbidden.shape
    if nrow < 0:
        nrow = n_dense
    g = np.full((n_dense + 1, ncell), np.inf)
    if n_dense == nrow:
        for c in range(c_goal, ncell):
            g[nrow, c] = t_map + nrow * h
    else:
        c_end = ncell if c_first < 0 else min(ncell, c_first + n_dense * reach + 1)
        for c in range(c_end):
            g[n_dense, c] = free_goal_time(n_dense, c, t_map, h, c_goal, reach, ds, v_max, nrow)
    # While every row from j + 1 on is free, row j + 1 is nonincreasing in c (the last row is:
    # inf, then the goal time; a free row's window minima of a nonincreasing row are the
    # window ends, and the distance bound decreases in c), so the minimum over a window is its
    # last cell: the same value as the scan below, read once. Obstacles are predicted over a
    # few seconds and the map runs to the arrival, so most rows are such a free suffix.
    suffix = True
    for j in range(n_dense - 1, -1, -1):
        tj = t_map + j * h
        c_end = ncell if c_first < 0 else min(ncell, c_first + j * reach + 1)
        if suffix:
            for c in range(ncell):
                if forbidden[j, c]:
                    suffix = False
                    break
        if suffix:
            for c in range(c_end):
                if c >= c_goal:
                    g[j, c] = tj
                    continue
                c2 = min(c + reach, ncell - 1)
                best = tj if c2 >= c_goal else g[j + 1, c2]
                g[j, c] = max(best, tj + (c_goal - c - 1) * ds / v_max)
            continue
        for c in range(c_end):
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


#: Largest lattice (steps x max(positions, map cells) x speeds) whose search keeps its marks in
#: dense arrays (allocated and zeroed each search: about a millisecond at this size); larger
#: ones keep them in hash tables (:func:`_probe`), whose cost follows the nodes reached.
DENSE_CELLS = 2 ** 22


@njit(cache=True)
def _probe(keys: np.ndarray, key: int) -> int:
    """The slot of ``key`` in the open-addressing table ``keys`` (a power-of-two size, -1 for
    empty, never full): where it is, or the empty slot where it goes (linear probing)."""
    mask = keys.shape[0] - 1
    hv = np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)
    i = np.int64(hv ^ (hv >> np.uint64(32))) & mask
    while keys[i] != -1 and keys[i] != key:
        i = (i + 1) & mask
    return i


@njit(cache=True)
def _grown(keys: np.ndarray, vals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The table (``keys``, ``vals``) in twice the slots; a table of keys alone (a set) has no
    ``vals`` (empty) and keeps none."""
    nk = np.full(2 * keys.shape[0], -1, dtype=np.int64)
    nv = np.zeros(2 * keys.shape[0] if vals.shape[0] > 0 else 0, dtype=np.int8)
    for i in range(keys.shape[0]):
        if keys[i] != -1:
            j = _probe(nk, keys[i])
            nk[j] = keys[i]
            if nv.shape[0] > 0:
                nv[j] = vals[i]
    return nk, nv


@njit(cache=True)
def search(lm: LatticeMap, gt: np.ndarray, t_a: float, s_a: float, k_a: int, a: float, dt: float,
           kmax: int, m_goal: int, n_max: int, key_cells: int, t_cap: float, c_goal: int,
           reach: int, v_max: float, dense_cells: int = DENSE_CELLS) -> np.ndarray:
    """A* over lattice nodes (step n, m, k), cost = time, heuristic = the larger of the
    obstacle-free time to go and the relaxed bound of :func:`goal_times` (both admissible:
    its table ``gt``, computed with ``c_goal``, ``reach`` and ``v_max``, then
    :func:`free_goal_time` on the rows after it);
    returns the accelerations (-1, 0, 1) of the earliest motion from
    (m=0, k=k_a) at t_a to (m_goal, 0), or [-9] if none within n_max steps.

    The marks of the nodes reached are kept in dense arrays up to ``dense_cells`` lattice
    cells (:data:`DENSE_CELLS`), else in hash tables: the same answers.

    ``t_cap`` (inf: no cap) ends the search without a motion as soon as the least estimate f
    popped exceeds it; :func:`~anyplan.trajectory.spacetime.lattice.plan_velocity` passes the
    latest arrival t_a + n_max dt (plus 1e-6 s for rounding). That changes no answer. Proof: f
    is a lower bound on the arrival of every motion through its node (admissible heuristic, to
    ~1e-9 s), and every arrival found is at most t_a + n_max dt. While the goal G of the motion
    the full search returns is not popped, the queue holds a node of G's parent chain (the first
    one not yet popped was pushed when its parent was expanded), whose f <= arrival(G) <= t_cap:
    so a node with f > t_cap is never popped before G, and until then both searches pop the same
    nodes and set the same marks. When the full search finds no motion, the capped one finds
    none either (it pops a subset of the same sequence). Once the least f exceeds t_cap, every
    later node descends from a node whose motions all arrive after t_cap: none reaches the goal
    in time, so the full search would end without a motion too.
    """
    forbidden, t_map, h, ds, xcap0, xcap1 = lm.forbidden, lm.t_map, lm.h, lm.ds, lm.xcap0, lm.xcap1
    nrow = lm.nrow
    delta = 0.5 * a * dt * dt
    vstep = a * dt
    nm = m_goal + 1
    s_goal = s_a + m_goal * delta
    kk = kmax + 1
    # The nodes reached, (step n, m, k) -> the step's acceleration + 2 (4 at the start), and the
    # (step, key cell, speed) taken (one node per (step, map cell, speed): two lattice points in
    # one cell at one speed and time differ by less than a cell; keeping the first, best f,
    # bounds the search by the map). Flat indices n (nm) kk + m kk + k < 2^27 (bounded_lattice).
    # Dense arrays for a small lattice (the fastest); hash tables beyond ``dense_cells``, as a
    # search reaches a narrow band of the lattice, whose dense arrays a long path made hundreds
    # of MB to allocate and zero on every search.
    ncell = forbidden.shape[1]
    dense = (n_max + 1) * max(nm, ncell) * kk <= dense_cells
    pd = np.zeros((n_max + 1) * nm * kk if dense else 1, dtype=np.int8)
    sd = np.zeros((n_max + 1) * ncell * kk if dense else 1, dtype=np.bool_)
    size0 = 1 if dense else 1024
    pk = np.full(size0, -1, dtype=np.int64)
    pv = np.zeros(size0, dtype=np.int8)
    sk = np.full(size0, -1, dtype=np.int64)  # a set: keys only
    no_vals = np.zeros(0, dtype=np.int8)
    if dense:
        pd[k_a] = 4
    else:
        i0 = _probe(pk, k_a)
        pk[i0] = k_a
        pv[i0] = 4
    n_parent = 1
    n_seen = 0
    heap = [(to_go(s_goal - s_a, k_a * vstep, a, kmax * vstep), 0, 0, 0, k_a)]
    found = -1
    while len(heap) > 0:
        f0, _, n, m, k = heapq.heappop(heap)
        if m == m_goal and k == 0:
            found = n
            break
        if f0 > t_cap:
            break  # every node left arrives after the latest arrival (see the docstring)
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
            if m2 > m_goal:
                continue
            node = ((n + 1) * nm + m2) * kk + k2
            pslot = 0 if dense else _probe(pk, node)  # (no table changes until the node is added)
            if (pd[node] != 0) if dense else (pk[pslot] == node):
                continue
            cell = -1
            sslot = 0
            taken = False
            if key_cells > 0:
                key = min(int((s_a + m2 * delta) / (key_cells * ds)), ncell - 1)
                cell = ((n + 1) * ncell + key) * kk + k2
                if dense:
                    taken = sd[cell]
                else:
                    sslot = _probe(sk, cell)
                    taken = sk[sslot] == cell
                if taken and m2 != m_goal:
                    continue
            if not edge_ok(forbidden, t_map, h, ds, xcap0, xcap1, t, s, v, u * a, dt, nrow):
                continue
            s2 = s_a + m2 * delta
            t2 = t + dt
            j2 = min(max(int((t2 - t_map) / h + 1e-9), 0), nrow)
            c2 = min(max(int(s2 / ds), 0), ncell - 1)
            g2 = (gt[j2, c2] if j2 < gt.shape[0] else
                  free_goal_time(j2, c2, t_map, h, c_goal, reach, ds, v_max, nrow))
            if g2 == np.inf:
                continue  # the goal cannot be reached from there within the map
            if dense:
                pd[node] = u + 2
                if key_cells > 0:
                    sd[cell] = True
            else:
                pk[pslot] = node
                pv[pslot] = u + 2
                n_parent += 1
                if 2 * n_parent > pk.shape[0]:
                    pk, pv = _grown(pk, pv)
                if key_cells > 0 and not taken:
                    sk[sslot] = cell
                    n_seen += 1
                    if 2 * n_seen > sk.shape[0]:
                        sk, _ = _grown(sk, no_vals)
            f = t2 + max(to_go(s_goal - s2, k2 * vstep, a, kmax * vstep), g2 - t2)
            heapq.heappush(heap, (f, -m2, n + 1, m2, k2))
    if found < 0:
        return np.full(1, -9, dtype=np.int64)
    acts = np.empty(found, dtype=np.int64)
    m, k = m_goal, 0
    for n in range(found, 0, -1):
        node = (n * nm + m) * kk + k
        u = int(pd[node] if dense else pv[_probe(pk, node)]) - 2
        acts[n - 1] = u
        k_prev = k - u
        m = m - 2 * k_prev - u
        k = k_prev
    return acts
