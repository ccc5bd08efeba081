"""st-bitstar's guard and the obstacles the robot outruns (``outrun_margin_mps``): the guard
checks the planned (capped) disc of an uncertain obstacle predicted slower than v_max minus the
margin, the full growth of the others, and decides nothing when every obstacle is outrun."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents import make_agent
from anyplan.prediction import PredictedObstacle
from anyplan.prediction.base import RadiusGrowth
from anyplan.world import UnicycleMotion
from anyplan.world.scenario import scenario_from_dict
from tests.agents.test_spacetime_agent import _agent_in_empty_room, _crossing_scenario

_JACKAL = {"v_max": 2.0, "a_max": 2.0, "omega_max": 2.0, "alpha_max": 4.0}
_GROWTH = RadiusGrowth(2.0, np.array([0.0, 1.0, 3.0]), np.array([0.1, 0.6, 1.0]))


def _towards(name: str, speed: float, y: float) -> PredictedObstacle:
    """An uncertain obstacle 3 m ahead of (1, 3), heading at the robot's row at ``speed``."""
    return PredictedObstacle(name, 0.5, UnicycleMotion(4.0, y, math.pi, speed, start_time=2.0),
                             _GROWTH, until=5.0)


def test_the_guard_checks_the_planned_disc_of_an_obstacle_the_robot_outruns():
    agent = _agent_in_empty_room(**_JACKAL)
    assert agent.outrun_margin_mps == pytest.approx(1.0 / 3.0)
    p = np.array([1.0, 3.0])
    slow, fast = _towards("slow", 1.0, 3.0), _towards("fast", 1.9, 2.0)
    edge = _towards("edge", 2.0 - agent.outrun_margin_mps, 4.0)  # not slower by more: in full
    planned, safe = agent._split([slow, fast, edge], p, 2.0)
    assert [o.growth.max_extra for o in planned] == pytest.approx([0.3] * 3)
    assert safe[0] is planned[0]
    assert [o.growth.max_extra for o in safe[1:]] == pytest.approx([1.0, 1.0])
    assert agent._guarded_by(safe)
    # the guard, capping what it checks, gets the planning's own objects
    assert all(a is b for a, b in zip(agent._capped(safe), planned, strict=True))
    # every obstacle outrun: the guard does not decide (as guard="never")
    _, only_slow = agent._split([slow], p, 2.0)
    assert only_slow[0].growth.max_extra == pytest.approx(0.3)
    assert not agent._guarded_by(only_slow)
    # None: every uncertain disc in full, as before
    agent.outrun_margin_mps = None
    _, safe = agent._split([slow, fast], p, 2.0)
    assert [o.growth.max_extra for o in safe] == pytest.approx([1.0, 1.0])
    assert agent._guarded_by(safe)


def test_a_slow_robot_outruns_nothing_and_its_guard_keeps_the_full_growth():
    # The P3DX (0.4 m/s) is not faster than a 0.1 m/s obstacle by 1/3 m/s.
    agent = _agent_in_empty_room()
    _, safe = agent._split([_towards("W", 0.1, 3.0)], np.array([1.0, 3.0]), 2.0)
    assert safe[0].growth.max_extra == pytest.approx(1.0) and agent._guarded_by(safe)


@pytest.mark.parametrize("margin", [None, 0.0])
def test_a_check_consults_the_guard_only_for_an_obstacle_not_outrun(margin):
    # The P3DX cruises towards its goal; an uncertain obstacle 1.2 m ahead comes at it at
    # 0.3 m/s. Not outrun (margin None), the guard finds the motion in use no longer stoppable
    # against the full growth and replans; outrun (margin 0: 0.3 < 0.4 m/s) the guard is not
    # consulted, and the check goes on against the planned disc alone.
    from anyplan.agents.base import Observation
    from anyplan.world import RobotState

    sc = scenario_from_dict({**_crossing_scenario().to_dict(), "dynamic_obstacles": []})
    agent = make_agent("st-bitstar", planning_delay=0.1, outrun_margin_mps=margin)
    agent.reset(sc, np.random.default_rng(0))
    for t0 in (0.0, 0.1):
        agent.act(Observation(t0, RobotState(1.0, 3.0, 0.0, 0.0, 0.0)))
    t = 6.0
    st = agent.trajectory.state(t)
    growth = RadiusGrowth(t, np.array([0.0, 1.0, 3.0]), np.array([0.1, 0.6, 1.0]))
    ahead = PredictedObstacle("A", 0.25, UnicycleMotion(st.x + 1.2, st.y, math.pi, 0.3,
                                                        start_time=t), growth, until=t + 3.0)
    seen = []
    decide, still_safe = agent.guard.decide, agent.guard.still_safe

    def spy_decide(*args, **kwargs):
        seen.append("decide")
        return decide(*args, **kwargs)

    def spy_still_safe(*args, **kwargs):
        seen.append("still_safe")
        return still_safe(*args, **kwargs)

    agent.guard.decide, agent.guard.still_safe = spy_decide, spy_still_safe
    agent._check(Observation(t, st), [ahead])
    if margin is None:
        assert agent.record.reasons[-1].startswith("safety") and "decide" in seen
    else:
        assert seen == [] and not agent.record.reasons[-1].startswith("safety")


def test_outrun_margin_is_checked():
    assert make_agent("st-bitstar", outrun_margin_mps=None).outrun_margin_mps is None
    for bad in (-0.1, "fast"):
        with pytest.raises(ValueError, match="outrun_margin_mps"):
            make_agent("st-bitstar", outrun_margin_mps=bad)
