"""The robot model: dynamic limits and exact integration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.world.robot import Command, RobotSpec, RobotState, clip_command, step

SPEC = RobotSpec(start=(0.0, 0.0, 0.0), goal=(5.0, 0.0))


@settings(max_examples=300, deadline=None)
@given(v0=st.floats(-0.4, 0.4), w0=st.floats(-0.4, 0.4), v=st.floats(-5, 5), w=st.floats(-5, 5),
       dt=st.floats(0.001, 0.05))
def test_clipped_command_respects_every_limit(v0, w0, v, w, dt):
    c = clip_command(SPEC, RobotState(0, 0, 0, v0, w0), Command(v, w), dt)
    assert abs(c.v) <= SPEC.v_max + 1e-12
    assert abs(c.omega) <= SPEC.omega_max + 1e-12
    assert abs(c.v - v0) <= SPEC.a_max * dt + 1e-12
    assert abs(c.omega - w0) <= SPEC.alpha_max * dt + 1e-12


def test_non_finite_command_means_stop():
    c = clip_command(SPEC, RobotState(0, 0, 0, 0.0, 0.0), Command(math.nan, math.inf), 0.05)
    assert c == Command(0.0, 0.0)


def test_step_integrates_an_exact_arc():
    s = RobotState(0.0, 0.0, 0.0, 0.4, 0.4)
    out = s
    for _ in range(100):
        out = step(SPEC, out, Command(0.4, 0.4), 0.05)
    # Five seconds on a circle of radius 1 centred at (0, 1): angle 2 rad.
    assert out.x == pytest.approx(math.sin(2.0), abs=1e-9)
    assert out.y == pytest.approx(1.0 - math.cos(2.0), abs=1e-9)
    assert out.theta == pytest.approx(2.0)


def test_acceleration_from_rest_takes_v_over_a():
    s = RobotState(0.0, 0.0, 0.0)
    vs = []
    for _ in range(40):
        s = step(SPEC, s, Command(10.0, 0.0), 0.05)
        vs.append(s.v)
    np.testing.assert_allclose(vs[:20], 0.02 * np.arange(1, 21))
    assert vs[-1] == pytest.approx(0.4)
