"""The gap-world generator: ranges, seeds, and waiting as a way out."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.experiments.gaps import (
    ROOM,
    WALL_X,
    gap_scenario,
    gap_suite,
    gap_world,
    issue_gap_scenario,
    waiting_is_safe,
)


def _gap(sc):
    """(centre y, width) of the gap between the two wall rectangles."""
    lo, hi = sorted(sc.static_obstacles, key=lambda s: s.shape.bounds[1])
    y0, y1 = lo.shape.bounds[3], hi.shape.bounds[1]
    return 0.5 * (y0 + y1), y1 - y0


def test_suite_ranges_and_way_out():
    suite = gap_suite(0, 12)
    assert len({sc.name for sc in suite}) == 12
    for sc in suite:
        assert (sc.width, sc.height) == ROOM
        y, w = _gap(sc)
        assert 1.0 - 1e-9 <= w <= 1.6 + 1e-9
        assert waiting_is_safe(sc, y)
        assert 1 <= len(sc.moving_obstacles) <= 2


def test_same_seed_same_world():
    a, b = gap_scenario(5), gap_scenario(5)
    assert a.content_hash() == b.content_hash()
    assert gap_scenario(6).content_hash() != a.content_hash()
    assert gap_suite(1, 3)[2].content_hash() == gap_suite(1, 5)[2].content_hash()


def test_walkers_meet_the_robot_at_the_gap():
    for kind in ("cross", "head-on"):
        sc = gap_scenario(3, kind=kind)
        y, _ = _gap(sc)
        o = sc.moving_obstacles[0]
        t = np.arange(0.0, 60.0, 0.05)
        d = np.hypot(*(o.motion.positions(t) - np.array([WALL_X, y])).T)
        assert d.min() < 1.5  # it comes to the gap ...
        t_near = t[np.argmin(d)]
        assert 8.0 < t_near < 25.0  # ... around when the robot would (12-17 s at v_max)


def test_issue_case():
    sc = issue_gap_scenario()
    y, w = _gap(sc)
    assert (sc.width, sc.height) == (12.0, 8.0)
    assert w == pytest.approx(1.2) and y == pytest.approx(4.0)
    (walker,) = sc.moving_obstacles
    assert walker.motion.max_speed == pytest.approx(0.3, rel=1e-3)
    assert waiting_is_safe(sc, y)


def test_waiting_is_unsafe_when_a_walker_comes_to_the_start():
    walker = {"name": "W", "type": "waypoints", "radius": 0.3,
              "keyframes": [[0.0, 4.0, 4.0], [10.0, 1.5, 4.0], [1000.0, 1.5, 4.0]]}
    sc = gap_world("bad", "test", np.array([1.5, 4.0]), np.array([10.5, 4.0]), 4.0, 1.2, [walker])
    assert not waiting_is_safe(sc, 4.0)


def test_bad_kind():
    with pytest.raises(ValueError, match="kind"):
        gap_scenario(0, kind="sideways")
