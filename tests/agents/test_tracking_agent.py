"""The tracking front end: agents in ``tracked`` mode plan against estimated, growing discs."""

from __future__ import annotations

import numpy as np

from anyplan.agents import make_agent
from anyplan.agents.base import Agent, Observation
from anyplan.agents.perceiving import TrackingAgent
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import TrackerConfig
from anyplan.prediction.uncertain import UncertaintyModel
from anyplan.simulation import SimConfig, simulate
from anyplan.world import Command, RobotState, scenario_from_dict
from tests.conftest import small_scenario_dict


class Spy(Agent):
    name = "spy"
    plan_at = 1

    def reset(self, scenario, rng):
        self.log = []
        self.replans = []

    def act(self, obs: Observation) -> Command:
        self.log.append(obs)
        if len(self.log) == self.plan_at:
            self.stats.planning_times_s.append(0.0)  # "plans" once
        return Command(0.0, 0.0)

    def request_replan(self, reason):
        self.replans.append(reason)


def test_inner_agent_sees_estimates_with_growth_never_detections():
    d = small_scenario_dict(static_obstacles=[])
    d["sensing"] = {"mode": "tracked"}
    spy = Spy()
    res = simulate(scenario_from_dict(d), spy, seed=0, config=SimConfig(time_limit=3.0))
    assert res.planner == "spy"
    assert all(not o.detections for o in spy.log)
    last = spy.log[-1].obstacles
    assert [o.name for o in last] == ["D1"] and last[0].growth is not None and last[0].motion is None
    # the estimate follows the truth (D1 goes up x = 4 at 0.3 m/s from y = 0.5)
    assert abs(last[0].x - 4.0) < 0.15 and abs(last[0].y - (0.5 + 0.3 * last[0].t)) < 0.15
    assert res.extra["tracking"]["tracks"] == 1


def test_detection_leaving_the_tube_requests_a_replan():
    spy = Spy()
    spy.plan_at = 10  # once the track has its speed
    ag = TrackingAgent(spy)
    ag.reset(scenario_from_dict(small_scenario_dict()), np.random.default_rng(0))
    robot = RobotState(1.0, 3.0, 0.0)
    for k in range(20):  # straight at 1 m/s along y = 1
        t = 0.1 * k
        ag.act(Observation(t, robot, (), (Detection("a", t, t, 1.0, 0.3),)))
    assert spy.replans == []
    ag.act(Observation(2.0, robot, (), (Detection("a", 2.0, 2.0, 1.0, 0.3),)))
    assert spy.replans == []
    # a sudden 1.5 m jump sideways: outside any tube grown in 0.1 s
    ag.act(Observation(2.1, robot, (), (Detection("a", 2.1, 2.1, 2.5, 0.3),)))
    assert len(spy.replans) == 1 and "left its predicted tube" in spy.replans[0]
    assert ag.tube_exits == 1


def _drift_run(tube_cap_m: float, offset_m: float) -> tuple[Spy, TrackingAgent]:
    """A track straight at 1 m/s along y = 1, planned against at 0.9 s, then detected at 2.0 s
    ``offset_m`` [m] off its line (sideways: it has turned)."""
    spy = Spy()
    spy.plan_at = 10
    ag = TrackingAgent(spy, uncertainty=UncertaintyModel(tube_cap_m=tube_cap_m))
    ag.reset(scenario_from_dict(small_scenario_dict()), np.random.default_rng(0))
    robot = RobotState(1.0, 3.0, 0.0)
    for k in range(20):
        t = 0.1 * k
        ag.act(Observation(t, robot, (), (Detection("a", t, t, 1.0, 0.3),)))
    ag.act(Observation(2.0, robot, (), (Detection("a", 2.0, 2.0, 1.0 + offset_m, 0.3),)))
    return spy, ag


def test_the_replan_tube_is_capped_narrower_than_the_planned_disc():
    sigma3 = 3.0 * TrackerConfig().sigma_m
    cap = UncertaintyModel().tube_cap_m
    offset = cap + sigma3 + 0.05  # outside the capped tube
    spy, ag = _drift_run(cap, offset)
    assert spy.replans and "left its predicted tube" in spy.replans[0] and ag.tube_exits == 1
    # ... but inside the disc planned against: only the cap made it leave
    spy_wide, ag_wide = _drift_run(10.0, offset)
    p = ag_wide._tube["a"]
    assert offset < float(p.radius_at(2.0)) - p.radius + sigma3
    assert spy_wide.replans == [] and ag_wide.tube_exits == 0
    # and within the capped tube nothing is requested
    spy_in, _ = _drift_run(cap, cap + sigma3 - 0.05)
    assert spy_in.replans == []


def test_seq_bitstar_and_dovs_run_in_tracked_mode():
    d = small_scenario_dict()
    d["sensing"] = {"mode": "tracked"}
    sc = scenario_from_dict(d)
    for name in ("seq-bitstar", "dovs"):
        res = simulate(sc, make_agent(name), seed=1, config=SimConfig(time_limit=30.0))
        assert res.reached_goal and not res.collision, name
        assert res.extra["perception"]["detections"] > 0
