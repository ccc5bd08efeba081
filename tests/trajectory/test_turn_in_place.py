"""Turning in place: exact rotation, limits, and used only when it beats the smooth start."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.trajectory import plan_motion, rotation_profile
from anyplan.world import RobotSpec, RobotState

SPEC = RobotSpec(start=(1.0, 1.0, 0.0), goal=(9.0, 1.0), v_max=0.4, omega_max=0.4, a_max=0.4,
                 alpha_max=1.0)


def rest_to_rest_time(d, wmax, amax):
    d = abs(d)
    if d >= wmax * wmax / amax:
        return d / wmax + wmax / amax
    return 2.0 * math.sqrt(d / amax)


@pytest.mark.parametrize("dtheta", [0.01, 0.1, 0.16, 1.0, -2.5, math.pi])
def test_rest_to_rest_rotation_is_time_optimal_and_exact(dtheta):
    r = rotation_profile(0.3, dtheta, 0.4, 1.0)
    assert r.duration == pytest.approx(rest_to_rest_time(dtheta, 0.4, 1.0), rel=1e-12)
    t = np.linspace(0.0, r.duration, 20001)
    th, w = r.at_time(t)
    assert th[-1] == pytest.approx(0.3 + dtheta, abs=1e-12)
    assert w[-1] == pytest.approx(0.0, abs=1e-12)
    assert np.abs(w).max() <= 0.4 + 1e-12
    assert np.abs(np.diff(w) / np.diff(t)).max() <= 1.0 + 1e-9
    # monotone rotation
    assert np.all(np.sign(dtheta) * np.diff(th) >= -1e-15)


@pytest.mark.parametrize(("dtheta", "w0"), [(1.0, -0.4), (0.02, 0.4), (-1.0, 0.3), (2.0, 0.2)])
def test_rotation_from_a_moving_turn_rate(dtheta, w0):
    r = rotation_profile(0.0, dtheta, 0.4, 1.0, omega0=w0)
    t = np.linspace(0.0, r.duration, 20001)
    th, w = r.at_time(t)
    assert w[0] == pytest.approx(w0)
    assert th[-1] == pytest.approx(dtheta, abs=1e-12) and abs(w[-1]) < 1e-12
    assert np.abs(w).max() <= 0.4 + 1e-12
    assert np.abs(np.diff(w) / np.diff(t)).max() <= 1.0 + 1e-9


def test_turn_chosen_when_facing_away(limits_checker):
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 4.0))
    path = np.array([[1.0, 2.0], [9.0, 2.0]])
    tr = plan_motion(path, SPEC, RobotState(1.0, 2.0, math.pi), obs, 3.0)
    assert tr.kind == "turn+smooth"
    c = tr.info["candidates"]
    assert tr.duration == pytest.approx(min(c.values()))
    assert c["turn+smooth"] < c.get("smooth", math.inf)
    # the turn happens in place, then the robot drives the straight line
    x, y, _, v, _ = tr.sample(np.linspace(3.0, tr.segments[1].t0, 50))
    assert np.ptp(x) == 0.0 and np.ptp(y) == 0.0 and np.all(v == 0.0)
    assert tr.segments[1].t0 - 3.0 == pytest.approx(rest_to_rest_time(math.pi, 0.4, 1.0))
    limits_checker(tr, SPEC)


def test_no_turn_when_nearly_aligned(limits_checker):
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 4.0))
    path = np.array([[1.0, 2.0], [9.0, 2.0]])
    tr = plan_motion(path, SPEC, RobotState(1.0, 2.0, 0.1), obs, 0.0)
    assert tr.kind == "smooth"
    c = tr.info["candidates"]
    # the turn's duration, or a lower bound of it when it was not built for that reason
    assert c["smooth"] <= {**tr.info.get("pruned", {}), **c}["turn+smooth"]
    limits_checker(tr, SPEC)


def test_turn_can_be_disabled():
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 4.0))
    path = np.array([[1.0, 2.0], [9.0, 2.0]])
    tr = plan_motion(path, SPEC, RobotState(1.0, 2.0, math.pi / 2), obs, 0.0, allow_turn=False)
    assert tr.kind == "smooth"


@settings(max_examples=200, deadline=None)
@given(st.floats(-7.0, 7.0), st.floats(-0.4, 0.4), st.floats(0.1, 2.0), st.floats(0.2, 3.0))
@example(0.0, 5e-324, 1.0, 1.0)  # found by Hypothesis 6.90 (.ci/lowest): a subnormal start rate
@example(0.0, 5e-324, 1.0, 1.5)
def test_rotation_property(dtheta, w0, wmax, amax):
    w0 = max(-wmax, min(wmax, w0))
    r = rotation_profile(1.0, dtheta, wmax, amax, omega0=w0)
    t = np.linspace(0.0, r.duration, 2001)
    th, w = r.at_time(t)
    assert th[-1] == pytest.approx(1.0 + dtheta, abs=1e-9)
    assert abs(w[-1]) < 1e-9 and w[0] == pytest.approx(w0)
    assert np.abs(w).max() <= wmax + 1e-9
    dt = np.diff(t)
    # a subnormal start rate (5e-324 rad/s) stops in 5e-324 s: the grid's steps underflow, and
    # subnormal differences are rounded too coarsely for a finite-difference rate
    step = dt > 1e-12
    if step.any():
        assert np.abs(np.diff(w)[step] / dt[step]).max() <= amax * (1 + 1e-6)
    # time-optimal from rest: the closed-form bang-coast-bang duration
    if w0 == 0.0:
        assert r.duration == pytest.approx(rest_to_rest_time(dtheta, wmax, amax), rel=1e-9, abs=1e-12)
