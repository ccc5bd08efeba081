"""Swerving: a twist ramped within the limits and held, then braking, as one certified motion."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.geometry.shapes import rectangle
from anyplan.trajectory.brake import SwerveSegment
from anyplan.trajectory.motion import swerve_trajectory
from anyplan.world import RobotSpec, RobotState

SPEC = RobotSpec(start=(0.0, 0.0, 0.0), goal=(9.0, 0.0), radius=0.3, v_max=1.0, omega_max=1.5,
                 a_max=1.0, alpha_max=3.0)


def _unicycle(state: RobotState, v1: float, w1: float, duration: float, n: int = 200000):
    """Reference integration (fine explicit midpoint steps) of the ramped twist."""
    dt = duration / n
    x, y, th, v, w = state.x, state.y, state.theta, state.v, state.omega
    for _ in range(n):
        v_next = v + float(np.clip(v1 - v, -SPEC.a_max * dt, SPEC.a_max * dt))
        w_next = w + float(np.clip(w1 - w, -SPEC.alpha_max * dt, SPEC.alpha_max * dt))
        vm, wm = 0.5 * (v + v_next), 0.5 * (w + w_next)
        thm = th + 0.5 * dt * wm
        x += vm * math.cos(thm) * dt
        y += vm * math.sin(thm) * dt
        th += wm * dt
        v, w = v_next, w_next
    return x, y, th, v, w


@pytest.mark.parametrize(("v0", "w0", "v1", "w1"), [(0.0, 0.0, 1.0, 1.5), (0.8, -1.2, 1.0, 1.5),
                                         (1.0, 0.0, 0.5, -0.75), (0.3, 1.5, 0.3, 1.5)])
def test_swerve_segment_matches_the_unicycle(v0, w0, v1, w1):
    s0 = RobotState(1.0, -2.0, 0.4, v0, w0)
    seg = SwerveSegment(s0.x, s0.y, s0.theta, v0, w0, v1, w1, SPEC.a_max, SPEC.alpha_max, 3.0, 1.5)
    x, y, th, v, w = (float(a[0]) for a in seg.sample(np.array([4.5])))
    rx, ry, rth, rv, rw = _unicycle(s0, v1, w1, 1.5, n=20000)
    assert (v, w) == pytest.approx((rv, rw), abs=1e-9)
    assert th == pytest.approx(rth, abs=1e-6)
    assert (x, y) == pytest.approx((rx, ry), abs=1e-5)
    # it starts exactly where the robot is, with its twist
    x0, y0, th0, v0s, w0s = (float(a[0]) for a in seg.sample(np.array([3.0])))
    assert (x0, y0, th0, v0s, w0s) == (s0.x, s0.y, s0.theta, v0, w0)


@settings(max_examples=40, deadline=None)
@given(v0=st.floats(-1.0, 1.0), w0=st.floats(-1.5, 1.5), v1=st.floats(-2.0, 2.0),
       w1=st.floats(-3.0, 3.0), dur=st.floats(0.0, 3.0))
def test_swerve_trajectory_respects_the_limits_and_ends_at_rest(v0, w0, v1, w1, dur):
    s0 = RobotState(0.0, 0.0, 0.0, v0, w0)
    tr = swerve_trajectory(s0, SPEC, ObstacleSet(), SPEC.radius, 0.0, v1, w1, dur)
    t = np.linspace(0.0, tr.t_end + 0.5, 4001)
    x, y, _, v, w = tr.sample(t)
    assert np.abs(v).max() <= max(SPEC.v_max, abs(v0)) + 1e-9
    assert np.abs(w).max() <= max(SPEC.omega_max, abs(w0)) + 1e-9
    dt = np.diff(t)
    assert np.abs(np.diff(v) / dt).max() <= SPEC.a_max * (1 + 1e-6) + 1e-9
    assert np.abs(np.diff(w) / dt).max() <= SPEC.alpha_max * (1 + 1e-6) + 1e-9
    assert v[-1] == 0.0 and w[-1] == 0.0
    # the position moves at the reference speed (no jump between the segments)
    step = np.hypot(np.diff(x), np.diff(y))
    assert np.all(step <= tr.max_speed * dt + 1e-9)


def test_swerve_into_a_wall_is_not_certified_and_beside_it_is():
    wall = ObstacleSet([rectangle((0.0, 1.6), (10.0, 0.2))])  # face at y = 1.5
    s0 = RobotState(0.0, 0.0, 0.0, 1.0, 0.0)
    left = swerve_trajectory(s0, SPEC, wall, SPEC.radius, 0.0, 1.0, 1.5, 1.5)
    right = swerve_trajectory(s0, SPEC, wall, SPEC.radius, 0.0, 1.0, -1.5, 1.5)
    y_left = left.sample(np.linspace(0.0, left.t_end, 2001))[1]
    assert y_left.max() + SPEC.radius > 1.5  # the left arc does reach the wall
    assert not left.certified_free
    assert right.certified_free
    assert left.kind == "swerve" and right.t_end > 1.5
