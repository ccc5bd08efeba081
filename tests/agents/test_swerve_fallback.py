"""st-bitstar's swerves: fallbacks that leave an obstacle's way without stopping first, offered
only against certain predictions (exact twists, announced motions), or uncertain ones of
obstacles the robot all outruns."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents import make_agent
from anyplan.prediction import PredictedObstacle
from anyplan.prediction.base import RadiusGrowth
from anyplan.prediction.collision import first_collision
from anyplan.trajectory.kinds import MotionKind
from anyplan.world import RobotState, UnicycleMotion
from tests.agents.test_spacetime_agent import _agent_in_empty_room

LIMITS = {"v_max": 1.0, "omega_max": 1.5, "a_max": 1.0, "alpha_max": 3.0}


def _walker(growth: RadiusGrowth | None = None) -> list[PredictedObstacle]:
    # head-on at 1 m/s towards a robot at (5, 1.5) driving at 1 m/s up the room, 1.8 m between
    # their discs (as in the recorded crowds: ETH hotel, window 14)
    return [PredictedObstacle("P", 0.25, UnicycleMotion(5.0, 1.5 + 1.8 + 0.55, -math.pi / 2, 1.0),
                              growth, until=5.0)]


def test_a_robot_driving_at_a_walker_swerves_when_nothing_else_leaves_its_way():
    # Braking stands the robot on the walker's path; turning away and backing off brake first;
    # the evasions along straight lines brake and turn, the curves to their end points cannot
    # turn tightly enough: every one is struck. An arc entered at speed leaves the walker's line
    # in time, and is the fallback chosen.
    agent = _agent_in_empty_room(**LIMITS)
    state = RobotState(5.0, 1.5, math.pi / 2, 1.0, 0.0)
    walker = _walker()
    r, m = agent.spec.radius, agent.guard.config.margin
    cands = agent._ranker().candidates(0.0, state, walker)
    free = {k for k, tr in cands
            if first_collision(tr, walker, r, t_from=0.0, t_until=5.0, margin=m) is None}
    assert free == {"swerve"}
    kind, tr, _ = agent._evasions(0.0, state, walker, None)
    assert kind == "swerve" and tr.kind == MotionKind.SWERVE
    assert first_collision(tr, walker, r, t_from=0.0, t_until=5.0, margin=m) is None
    assert tr.state(0.3).v > 0.9  # it kept moving


def test_no_swerve_is_offered_among_uncertain_discs_or_when_switched_off():
    # The same walker as an uncertain (tracked) disc: a swerve would keep the robot moving into
    # space the grown disc may hold (measured: more robot-caused collisions), so none is offered.
    agent = _agent_in_empty_room(**LIMITS)
    state = RobotState(5.0, 1.5, math.pi / 2, 1.0, 0.0)
    grown = _walker(RadiusGrowth(0.0, np.array([0.0, 2.0]), np.array([0.0, 0.4])))
    assert "swerve" not in {k for k, _ in agent._ranker().candidates(0.0, state, grown)}
    agent.swerves = False
    assert "swerve" not in {k for k, _ in agent._ranker().candidates(0.0, state, _walker())}


def test_a_swerve_wins_only_on_a_better_head():
    # Nothing to escape: every candidate is free and a swerve would clear as much as braking;
    # the key prefers the others on a tie, so the robot does not wander off on an arc.
    agent = _agent_in_empty_room(**LIMITS)
    far = [PredictedObstacle("far", 0.25, UnicycleMotion(11.0, 5.5, 0.0, 0.0), until=5.0)]
    state = RobotState(5.0, 3.0, 0.0, 1.0, 0.0)
    assert "swerve" in [k for k, _ in agent._ranker().candidates(0.0, state, far)]
    kind, tr, _ = agent._evasions(0.0, state, far, None)
    assert kind != "swerve" and tr.kind != MotionKind.SWERVE


def test_the_swerves_setting_is_checked():
    with pytest.raises(ValueError, match="swerves"):
        make_agent("st-bitstar", swerves="yes")


def test_swerves_among_uncertain_discs_when_the_robot_outruns_every_obstacle(monkeypatch):
    # When the robot outruns every uncertain obstacle, st-bitstar's guard does not decide, and
    # its fallback offers the swerves as among certain predictions; a walker it does not
    # outrun (1 m/s against the robot's 1 m/s) keeps them out.
    from anyplan.agents.base import Observation

    agent = _agent_in_empty_room(**LIMITS)
    state = RobotState(5.0, 1.5, math.pi / 2, 1.0, 0.0)
    growth = RadiusGrowth(0.0, np.array([0.0, 2.0]), np.array([0.0, 0.4]))
    grown = _walker(growth)
    assert "swerve" in {k for k, _ in agent._ranker(outrun=True).candidates(0.0, state, grown)}
    slow = [PredictedObstacle("S", 0.25, UnicycleMotion(5.0, 4.0, -math.pi / 2, 0.5), growth,
                              until=5.0)]  # 0.5 m/s < 1 m/s - 1/3 m/s: outrun
    seen: list[bool] = []
    ranker = agent._ranker
    monkeypatch.setattr(agent, "_ranker", lambda outrun=False: seen.append(outrun) or ranker(outrun))
    obs = Observation(0.0, state)
    agent._fallback(obs, 0.0, slow, "test")
    agent._fallback(obs, 0.0, grown, "test")
    assert seen == [True, False]
