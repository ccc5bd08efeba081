"""Cubic-spline smoothing: interpolation, arc length, certified collision check and repair."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.geometry import Circle, ObstacleSet, rectangle
from anyplan.trajectory import SmoothCurve, clean_path, curve_clearance_ok, shortcut_path, smooth_path


def dense_min_clearance(curve: SmoothCurve, obstacles: ObstacleSet, n: int = 200_000) -> float:
    u = np.linspace(0.0, curve.knots[-1], n)
    return float(obstacles.clearances(curve.position(u)).min())


def test_interpolates_points_and_keeps_endpoints():
    pts = np.array([[0.0, 0.0], [2.0, 1.0], [4.0, -1.0], [7.0, 0.5]])
    c = SmoothCurve(pts)
    np.testing.assert_allclose(c.position(c.point_u), pts, atol=1e-12)
    np.testing.assert_allclose(c.position(np.array([0.0, c.knots[-1]])), pts[[0, -1]], atol=1e-12)


def test_start_heading_is_kept():
    pts = np.array([[0.0, 0.0], [2.0, 1.0], [4.0, -1.0]])
    c = SmoothCurve(pts, start_heading=1.2)
    assert c.heading(np.array([0.0]))[0] == pytest.approx(1.2, abs=1e-12)
    # natural end: zero curvature at the end
    k, _ = c.curvature(np.array([c.knots[-1]]))
    assert abs(k[0]) < 1e-9


def test_parameter_is_close_to_arc_length_and_length_is_exact():
    pts = np.array([[0.0, 0.0], [3.0, 2.0], [5.0, -1.0], [9.0, 0.0]])
    c = SmoothCurve(pts)
    # reference arc length by a very fine polyline
    u = np.linspace(0.0, c.knots[-1], 400_001)
    p = c.position(u)
    ref = float(np.sum(np.hypot(*np.diff(p, axis=0).T)))
    assert c.length == pytest.approx(ref, rel=1e-8)
    # |r'(u)| = 1: parameterised by arc length
    sp = np.hypot(*c.derivatives(u[::100])[0].T)
    assert np.max(np.abs(sp - 1.0)) < 1e-3
    # u_of_s inverts s(u)
    s = np.linspace(0.0, c.length, 101)
    uu = c.u_of_s(s)
    q = c.position(np.linspace(0, uu[37], 100001))
    assert float(np.sum(np.hypot(*np.diff(q, axis=0).T))) == pytest.approx(s[37], abs=1e-6)


def test_two_points_give_a_straight_line():
    c = SmoothCurve(np.array([[1.0, 1.0], [4.0, 5.0]]))
    k, dk = c.curvature(np.linspace(0.0, c.knots[-1], 50))
    assert np.max(np.abs(k)) < 1e-9 and np.max(np.abs(dk)) < 1e-8
    assert c.length == pytest.approx(5.0, rel=1e-12)


def test_clean_path_drops_duplicates_and_collinear_points():
    p = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    np.testing.assert_allclose(clean_path(p), [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    with pytest.raises(ValueError, match="at least two points"):
        SmoothCurve(np.array([[0.0, 0.0]]))


def test_remaining_path_starts_at_the_robot_and_drops_what_is_behind():
    from anyplan.trajectory.path import remaining_path

    path = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0]])
    # beside the first segment: the rest is the robot, then the corner and the end
    np.testing.assert_allclose(remaining_path(path, np.array([1.0, 0.2])),
                               [[1.0, 0.2], [4.0, 0.0], [4.0, 3.0]])
    # nearest to the second segment: the corner is behind
    np.testing.assert_allclose(remaining_path(path, np.array([3.9, 2.0])), [[3.9, 2.0], [4.0, 3.0]])
    # on the corner itself: the corner is not repeated
    np.testing.assert_allclose(remaining_path(path, np.array([4.0, 0.0])), [[4.0, 0.0], [4.0, 3.0]])
    # past the end: the robot and the end
    np.testing.assert_allclose(remaining_path(path, np.array([4.0, 5.0])), [[4.0, 5.0], [4.0, 3.0]])


@pytest.mark.parametrize("seed", range(25))
def test_certification_never_misses_a_contact(seed):
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform(-1.0, 2.0, (5, 2)), axis=0)
    c = SmoothCurve(pts, start_heading=float(rng.uniform(-np.pi, np.pi)) if seed % 2 else None)
    shapes = [Circle(rng.uniform(pts.min(0), pts.max(0)), float(rng.uniform(0.1, 0.6))) for _ in range(3)]
    shapes.append(rectangle(rng.uniform(pts.min(0), pts.max(0)), (0.5, 0.3), float(rng.uniform(0, 3))))
    obs = ObstacleSet(shapes)
    true_min = dense_min_clearance(c, obs)
    for radius in (0.05, 0.2, 0.4, true_min - 1e-4, true_min + 1e-4):
        if radius <= 0.0:
            continue
        free, bad, margin = curve_clearance_ok(c, obs, radius)
        if free:
            assert true_min >= radius - 1e-9
            assert margin <= true_min - radius + 1e-9
        if true_min < radius - 1e-6:
            assert not free and len(bad) > 0


def test_certification_is_nearly_tight():
    # A curve 1 mm clear of an obstacle is certified free with 0.5 mm to spare.
    c = SmoothCurve(np.array([[0.0, 0.0], [3.0, 1.0], [6.0, 0.0]]))
    obs = ObstacleSet([Circle((3.0, 2.0), 0.5)])
    true_min = dense_min_clearance(c, obs)
    assert curve_clearance_ok(c, obs, true_min - 0.0005)[0]


def test_repair_corner_hugging_path():
    # The polyline keeps only 2 cm of slack along an obstacle that runs into a corner; the first
    # spline swings out of the corner and cuts it; repair pulls it back.
    r = 0.3
    path = np.array([[1.0, 4.0], [5.0, 2.0], [9.0, 4.0]])
    d = (path[1] - path[0]) / np.hypot(*(path[1] - path[0]))
    n = np.array([d[1], -d[0]])  # below the first segment, outside the corner
    ang = math.atan2(d[1], d[0])
    box = rectangle((3.0, 3.0) + n * (r + 0.02 + 0.25), (3.0, 0.5), ang)
    obs = ObstacleSet([box], bounds=(0.0, 0.0, 10.0, 6.0))
    assert obs.path_free(path, r)
    assert obs.segment_clearance(path[0], path[1]) == pytest.approx(r + 0.02, abs=1e-9)
    assert obs.path_free(path, r)
    first = SmoothCurve(clean_path(path))
    assert not curve_clearance_ok(first, obs, r)[0]
    res = smooth_path(path, obs, r)
    assert res.curve is not None and res.rounds > 0 and res.points_added > 0
    assert dense_min_clearance(res.curve, obs) >= r - 1e-9
    np.testing.assert_allclose(res.curve.position(res.curve.knots[[0, -1]]), path[[0, -1]], atol=1e-12)


def test_random_worlds_are_repaired_and_certified(world_factory):
    for seed in range(8):
        obs, path, spec = world_factory(seed)
        res = smooth_path(path, obs, spec.radius, start_heading=spec.start[2])
        assert res.curve is not None, seed
        assert dense_min_clearance(res.curve, obs, 100_000) >= spec.radius - 1e-9


def test_shortcut_removes_jitter_and_keeps_clearance():
    rng = np.random.default_rng(3)
    obs = ObstacleSet([Circle((5.0, 3.0), 1.0)], bounds=(0.0, 0.0, 10.0, 6.0))
    # a jittery detour over the circle, as a sampling planner returns it
    t = np.linspace(0.0, 1.0, 120)
    base = np.column_stack([1.0 + 8.0 * t, 3.0 + 1.6 * np.sin(np.pi * t)])
    path = base + rng.normal(0.0, 0.003, base.shape)
    path[0], path[-1] = base[0], base[-1]
    assert obs.path_free(path, 0.3)
    out = shortcut_path(path, obs, 0.3)
    assert len(out) < 10
    np.testing.assert_allclose(out[[0, -1]], path[[0, -1]])
    assert obs.path_free(out, 0.3)
    length = lambda p: float(np.sum(np.hypot(*np.diff(p, axis=0).T)))  # noqa: E731
    assert length(out) < length(path)
    # every kept point is a vertex of the input
    assert all(np.any(np.all(path == q, axis=1)) for q in out)


@pytest.mark.parametrize("mode", ["project", "midpoint"])
def test_both_repair_modes_certify(mode, world_factory):
    obs, path, spec = world_factory(5)
    res = smooth_path(path, obs, spec.radius, repair=mode)
    assert res.curve is not None
    assert dense_min_clearance(res.curve, obs, 100_000) >= spec.radius - 1e-9


def test_a_long_path_is_fitted_over_segments_of_at_most_max_segment():
    # A 600 m corridor path with a sharp first turn: the spline through its five points swung
    # 15 m out of the 12 m corridor, and the repair certified all 600 m round after round.
    # Over segments of at most MAX_SEGMENT_M the first fit stays in the corridor and is
    # certified at once; the points added lie on the polyline (the route is unchanged).
    from anyplan.trajectory.path import split_long_segments
    from anyplan.trajectory.spline.smooth import MAX_SEGMENT_M

    path = np.array([[0.0, 0.0], [3.3, 1.5], [95.0, 0.0], [132.7, 1.0], [596.0, 0.0]])
    dense = split_long_segments(path, MAX_SEGMENT_M)
    seg = np.hypot(*np.diff(dense, axis=0).T)
    assert seg.max() <= MAX_SEGMENT_M + 1e-9 and len(dense) > len(path)
    for p in path:  # every original point kept, in order
        assert np.any(np.all(dense == p, axis=1))
    for a, b in zip(path[:-1], path[1:], strict=True):  # every added point on its segment
        inside = [q for q in dense if 0.0 < np.dot(q - a, b - a) < np.dot(b - a, b - a)]
        for q in inside:
            u, w = b - a, q - a
            assert abs(u[0] * w[1] - u[1] * w[0]) <= 1e-9 * np.dot(u, u)
    obs = ObstacleSet([], bounds=(-1.0, -6.0, 597.0, 6.0))
    res = smooth_path(path, obs, 0.35, start_heading=-0.9)
    assert res.curve is not None and res.rounds == 0
    y = res.curve.position(np.linspace(0.0, res.curve.knots[-1], 20_000))[:, 1]
    assert np.abs(y).max() < 6.0 - 0.35
    # below the bound nothing is split: the arenas' paths are fitted as before
    short = np.array([[0.0, 0.0], [20.0, 3.0], [24.0, -1.0]])
    assert split_long_segments(short, MAX_SEGMENT_M) is short
