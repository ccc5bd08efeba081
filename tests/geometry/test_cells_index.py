"""Map cells merged into rectangles (exact partition), the grid index (never misses a cell) and
clearance on maps against brute force over every cell (hypothesis)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.geometry import collision as coll
from anyplan.geometry.cells import cell_boxes, convex_corners, merge_cells, paint
from anyplan.geometry.index import build_grid, cell_items
from anyplan.geometry.shapes import Circle, square


def grids(max_side: int = 24):
    return st.integers(1, max_side).flatmap(lambda ny: st.integers(1, max_side).flatmap(
        lambda nx: st.lists(st.booleans(), min_size=nx * ny, max_size=nx * ny).map(
            lambda v: np.array(v, dtype=bool).reshape(ny, nx))))


@given(grids())
@settings(max_examples=200, deadline=None)
def test_merge_is_an_exact_partition(occ):
    rects = merge_cells(occ)
    cover = paint(rects, occ.shape)
    assert np.array_equal(cover, occ.astype(np.int64))  # every occupied cell once, nothing else
    area = int(((rects[:, 2] - rects[:, 0]) * (rects[:, 3] - rects[:, 1])).sum())
    assert area == int(occ.sum())


def test_merge_makes_walls_one_rectangle():
    occ = np.zeros((40, 60), dtype=bool)
    occ[10:13, 5:55] = True    # a horizontal wall, 3 cells thick
    occ[0:40, 30:32] = True    # a vertical wall crossing it
    rects = merge_cells(occ)
    assert np.array_equal(paint(rects, occ.shape), occ.astype(np.int64))
    assert len(rects) <= 5


def test_cell_boxes_share_exact_coordinates():
    occ = np.ones((3, 7), dtype=bool)
    occ[1, 3] = False
    b = cell_boxes(merge_cells(occ), (0.1, -0.3), 0.05)
    xs = set(b[:, [0, 2]].ravel().tolist())
    assert xs <= {0.1 + i * 0.05 for i in range(8)}


def test_convex_corners_of_a_block_and_an_l():
    occ = np.zeros((5, 5), dtype=bool)
    occ[1:3, 1:4] = True
    assert sorted(map(tuple, convex_corners(occ).tolist())) == [(1, 1), (1, 3), (4, 1), (4, 3)]
    occ[3, 1] = True   # an L: five convex corners, one concave (not listed)
    c = sorted(map(tuple, convex_corners(occ).tolist()))
    assert c == [(1, 1), (1, 4), (2, 4), (4, 1), (4, 3)]


@given(st.lists(st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(0.01, 8),
                          st.floats(0.01, 8)), min_size=1, max_size=80),
       st.floats(0.05, 3.0))
@settings(max_examples=100, deadline=None)
def test_index_lists_every_box_in_every_cell_it_meets(spec, cell):
    b = np.array([[x, y, x + w, y + h] for x, y, w, h in spec])
    meta, csr = build_grid(b, cell=cell)
    x0, y0, h, nx, ny = meta[0], meta[1], meta[2], int(meta[3]), int(meta[4])
    assert nx * ny <= 4 * len(b) + 64
    for row in range(ny):
        for col in range(nx):
            cx0, cy0 = x0 + col * h, y0 + row * h
            e = 1e-9
            meets = np.nonzero((b[:, 0] <= cx0 + h + e) & (b[:, 2] >= cx0 - e)
                               & (b[:, 1] <= cy0 + h + e) & (b[:, 3] >= cy0 - e))[0]
            listed = set(cell_items(meta, csr, row, col).tolist())
            # every box meeting the cell's interior is listed (boundary contacts may be too)
            strict = np.nonzero((b[:, 0] < cx0 + h - e) & (b[:, 2] > cx0 + e)
                                & (b[:, 1] < cy0 + h - e) & (b[:, 3] > cy0 + e))[0]
            assert set(strict.tolist()) <= listed <= set(meets.tolist())


# ---- brute force: exact distance from a point / a segment to every cell box ------------------
def _pt_boxes(p, b):
    dx = np.maximum.reduce([b[:, 0] - p[0], np.zeros(len(b)), p[0] - b[:, 2]])
    dy = np.maximum.reduce([b[:, 1] - p[1], np.zeros(len(b)), p[1] - b[:, 3]])
    return np.hypot(dx, dy)


def _pt_seg(p, a, c):
    d = c - a
    l2 = float(d @ d)
    t = 0.0 if l2 == 0 else np.clip(((p - a) @ d) / l2, 0.0, 1.0)
    return float(np.hypot(*(a + t * d - p)))


def _seg_box(a, c, box):
    """Exact distance from segment ac to a closed box (0 if they meet), by clipping then edges."""
    t0, t1 = 0.0, 1.0
    d = c - a
    meets = True
    for k in range(2):
        lo, hi = box[k], box[k + 2]
        if d[k] == 0.0:
            if not lo <= a[k] <= hi:
                meets = False
        else:
            u, v = (lo - a[k]) / d[k], (hi - a[k]) / d[k]
            t0, t1 = max(t0, min(u, v)), min(t1, max(u, v))
    if meets and t0 <= t1:
        return 0.0
    corners = np.array([[box[0], box[1]], [box[2], box[1]], [box[2], box[3]], [box[0], box[3]]])
    best = min(_pt_seg(q, a, c) for q in corners)
    for q in (a, c):  # endpoints against the box
        best = min(best, float(_pt_boxes(q, box[None, :])[0]))
    return best


def _random_map(rng, ny, nx, p):
    occ = rng.random((ny, nx)) < p
    return occ, cell_boxes(np.array([[i, j, i + 1, j + 1] for j, i in np.argwhere(occ)],
                                    dtype=np.int64).reshape(-1, 4), (-1.3, 0.7), 0.25)


@given(st.integers(0, 2**31 - 1), st.floats(0.02, 0.5), st.booleans())
@settings(max_examples=40, deadline=None)
def test_clearance_on_maps_matches_brute_force(seed, p, walls):
    rng = np.random.default_rng(seed)
    occ, cells = _random_map(rng, 30, 40, p)
    if len(cells) == 0:
        return
    merged = cell_boxes(merge_cells(occ), (-1.3, 0.7), 0.25)
    bounds = (-2.0, 0.0, 10.0, 9.0) if walls else None
    obs = ObstacleSet([], bounds=bounds, boxes=merged, index=True)
    assert obs.indexed
    pts = rng.uniform([-2.5, -0.5], [10.5, 9.5], size=(60, 2))

    def wall(q):
        if bounds is None:
            return np.inf
        return max(0.0, min(q[0] - bounds[0], bounds[2] - q[0], q[1] - bounds[1], bounds[3] - q[1]))

    got = obs.clearances(pts)
    for q, g in zip(pts, got, strict=True):
        want = min(float(_pt_boxes(q, cells).min()), wall(q))
        assert g == pytest.approx(want, abs=1e-9)
    for q, r in zip(pts[:30], pts[30:], strict=True):
        want = min(min(_seg_box(q, r, bx) for bx in cells), wall(q), wall(r))
        assert obs.segment_clearance(q, r) == pytest.approx(want, abs=1e-9)
        for lim in (0.05, 0.3, 1.0):
            assert obs.segment_free(q, r, lim) == (want >= lim - coll.COLLISION_EPS)


@given(st.integers(0, 2**31 - 1))
@settings(max_examples=25, deadline=None)
def test_indexed_equals_linear_scan_with_shapes(seed):
    """The grid answers exactly what the plain scan answers, with circles, polygons and shapes
    added later (with_shapes keeps the index and scans the additions linearly)."""
    rng = np.random.default_rng(seed)
    occ = rng.random((25, 25)) < 0.3
    boxes = cell_boxes(merge_cells(occ), (0.0, 0.0), 0.2)
    shapes = [Circle((2.0, 2.5), 0.3), square((4.0, 1.0), 0.4)]
    extra = [square(tuple(rng.uniform(0, 5, 2)), 0.3) for _ in range(3)]
    fast = ObstacleSet(shapes, bounds=(0, 0, 5, 5), boxes=boxes).with_shapes(extra)
    assert fast.indexed
    slow = ObstacleSet(shapes + extra, bounds=(0, 0, 5, 5), boxes=boxes, index=False)
    assert not slow.indexed  # the plain scan over every box
    a = rng.uniform(-0.2, 5.2, size=(80, 2))
    b = rng.uniform(-0.2, 5.2, size=(80, 2))
    assert np.allclose(fast.clearances(a), slow.clearances(a), rtol=0, atol=1e-12)
    assert np.allclose(fast.segments_clearance(a, b), slow.segments_clearance(a, b), rtol=0,
                       atol=1e-12)
    for lim in (0.1, 0.4):
        assert np.array_equal(fast.segments_free(a, b, lim), slow.segments_free(a, b, lim))
        assert [fast.segment_free(p, q, lim) for p, q in zip(a, b, strict=True)] == \
               [slow.segment_free(p, q, lim) for p, q in zip(a, b, strict=True)]


def test_few_obstacles_build_no_index():
    obs = ObstacleSet([Circle((1.0, 1.0), 0.5), square((3.0, 3.0), 1.0)], bounds=(0, 0, 5, 5))
    assert not obs.indexed and len(obs) == 2


def test_bad_boxes_are_refused():
    with pytest.raises(ValueError, match="xmax > xmin"):
        ObstacleSet([], boxes=np.array([[0.0, 0.0, 0.0, 1.0]]))


@given(st.integers(0, 2**31 - 1), st.floats(0.02, 0.5), st.booleans())
@settings(max_examples=30, deadline=None)
def test_capped_clearance_is_the_exact_one_below_the_cap(seed, p, walls):
    """segment_clearance_below(cap) == min(exact clearance, cap), bit for bit below the cap
    (it scans only the cells within cap: the filter never skips a box nearer than the cap)."""
    rng = np.random.default_rng(seed)
    occ, cells = _random_map(rng, 30, 40, p)
    if len(cells) == 0:
        return
    merged = cell_boxes(merge_cells(occ), (-1.3, 0.7), 0.25)
    obs = ObstacleSet([Circle((4.0, 4.0), 0.4)], bounds=(-2.0, 0.0, 10.0, 9.0) if walls else None,
                      boxes=merged, index=True)
    a = rng.uniform([-2.5, -0.5], [10.5, 9.5], size=(40, 2))
    b = a + rng.normal(0.0, 0.3, size=a.shape)
    for q, r in zip(a, b, strict=True):
        exact = coll.segment_clearance_kernel(q[0], q[1], r[0], r[1], obs.arrays, -1.0)
        dq = _pt_boxes(q, cells)  # a box nearest to the segment is this near to q
        near = cells[dq <= dq.min() + float(np.hypot(*(r - q))) + 1e-9]
        brute = min(min(_seg_box(q, r, bx) for bx in near),
                    max(_pt_seg(np.array([4.0, 4.0]), q, r) - 0.4, 0.0))
        if walls:
            brute = min(brute, *(max(0.0, min(x[0] + 2.0, 10.0 - x[0], x[1], 9.0 - x[1]))
                                 for x in (q, r)))
        assert exact == pytest.approx(brute, abs=1e-9)
        # caps of a length scale (a cap below ~1e-150 m squares to 0: meaningless)
        for cap in {0.01, 0.1, 0.35, exact, np.nextafter(exact, np.inf), 2.0} - {0.0, 5e-324}:
            got = coll.segment_clearance_below_kernel(q[0], q[1], r[0], r[1], obs.arrays, cap)
            assert got == (exact if exact < cap else cap)


@given(st.integers(0, 2**31 - 1), st.floats(0.2, 0.7))
@settings(max_examples=30, deadline=None)
def test_buried_capsules_have_zero_clearance(seed, p):
    """capsule_buried is conservative: when it says True, every segment within the pad of the
    segment (sampled, to the capsule's edge) has clearance exactly 0 (brute force and kernel)."""
    rng = np.random.default_rng(seed)
    occ, cells = _random_map(rng, 30, 40, p)
    if len(cells) == 0:
        return
    merged = cell_boxes(merge_cells(occ), (-1.3, 0.7), 0.25)
    obs = ObstacleSet([Circle((4.0, 4.0), 0.6)], bounds=(-2.0, 0.0, 10.0, 9.0), boxes=merged,
                      index=True)
    n_buried = 0
    for _ in range(200):
        q = rng.uniform([-2.5, -0.5], [10.5, 9.5])
        r = q + rng.normal(0.0, 0.1, size=2)
        pad = float(rng.uniform(0.0, 0.05))
        if not coll.capsule_buried_kernel(q[0], q[1], r[0], r[1], pad, obs.arrays):
            continue
        n_buried += 1
        for _ in range(10):
            u = q + rng.uniform(0, 1) * (r - q) + pad * rng.uniform(-1, 1, 2) / np.sqrt(2)
            v = q + rng.uniform(0, 1) * (r - q) + pad * rng.uniform(-1, 1, 2) / np.sqrt(2)
            assert coll.segment_clearance_kernel(u[0], u[1], v[0], v[1], obs.arrays, -1.0) == 0.0
            near = cells[(cells[:, 0] <= max(u[0], v[0]) + 0.1) & (cells[:, 2] >= min(u[0], v[0]) - 0.1)
                         & (cells[:, 1] <= max(u[1], v[1]) + 0.1) & (cells[:, 3] >= min(u[1], v[1]) - 0.1)]
            brute = min(min((_seg_box(u, v, bx) for bx in near), default=np.inf),
                        max(_pt_seg(np.array([4.0, 4.0]), u, v) - 0.6, 0.0),
                        *(max(0.0, min(x[0] + 2.0, 10.0 - x[0], x[1], 9.0 - x[1])) for x in (u, v)))
            assert brute == 0.0
    assert n_buried > 0 or p < 0.3


def test_fingerprint_tells_sets_apart():
    boxes = np.array([[0.0, 0.0, 1.0, 1.0]] * 1 + [[2.0 + i, 0.0, 2.5 + i, 0.5] for i in range(60)])
    a = ObstacleSet([], bounds=(-1, -1, 70, 5), boxes=boxes)
    assert a.indexed
    same = ObstacleSet([], bounds=(-1, -1, 70, 5), boxes=boxes.copy())
    assert a.fingerprint == same.fingerprint
    sq = square((0.5, 3.0), 0.4)
    assert a.with_shapes([sq]).fingerprint == a.with_shapes([sq]).fingerprint
    others = [ObstacleSet([], bounds=(-1, -1, 70, 6), boxes=boxes), a.with_shapes([sq]),
              a.with_shapes([square((0.5, 3.0), 0.41)]), a.with_shapes([Circle((1.0, 3.0), 0.2)]),
              ObstacleSet([], bounds=(-1, -1, 70, 5), boxes=boxes[1:])]
    prints = [o.fingerprint for o in [a, *others]]
    assert len(set(prints)) == len(prints)
