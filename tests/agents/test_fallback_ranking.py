"""st-bitstar's fallback ranking: the approach speed counts every obstacle met within the
reaction time, not only the first."""

from __future__ import annotations

import math

import numpy as np

from anyplan.prediction import PredictedObstacle
from anyplan.prediction.collision import predict_collisions
from anyplan.trajectory import plan_motion
from anyplan.world import RobotState, UnicycleMotion
from tests.agents.test_spacetime_agent import _agent_in_empty_room


def _grazed_then_blocked(agent):
    """A robot driving east at 1 m/s, a drive straight on and a brake; A crosses its path from
    the north and meets every candidate first, beside the robot (no approach); B stands on the
    drive's line, 1.2 m ahead, where braking stops short of it."""
    spec, m = agent.spec, agent.guard.config.margin
    state = RobotState(2.0, 3.0, 0.0, 1.0, 0.0)
    drive = plan_motion(np.array([[2.0, 3.0], [6.0, 3.0]]), spec, state, agent.obstacles, 0.0,
                        allow_turn=False)
    brake = next(tr for kind, tr in agent._ranker().candidates(0.0, state, [])
                 if kind == "brake")
    reach = spec.radius + 0.25 + m
    a = PredictedObstacle("A", 0.25, UnicycleMotion(2.1, 3.0 + reach + 0.5, -math.pi / 2, 2.5))
    b = PredictedObstacle("B", 0.25, UnicycleMotion(3.2, 3.0, 0.0, 0.0))
    return spec, drive, brake, a, b


def test_a_drive_grazed_first_then_into_a_standing_obstacle_ranks_as_driving_into_it():
    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    spec, drive, brake, a, b = _grazed_then_blocked(agent)
    ranker = agent._ranker()
    hits = predict_collisions(drive, [a, b], spec.radius, t_from=0.0, t_until=ranker.react_s,
                              margin=agent.guard.config.margin, sample_dt=0.02)
    assert [h.obstacle for h in hits] == ["A", "B"]  # A first, then B, both within react_s
    assert drive.state(hits[1].t).v > 0.5  # driving into B
    # A alone: met beside the robot, no approach; with B the drive's approach is B's
    k_alone, _ = agent._fallback_rank(drive, 0.0, [a], [a])
    k_drive, _ = agent._fallback_rank(drive, 0.0, [a, b], [a, b])
    assert k_alone[4] == 0.0
    assert k_drive[4] <= -0.5
    # braking, struck by A only (at rest or slowing beside it), now ranks before driving on
    assert predict_collisions(brake, [b], spec.radius, t_from=0.0, t_until=5.0,
                              margin=agent.guard.config.margin, sample_dt=0.02) == []
    k_brake, _ = agent._fallback_rank(brake, 0.0, [a, b], [a, b])
    assert k_brake[:4] == k_drive[:4]
    assert k_brake > k_drive
