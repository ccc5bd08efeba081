"""BIT*'s tree (OMPL ``BITstar::Vertex``): parent links, children and cost-to-come.

The tree over the points of the implicit graph is held in one record, :class:`Tree`: for each
point its parent, first child and siblings (doubly linked, so a rewiring detaches in O(1)),
its cost-to-come ``g_T`` and whether it is a vertex. Point 0 is the start (the root), 1 the
goal. The kernels edit the links in place; :func:`with_capacity` makes a larger record.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit


class Tree(NamedTuple):
    """The search tree over C point slots. Produced by :func:`new_tree` and
    :func:`with_capacity` only."""

    #: Cost-to-come ``g_T`` [m] (inf for a sample), shape (C,).
    g: np.ndarray
    #: Parent (-1 for the root and for samples), int64, shape (C,).
    parent: np.ndarray
    #: First child (-1: none), int64, shape (C,).
    child: np.ndarray
    #: Next sibling (-1: none), int64, shape (C,).
    next_sibling: np.ndarray
    #: Previous sibling (-1: the parent's first child), int64, shape (C,).
    prev_sibling: np.ndarray
    #: True for a vertex (a point in the tree), shape (C,).
    vertex: np.ndarray
    #: True for a vertex that was one already when the current batch started, shape (C,).
    old: np.ndarray
    #: Batch in which the vertex was last expanded (-1: to be expanded), int64, shape (C,).
    expanded: np.ndarray


def new_tree(cap: int) -> Tree:
    """A tree holding only the root (point 0, the start, at cost 0)."""
    t = Tree(np.full(cap, math.inf), np.full(cap, -1, np.int64), np.full(cap, -1, np.int64),
             np.full(cap, -1, np.int64), np.full(cap, -1, np.int64), np.zeros(cap, np.bool_),
             np.zeros(cap, np.bool_), np.full(cap, -1, np.int64))
    t.g[0] = 0.0
    t.vertex[0] = True
    return t


def with_capacity(t: Tree, cap: int) -> Tree:
    """``t`` with ``cap`` point slots (the first ones kept, the new ones samples)."""
    old = t.g.shape[0]
    if cap <= old:
        return t

    def more(a: np.ndarray, fill: float | int | bool) -> np.ndarray:
        return np.concatenate([a, np.full(cap - old, fill, a.dtype)])

    return Tree(more(t.g, math.inf), more(t.parent, -1), more(t.child, -1),
                more(t.next_sibling, -1), more(t.prev_sibling, -1), more(t.vertex, False),
                more(t.old, False), more(t.expanded, -1))


def reset(t: Tree, lo: int, hi: int) -> None:
    """Make the slots ``lo:hi`` samples (no links, cost-to-come inf)."""
    t.g[lo:hi] = math.inf
    for a in (t.parent, t.child, t.next_sibling, t.prev_sibling, t.expanded):
        a[lo:hi] = -1
    t.vertex[lo:hi] = False
    t.old[lo:hi] = False


def attach_root_child(t: Tree, x: int, cost: float) -> None:
    """From Python: make point x a vertex, a child of the root, at cost-to-come ``cost``."""
    t.g[x] = cost
    t.parent[x] = 0
    t.prev_sibling[x] = -1
    t.next_sibling[x] = t.child[0]
    if t.child[0] >= 0:
        t.prev_sibling[t.child[0]] = x
    t.child[0] = x
    t.vertex[x] = True
    t.old[x] = False


def path_to(t: Tree, xy: np.ndarray, x: int) -> np.ndarray:
    """Positions (K, 2) of the tree path from the root to vertex x."""
    chain = [x]
    while chain[-1] != 0:
        chain.append(int(t.parent[chain[-1]]))
        if len(chain) > xy.shape[0]:
            raise RuntimeError("BIT* tree corrupted: cycle in the parent chain")
    return xy[chain[::-1]].copy()


@njit(cache=True, inline="always")
def detach(t: Tree, x: int) -> None:
    """Remove x from its parent's children (x keeps its own children)."""
    p = t.parent[x]
    if p < 0:
        return
    ps = t.prev_sibling[x]
    ns = t.next_sibling[x]
    if ps >= 0:
        t.next_sibling[ps] = ns
    else:
        t.child[p] = ns
    if ns >= 0:
        t.prev_sibling[ns] = ps
    t.parent[x] = -1
    t.next_sibling[x] = -1
    t.prev_sibling[x] = -1


@njit(cache=True, inline="always")
def attach(t: Tree, x: int, p: int) -> None:
    """Make x (detached) the first child of p."""
    t.parent[x] = p
    f = t.child[p]
    t.next_sibling[x] = f
    t.prev_sibling[x] = -1
    if f >= 0:
        t.prev_sibling[f] = x
    t.child[p] = x


@njit(cache=True)
def shift_subtree(t: Tree, root: int, delta: float, stack: np.ndarray) -> None:
    """Subtract ``delta`` from g_T of every strict descendant of ``root`` (``stack``: scratch
    of at least as many slots as vertices)."""
    top = 0
    c = t.child[root]
    while c >= 0:
        stack[top] = c
        top += 1
        c = t.next_sibling[c]
    while top > 0:
        top -= 1
        x = stack[top]
        t.g[x] -= delta
        c = t.child[x]
        while c >= 0:
            stack[top] = c
            top += 1
            c = t.next_sibling[c]


@njit(cache=True)
def surviving_vertices(t: Tree, n: int, state: np.ndarray) -> np.ndarray:
    """Mask (n,): the vertices below which every ancestor has ``state`` 2 (kept as a vertex);
    the root always survives."""
    keepv = np.zeros(n, np.bool_)
    keepv[0] = True
    stack = np.empty(n, np.int64)
    top = 0
    c = t.child[0]
    while c >= 0:
        stack[top] = c
        top += 1
        c = t.next_sibling[c]
    while top > 0:
        top -= 1
        x = stack[top]
        if state[x] == 2 and keepv[t.parent[x]]:
            keepv[x] = True
        c = t.child[x]
        while c >= 0:
            stack[top] = c
            top += 1
            c = t.next_sibling[c]
    return keepv
