"""Obstacle motions against the formulas of the scenario contract."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.world.motion import TrackMotion, UnicycleMotion, WaypointMotion, positions_of


@settings(max_examples=100, deadline=None)
@given(x0=st.floats(-10, 10), y0=st.floats(-10, 10), th=st.floats(-3.2, 3.2),
       v=st.floats(-1, 1), om=st.just(0.0) | st.floats(1e-3, 1) | st.floats(-1, -1e-3),
       t=st.floats(0, 100))
def test_unicycle_motion_matches_contract_formulas(x0, y0, th, v, om, t):
    m = UnicycleMotion(x0, y0, th, v, om)
    x, y = m.position(t)
    if om == 0.0:
        ex, ey = x0 + v * t * math.cos(th), y0 + v * t * math.sin(th)
    else:
        ex = x0 + v / om * (math.sin(th + om * t) - math.sin(th))
        ey = y0 - v / om * (math.cos(th + om * t) - math.cos(th))
    assert x == pytest.approx(ex, abs=1e-9)
    assert y == pytest.approx(ey, abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(x0=st.floats(-1e3, 1e3), y0=st.floats(-1e3, 1e3), th=st.floats(-7, 7),
       v=st.floats(-3, 3), om=st.just(0.0) | st.floats(-2, 2), t0=st.floats(-5, 5),
       t=st.floats(-10, 1e3))
def test_unicycle_position_is_positions_bit_for_bit(x0, y0, th, v, om, t0, t):
    # position() has its own scalar path for straight motions; the simulator and the
    # filters mix it with positions(), so the two must agree exactly, not approximately
    m = UnicycleMotion(x0, y0, th, v, om, start_time=t0)
    assert m.position(t).tolist() == m.positions(np.array([t]))[0].tolist()


def test_tiny_turn_rate_is_continuous_with_the_straight_line():
    t = np.linspace(0.0, 50.0, 11)
    straight = UnicycleMotion(1.0, 2.0, 0.3, 0.5, 0.0).positions(t)
    for om in (5e-324, 1e-12, -1e-9):
        np.testing.assert_allclose(UnicycleMotion(1.0, 2.0, 0.3, 0.5, om).positions(t), straight,
                                   atol=1e-6)


def test_circular_motion_stays_on_its_circle_and_keeps_speed():
    m = UnicycleMotion(9.0, 8.0, 0.0, 0.12, -0.14)
    t = np.linspace(0.0, 60.0, 6001)
    p = m.positions(t)
    c = m.circle_center
    np.testing.assert_allclose(np.hypot(*(p - c).T), 0.12 / 0.14, atol=1e-12)
    speed = np.hypot(*np.diff(p, axis=0).T) / np.diff(t)
    np.testing.assert_allclose(speed, 0.12, rtol=1e-5)
    # Clockwise for omega < 0: the heading after 1 s decreased by 0.14 rad.
    assert m.state(1.0)[2] == pytest.approx(-0.14)


def test_start_time_holds_the_obstacle_still():
    m = UnicycleMotion(1.0, 2.0, 0.5, 0.3, 0.0, start_time=5.0)
    np.testing.assert_allclose(m.positions(np.array([0.0, 5.0])), [[1.0, 2.0], [1.0, 2.0]])
    assert m.state(2.0)[3] == 0.0
    assert m.position(7.0)[0] == pytest.approx(1.0 + 0.6 * math.cos(0.5))


def test_waypoint_motion_loops_and_hits_keyframes_exactly():
    k = np.array([[0.0, 0.0, 0.0], [2.0, 2.0, 0.0], [5.0, 2.0, 3.0], [8.0, 0.0, 0.0]])
    m = WaypointMotion(k)
    for t, x, y in k:
        np.testing.assert_allclose(m.position(t), [x, y] if t < 8.0 else [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(m.position(8.0 + 3.5), m.position(3.5))
    assert m.max_speed == pytest.approx(math.hypot(2.0, 3.0) / 3.0)
    with pytest.raises(ValueError, match="keyframe times must start at 0 and increase strictly"):
        WaypointMotion(np.array([[0.0, 0, 0], [0.0, 1, 1]]))


@st.composite
def _tracks(draw):
    """Keyframes (t, x, y): 2-12 rows, times strictly increasing, from a first time."""
    n = draw(st.integers(2, 12))
    gaps = draw(st.lists(st.floats(1e-3, 10), min_size=n - 1, max_size=n - 1))
    xy = draw(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=n, max_size=n))
    t0 = draw(st.floats(-100, 100))
    t = np.concatenate([[0.0], np.cumsum(gaps)])
    return t0, np.column_stack([t, np.array(xy)])


@settings(max_examples=200, deadline=None)
@given(track=_tracks(), u=st.lists(st.floats(-0.5, 3.0), min_size=1, max_size=8),
       at_knot=st.integers(0, 11))
def test_one_time_gives_the_bits_of_the_array_path(track, u, at_knot):
    # position(t) and state(t) take a scalar path (the simulator's, every step); they must give
    # exactly what positions() gives, at knots (where segments meet), between them, before the
    # track, after it and, for a looping track, in later periods.
    t0, k = track
    loop = WaypointMotion(k)
    rec = TrackMotion(np.column_stack([k[:, 0] + t0, k[:, 1:]]))
    for m, first in ((loop, 0.0), (rec, t0)):
        span = float(k[-1, 0])
        knot = first + float(k[min(at_knot, len(k) - 1), 0])
        times = [first + f * span for f in u] + [knot, np.nextafter(knot, -np.inf),
                                                 np.nextafter(knot, np.inf)]
        for t in times:
            want = m.positions(np.array([t]))[0]
            got = m.position(t)
            assert got[0] == want[0] and got[1] == want[1], (t, got, want)
            x, y, th, v, _ = m.state(t)
            assert (x, y) == (want[0], want[1])
            assert math.isfinite(th) and v >= 0.0


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 12), nt=st.integers(0, 9))
def test_positions_of_many_motions_is_each_ones_bit_for_bit(seed, n, nt):
    """``positions_of`` (straight lines at once) gives every motion's own ``positions``, the
    same bits, among turning, keyframed and straight motions, before and after their starts."""
    rng = np.random.default_rng(seed)
    ms = []
    for k in range(n):
        x0, y0, th = rng.uniform(-10, 10, 3)
        kind = k % 4
        if kind == 3:
            ms.append(WaypointMotion(np.array([[0.0, x0, y0], [2.0, y0, x0], [3.5, 1.0, -1.0]])))
        else:
            om = 0.0 if kind < 2 else float(rng.uniform(-1, 1))
            th = -0.0 if k == 1 else th
            ms.append(UnicycleMotion(x0, y0, th, float(rng.uniform(-2, 2)), om,
                                     float(rng.uniform(-1, 3))))
    t = np.sort(rng.uniform(-2, 8, nt))
    got = positions_of(ms, t)
    assert got.shape == (n, nt, 2)
    for k, m in enumerate(ms):
        assert np.array_equal(got[k].view(np.int64), m.positions(t).view(np.int64))
