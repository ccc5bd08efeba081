"""Compiled core of BIT* (see :mod:`anyplan.planning.bitstar` for the algorithm and notation).

All state lives in flat arrays owned by :class:`anyplan.planning.bitstar.BITStar`; these
functions mutate them in place. Layout:

``P`` (C, 2) float: point positions [m]. Index 0 is the start, 1 the goal.
``F`` (C, 3) float: ``g_hat`` (distance to start), ``h_hat`` (distance to goal), ``g_T``
    (cost-to-come in the tree; inf for a sample).
``IT`` (C, 7) int: parent, first child, next sibling, previous sibling, batch in which the
    vertex was last expanded, flags (bit 0: vertex, bit 1: vertex already at batch start),
    batch in which the point became a sample (new samples are those of the current batch).
``vk``/``vp``: vertex queue (binary min-heap keyed ``g_T(v) + h_hat(v)``), payload vp[:, 0].
``ek``/``ep``: edge queue (binary min-heap keyed ``g_T(v) + c_hat(v, x) + h_hat(x)``), payload
    (v, x).
``cstart``/``citems``: uniform grid of cell size r over all points (neighbour queries);
    ``nstart``/``nitems``: the same over the new samples only.
``S`` float scalars and ``N`` int counters, indexed by the constants below.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from anyplan.geometry.collision import ObstacleArrays, segment_blocked_kernel

# Scalar slots.
S_CBEST, S_R, S_X0, S_Y0, S_CELL, S_LIMIT = 0, 1, 2, 3, 4, 5
N_N, N_VS, N_ES, N_BATCH, N_K, N_CHECKS, N_FAILS, N_EXP, N_REWIRE, N_ITERS, N_QUEUED, \
    N_NCX, N_NCY = range(13)
# Column slots.
G_HAT, H_HAT, G_T = 0, 1, 2
PAR, FCHILD, NSIB, PSIB, EXPB, FLAGS, SBATCH = 0, 1, 2, 3, 4, 5, 6
F_VERTEX, F_OLD = 1, 2
# Return codes of iterate().
RC_BUDGET, RC_BATCH_DONE, RC_IMPROVED, RC_GROW = 0, 1, 2, 3

INF = math.inf


# --- binary heaps ---------------------------------------------------------------------------
@njit(cache=True)
def heap_push(keys: np.ndarray, pay: np.ndarray, size: int, key: float, a: int, b: int) -> int:
    """Push (key, a, b); returns the new size (capacity must suffice)."""
    i = size
    while i > 0:
        p = (i - 1) >> 1
        if keys[p] <= key:
            break
        keys[i] = keys[p]
        pay[i, 0] = pay[p, 0]
        pay[i, 1] = pay[p, 1]
        i = p
    keys[i] = key
    pay[i, 0] = a
    pay[i, 1] = b
    return size + 1


@njit(cache=True)
def heap_pop(keys: np.ndarray, pay: np.ndarray, size: int) -> int:
    """Remove the top; returns the new size."""
    size -= 1
    if size <= 0:
        return 0
    key = keys[size]
    a = pay[size, 0]
    b = pay[size, 1]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= size:
            break
        if c + 1 < size and keys[c + 1] < keys[c]:
            c += 1
        if keys[c] >= key:
            break
        keys[i] = keys[c]
        pay[i, 0] = pay[c, 0]
        pay[i, 1] = pay[c, 1]
        i = c
    keys[i] = key
    pay[i, 0] = a
    pay[i, 1] = b
    return size


# --- grid -------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _cell_of(x: float, y: float, x0: float, y0: float, cell: float, ncx: int,
             ncy: int) -> tuple[int, int]:
    """Grid cell (column, row) of the point (x, y), clamped to the grid."""
    return (min(max(int((x - x0) / cell), 0), ncx - 1), min(max(int((y - y0) / cell), 0), ncy - 1))


@njit(cache=True)
def build_grid(P: np.ndarray, idx: np.ndarray, x0: float, y0: float, cell: float, ncx: int,
               ncy: int) -> tuple[np.ndarray, np.ndarray]:
    """Counting sort of the points ``idx`` into ncx x ncy cells of side ``cell``."""
    n = idx.shape[0]
    cstart = np.zeros(ncx * ncy + 1, np.int64)
    cid = np.empty(n, np.int64)
    for t in range(n):
        i = idx[t]
        cx, cy = _cell_of(P[i, 0], P[i, 1], x0, y0, cell, ncx, ncy)
        cid[t] = cy * ncx + cx
        cstart[cid[t] + 1] += 1
    for c in range(ncx * ncy):
        cstart[c + 1] += cstart[c]
    fill = cstart[:-1].copy()
    citems = np.empty(n, np.int64)
    for t in range(n):
        citems[fill[cid[t]]] = idx[t]
        fill[cid[t]] += 1
    return cstart, citems


@njit(cache=True)
def _near(v: int, P: np.ndarray, rad: float, cstart: np.ndarray, citems: np.ndarray,
          S: np.ndarray, N: np.ndarray, out: np.ndarray, dout: np.ndarray) -> int:
    """Points within ``rad`` of point v (v excluded) into out/dout; returns their number.

    ``rad`` must not exceed the grid cell size.
    """
    x0 = S[S_X0]
    y0 = S[S_Y0]
    cell = S[S_CELL]
    ncx = N[N_NCX]
    ncy = N[N_NCY]
    px = P[v, 0]
    py = P[v, 1]
    cx, cy = _cell_of(px, py, x0, y0, cell, ncx, ncy)
    r2 = rad * rad
    m = 0
    for yy in range(max(cy - 1, 0), min(cy + 2, ncy)):
        for xx in range(max(cx - 1, 0), min(cx + 2, ncx)):
            c = yy * ncx + xx
            for t in range(cstart[c], cstart[c + 1]):
                j = citems[t]
                if j == v:
                    continue
                dx = P[j, 0] - px
                dy = P[j, 1] - py
                d2 = dx * dx + dy * dy
                if d2 <= r2:
                    out[m] = j
                    dout[m] = math.sqrt(d2)
                    m += 1
    return m


@njit(cache=True)
def _k_nearest(v: int, P: np.ndarray, k: int, cstart: np.ndarray, citems: np.ndarray,
               S: np.ndarray, N: np.ndarray, out: np.ndarray, dout: np.ndarray) -> int:
    """The k nearest points to v (v excluded), searching grid rings outwards.

    Points outside the (2 ring + 1)^2 block of cells around v's cell are farther than
    ``ring * cell``, so the search stops once k candidates lie within that distance.
    """
    x0 = S[S_X0]
    y0 = S[S_Y0]
    cell = S[S_CELL]
    ncx = N[N_NCX]
    ncy = N[N_NCY]
    px = P[v, 0]
    py = P[v, 1]
    cx, cy = _cell_of(px, py, x0, y0, cell, ncx, ncy)
    ring = 1
    n_total = N[N_N] - 1
    kk = min(k, n_total)
    while True:
        m = 0
        for yy in range(max(cy - ring, 0), min(cy + ring + 1, ncy)):
            for xx in range(max(cx - ring, 0), min(cx + ring + 1, ncx)):
                c = yy * ncx + xx
                for t in range(cstart[c], cstart[c + 1]):
                    j = citems[t]
                    if j == v:
                        continue
                    out[m] = j
                    dout[m] = math.hypot(P[j, 0] - px, P[j, 1] - py)
                    m += 1
        covers_all = (cx - ring <= 0 and cy - ring <= 0 and cx + ring >= ncx - 1
                      and cy + ring >= ncy - 1)
        if m >= kk:
            # The kk nearest first, ascending, ties in candidate order (a partial stable
            # selection sort, in place: out and dout are refilled if the ring grows; far
            # cheaper to compile than np.argsort).
            for i in range(kk):
                j = i
                for t in range(i + 1, m):
                    if dout[t] < dout[j]:
                        j = t
                dj = dout[j]
                oj = out[j]
                for t in range(j, i, -1):
                    dout[t] = dout[t - 1]
                    out[t] = out[t - 1]
                dout[i] = dj
                out[i] = oj
            if dout[kk - 1] <= ring * cell or covers_all:
                return kk
        elif covers_all:
            return m
        ring += 1


# --- tree helpers -------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _detach(IT: np.ndarray, x: int) -> None:
    p = IT[x, PAR]
    if p < 0:
        return
    ps = IT[x, PSIB]
    ns = IT[x, NSIB]
    if ps >= 0:
        IT[ps, NSIB] = ns
    else:
        IT[p, FCHILD] = ns
    if ns >= 0:
        IT[ns, PSIB] = ps
    IT[x, PAR] = -1
    IT[x, NSIB] = -1
    IT[x, PSIB] = -1


@njit(cache=True, inline="always")
def _attach(IT: np.ndarray, x: int, p: int) -> None:
    IT[x, PAR] = p
    f = IT[p, FCHILD]
    IT[x, NSIB] = f
    IT[x, PSIB] = -1
    if f >= 0:
        IT[f, PSIB] = x
    IT[p, FCHILD] = x


@njit(cache=True)
def _shift_subtree(F: np.ndarray, IT: np.ndarray, root: int, delta: float,
                   stack: np.ndarray) -> None:
    """Subtract ``delta`` from g_T of every strict descendant of ``root``."""
    top = 0
    c = IT[root, FCHILD]
    while c >= 0:
        stack[top] = c
        top += 1
        c = IT[c, NSIB]
    while top > 0:
        top -= 1
        x = stack[top]
        F[x, G_T] -= delta
        c = IT[x, FCHILD]
        while c >= 0:
            stack[top] = c
            top += 1
            c = IT[c, NSIB]


# --- the search ---------------------------------------------------------------------------------
@njit(cache=True)
def _expand(v: int, P: np.ndarray, F: np.ndarray, IT: np.ndarray, ek: np.ndarray, ep: np.ndarray,
            cstart: np.ndarray, citems: np.ndarray, nstart: np.ndarray, nitems: np.ndarray,
            S: np.ndarray, N: np.ndarray, nb: np.ndarray, nd: np.ndarray) -> None:
    """ExpandVertex(v): queue the edges from v that could improve the solution.

    A vertex already expanded in an earlier batch has seen every older sample within the
    (then larger) radius, so only the new samples are considered for it (as OMPL does); a
    vertex that is new in this batch also gets its rewiring candidates.
    """
    is_new = (IT[v, FLAGS] & F_OLD) == 0
    seen_before = IT[v, EXPB] >= 0 and IT[v, EXPB] < N[N_BATCH]
    IT[v, EXPB] = N[N_BATCH]
    N[N_EXP] += 1
    batch = N[N_BATCH]
    if N[N_K] > 0:
        m = _k_nearest(v, P, N[N_K], cstart, citems, S, N, nb, nd)
    elif seen_before and not is_new:
        m = _near(v, P, S[S_R], nstart, nitems, S, N, nb, nd)
    else:
        m = _near(v, P, S[S_R], cstart, citems, S, N, nb, nd)
    c_best = S[S_CBEST]
    gv = F[v, G_T]
    ghv = F[v, G_HAT]
    es = N[N_ES]
    for t in range(m):
        x = nb[t]
        d = nd[t]
        if (IT[x, FLAGS] & F_VERTEX) == 0:
            if seen_before and not is_new and IT[x, SBATCH] != batch:
                continue
            # g_hat(v) + c_hat(v, x) + h_hat(x) < c_best ?
            if ghv + d + F[x, H_HAT] < c_best:
                es = heap_push(ek, ep, es, gv + d + F[x, H_HAT], v, x)
                N[N_QUEUED] += 1
        # Rewiring candidate (new vertices only): g_hat(v) + c_hat(v, x) + h_hat(x) < c_best
        # and g_T(v) + c_hat(v, x) < g_T(x) ?
        elif (is_new and x != IT[v, PAR] and IT[x, PAR] != v
              and ghv + d + F[x, H_HAT] < c_best and gv + d < F[x, G_T]):
            es = heap_push(ek, ep, es, gv + d + F[x, H_HAT], v, x)
            N[N_QUEUED] += 1
    if v == 0 and (IT[1, FLAGS] & F_VERTEX) == 0 and F[1, G_HAT] > S[S_R]:
        # Always try the direct start-goal edge, the best possible one, even beyond r.
        es = heap_push(ek, ep, es, F[1, G_HAT], np.int64(0), np.int64(1))
        N[N_QUEUED] += 1
    N[N_ES] = es


@njit(cache=True)
def iterate(P: np.ndarray, F: np.ndarray, IT: np.ndarray, vk: np.ndarray, vp: np.ndarray,
            ek: np.ndarray, ep: np.ndarray, cstart: np.ndarray, citems: np.ndarray,
            nstart: np.ndarray, nitems: np.ndarray, S: np.ndarray, N: np.ndarray,
            stack: np.ndarray, nb: np.ndarray, nd: np.ndarray,
            obs: ObstacleArrays, max_iter: int) -> int:
    """Run one batch for up to ``max_iter`` units of work (edge pops plus vertex expansions).

    Returns RC_IMPROVED as soon as the goal's cost drops, RC_BATCH_DONE when the batch cannot
    improve the solution any more, RC_GROW when a queue may overflow (the caller enlarges the
    queues and calls again), else RC_BUDGET.
    """
    n = N[N_N]
    limit = S[S_LIMIT]
    work = 0  # edge pops + vertex expansions, bounded by max_iter per call
    while work < max_iter:
        if ek.shape[0] - N[N_ES] < n + 8 or vk.shape[0] - N[N_VS] < 8:
            return RC_GROW
        work += 1
        c_best = S[S_CBEST]
        # Expand vertices while the best vertex key <= the best edge key.
        while N[N_VS] > 0:
            if work >= max_iter:
                return RC_BUDGET
            v = vp[0, 0]
            kv = vk[0]
            if IT[v, EXPB] == N[N_BATCH] or (IT[v, FLAGS] & F_VERTEX) == 0:
                N[N_VS] = heap_pop(vk, vp, N[N_VS])
                continue
            if N[N_ES] > 0 and kv > ek[0]:
                break
            if kv >= c_best:
                break
            N[N_VS] = heap_pop(vk, vp, N[N_VS])
            _expand(v, P, F, IT, ek, ep, cstart, citems, nstart, nitems, S, N, nb, nd)
            work += 1
            if ek.shape[0] - N[N_ES] < n + 8:
                return RC_GROW
        if N[N_ES] == 0:
            return RC_BATCH_DONE
        key = ek[0]
        if key >= c_best:
            # Every queued edge is (as far as the keys know) useless: the batch is done.
            N[N_ES] = 0
            N[N_VS] = 0
            return RC_BATCH_DONE
        a = ep[0, 0]
        b = ep[0, 1]
        N[N_ES] = heap_pop(ek, ep, N[N_ES])
        N[N_ITERS] += 1  # edges popped
        ga = F[a, G_T]
        chat = math.hypot(P[b, 0] - P[a, 0], P[b, 1] - P[a, 1])
        # g_T(a) + c_hat(a, b) + h_hat(b) < c_best ?
        if ga + chat + F[b, H_HAT] >= c_best:
            continue
        # g_T(a) + c_hat(a, b) < g_T(b) ?  (also rejects edges already in the tree)
        if ga + chat >= F[b, G_T] or IT[b, PAR] == a:
            continue
        # Exact, lazy edge check: is the straight motion free for the disc robot?
        N[N_CHECKS] += 1
        if segment_blocked_kernel(P[a, 0], P[a, 1], P[b, 0], P[b, 1], obs, limit):
            N[N_FAILS] += 1
            continue
        # The true cost equals the heuristic (straight line), so the tests above stand.
        gb_new = ga + chat
        if (IT[b, FLAGS] & F_VERTEX) != 0:
            delta = F[b, G_T] - gb_new
            _detach(IT, b)
            _attach(IT, b, a)
            F[b, G_T] = gb_new
            _shift_subtree(F, IT, b, delta, stack)
            N[N_REWIRE] += 1
            if IT[b, EXPB] == N[N_BATCH]:
                IT[b, EXPB] = -1  # its queued edges are stale: expand it again
        else:
            IT[b, FLAGS] |= F_VERTEX
            IT[b, FLAGS] &= ~F_OLD
            F[b, G_T] = gb_new
            _attach(IT, b, a)
            IT[b, EXPB] = -1
        N[N_VS] = heap_push(vk, vp, N[N_VS], gb_new + F[b, H_HAT], b, np.int64(0))
        if F[1, G_T] < c_best:
            S[S_CBEST] = F[1, G_T]
            return RC_IMPROVED
    return RC_BUDGET


@njit(cache=True)
def start_batch(P: np.ndarray, F: np.ndarray, IT: np.ndarray, vk: np.ndarray, vp: np.ndarray,
                S: np.ndarray, N: np.ndarray, cstart: np.ndarray, citems: np.ndarray,
                newidx: np.ndarray, nb: np.ndarray, nd: np.ndarray) -> None:
    """New batch: clear both queues, mark all vertices old and queue the useful ones.

    A vertex expanded in an earlier batch only needs expanding again if a new sample lies
    within r of it (its expansion considers new samples only); skipping the others changes
    nothing but the cost. The grid must be built for this batch.
    """
    N[N_BATCH] += 1
    N[N_ES] = 0
    n = N[N_N]
    near_new = np.zeros(n, np.bool_)
    if N[N_K] > 0:
        near_new[:] = True
    else:
        for t in range(newidx.shape[0]):
            m = _near(newidx[t], P, S[S_R], cstart, citems, S, N, nb, nd)
            for u in range(m):
                near_new[nb[u]] = True
    vs = np.int64(0)  # not a literal: one specialisation of heap_push
    c_best = S[S_CBEST]
    for i in range(n):
        if (IT[i, FLAGS] & F_VERTEX) != 0:
            IT[i, FLAGS] |= F_OLD
            key = F[i, G_T] + F[i, H_HAT]
            if key < c_best and (near_new[i] or IT[i, EXPB] < 0):
                vs = heap_push(vk, vp, vs, key, i, np.int64(0))
    N[N_VS] = vs


@njit(cache=True)
def compact(P: np.ndarray, F: np.ndarray, IT: np.ndarray, N: np.ndarray, state: np.ndarray,
            stack: np.ndarray) -> np.ndarray:
    """Drop, recycle and keep points, keeping the tree consistent.

    ``state[i]``: 0 drop, 1 keep as a sample, 2 keep as a vertex if still a vertex. A vertex
    keeps its place in the tree only if its parent does; otherwise it (and its subtree) becomes
    a sample (or is dropped if its state is 0). Start and goal are never dropped. Returns the
    old-to-new index map (-1 for dropped points).
    """
    n = N[N_N]
    state[0] = 2
    if state[1] == 0:
        state[1] = 1
    # Top-down pass from the root: a vertex survives only below a surviving vertex.
    keepv = np.zeros(n, np.bool_)
    keepv[0] = True
    top = 0
    c = IT[0, FCHILD]
    while c >= 0:
        stack[top] = c
        top += 1
        c = IT[c, NSIB]
    while top > 0:
        top -= 1
        x = stack[top]
        if state[x] == 2 and keepv[IT[x, PAR]]:
            keepv[x] = True
        c = IT[x, FCHILD]
        while c >= 0:
            stack[top] = c
            top += 1
            c = IT[c, NSIB]
    new = np.full(n, -1, np.int64)
    m = 0
    for i in range(n):
        if state[i] > 0 or keepv[i]:
            new[i] = m
            m += 1
    for i in range(n):
        j = new[i]
        if j < 0:
            continue
        P[j, 0] = P[i, 0]
        P[j, 1] = P[i, 1]
        F[j, G_HAT] = F[i, G_HAT]
        F[j, H_HAT] = F[i, H_HAT]
        if keepv[i]:
            F[j, G_T] = F[i, G_T]
            IT[j, PAR] = new[IT[i, PAR]] if i != 0 else -1
            IT[j, FLAGS] = F_VERTEX | (IT[i, FLAGS] & F_OLD)
            IT[j, EXPB] = IT[i, EXPB]
        else:
            if (IT[i, FLAGS] & F_VERTEX) != 0:
                IT[j, SBATCH] = N[N_BATCH] + 1  # a recycled vertex is a new sample next batch
            else:
                IT[j, SBATCH] = IT[i, SBATCH]
            F[j, G_T] = INF
            IT[j, PAR] = -1
            IT[j, FLAGS] = 0
            IT[j, EXPB] = -1
    for j in range(m):
        IT[j, FCHILD] = -1
        IT[j, NSIB] = -1
        IT[j, PSIB] = -1
    for j in range(m - 1, -1, -1):
        p = IT[j, PAR]
        if p >= 0:
            _attach(IT, j, p)
    F[0, G_T] = 0.0
    N[N_N] = m
    return new


@njit(cache=True)
def blocked_edges(P: np.ndarray, IT: np.ndarray, n: int, obs: ObstacleArrays,
                  limit: float) -> np.ndarray:
    """Mask of vertices whose tree edge (parent -> vertex) is blocked by the given obstacles."""
    out = np.zeros(n, np.bool_)
    for i in range(n):
        p = IT[i, PAR]
        if p < 0:
            continue
        if segment_blocked_kernel(P[p, 0], P[p, 1], P[i, 0], P[i, 1], obs, limit):
            out[i] = True
    return out
