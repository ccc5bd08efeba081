"""BIT*'s search queue (OMPL ``BITstar::SearchQueue``): the vertex and edge queues.

Both are binary min-heaps in flat arrays, held in one record, :class:`SearchQueue`. The vertex
queue is keyed ``g_T(v) + h_hat(v)``, the edge queue ``g_T(v) + c_hat(v, x) + h_hat(x)``
(notation of :mod:`anyplan.planning.bitstar`). The kernels push and pop in place; the
capacity is grown from Python between calls (:func:`grown`), which makes a new record.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit


class SearchQueue(NamedTuple):
    """The two heaps. Produced by :func:`new_queue` and :func:`grown` only."""

    #: Vertex-queue keys [m], shape (Qv,); ``vkey[:nv[0]]`` is the heap.
    vkey: np.ndarray
    #: Vertex ids of the vertex queue, int64, shape (Qv,).
    vertex: np.ndarray
    #: Edge-queue keys [m], shape (Qe,); ``ekey[:ne[0]]`` is the heap.
    ekey: np.ndarray
    #: Edges (v, x) of the edge queue, int64, shape (Qe, 2).
    edge: np.ndarray
    #: Number of queued vertices, int64, shape (1,).
    nv: np.ndarray
    #: Number of queued edges, int64, shape (1,).
    ne: np.ndarray


def new_queue(cap: int) -> SearchQueue:
    """Empty queues for about ``cap`` points."""
    return SearchQueue(np.zeros(cap), np.zeros(cap, np.int64), np.zeros(4 * cap),
                       np.zeros((4 * cap, 2), np.int64), np.zeros(1, np.int64),
                       np.zeros(1, np.int64))


def grown(q: SearchQueue, n_points: int) -> SearchQueue:
    """``q`` with room for at least another ``n_points + 8`` edges and 8 vertices (contents
    kept)."""
    vkey, vertex, ekey, edge = q.vkey, q.vertex, q.ekey, q.edge
    ne = int(q.ne[0])
    if ekey.shape[0] - ne < n_points + 8:
        size = max(2 * ekey.shape[0], ne + 2 * n_points + 16)
        ekey = np.concatenate([ekey, np.zeros(size - ekey.shape[0])])
        edge = np.vstack([edge, np.zeros((size - edge.shape[0], 2), np.int64)])
    if vkey.shape[0] - int(q.nv[0]) < 8:
        size = 2 * vkey.shape[0]
        vkey = np.concatenate([vkey, np.zeros(size - vkey.shape[0])])
        vertex = np.concatenate([vertex, np.zeros(size - vertex.shape[0], np.int64)])
    return SearchQueue(vkey, vertex, ekey, edge, q.nv, q.ne)


def with_vertex_room(q: SearchQueue, n_points: int) -> SearchQueue:
    """``q`` whose vertex queue can hold ``n_points + 8`` vertices (a new, empty vertex queue
    if it had to grow: call it only when the vertex queue is about to be refilled)."""
    if q.vkey.shape[0] >= n_points + 8:
        return q
    size = 2 * (n_points + 8)
    return SearchQueue(np.zeros(size), np.zeros(size, np.int64), q.ekey, q.edge, q.nv, q.ne)


# The heap primitives take the arrays themselves (hoisted by the caller): reading a record's
# field in compiled code takes a reference (an atomic increment and decrement), too costly per
# push and pop.
@njit(cache=True)
def push_vertex(keys: np.ndarray, pay: np.ndarray, size: int, key: float, v: int) -> int:
    """Push vertex v with ``key`` on the vertex heap (``vkey``, ``vertex``) of ``size``
    entries; returns the new size (the capacity must suffice)."""
    i = size
    while i > 0:
        p = (i - 1) >> 1
        if keys[p] <= key:
            break
        keys[i] = keys[p]
        pay[i] = pay[p]
        i = p
    keys[i] = key
    pay[i] = v
    return size + 1


@njit(cache=True)
def pop_vertex(keys: np.ndarray, pay: np.ndarray, size: int) -> int:
    """Remove the top of the vertex heap of ``size`` entries; returns the new size."""
    size -= 1
    if size <= 0:
        return 0
    key = keys[size]
    a = pay[size]
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
        pay[i] = pay[c]
        i = c
    keys[i] = key
    pay[i] = a
    return size


@njit(cache=True)
def push_edge(keys: np.ndarray, pay: np.ndarray, size: int, key: float, v: int, x: int) -> int:
    """Push edge (v, x) with ``key`` on the edge heap (``ekey``, ``edge``) of ``size``
    entries; returns the new size (the capacity must suffice)."""
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
    pay[i, 0] = v
    pay[i, 1] = x
    return size + 1


@njit(cache=True)
def pop_edge(keys: np.ndarray, pay: np.ndarray, size: int) -> int:
    """Remove the top of the edge heap of ``size`` entries; returns the new size."""
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
