"""The s-t obstacle map of a path: where and when the moving obstacles forbid the robot.

For a path C(s) (arc length s in [0, L]) and predicted moving discs o_i(t) of radius r_i(t), the
forbidden region of the (s, t) plane is {(s, t): |C(s) - o_i(t)| <= r + r_i(t) + margin}. It is
covered by a boolean grid of cells [c ds, (c+1) ds] x [t_map + j h, t_map + (j+1) h], a cell
marked when |C(s_c) - o_i(t_mid)| <= r + r_i,max + margin + ds/2 + v_i h/2 (s_c, t_mid the cell's
centre, r_i,max the largest radius at the row's ends and middle): conservative, so a motion
that avoids every marked cell is collision-free with the predicted discs (an obstacle whose
position jumps, an open track at each period, is marked piece by piece between its jumps,
:func:`_pieces`). Predictions are
:class:`~anyplan.prediction.PredictedObstacle` or any object with ``name``, ``positions(t)``,
``max_speed`` and ``radius`` or a vectorised ``radius_at(t)`` (a radius may grow with time).
Derivation: ``docs/spacetime.md`` ("Design: path-velocity decomposition ...", step 4).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numba import njit

from anyplan.prediction.base import jump_times_of
from anyplan.world.motion import JUMP_SLACK_S

__all__ = ["STMap", "RowCache", "build_stmap", "radii_at"]

_CHUNK = 16  # path cells per bounding circle of the coarse test
_BLOCK = 16  # map rows per block of the coarse test
_GROUP = 8  # chunks per group of the coarsest test
_SPARE_ROWS = 200  # rows a RowCache computes beyond the first request


def radii_at(obstacle: Any, t: np.ndarray) -> np.ndarray:
    """Radius [m] of a predicted obstacle at absolute times ``t`` [s] (constant or ``radius_at``)."""
    t = np.asarray(t, dtype=float)
    fn = getattr(obstacle, "radius_at", None)
    if callable(fn):
        r = np.asarray(fn(t), dtype=float)
        return r.copy() if r.shape == t.shape else np.broadcast_to(r, t.shape).copy()
    return np.full(t.shape, float(obstacle.radius))


@njit(cache=True)
def _fill(out: np.ndarray, px: np.ndarray, py: np.ndarray, cx: np.ndarray, cy: np.ndarray,
          crad: np.ndarray, qx: np.ndarray, qy: np.ndarray, reach: np.ndarray, spread: np.ndarray,
          chunk: int, n_free: int, sx: np.ndarray, sy: np.ndarray, srad: np.ndarray,
          group: int) -> np.ndarray:
    """Mark the cells (j, c) with |P_c - Q_oj| <= reach_oj for every obstacle o (rows of q, reach);
    cells c >= n_free stay free; ``spread[o]`` bounds how far [m] obstacle o moves per row (blocks
    of rows far from a chunk of cells are skipped at once, and far from a group of ``group``
    chunks, bounded by the circles ``sx, sy, srad``, all its chunks at once). Returns, per
    obstacle, whether it marked a cell. The skips compare squared distances with 1e-9 m to
    spare: they only leave out cells the exact test would not mark."""
    nrow = out.shape[0]
    ncell = min(out.shape[1], n_free)
    nchunk = cx.shape[0]
    hit = np.zeros(qx.shape[0], dtype=np.bool_)
    nb = (nrow + _BLOCK - 1) // _BLOCK
    for o in range(qx.shape[0]):
        for b in range(nb):
            j0, j1 = b * _BLOCK, min((b + 1) * _BLOCK, nrow)
            jm = (j0 + j1) // 2
            # every row of the block is within spread[o] * (rows apart) of the middle row
            rb = -np.inf
            for j in range(j0, j1):
                rb = max(rb, reach[o, j])
            if rb < 0.0:
                continue  # no disc in any row of the block (after the prediction's end)
            rb += spread[o] * max(jm - j0, j1 - 1 - jm) + 1e-9
            xm, ym = qx[o, jm], qy[o, jm]
            for k in range(sx.shape[0]):
                dx, dy = xm - sx[k], ym - sy[k]
                lim = rb + srad[k]
                if dx * dx + dy * dy > lim * lim:
                    continue
                for g in range(k * group, min((k + 1) * group, nchunk)):
                    dx, dy = xm - cx[g], ym - cy[g]
                    lim = rb + crad[g]
                    if dx * dx + dy * dy > lim * lim:
                        continue
                    c1 = min((g + 1) * chunk, ncell)
                    for j in range(j0, j1):
                        r = reach[o, j]
                        if r < 0.0:
                            continue  # no disc in this row (after the prediction's end)
                        x, y = qx[o, j], qy[o, j]
                        dx, dy = x - cx[g], y - cy[g]
                        lim = r + crad[g] + 1e-9
                        if dx * dx + dy * dy > lim * lim:
                            continue
                        r2 = r * r
                        for c in range(g * chunk, c1):
                            dx = px[c] - x
                            dy = py[c] - y
                            if dx * dx + dy * dy <= r2:
                                out[j, c] = True
                                hit[o] = True
    return hit


def _bounding_circles(px: np.ndarray, py: np.ndarray, size: int
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre (x, y) and radius [m] of a circle around each run of ``size`` consecutive path
    points (the last run may be shorter): the mean point, and the largest distance to it."""
    n = len(px)
    runs = int(math.ceil(n / size))
    flat_x, flat_y = np.full(runs * size, np.nan), np.full(runs * size, np.nan)
    flat_x[:n], flat_y[:n] = px, py
    xs, ys = flat_x.reshape(runs, size), flat_y.reshape(runs, size)
    cx, cy = np.nanmean(xs, axis=1), np.nanmean(ys, axis=1)
    return cx, cy, np.nanmax(np.hypot(xs - cx[:, None], ys - cy[:, None]), axis=1)


def _row_key(o: Any) -> tuple[int, Any, float | None, float]:
    """What an obstacle's rows depend on: a prediction of fixed size (``growth`` None) by its
    motion and radius (a new prediction of the same announced motion shares its rows, whatever
    its end), any other by itself. Returns (key, the object the entry holds, radius [m] or
    None, the end [s] applied to the fixed-size rows when they are read: ``until``, or inf)."""
    m = getattr(o, "motion", None)
    if m is not None and getattr(o, "growth", 0) is None:
        return id(m), m, float(o.radius), float(getattr(o, "until", math.inf))
    return id(o), o, None, math.inf


class RowCache:
    """The obstacles' centres and largest radii at the rows of one time grid, kept across maps.

    Rows are [t_origin + j h, t_origin + (j+1) h] for integers j; a map built with a cache starts
    on this grid (its first row at or before the requested start), so the maps of one
    replanning (the same predictions, the same start) share the obstacles' rows instead of
    sampling every obstacle again for every candidate path, and so do later replannings on the
    same grid for predictions of the same motions (:func:`_row_key`). Entries hold their
    obstacle or motion, so an ``id`` seen here is the same live object (predictions do not
    change once made).
    """

    def __init__(self, t_origin: float, h: float) -> None:
        self.t_origin, self.h = float(t_origin), float(h)
        self._rows: dict[int, tuple[Any, int, int, np.ndarray, np.ndarray, float | None]] = {}
        self._stack: tuple[list[Any], int, int, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._j_begin = 0
        self._used: set[int] = set()
        self._times_memo: tuple[int, int, np.ndarray, np.ndarray] | None = None

    def on_grid(self, t: float) -> bool:
        """Whether time ``t`` [s] is a row boundary of this grid (to 1e-9 of a row)."""
        x = (float(t) - self.t_origin) / self.h
        return abs(x - round(x)) < 1e-9

    def begin(self, t: float) -> None:
        """A new replanning starts at ``t`` [s]: stacks start there (:meth:`rows_all`), and the
        entries the last replanning did not use are dropped (a prediction made anew each
        time, e.g. from a twist, never comes back)."""
        self._j_begin = self.first_row(t)
        self._rows = {k: e for k, e in self._rows.items() if k in self._used}
        self._used = set()

    def first_row(self, t: float) -> int:
        """Index j of the row that contains time ``t`` [s]."""
        return int(math.floor((float(t) - self.t_origin) / self.h + 1e-9))

    def rows(self, o: Any, j0: int, j1: int) -> tuple[np.ndarray, np.ndarray]:
        """Centres (j1 - j0, 2) [m] at the rows' middles and largest radii (j1 - j0,) [m] at
        their ends and middles, rows j0 .. j1 - 1."""
        q, r, until = self._entry(o, j0, j1)
        if until < math.inf:
            r = np.where(self._row_starts(j0, j1) <= until, r, -math.inf)
        return q, r

    def _row_starts(self, j0: int, j1: int) -> np.ndarray:
        """Start times [s] of rows j0 .. j1 - 1."""
        return self.t_origin + self.h * np.arange(j0, j1)

    def _entry(self, o: Any, j0: int, j1: int) -> tuple[np.ndarray, np.ndarray, float]:
        """:meth:`rows` before a fixed-size prediction's end is applied, and that end [s]
        (inf for the others, whose radii already say it): a row whose start is after the end
        has no disc (radius -inf, as ``radius_at`` says); one that starts at or before it has
        the disc at its start."""
        key, holder, size, until = _row_key(o)
        self._used.add(key)
        e = self._rows.get(key)
        if e is not None and (e[0] is not holder or e[5] != size):
            e = None  # not the same motion, or another radius
        if e is None or not (e[1] <= j0 and j1 <= e[2]):
            # Rows to spare: the next map (a longer path, a longer wait) needs a few more.
            if e is None:
                a, b = j0, j1 + _SPARE_ROWS
            else:  # (rows before this replanning's start are not kept)
                a = min(max(e[1], self._j_begin), j0)
                b = max(e[2] + (e[2] - a), j1)
            t_mid, t_edges = self._times(a, b)
            q = np.asarray(o.positions(t_mid), dtype=float).reshape(-1, 2)
            if size is not None:  # fixed size: the end is applied below
                r_max = np.full(len(t_mid), size)
            else:
                r_edge = radii_at(o, t_edges)
                r_max = np.maximum(radii_at(o, t_mid), np.maximum(r_edge[:-1], r_edge[1:]))
            e = (holder, a, b, q, r_max, size)
            self._rows[key] = e
        return e[3][j0 - e[1]:j1 - e[1]], e[4][j0 - e[1]:j1 - e[1]], until

    def _times(self, a: int, b: int) -> tuple[np.ndarray, np.ndarray]:
        """The middles (b - a,) and the edges (b - a + 1,) [s] of rows a .. b - 1; the last
        answer is kept (the new entries of one stack are all asked for the same rows)."""
        if self._times_memo is None or self._times_memo[:2] != (a, b):
            t_mid = self.t_origin + self.h * (np.arange(a, b) + 0.5)
            t_edges = self.t_origin + self.h * np.arange(a, b + 1)
            self._times_memo = (a, b, t_mid, t_edges)
        return self._times_memo[2], self._times_memo[3]

    def rows_all(self, obstacles: Sequence[Any], j0: int, j1: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`rows` of every obstacle, stacked: centres' x and y (n, j1 - j0) [m] and
        largest radii (n, j1 - j0) [m]. The stack of the last list of obstacles is kept (the
        maps of one replanning ask for the same ones), over rows to spare like :meth:`rows`."""
        st = self._stack
        same = st is not None and len(st[0]) == len(obstacles) and all(
            x is y for x, y in zip(st[0], obstacles, strict=True))
        if st is None or not same or not (st[1] <= j0 and j1 <= st[2]):
            # From the replanning's start (:meth:`begin`: maps start a few rows apart, after a
            # turn in place or a brake) and with rows to spare (longer paths, longer waits):
            # every regrowth stacks all the obstacles again.
            a, b = min(j0, self._j_begin), j1 + _SPARE_ROWS
            if st is not None and same:
                a, b = min(st[1], a), max(st[2], b)
            parts = [self._entry(o, a, b) for o in obstacles]
            # the rows each obstacle's entry holds (rows to spare included) bound the stack
            held = [self._rows[_row_key(o)[0]] for o in obstacles]
            hi = min(e[2] for e in held)
            if all(e[1] <= a for e in held) and b <= hi:
                parts = [self._entry(o, a, hi) for o in obstacles]
                b = hi
            q = np.stack([p[0] for p in parts])
            r = np.stack([p[1] for p in parts])
            until = np.array([p[2] for p in parts])
            if np.any(until < math.inf):  # the ends, all at once
                r = np.where(self._row_starts(a, b)[None, :] <= until[:, None], r, -math.inf)
            st = (list(obstacles), a, b, np.ascontiguousarray(q[:, :, 0]),
                  np.ascontiguousarray(q[:, :, 1]), r)
            self._stack = st
        i0, i1 = j0 - st[1], j1 - st[1]
        return st[3][:, i0:i1], st[4][:, i0:i1], st[5][:, i0:i1]


class STMap:
    """A boolean s-t map (see the module docstring).

    Attributes:
        forbidden: (R, cells) boolean array: the map's first R rows, those the predictions may
            mark; its other rows are free (not stored: a long path's map, whose predictions
            end within seconds, costs what those seconds cost).
        rows: The map's rows (>= R).
        t_map: Time [s] of the first row's start.
        h: Row duration [s].
        ds: Cell width [m].
        length: Path length [m].
        blockers: Names of the obstacles that mark at least one cell.
    """

    def __init__(self, forbidden: np.ndarray, t_map: float, h: float, ds: float, length: float,
                 blockers: list[str], rows: int | None = None) -> None:
        self.forbidden = forbidden
        self.rows = forbidden.shape[0] if rows is None else int(rows)
        if self.rows < forbidden.shape[0]:
            raise ValueError(f"rows: {self.rows} is fewer than the stored {forbidden.shape[0]}")
        self.t_map, self.h, self.ds, self.length = float(t_map), float(h), float(ds), float(length)
        self.blockers = blockers

    @property
    def horizon_s(self) -> float:
        """Duration [s] covered by the rows."""
        return self.rows * self.h

    def grid(self) -> np.ndarray:
        """The whole map, (rows, cells) boolean, its free rows included (for tests and
        pictures; the planner reads :attr:`forbidden` and :attr:`rows`)."""
        out = np.zeros((self.rows, self.forbidden.shape[1]), dtype=np.bool_)
        out[: self.forbidden.shape[0]] = self.forbidden
        return out


def _pieces(o: Any, js: list[float], t_map: float, h: float, nfill: int, reach: np.ndarray,
            speed: float) -> tuple[np.ndarray, np.ndarray]:
    """An obstacle whose position jumps within the rows (at the times ``js`` [s]) as one entry
    per piece between its jumps: centres (pieces, rows, 2) [m] at each row's middle clamped
    into the piece (just after the jump it starts with, just before the one it ends with),
    contact distances (pieces, rows) [m] ``reach`` grown by v h / 2 (a time of the piece in
    the row lies within h of the clamped one, up to the slack, and the motion is continuous on
    the piece), none (-1) in rows outside the piece. Consecutive rows' clamped times are at most 1.5 h apart
    (the spread :func:`_fill` is given)."""
    t_end = t_map + nfill * h
    row0 = t_map + h * np.arange(nfill)
    t_mid = row0 + 0.5 * h
    grow = 0.5 * speed * h + speed * 4.0 * JUMP_SLACK_S + 1e-9
    qs, rs = [], []
    for a, b in zip([t_map, *js], [*js, t_end], strict=True):
        lo = a + JUMP_SLACK_S if a in js else a
        hi = max(lo, b - JUMP_SLACK_S) if b in js else max(lo, b)
        qs.append(np.asarray(o.positions(np.clip(t_mid, lo, hi)), dtype=float).reshape(-1, 2))
        inside = (row0 + h >= a - JUMP_SLACK_S) & (row0 <= b + JUMP_SLACK_S)
        rs.append(np.where(inside, reach + grow, -1.0))
    return np.stack(qs), np.stack(rs)


def build_stmap(points_at: Any, length: float, obstacles: Sequence[Any], robot_radius: float,
                t_map: float, horizon_s: float, *, margin: float = 0.0, ds: float = 0.05,
                h: float = 0.05, free_tail_m: float = 0.0, rows: RowCache | None = None) -> STMap:
    """The s-t map of a path for the predicted ``obstacles``.

    Args:
        points_at: Function arc lengths (N,) [m] -> points (N, 2) [m] of the path.
        length: Path length L [m].
        obstacles: Predicted moving discs (see the module docstring).
        robot_radius: [m].
        t_map: Start time [s] of the map.
        horizon_s: Duration [s] the map covers.
        margin: Extra clearance [m] required between robot and obstacle discs.
        ds: Cell width [m] along the path.
        h: Row duration [s].
        free_tail_m: The last ``free_tail_m`` metres of the path are never marked (inside the
            goal tolerance the run is over).
        rows: The obstacles' rows shared by the maps of one replanning (its ``h`` is used);
            the map then starts at the row of ``rows`` that contains ``t_map`` and covers
            ``t_map + horizon_s`` all the same.
    """
    j_first = 0
    if rows is not None:
        h = rows.h
        j_first = rows.first_row(t_map)
        t_end = t_map + horizon_s
        t_map = rows.t_origin + j_first * h
        horizon_s = t_end - t_map
    ncell = max(1, int(math.ceil(length / ds)))
    nrow = max(1, int(math.ceil(horizon_s / h)))
    sc = np.minimum((np.arange(ncell) + 0.5) * ds, length)
    p = np.asarray(points_at(sc), dtype=float).reshape(-1, 2)
    px, py = np.ascontiguousarray(p[:, 0]), np.ascontiguousarray(p[:, 1])
    cx, cy, crad = _bounding_circles(px, py, _CHUNK)
    sx, sy, srad = _bounding_circles(px, py, _GROUP * _CHUNK)  # groups of _GROUP chunks
    n_free = int(math.floor(max(length - free_tail_m, 0.0) / ds)) if free_tail_m > 0.0 else ncell
    gx, gy = float(px.mean()), float(py.mean())
    grad = float(np.max(np.hypot(px - gx, py - gy)))
    obstacles = list(obstacles)
    blockers: list[str] = []
    if not obstacles:
        return STMap(np.zeros((0, ncell), dtype=np.bool_), t_map, h, ds, length, blockers, nrow)
    # Rows that start after every prediction's end hold no disc: they stay free, not stored.
    ends = max(float(getattr(o, "until", math.inf)) for o in obstacles)
    nfill = nrow if ends == math.inf else max(1, min(nrow, int(math.floor((ends - t_map) / h)) + 2))
    out = np.zeros((nfill, ncell), dtype=np.bool_)
    if rows is not None:
        qx, qy, r_max = rows.rows_all(obstacles, j_first, j_first + nfill)
    else:
        t_edges = t_map + h * np.arange(nfill + 1)
        t_mid = t_map + h * (np.arange(nfill) + 0.5)
        q = np.stack([np.asarray(o.positions(t_mid), dtype=float).reshape(-1, 2) for o in obstacles])
        qx, qy = q[:, :, 0], q[:, :, 1]
        r_edges = np.stack([radii_at(o, t_edges) for o in obstacles])
        r_mid = np.stack([radii_at(o, t_mid) for o in obstacles])
        r_max = np.maximum(r_mid, np.maximum(r_edges[:, :-1], r_edges[:, 1:]))
    speed = np.array([float(o.max_speed) for o in obstacles])
    # All obstacles at once, element by element the same operations as one at a time.
    reach = robot_radius + r_max + margin + 0.5 * ds + (0.5 * speed)[:, None] * h
    spread = speed * h
    owner = np.arange(len(obstacles))
    t_end = t_map + nfill * h
    jumps = {k: js for k, o in enumerate(obstacles) if (js := jump_times_of(o, t_map, t_end))}
    jumpy = list(jumps)
    if jumpy:  # each such obstacle as its pieces between jumps (_pieces)
        parts = [_pieces(obstacles[k], jumps[k], t_map, h, nfill, reach[k], float(speed[k]))
                 for k in jumpy]
        keep = np.setdiff1d(owner, jumpy)
        owner = np.concatenate([keep, *(np.full(len(pc[0]), k) for k, pc in zip(jumpy, parts,
                                                                               strict=True))])
        qx = np.concatenate([qx[keep], *(pc[0][:, :, 0] for pc in parts)])
        qy = np.concatenate([qy[keep], *(pc[0][:, :, 1] for pc in parts)])
        reach = np.concatenate([reach[keep], *(pc[1] for pc in parts)])
        spread = np.concatenate([spread[keep], *(np.full(len(pc[0]), 1.5 * speed[k] * h + 1e-8)
                                                 for k, pc in zip(jumpy, parts, strict=True))])
    away = np.min(np.hypot(qx - gx, qy - gy) - grad - reach, axis=1) > 0.0  # never near the path
    near = np.flatnonzero(~away)
    if len(near):
        hit = _fill(out, px, py, cx, cy, crad, np.ascontiguousarray(qx[near]),
                    np.ascontiguousarray(qy[near]), np.ascontiguousarray(reach[near]),
                    spread[near], _CHUNK, n_free, sx, sy, srad, _GROUP)
        hits = {int(owner[k]) for k, hh in zip(near, hit, strict=True) if hh}
        blockers = [str(obstacles[k].name) for k in sorted(hits)]
    return STMap(out, t_map, h, ds, length, blockers, nrow)
