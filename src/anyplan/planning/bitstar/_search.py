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


@njit(cache=True, inline="always")
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
    # the fields as locals in the loop (one reference each, not one per access)
    g = t.g
    parent = t.parent
    vertex = t.vertex
    h_hat = p.h_hat
    sbatch = p.batch
    ekey = q.ekey
    edge = q.edge
    es = q.ne[0]
    gv = g[v]
    ghv = p.g_hat[v]
    for i in range(m):
        x = near[i]
        d = near_d[i]
        if not vertex[x]:
            if seen_before and not is_new and sbatch[x] != batch:
                continue
            # g_hat(v) + c_hat(v, x) + h_hat(x) < c_best ?
            if ghv + d + h_hat[x] < c_best:
                es = _queue.push_edge(ekey, edge, es, gv + d + h_hat[x], v, x)
                st.edges_queued += 1
        # Rewiring candidate (new vertices only): g_hat(v) + c_hat(v, x) + h_hat(x) < c_best
        # and g_T(v) + c_hat(v, x) < g_T(x) ?
        elif (is_new and x != parent[v] and parent[x] != v
              and ghv + d + h_hat[x] < c_best and gv + d < g[x]):
            es = _queue.push_edge(ekey, edge, es, gv + d + h_hat[x], v, x)
            st.edges_queued += 1
    if v == 0 and not vertex[1] and p.g_hat[1] > b.radius:
        # Always try the direct start-goal edge, the best possible one, even beyond r.
        es = _queue.push_edge(ekey, edge, es, p.g_hat[1], np.int64(0), np.int64(1))
        st.edges_queued += 1
    q.ne[0] = es


@njit(cache=True, inline="always")
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
    xy = p.xy
    h_hat = p.h_hat
    g = t.g
    parent = t.parent
    vertex = t.vertex
    expanded = t.expanded
    vkey = q.vkey
    vqueue = q.vertex
    ekey = q.ekey
    edge = q.edge
    nv = q.nv
    ne = q.ne
    batch = b.number
    work = 0  # edge pops + vertex expansions, bounded by max_iter per call
    while work < max_iter:
        if ekey.shape[0] - ne[0] < n + 8 or vkey.shape[0] - nv[0] < 8:
            return GROW
        work += 1
        c_best = st.best
        # Expand vertices while the best vertex key <= the best edge key.
        while nv[0] > 0:
            if work >= max_iter:
                return BUDGET
            v = vqueue[0]
            kv = vkey[0]
            if expanded[v] == batch or not vertex[v]:
                nv[0] = _queue.pop_vertex(vkey, vqueue, nv[0])
                continue
            if ne[0] > 0 and kv > ekey[0]:
                break
            if kv >= c_best:
                break
            nv[0] = _queue.pop_vertex(vkey, vqueue, nv[0])
            _expand(v, p, t, q, b, pr, near, near_d)
            work += 1
            if ekey.shape[0] - ne[0] < n + 8:
                return GROW
        if ne[0] == 0:
            return BATCH_DONE
        if ekey[0] >= c_best:
            # Every queued edge is (as far as the keys know) useless: the batch is done.
            ne[0] = 0
            nv[0] = 0
            return BATCH_DONE
        a = edge[0, 0]
        x = edge[0, 1]
        ne[0] = _queue.pop_edge(ekey, edge, ne[0])
        st.edges_popped += 1
        ga = g[a]
        chat = math.hypot(xy[x, 0] - xy[a, 0], xy[x, 1] - xy[a, 1])
        # g_T(a) + c_hat(a, x) + h_hat(x) < c_best ?
        if ga + chat + h_hat[x] >= c_best:
            continue
        # g_T(a) + c_hat(a, x) < g_T(x) ?  (also rejects edges already in the tree)
        if ga + chat >= g[x] or parent[x] == a:
            continue
        # Exact, lazy edge check: is the straight motion free for the disc robot?
        st.edge_checks += 1
        if segment_blocked_kernel(xy[a, 0], xy[a, 1], xy[x, 0], xy[x, 1], obs, limit):
            st.edge_checks_failed += 1
            continue
        # The true cost equals the heuristic (straight line), so the tests above stand.
        gx_new = ga + chat
        if vertex[x]:
            delta = g[x] - gx_new
            _tree.detach(t, x)
            _tree.attach(t, x, a)
            g[x] = gx_new
            _tree.shift_subtree(t, x, delta, stack)
            st.rewirings += 1
            if expanded[x] == batch:
                expanded[x] = -1  # its queued edges are stale: expand it again
        else:
            vertex[x] = True
            t.old[x] = False
            g[x] = gx_new
            _tree.attach(t, x, a)
            expanded[x] = -1
        nv[0] = _queue.push_vertex(vkey, vqueue, nv[0], gx_new + h_hat[x], x)
        if g[1] < c_best:
            st.best = g[1]
            return IMPROVED
    return BUDGET


@njit(cache=True, inline="always")
def start_batch(p: Points, t: Tree, q: SearchQueue, b: Batch, pr: np.ndarray) -> None:
    """Batch ``b`` starts: clear both queues, mark all vertices old and queue the useful ones.

    A vertex expanded in an earlier batch only needs expanding again if a new sample lies
    within r of it (its expansion considers new samples only); skipping the others changes
    nothing but the cost. That test asks the new samples' grid about each such vertex (the
    distance is symmetric, so it finds what asking all points about each new sample finds):
    a search whose tree stays small while its samples pile up (a start boxed in by squares,
    40 batches of 400) pays for its few vertices, not for every new sample's neighbours.
    """
    q.ne[0] = 0
    n = p.n[0]
    near = np.empty(b.new.shape[0], np.int64)  # scratch: a vertex's new neighbours
    near_d = np.empty(b.new.shape[0])
    vs = np.int64(0)  # not a literal: one specialisation of push_vertex
    c_best = pr[0].best
    for i in range(n):
        if t.vertex[i]:
            t.old[i] = True
            key = t.g[i] + p.h_hat[i]
            if key < c_best and (t.expanded[i] < 0 or b.k > 0 or _graph.near(
                    i, p, b, b.radius, b.new_start, b.new_items, near, near_d) > 0):
                vs = _queue.push_vertex(q.vkey, q.vertex, vs, key, i)
    q.nv[0] = vs
