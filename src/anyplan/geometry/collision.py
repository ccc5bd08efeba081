"""Exact collision and clearance queries for a disc robot among static shapes.

An :class:`ObstacleSet` holds circles, simple polygons and optional arena walls in flat arrays,
handed to compiled kernels as one record, :class:`ObstacleArrays` (:attr:`ObstacleSet.arrays`).
A disc robot of radius ``r`` centred at ``p`` is in collision iff ``clearance(p) < r``: this is
the obstacle set *inflated* by ``r`` (the Minkowski sum with a disc, rounded corners included),
tested exactly, with no sampling and no resolution.
A straight motion from ``a`` to ``b`` is free iff the segment's clearance is ``>= r``.

Examples:
    >>> from anyplan.geometry.shapes import Circle, rectangle
    >>> obs = ObstacleSet([Circle((5.0, 5.0), 1.0)], bounds=(0.0, 0.0, 10.0, 10.0))
    >>> round(obs.clearance((5.0, 2.0)), 6)
    2.0
    >>> obs.segment_free((1.0, 5.0), (9.0, 5.0), 0.3)
    False
    >>> obs.segment_free((1.0, 1.0), (9.0, 1.0), 0.3)
    True
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Sequence

import numpy as np

from anyplan.geometry import _clearance as k
from anyplan.geometry._clearance import ObstacleArrays
from anyplan.geometry.index import MIN_INDEXED, NO_GRID, build_grid
from anyplan.geometry.shapes import Circle, Polygon, Shape

__all__ = ["ObstacleSet", "ObstacleArrays", "COLLISION_EPS", "segment_clearance_kernel",
           "segment_clearance_below_kernel", "segment_blocked_kernel", "capsule_buried_kernel"]

#: Tolerance [m] on contact: a clearance of ``r - COLLISION_EPS`` still counts as touching, not
#: as penetrating, so that paths which graze an inflated boundary exactly are accepted.
COLLISION_EPS = 1e-9

#: Compiled ``(ax, ay, bx, by, obs: ObstacleArrays, stop_below) -> float``: the minimum distance
#: [m] from segment ab to the obstacles and walls (0 on contact); returns early, with some value
#: below ``stop_below``, once the clearance is known to be below it (``-1`` for the exact
#: minimum). Callable from Python and from other ``@njit`` code.
segment_clearance_kernel = k.segment_clearance
#: Compiled ``(ax, ay, bx, by, obs: ObstacleArrays, cap) -> float``: ``min(clearance, cap)``,
#: the exact clearance of segment ab when it is below ``cap`` [m], else ``cap``; on a map it
#: scans only the cells within ``cap`` of the segment. Callable from ``@njit`` code.
segment_clearance_below_kernel = k.segment_clearance_below
#: Compiled ``(ax, ay, bx, by, pad, obs: ObstacleArrays) -> bool``: True if the ``pad``-
#: neighbourhood of segment ab lies (by more than 1e-9 m) inside one circle, one map box or
#: beyond an arena wall, so that every segment within it has clearance exactly 0; a
#: conservative test (False says nothing). Callable from ``@njit`` code.
capsule_buried_kernel = k.capsule_buried
#: Compiled ``(ax, ay, bx, by, obs: ObstacleArrays, limit) -> bool``: True iff the exact
#: clearance of segment ab is < ``limit`` [m] (pass/fail only: on a map it scans only the cells
#: within ``limit`` of the segment). Callable from Python and from other ``@njit`` code.
segment_blocked_kernel = k.segment_blocked


#: Digests of recent boxes arrays (kept alive here, so that an id seen is the same array).
_BOX_DIGESTS: list[tuple[np.ndarray, bytes]] = []


def _boxes_digest(boxes: np.ndarray) -> bytes:
    for b, d in _BOX_DIGESTS:
        if b is boxes:
            return d
    d = hashlib.blake2b(np.ascontiguousarray(boxes).tobytes(), digest_size=16).digest()
    _BOX_DIGESTS.append((boxes, d))
    del _BOX_DIGESTS[:-8]
    return d


#: Recent sets of boxes and walls alone (:meth:`ObstacleSet.split_boxes`), with their boxes
#: array (kept alive here, so that an id seen is the same array) and (walls, index choice).
_BOX_SETS: list[tuple[np.ndarray, tuple[object, object], ObstacleSet]] = []


class ObstacleSet:
    """Static obstacles (circles, polygons, axis-aligned boxes) plus optional arena walls.

    Args:
        shapes: Circles and polygons.
        bounds: Arena (xmin, ymin, xmax, ymax) [m]; a point outside, or on the boundary, has
            clearance 0. ``None`` means no walls.
        boxes: Axis-aligned boxes (M, 4) = (xmin, ymin, xmax, ymax) [m], e.g. the merged
            occupied cells of a map; they are kept as arrays, not as :class:`Polygon` objects.
        index: Build the grid index (True), never (False), or when there are at least
            :data:`~anyplan.geometry.index.MIN_INDEXED` polygons (None, the default).

    With :data:`~anyplan.geometry.index.MIN_INDEXED` polygons or more (boxes included), a
    uniform-grid index (:mod:`anyplan.geometry.index`) serves the queries; they stay exact
    (the index only decides which polygons are tested).
    """

    def __init__(self, shapes: Iterable[Shape] = (),
                 bounds: Sequence[float] | None = None,
                 boxes: np.ndarray | None = None, index: bool | None = None) -> None:
        self.shapes: tuple[Shape, ...] = tuple(shapes)
        for s in self.shapes:
            if not isinstance(s, Circle | Polygon):
                raise TypeError(f"unsupported shape {type(s).__name__}")
        b = np.zeros((0, 4)) if boxes is None else np.asarray(boxes, dtype=float).reshape(-1, 4)
        if len(b) and not (np.all(np.isfinite(b)) and np.all(b[:, 2] > b[:, 0])
                           and np.all(b[:, 3] > b[:, 1])):
            raise ValueError("boxes must be finite (xmin, ymin, xmax, ymax) with xmax > xmin, "
                             "ymax > ymin")
        b.setflags(write=False)
        self.boxes = b
        self._set_arrays(self.shapes, bounds)
        self._index = index
        if len(self.pbox) and (index or (index is None and len(self.pbox) >= MIN_INDEXED)):
            self._gmeta, self._gcsr = build_grid(self.pbox)
            self._gmeta[6] = len(self.boxes)  # the first polygons are the boxes
        else:
            self._gmeta, self._gcsr = NO_GRID
        self._pack()

    def _set_arrays(self, shapes: Sequence[Shape], bounds: Sequence[float] | None) -> None:
        circles = [s for s in shapes if isinstance(s, Circle)]
        polys = [s for s in shapes if isinstance(s, Polygon)]
        self.circles = np.array([[c.center[0], c.center[1], c.radius] for c in circles],
                                dtype=float).reshape(-1, 3)
        b = self.boxes
        # axis-aligned boxes first, as counter-clockwise rectangles
        bvx = np.column_stack([b[:, 0], b[:, 2], b[:, 2], b[:, 0]]).ravel()
        bvy = np.column_stack([b[:, 1], b[:, 1], b[:, 3], b[:, 3]]).ravel()
        verts = [np.column_stack([bvx, bvy])] + [p.vertices for p in polys]
        counts = np.concatenate([np.full(len(b), 4), [len(p.vertices) for p in polys]])
        self.starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        allv = np.vstack(verts)
        self.vx = np.ascontiguousarray(allv[:, 0], dtype=float)
        self.vy = np.ascontiguousarray(allv[:, 1], dtype=float)
        self.pbox = np.vstack([b, np.array([p.bounds for p in polys], dtype=float).reshape(-1, 4)])
        self.bounds = (None if bounds is None else tuple(float(x) for x in bounds))
        self._bounds_arr = (np.array([1.0, 1.0, -1.0, -1.0]) if bounds is None
                            else np.array(self.bounds, dtype=float))

    def _pack(self) -> None:
        self._arrays = ObstacleArrays(self.vx, self.vy, self.starts, self.pbox, self.circles,
                                      self._bounds_arr, self._gmeta, self._gcsr)

    def __len__(self) -> int:
        return len(self.shapes) + len(self.boxes)

    @property
    def fingerprint(self) -> bytes:
        """A digest of the obstacles (equal digests: the same record of arrays), for memos of
        pure functions of the set. Computed once per set; the boxes' part once per boxes array
        (a set made by :meth:`with_shapes` shares it), so it costs what the shapes cost."""
        fp = self.__dict__.get("_fingerprint")
        if fp is None:
            # the record is a function of these: the boxes' vertices, the first starts and the
            # grid's cells follow from the boxes, the polygons' boxes and gmeta (build_grid)
            nb = len(self.boxes)
            h = hashlib.blake2b(_boxes_digest(self.boxes), digest_size=16)
            for a in (self.vx[4 * nb:], self.vy[4 * nb:], self.starts[nb:], self.pbox[nb:],
                      self.circles, self._bounds_arr, self._gmeta):
                h.update(np.ascontiguousarray(a).tobytes())
                h.update(b"|")
            fp = self.__dict__["_fingerprint"] = h.digest()
        return fp

    @property
    def indexed(self) -> bool:
        """True if a grid index serves the queries (many polygons, e.g. a map's cells)."""
        return bool(self._gmeta[3] > 0)

    def with_shapes(self, extra: Iterable[Shape]) -> ObstacleSet:
        """A new set with ``extra`` shapes added (same walls and boxes); ``self`` is unchanged.

        The grid index, if any, is kept: the added polygons are scanned linearly (they are
        few, e.g. Sequential BIT*'s virtual obstacles), so adding them costs no rebuild."""
        extra = tuple(extra)
        n_new = sum(isinstance(s, Polygon) for s in extra)
        if not self.indexed or len(self.pbox) - int(self._gmeta[5]) + n_new >= MIN_INDEXED:
            return ObstacleSet(self.shapes + extra, self.bounds, boxes=self.boxes,
                               index=self._index)
        out = ObstacleSet.__new__(ObstacleSet)
        out.shapes = self.shapes + extra
        for s in extra:
            if not isinstance(s, Circle | Polygon):
                raise TypeError(f"unsupported shape {type(s).__name__}")
        out.boxes = self.boxes
        out._index = self._index
        out._set_arrays(out.shapes, self.bounds)
        out._gmeta, out._gcsr = self._gmeta, self._gcsr
        out._pack()
        return out

    def split_boxes(self) -> tuple[ObstacleSet, ObstacleSet]:
        """(the boxes with the walls, the shapes alone): the clearance of this set is the
        smaller of theirs, so a point is clear of it to a limit iff it is clear of both.

        The first set is the same object for every set that shares this one's boxes array,
        walls and index choice (the sets :meth:`with_shapes` makes from one map): a memo keyed
        by its :attr:`fingerprint` serves all of them, and its grid index is built once."""
        key = (self.bounds, self._index)
        base = next((s for b, k_, s in _BOX_SETS if b is self.boxes and k_ == key), None)
        if base is None:
            base = ObstacleSet((), self.bounds, boxes=self.boxes, index=self._index)
            _BOX_SETS.append((self.boxes, key, base))
            del _BOX_SETS[:-4]
        return base, ObstacleSet(self.shapes)

    @property
    def arrays(self) -> ObstacleArrays:
        """The obstacles as one record of flat arrays for compiled kernels
        (:class:`ObstacleArrays` documents the layout)."""
        return self._arrays

    # --- single queries -------------------------------------------------------------------
    # (the record's fields one by one: see the note on the py_* entries in _clearance)
    def clearance(self, point: Sequence[float] | np.ndarray) -> float:
        """Distance [m] from ``point`` to the nearest obstacle or wall (0 inside one)."""
        o = self._arrays
        x, y = float(point[0]), float(point[1])
        return k.py_query(k.POINT, x, y, x, y, o.vx, o.vy, o.starts, o.pbox, o.circles, o.bounds,
                          o.gmeta, o.gcsr, 0.0)

    def point_free(self, point: Sequence[float] | np.ndarray, radius: float) -> bool:
        """True if a disc of ``radius`` [m] at ``point`` touches no obstacle and no wall."""
        return self.clearance(point) >= radius - COLLISION_EPS

    def segment_clearance(self, a: Sequence[float] | np.ndarray,
                          b: Sequence[float] | np.ndarray) -> float:
        """Exact minimum distance [m] from segment ``ab`` to the obstacles and walls."""
        o = self._arrays
        return k.py_query(k.SEGMENT, float(a[0]), float(a[1]), float(b[0]), float(b[1]), o.vx,
                          o.vy, o.starts, o.pbox, o.circles, o.bounds, o.gmeta, o.gcsr, -1.0)

    def segment_free(self, a: Sequence[float] | np.ndarray, b: Sequence[float] | np.ndarray,
                     radius: float) -> bool:
        """True if a disc of ``radius`` [m] moving straight from ``a`` to ``b`` touches nothing."""
        o = self._arrays
        limit = radius - COLLISION_EPS
        return not k.py_query(k.PASS_FAIL, float(a[0]), float(a[1]), float(b[0]), float(b[1]),
                              o.vx, o.vy, o.starts, o.pbox, o.circles, o.bounds, o.gmeta, o.gcsr,
                              limit) < limit

    # --- batched queries ------------------------------------------------------------------
    def _queries(self, kind: int, a: np.ndarray, b: np.ndarray | None, arg: float) -> np.ndarray:
        """The query ``kind`` (``py_query``'s) of each (a[n], b[n]) (b None: a), ``a``, ``b``
        shape (N, 2)."""
        o = self._arrays
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        ax, ay = np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1])
        if b is None:
            bx, by = ax, ay
        else:
            b = np.asarray(b, dtype=float).reshape(-1, 2)
            bx, by = np.ascontiguousarray(b[:, 0]), np.ascontiguousarray(b[:, 1])
        return k.py_queries(kind, ax, ay, bx, by, o.vx, o.vy, o.starts, o.pbox, o.circles,
                            o.bounds, o.gmeta, o.gcsr, arg)

    def clearances(self, points: np.ndarray) -> np.ndarray:
        """Clearance of each point, ``points`` shape (N, 2), result shape (N,) [m]."""
        return self._queries(k.POINT, points, None, 0.0)

    def points_free(self, points: np.ndarray, radius: float) -> np.ndarray:
        """Boolean mask (N,): a disc of ``radius`` at each point touches nothing."""
        return self.points_clear(points, radius - COLLISION_EPS)

    def points_clear(self, points: np.ndarray, limit: float) -> np.ndarray:
        """Boolean mask (N,): the clearance of each point is >= ``limit`` [m]; the same answer
        as ``clearances(points) >= limit``, faster on maps (it stops at ``limit``)."""
        limit = float(limit)
        return self._queries(k.PASS_FAIL, points, None, limit) >= limit

    def segments_clear(self, a: np.ndarray, b: np.ndarray, limit: float) -> np.ndarray:
        """Boolean mask (N,): the clearance of each segment ``a[i] -> b[i]`` is >= ``limit``
        [m] (pass/fail only, as ``segment_blocked_kernel``: on a map it scans only the cells
        within ``limit`` of each segment)."""
        limit = float(limit)
        return self._queries(k.PASS_FAIL, a, b, limit) >= limit

    def segments_clearance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Exact clearance of each segment ``a[i] -> b[i]``, both shape (N, 2); result (N,)."""
        return self._queries(k.SEGMENT, a, b, -1.0)

    def segments_free(self, a: np.ndarray, b: np.ndarray, radius: float) -> np.ndarray:
        """Boolean mask (N,): a disc of ``radius`` moving along each segment touches nothing."""
        return self.segments_clear(a, b, radius - COLLISION_EPS)

    def path_free(self, path: np.ndarray, radius: float) -> bool:
        """True if every segment of the polyline ``path`` (N, 2) is free for the disc robot."""
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(p) == 1:
            return self.point_free(p[0], radius)
        return bool(np.all(self.segments_free(p[:-1], p[1:], radius)))
