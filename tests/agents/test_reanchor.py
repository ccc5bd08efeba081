"""Re-anchoring (``reanchor_m``): a robot found off its reference plans its next motion from its
own state, not from the reference's.

The replanning agents plan from the state the robot will have on its reference. A robot pushed
off it (or one that falls behind a reference it cannot follow: DynaBARN world 38, ``tracked``,
seed 8, where the error grew to 2.1 m and the robot cut a corner into the back wall) would
otherwise keep planning, and checking its motions, for a place where it is not.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents import make_agent
from anyplan.agents.replanning import REANCHOR_RAD
from anyplan.agents.settings import deterministic_settings
from anyplan.simulation import SimConfig
from anyplan.simulation.simulator import Simulation
from anyplan.world import RobotState
from anyplan.world.scenario import scenario_from_dict

_PUSH_S = 2.0


def _room() -> object:
    return scenario_from_dict({
        "name": "push", "time_limit": 40.0, "arena": {"width": 20.0, "height": 6.0},
        "robot": {"start": [1.0, 3.0, 0.0], "goal": [19.0, 3.0], "radius": 0.34, "v_max": 2.0,
                  "omega_max": 2.0, "a_max": 2.0, "alpha_max": 4.0, "goal_tolerance": 0.5},
        "static_obstacles": [], "dynamic_obstacles": []})


def _run_pushed(planner: str, dy: float = 0.0, dtheta: float = 0.0, **settings: object):
    """Run ``planner`` in an empty room; at ``_PUSH_S`` the robot is moved ``dy`` [m] sideways
    and turned ``dtheta`` [rad] (a push the agent does not see coming). Returns the agent, the
    simulation and the robot's (t, x, y) rows."""
    cls = type(make_agent(planner))
    agent = make_agent(planner, **{**deterministic_settings(cls, planner), **settings})
    sc = _room()
    sim = Simulation(sc, SimConfig(), 0)
    agent.reset(sc.static_only(), np.random.default_rng(0))
    pushed = False
    while not sim.done:
        if not pushed and sim.t >= _PUSH_S - 1e-9:
            s = sim.state
            sim.state = RobotState(s.x, s.y + dy, s.theta + dtheta, s.v, s.omega)
            pushed = True
        sim.step(agent.act(sim.observation()))
    return agent, sim, np.asarray(sim.trajectory)[:, :3]


def _start_offset(agent, rows: np.ndarray, after: float) -> float:
    """Distance [m] between the robot and the first motion switched to after ``after`` [s],
    at its switch time."""
    ts, motion = next((ts, m) for ts, m in agent.executed if ts > after + 1e-9)
    i = int(np.argmin(np.abs(rows[:, 0] - ts)))
    st = motion.state(ts)
    return math.hypot(st.x - rows[i, 1], st.y - rows[i, 2])


@pytest.mark.parametrize("planner", ["st-bitstar", "seq-bitstar"])
def test_a_pushed_robot_plans_from_where_it_is(planner):
    agent, sim, rows = _run_pushed(planner, dy=0.6)
    assert sim.reached
    # found off its reference at the first step after the push, once
    assert len(agent.record.reanchored_s) == 1
    assert _PUSH_S <= agent.record.reanchored_s[0] <= _PUSH_S + 0.051
    assert any(r.startswith("off the reference by 0.6") for r in agent.record.reasons)
    # the motion it then takes up starts where the robot is (its twist held over the
    # planning delay: a few centimetres), not 0.6 m away on the old reference
    assert _start_offset(agent, rows, _PUSH_S) < 0.05
    assert agent.record.tracking_max_m == pytest.approx(0.6, abs=0.05)  # the push itself


@pytest.mark.parametrize("planner", ["st-bitstar", "seq-bitstar"])
def test_without_reanchoring_a_pushed_robot_falls_behind_its_reference(planner):
    # The reference runs at v_max: a robot that turns back to it cannot catch up, and the
    # error grows past the push (2.5 m here) until the reference slows down at the goal.
    agent, sim, _ = _run_pushed(planner, dy=0.6, reanchor_m=None)
    assert agent.record.reanchored_s == []
    assert not any(r.startswith("off the reference") for r in agent.record.reasons)
    assert agent.record.tracking_max_m > 2.0
    _, sim2, _ = _run_pushed(planner, dy=0.6)
    assert sim2.time_to_goal_s < sim.time_to_goal_s - 1.0


def test_a_heading_error_alone_reanchors():
    agent, sim, _ = _run_pushed("st-bitstar", dtheta=REANCHOR_RAD + 0.05)
    assert sim.reached
    assert len(agent.record.reanchored_s) == 1
    assert _PUSH_S <= agent.record.reanchored_s[0] <= _PUSH_S + 0.051  # at once, 0 m off
    # a small heading error the controller takes back before the robot drifts 0.2 m
    calm, sim, _ = _run_pushed("st-bitstar", dtheta=0.05)
    assert sim.reached and calm.record.reanchored_s == []
    assert 0.0 < calm.record.tracking_max_m < calm.reanchor_m


def test_an_undisturbed_run_is_never_off_its_reference():
    agent, sim, _ = _run_pushed("st-bitstar")
    assert sim.reached and agent.record.reanchored_s == []
    assert agent.record.tracking_max_m < 0.01


@pytest.mark.parametrize("value", [0.0, -0.1, "far"])
def test_bad_reanchor_distance(value):
    with pytest.raises(ValueError, match="reanchor_m"):
        make_agent("st-bitstar", reanchor_m=value)


def test_off_its_reference_the_robot_is_not_offered_the_motion_in_use():
    # Keeping the motion in use (a guard's or a fallback's "keep") would keep a motion whose
    # checks are about a place the robot is not.
    cls = type(make_agent("st-bitstar"))
    agent = make_agent("st-bitstar", **deterministic_settings(cls, "st-bitstar"))
    sc = _room()
    sim = Simulation(sc, SimConfig(), 0)
    agent.reset(sc.static_only(), np.random.default_rng(0))
    while sim.t < _PUSH_S - 1e-9:
        sim.step(agent.act(sim.observation()))
    assert agent._in_use() is agent.trajectory is not None
    s = sim.state
    sim.state = RobotState(s.x - 0.5, s.y, s.theta, s.v, s.omega)  # held back 0.5 m
    obs = sim.observation()
    in_use = agent.trajectory
    sim.step(agent.act(obs))
    assert agent._off_reference and agent._in_use() is None
    assert agent.trajectory is in_use and agent.pending is not None  # a new motion is coming
    t_switch, motion = agent.pending
    st = motion.state(t_switch)
    robot = agent._state_at(obs, t_switch)
    assert math.hypot(st.x - robot.x, st.y - robot.y) < 1e-6
