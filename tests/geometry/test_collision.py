"""Exact clearance kernels against brute-force references (hypothesis)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import Circle, ObstacleSet, Polygon, rectangle, regular_polygon

coord = st.floats(-5.0, 5.0, allow_nan=False)
pos = st.floats(0.2, 3.0, allow_nan=False)


def brute_points_convex(points: np.ndarray, verts: np.ndarray, n_edge: int = 4001) -> np.ndarray:
    """Distances from points (N, 2) to a convex CCW polygon region: half-plane inside test and
    dense boundary sampling (overestimates by at most half the sample spacing)."""
    pts = np.atleast_2d(points)
    e = np.roll(verts, -1, axis=0) - verts
    rel = pts[:, None, :] - verts[None, :, :]
    inside = np.all(e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0] >= 0.0, axis=1)
    s = np.linspace(0.0, 1.0, n_edge)
    boundary = (verts[:, None, :] + s[None, :, None] * e[:, None, :]).reshape(-1, 2)
    d = np.min(np.hypot(pts[:, None, 0] - boundary[None, :, 0], pts[:, None, 1] - boundary[None, :, 1]),
               axis=1)
    return np.where(inside, 0.0, d)


def brute_point_polygon(p: np.ndarray, verts: np.ndarray) -> float:
    return float(brute_points_convex(p, verts)[0])


@settings(max_examples=150, deadline=None)
@given(cx=coord, cy=coord, w=pos, h=pos, ang=st.floats(-3.2, 3.2), px=coord, py=coord)
def test_point_clearance_rectangle_matches_brute_force(cx, cy, w, h, ang, px, py):
    rect = rectangle((cx, cy), (w, h), ang)
    obs = ObstacleSet([rect])
    exact = obs.clearance((px, py))
    ref = brute_point_polygon(np.array([px, py]), rect.vertices)
    # Boundary sampling overestimates by at most half the sample spacing.
    tol = max(w, h) / 4000 + 1e-9
    assert exact <= ref + 1e-9
    assert exact >= ref - tol


@settings(max_examples=150, deadline=None)
@given(cx=coord, cy=coord, r=pos, ax=coord, ay=coord, bx=coord, by=coord)
def test_segment_clearance_circle_matches_sampling(cx, cy, r, ax, ay, bx, by):
    obs = ObstacleSet([Circle((cx, cy), r)])
    exact = obs.segment_clearance((ax, ay), (bx, by))
    s = np.linspace(0.0, 1.0, 20001)[:, None]
    pts = np.array([ax, ay]) + s * (np.array([bx - ax, by - ay]))
    d = np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) - r
    ref = max(float(d.min()), 0.0)
    step = math.hypot(bx - ax, by - ay) / 20000
    assert exact <= ref + 1e-9
    assert exact >= ref - step - 1e-9


@settings(max_examples=120, deadline=None)
@given(cx=coord, cy=coord, w=pos, h=pos, ang=st.floats(-3.2, 3.2),
       ax=coord, ay=coord, bx=coord, by=coord)
def test_segment_clearance_polygon_matches_sampling(cx, cy, w, h, ang, ax, ay, bx, by):
    rect = rectangle((cx, cy), (w, h), ang)
    obs = ObstacleSet([rect])
    exact = obs.segment_clearance((ax, ay), (bx, by))
    s = np.linspace(0.0, 1.0, 801)[:, None]
    a, b = np.array([ax, ay]), np.array([bx, by])
    ref = float(brute_points_convex(a + s * (b - a), rect.vertices, 1001).min())
    step = math.hypot(bx - ax, by - ay) / 800
    assert exact <= ref + 1e-9
    assert exact >= ref - step - max(w, h) / 1000 - 1e-9


def test_nonconvex_polygon_inside_and_notch():
    # A U shape: the notch is outside the polygon.
    u = Polygon(np.array([[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]], float))
    obs = ObstacleSet([u])
    assert obs.clearance((1.5, 2.0)) == pytest.approx(0.5)  # in the notch, 0.5 from both arms
    assert obs.clearance((0.5, 0.5)) == 0.0  # inside
    assert not obs.segment_free((1.5, 2.5), (1.5, 0.5), 0.1)  # runs into the bottom of the U
    assert obs.segment_free((1.5, 2.9), (1.5, 1.5), 0.45)
    assert not obs.segment_free((1.5, 2.9), (1.5, 1.4), 0.45)


def test_walls_bound_the_robot():
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 5.0))
    assert obs.clearance((1.0, 2.0)) == pytest.approx(1.0)
    assert obs.clearance((-1.0, 2.0)) == 0.0
    assert obs.segment_free((0.5, 0.5), (9.5, 4.5), 0.5)
    assert not obs.segment_free((0.5, 0.5), (9.6, 4.5), 0.5)


def test_batched_queries_equal_single_queries(rng):
    shapes = [rectangle(rng.uniform(1, 9, 2), rng.uniform(0.3, 2, 2), rng.uniform(-3, 3))
              for _ in range(6)] + [Circle(rng.uniform(1, 9, 2), rng.uniform(0.2, 1)) for _ in range(4)]
    obs = ObstacleSet(shapes, bounds=(0, 0, 10, 10))
    a = rng.uniform(0, 10, (200, 2))
    b = rng.uniform(0, 10, (200, 2))
    c = obs.segments_clearance(a, b)
    single = np.array([obs.segment_clearance(p, q) for p, q in zip(a, b, strict=True)])
    np.testing.assert_allclose(c, single, atol=1e-12)
    free = obs.segments_free(a, b, 0.3)
    np.testing.assert_array_equal(free, c >= 0.3 - 1e-9)
    np.testing.assert_allclose(obs.clearances(a), [obs.clearance(p) for p in a], atol=1e-12)


def test_inflation_is_exact_at_rounded_corners():
    # The inflated square has rounded corners: a point diagonal from the corner at distance
    # just above r is free, although it lies inside the square's bounding box inflated by r.
    obs = ObstacleSet([rectangle((0.0, 0.0), (2.0, 2.0))])
    r = 0.5
    d = (r + 1e-6) / math.sqrt(2)
    assert obs.point_free((1.0 + d, 1.0 + d), r)
    assert not obs.point_free((1.0 + 0.3, 1.0 + 0.3), r)


def test_regular_polygon_inscribed_and_circumscribed():
    c = Circle((0.0, 0.0), 1.0)
    inner = regular_polygon(c.center, 1.0, 12)
    outer = regular_polygon(c.center, 1.0, 12, circumscribed=True)
    assert inner.area < math.pi < outer.area
    assert np.allclose(np.hypot(*inner.vertices.T), 1.0)


@pytest.mark.parametrize("pts", [[[0, 0], [1, 1]], [[0, 0], [1, 0], [2, 0]],
                                 [[0, 0], [2, 2], [2, 0], [0, 2]]])
def test_bad_polygons_are_rejected(pts):
    with pytest.raises(ValueError, match="polygon"):
        Polygon(np.array(pts, float))
