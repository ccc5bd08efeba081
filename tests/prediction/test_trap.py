"""The trap test: a predicted disc that holds every place the robot can reach (sound: every
motion within the robot's limits is then in contact), and st-bitstar's decisions without the
search it skips."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.agents import make_agent
from anyplan.agents.settings import deterministic_settings
from anyplan.agents.spacetime import SpaceTimeBITStarAgent
from anyplan.agents.st_predictions import PlanningPredictions
from anyplan.prediction import PredictedObstacle
from anyplan.prediction.base import RadiusGrowth
from anyplan.prediction.trap import first_trap, reach_m
from anyplan.simulation import simulate
from anyplan.simulation.perception import override_sensing
from anyplan.world import UnicycleMotion
from anyplan.world.scenario import scenario_from_dict
from tests.conftest import head_on_corridor_dict

V_MAX, A_MAX, RADIUS, MARGIN = 1.0, 1.0, 0.3, 0.05


def _drive(rng: np.random.Generator, v0: float, theta0: float, t: float, n: int = 400) -> np.ndarray:
    """The end point of a random unicycle motion from the origin over ``t`` [s]: the speed
    within +-V_MAX changing by at most A_MAX (bang-bang pieces, reversals included), any turn
    rate (up to 4 rad/s)."""
    h = t / n
    x = y = 0.0
    v, th = v0, theta0
    acc = rng.uniform(-A_MAX, A_MAX)
    w = rng.uniform(-4.0, 4.0)
    for k in range(n):
        if k % 40 == 0:
            acc = rng.choice([-A_MAX, A_MAX, rng.uniform(-A_MAX, A_MAX)])
            w = rng.uniform(-4.0, 4.0)
        v2 = float(np.clip(v + acc * h, -V_MAX, V_MAX))
        vm = 0.5 * (v + v2)
        x += vm * math.cos(th + 0.5 * w * h) * h
        y += vm * math.sin(th + 0.5 * w * h) * h
        th += w * h
        v = v2
    return np.array([x, y])


def test_reach_is_the_farthest_run_from_the_speed_within_the_limits():
    tau = np.linspace(0.0, 3.0, 31)
    # from rest: accelerate to v_max at a_max (1 s, 0.5 m), then cruise
    d = reach_m(0.0, 1.0, 1.0, tau)
    assert np.allclose(d, np.where(tau <= 1.0, 0.5 * tau**2, 0.5 + (tau - 1.0)))
    # already at top speed (either direction): cruise at once
    assert np.allclose(reach_m(-1.0, 1.0, 1.0, tau), tau)
    # the bound grows with the speed and with time
    assert np.all(np.diff(d) >= 0.0)
    assert np.all(reach_m(0.5, 1.0, 1.0, tau) >= d)


@settings(max_examples=80, deadline=None)
@given(st.floats(0.4, 1.2), st.floats(-0.3, 0.3), st.floats(0.0, 1.5), st.floats(-1.0, 1.0),
       st.floats(0.0, 0.6), st.floats(-3.1, 3.1), st.floats(0.2, 0.6), st.booleans(),
       st.integers(0, 2**31 - 1))
def test_a_trap_holds_every_motion_within_the_limits(dx, dy, speed, aim, v0, theta0, radius,
                                                     grows, seed):
    # An obstacle near the robot (at the origin) on a straight line roughly towards it (about
    # half of these are traps), with or without a growing disc: when a trap is reported at t,
    # every random motion within the limits (any turns, reversals, stops) ends inside the
    # obstacle's contact distance at t.
    growth = RadiusGrowth(0.0, np.array([0.0, 1.0]), np.array([0.0, 0.5])) if grows else None
    heading = math.atan2(-dy, -dx) + aim
    o = PredictedObstacle("O", radius, UnicycleMotion(dx, dy, heading, speed), growth)
    trap = first_trap([o], (0.0, 0.0), v0, 0.0, RADIUS, V_MAX, A_MAX, MARGIN, 3.0)
    if trap is None:
        return
    assert trap.obstacle == "O" and 0.0 <= trap.t <= 3.0
    c = o.positions(np.array([trap.t]))[0]
    reach = RADIUS + float(o.radius_at(trap.t)) + MARGIN
    rng = np.random.default_rng(seed)
    for _ in range(20):
        end = _drive(rng, v0 * rng.choice([-1.0, 1.0]), theta0, trap.t) if trap.t > 0.0 else np.zeros(2)
        assert math.hypot(*(end - c)) < reach


def test_no_trap_when_the_robot_can_get_out_of_the_way_or_the_disc_ends():
    # 2 m away at 1 m/s: the robot leaves its line in time
    far = PredictedObstacle("P", 0.5, UnicycleMotion(2.0, 0.0, math.pi, 1.0))
    assert first_trap([far], (0.0, 0.0), 0.0, 0.0, RADIUS, V_MAX, A_MAX, MARGIN, 5.0) is None
    # close, but its prediction ends before it arrives (no disc after ``until``)
    near = PredictedObstacle("P", 0.5, UnicycleMotion(1.0, 0.0, math.pi, 1.0), until=0.1)
    assert first_trap([near], (0.0, 0.0), 0.0, 0.0, RADIUS, V_MAX, A_MAX, MARGIN, 5.0) is None
    # close, but a motion may end (at a goal) before the disc holds the robot's whole reach
    near = PredictedObstacle("P", 0.5, UnicycleMotion(1.0, 0.0, math.pi, 1.0))
    assert first_trap([near], (0.0, 0.0), 0.0, 0.0, RADIUS, V_MAX, A_MAX, MARGIN, 5.0) is not None
    assert first_trap([near], (0.0, 0.0), 0.0, 0.0, RADIUS, V_MAX, A_MAX, MARGIN, 5.0,
                      reach_cap_m=0.01) is None
    assert first_trap([], (0.0, 0.0), 0.0, 0.0, RADIUS, V_MAX, A_MAX, MARGIN, 5.0) is None


def _runs(mode: str, monkeypatch: pytest.MonkeyPatch):
    sc = override_sensing(scenario_from_dict(head_on_corridor_dict(20.0)), mode)
    cfg = deterministic_settings(SpaceTimeBITStarAgent, "st-bitstar")
    with_trap = make_agent("st-bitstar", **cfg)
    a = simulate(sc, with_trap, seed=1)
    monkeypatch.setattr(PlanningPredictions, "_trapped", lambda self, *args: False)
    searched = make_agent("st-bitstar", **cfg)
    b = simulate(sc, searched, seed=1)
    return with_trap, a, searched, b


def _same_decisions(mode: str, monkeypatch: pytest.MonkeyPatch) -> None:
    # The corridor's walker comes head-on and no motion avoids it: the calls where its disc
    # holds the robot's whole reach skip the search, and the robot does exactly what it does
    # when every call searches (each call's BIT* draws from its own generator).
    with_trap, a, searched, b = _runs(mode, monkeypatch)
    assert with_trap.record.st_trapped > 0 and searched.record.st_trapped == 0
    assert a.trajectory == b.trajectory
    assert a.status == b.status and a.collision_with == b.collision_with
    assert with_trap.record.fallbacks == searched.record.fallbacks


def test_skipping_the_search_when_trapped_changes_no_decision_tracked(monkeypatch):
    _same_decisions("tracked", monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["twist", "oracle"])
def test_skipping_the_search_when_trapped_changes_no_decision(mode, monkeypatch):
    _same_decisions(mode, monkeypatch)


def _first_held(o, t0, speed, horizon_s, step_s=0.02):
    """first_trap's grid test for one obstacle at every grid time (no pre-filter), by hand."""
    from anyplan.prediction.trap import _DIST_SLACK, _LIMIT_FACTOR, _SPEED_SLACK

    tau = np.arange(0.0, horizon_s + 0.5 * step_s, step_s)
    d = reach_m(min(speed + _SPEED_SLACK, _LIMIT_FACTOR * V_MAX), _LIMIT_FACTOR * V_MAX,
                _LIMIT_FACTOR * A_MAX, tau) + _DIST_SLACK
    t = t0 + tau
    q = o.positions(t)
    held = (np.hypot(q[:, 0], q[:, 1]) + d < RADIUS + float(o.radius) + MARGIN) \
        & (d < RADIUS + MARGIN + float(o.radius))
    return float(t[np.argmax(held)]) if held.any() else None


def test_an_open_track_that_jumps_onto_the_robot_traps_it():
    # B's open track starts on the robot (at the origin), walks away at 0.5 m/s for 40 s and
    # jumps back. From t0 = 39.9 (B 19.95 m away) its speed bound says it cannot come near
    # within the trap's horizon, but at t = 40 it lands on the robot: the robot is trapped.
    from anyplan.world.motion import WaypointMotion

    b = PredictedObstacle("B", 0.5, WaypointMotion(np.array([[0.0, 0.0, 0.0], [40.0, 20.0, 0.0]])))
    assert b.motion.jump_times(39.9, 50.0) == [40.0]
    trap = first_trap([b], (0.0, 0.0), 0.0, 39.9, RADIUS, V_MAX, A_MAX, MARGIN, 10.0)
    assert trap is not None and trap.obstacle == "B"
    assert trap.t == pytest.approx(40.0) == _first_held(b, 39.9, 0.0, 10.0)
    # from just before a later jump, and from the jumps themselves, likewise
    for t0 in (79.99, 40.0, 80.0):
        trap = first_trap([b], (0.0, 0.0), 0.0, t0, RADIUS, V_MAX, A_MAX, MARGIN, 10.0)
        assert trap is not None and trap.t == _first_held(b, t0, 0.0, 10.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 0.4), st.floats(-3.1, 3.1), st.floats(0.2, 3.0), st.floats(2.0, 12.0),
       st.integers(1, 5), st.floats(0.0, 1.5), st.floats(0.0, 0.5))
def test_the_pre_filter_keeps_every_open_track_that_traps(near, bearing, dwell, leave, n, before,
                                                          speed):
    # An open track lands within `near` of the robot, dwells, then leaves for 15 m away and
    # jumps back: first_trap finds the first held grid time of every grid time tested by hand.
    from anyplan.world.motion import WaypointMotion

    a = np.array([near * math.cos(bearing), near * math.sin(bearing)])
    far = a + 15.0 * np.array([math.cos(bearing + 1.0), math.sin(bearing + 1.0)])
    m = WaypointMotion(np.array([[0.0, *a], [dwell, *(a + 0.05)], [dwell + leave, *far]]))
    o = PredictedObstacle("B", 0.5, m)
    t0 = n * m.period - before
    got = first_trap([o], (0.0, 0.0), speed, t0, RADIUS, V_MAX, A_MAX, MARGIN, 3.0)
    want = _first_held(o, t0, speed, 3.0)
    assert (got is None) == (want is None)
    assert got is None or got.t == want
