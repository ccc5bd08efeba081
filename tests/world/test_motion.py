"""Obstacle motions against the formulas of the scenario contract."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.world.motion import UnicycleMotion, WaypointMotion


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
