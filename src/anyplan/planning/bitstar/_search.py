"""BIT*'s search (OMPL ``BITstar``'s main loop): vertex expansion and lazy edge processing.

:func:`iterate` pops the queues of :mod:`._queue` in order of the potential solution cost,
expands vertices into the implicit graph of :mod:`._graph`, checks the popped edges exactly
and lazily (``segment_blocked_kernel``) and grows or rewires the tree of :mod:`._tree`; the
solution cost and the counters are a record of their own (:data:`PROGRESS`). Notation of
:mod:`anyplan.planning.bitstar`.

numba types a NamedTuple argument from Python slowly (each array through Python's typeof, about
0.5 us), but a plain tuple in C, so the entries called from Python (:func:`run`,
:func:`begin_batch`) pass the records as plain tuples and rebuild them in compiled code; each
array crossing costs about 0.3 us per call, so scratch is allocated inside and the counters are
one structured array.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from anyplan.geometry.collision import ObstacleArrays, segment_blocked_kernel
from anyplan.planning.bitstar import _graph, _queue, _tree
from anyplan.planning.bitstar._graph import Batch, Points
from anyplan.planning.bitstar._queue import SearchQueue
from anyplan.planning.bitstar._tree import Tree

#: Return codes of :func:`run`: the work budget is spent; the batch cannot improve the solution
#: any more; the solution improved; a queue may overflow (grow it and call again).
BUDGET, BATCH_DONE, IMPROVED, GROW = 0, 1, 2, 3


#: The solution cost and the search counters: a structured array of shape (1,) (one record
#: with named fields), produced by :func:`new_progress` only. ``best`` is ``c_best`` [m] (inf
#: if none); the counters are edges checked for collision, found blocked, vertex expansions,
#: rewirings, edges popped from and pushed onto the queue.
PROGRESS = np.dtype([("best", np.float64), ("edge_checks", np.int64),
                     ("edge_checks_failed", np.int64), ("expansions", np.int64),
                     ("rewirings", np.int64), ("edges_popped", np.int64),
                     ("edges_queued", np.int64)])


def new_progress() -> np.ndarray:
    """No solution, counters at 0 (a :data:`PROGRESS` array)."""
    pr = np.zeros(1, PROGRESS)
    pr["best"] = math.inf
    return pr


def run(p: Points, t: Tree, q: SearchQueue, b: Batch, pr: np.ndarray, obs: ObstacleArrays,
        limit: float, max_iter: int) -> int:
    """:func:`iterate`, from Python."""
    return _run(tuple(p), tuple(t), tuple(q), tuple(b), pr, tuple(obs), limit, max_iter)


def begin_batch(p: Points, t: Tree, q: SearchQueue, b: Batch, pr: np.ndarray) -> None:
    """:func:`start_batch`, from Python."""
    _begin_batch(tuple(p), tuple(t), tuple(q), tuple(b), pr)


@njit(cache=True)
def _run(p: tuple, t: tuple, q: tuple, b: tuple, pr: np.ndarray,
         obs: tuple, limit: float, max_iter: int) -> int:
    return iterate(Points(*p), Tree(*t), SearchQueue(*q), Batch(*b), pr, ObstacleArrays(*obs),
                   limit, max_iter)


@njit(cache=True)
def _begin_batch(p: tuple, t: tuple, q: tuple, b: tuple, pr: np.ndarray) -> None:
    start_batch(Points(*p), Tree(*t), SearchQueue(*q), Batch(*b), pr)


@njit(cache=True)
def _expand(v: int, p: Points, t: Tree, q: SearchQueue, b: Batch, pr: np.ndarray,
            near: np.ndarray, near_d: np.ndarray) -> None:
    """ExpandVertex(v): queue the edges from v that could improve the solution.

    A vertex already expanded in an earlier batch has seen every older sample within the
    (then larger) radius, so only the new samples are considered for it (as OMPL does); a
    vertex that is new in this batch also gets its rewiring candidates.
    """
    is_new = not t.old[v]
    batch = b.number
    seen_before = t.expanded[v] >= 0 and t.expanded[v] < batch
    t.expanded[v] = batch
    st = pr[0]
    st.expansions += 1
    if b.k > 0:
        m = _graph.k_nearest(v, p, b, near, near_d)
    elif seen_before and not is_new:
        m = _graph.near(v, p, b, b.radius, b.new_start, b.new_items, near, near_d)
    else:
        m = _graph.near(v, p, b, b.radius, b.start, b.items, near, near_d)
    c_best = st.best
    gv = t.g[v]
    ghv = p.g_hat[v]
    for i in range(m):
        x = near[i]
        d = near_d[i]
        if not t.vertex[x]:
            if seen_before and not is_new and p.batch[x] != batch:
                continue
            # g_hat(v) + c_hat(v, x) + h_hat(x) < c_best ?
            if ghv + d + p.h_hat[x] < c_best:
                _queue.push_edge(q, gv + d + p.h_hat[x], v, x)
                st.edges_queued += 1
        # Rewiring candidate (new vertices only): g_hat(v) + c_hat(v, x) + h_hat(x) < c_best
        # and g_T(v) + c_hat(v, x) < g_T(x) ?
        elif (is_new and x != t.parent[v] and t.parent[x] != v
              and ghv + d + p.h_hat[x] < c_best and gv + d < t.g[x]):
            _queue.push_edge(q, gv + d + p.h_hat[x], v, x)
            st.edges_queued += 1
    if v == 0 and not t.vertex[1] and p.g_hat[1] > b.radius:
        # Always try the direct start-goal edge, the best possible one, even beyond r.
        _queue.push_edge(q, p.g_hat[1], np.int64(0), np.int64(1))
        st.edges_queued += 1


@njit(cache=True)
def iterate(p: Points, t: Tree, q: SearchQueue, b: Batch, pr: np.ndarray, obs: ObstacleArrays,
            limit: float, max_iter: int) -> int:
    """Run the batch ``b`` for up to ``max_iter`` units of work (edge pops plus vertex
    expansions); an edge is free when its clearance in ``obs`` is at least ``limit`` [m].

    Returns IMPROVED as soon as the goal's cost drops, BATCH_DONE when the batch cannot
    improve the solution any more, GROW when a queue may overflow (the caller enlarges the
    queues and calls again), else BUDGET.
    """
    n = p.n[0]
    st = pr[0]
    near = np.empty(n, np.int64)  # scratch of the neighbour queries and subtree walks
    near_d = np.empty(n)
    stack = np.empty(n, np.int64)
    work = 0  # edge pops + vertex expansions, bounded by max_iter per call
    while work < max_iter:
        if q.ekey.shape[0] - q.ne[0] < n + 8 or q.vkey.shape[0] - q.nv[0] < 8:
            return GROW
        work += 1
        c_best = st.best
        # Expand vertices while the best vertex key <= the best edge key.
        while q.nv[0] > 0:
            if work >= max_iter:
                return BUDGET
            v = q.vertex[0]
            kv = q.vkey[0]
            if t.expanded[v] == b.number or not t.vertex[v]:
                _queue.pop_vertex(q)
                continue
            if q.ne[0] > 0 and kv > q.ekey[0]:
                break
            if kv >= c_best:
                break
            _queue.pop_vertex(q)
            _expand(v, p, t, q, b, pr, near, near_d)
            work += 1
            if q.ekey.shape[0] - q.ne[0] < n + 8:
                return GROW
        if q.ne[0] == 0:
            return BATCH_DONE
        if q.ekey[0] >= c_best:
            # Every queued edge is (as far as the keys know) useless: the batch is done.
            q.ne[0] = 0
            q.nv[0] = 0
            return BATCH_DONE
        a = q.edge[0, 0]
        x = q.edge[0, 1]
        _queue.pop_edge(q)
        st.edges_popped += 1
        ga = t.g[a]
        chat = math.hypot(p.xy[x, 0] - p.xy[a, 0], p.xy[x, 1] - p.xy[a, 1])
        # g_T(a) + c_hat(a, x) + h_hat(x) < c_best ?
        if ga + chat + p.h_hat[x] >= c_best:
            continue
        # g_T(a) + c_hat(a, x) < g_T(x) ?  (also rejects edges already in the tree)
        if ga + chat >= t.g[x] or t.parent[x] == a:
            continue
        # Exact, lazy edge check: is the straight motion free for the disc robot?
        st.edge_checks += 1
        if segment_blocked_kernel(p.xy[a, 0], p.xy[a, 1], p.xy[x, 0], p.xy[x, 1], obs, limit):
            st.edge_checks_failed += 1
            continue
        # The true cost equals the heuristic (straight line), so the tests above stand.
        gx_new = ga + chat
        if t.vertex[x]:
            delta = t.g[x] - gx_new
            _tree.detach(t, x)
            _tree.attach(t, x, a)
            t.g[x] = gx_new
            _tree.shift_subtree(t, x, delta, stack)
            st.rewirings += 1
            if t.expanded[x] == b.number:
                t.expanded[x] = -1  # its queued edges are stale: expand it again
        else:
            t.vertex[x] = True
            t.old[x] = False
            t.g[x] = gx_new
            _tree.attach(t, x, a)
            t.expanded[x] = -1
        _queue.push_vertex(q, gx_new + p.h_hat[x], x)
        if t.g[1] < c_best:
            st.best = t.g[1]
            return IMPROVED
    return BUDGET


@njit(cache=True)
def start_batch(p: Points, t: Tree, q: SearchQueue, b: Batch, pr: np.ndarray) -> None:
    """Batch ``b`` starts: clear both queues, mark all vertices old and queue the useful ones.

    A vertex expanded in an earlier batch only needs expanding again if a new sample lies
    within r of it (its expansion considers new samples only); skipping the others changes
    nothing but the cost.
    """
    q.ne[0] = 0
    n = p.n[0]
    near_new = np.zeros(n, np.bool_)
    if b.k > 0:
        near_new[:] = True
    else:
        near = np.empty(n, np.int64)
        near_d = np.empty(n)
        for i in range(b.new.shape[0]):
            m = _graph.near(b.new[i], p, b, b.radius, b.start, b.items, near, near_d)
            for u in range(m):
                near_new[near[u]] = True
    q.nv[0] = 0
    c_best = pr[0].best
    for i in range(n):
        if t.vertex[i]:
            t.old[i] = True
            key = t.g[i] + p.h_hat[i]
            if key < c_best and (near_new[i] or t.expanded[i] < 0):
                _queue.push_vertex(q, key, i)
