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


def _drift_run(tube_cap_m: float, offset_m: float, name: str | None = "a"
               ) -> tuple[Spy, TrackingAgent]:
    """A track straight at 1 m/s along y = 1, planned against at 0.9 s, then detected at 2.0 s
    ``offset_m`` [m] off its line (sideways: it has turned); ``name=None``: anonymous."""
    spy = Spy()
    spy.plan_at = 10
    ag = TrackingAgent(spy, uncertainty=UncertaintyModel(tube_cap_m=tube_cap_m))
    ag.reset(scenario_from_dict(small_scenario_dict()), np.random.default_rng(0))
    robot = RobotState(1.0, 3.0, 0.0)
    for k in range(20):
        t = 0.1 * k
        ag.act(Observation(t, robot, (), (Detection(name, t, t, 1.0, 0.3),)))
    ag.act(Observation(2.0, robot, (), (Detection(name, 2.0, 2.0, 1.0 + offset_m, 0.3),)))
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


def test_an_anonymous_detection_leaving_the_tube_requests_a_replan_under_its_tracks_name():
    sigma3 = 3.0 * TrackerConfig().sigma_m
    cap = UncertaintyModel().tube_cap_m
    spy, ag = _drift_run(cap, cap + sigma3 + 0.05, name=None)
    assert spy.replans == ["track-1 left its predicted tube"] and ag.tube_exits == 1
    spy_in, _ = _drift_run(cap, cap + sigma3 - 0.05, name=None)
    assert spy_in.replans == []


def test_seq_bitstar_and_dovs_run_in_tracked_mode():
    d = small_scenario_dict()
    d["sensing"] = {"mode": "tracked"}
    sc = scenario_from_dict(d)
    for name in ("seq-bitstar", "dovs"):
        res = simulate(sc, make_agent(name), seed=1, config=SimConfig(time_limit=30.0))
        assert res.reached_goal and not res.collision, name
        assert res.extra["perception"]["detections"] > 0


class Mover(Spy):
    """Drives a fixed command (an arc) and records what it is shown."""

    def act(self, obs: Observation) -> Command:
        super().act(obs)
        return Command(0.4, 0.2)


def _standing_person_speeds(odom: bool) -> np.ndarray:
    """The estimated speed [m/s] of a person standing still, seen by a robot that drives an arc
    with a 5 cm localization error, the tracks kept in the odometry frame or in the map's."""
    from anyplan.simulation.simulator import Simulation

    d = small_scenario_dict(static_obstacles=[])
    d["dynamic_obstacles"] = [{"name": "P", "start": [5.0, 4.0, 0.0], "v": 0.0, "radius": 0.25}]
    d["sensing"] = {"mode": "tracked", "noise_m": 0.01, "rate_hz": 10.0}
    sc = scenario_from_dict(d)
    sim = Simulation(sc, SimConfig(time_limit=12.0, localization_sigma_xy=0.05,
                                   localization_sigma_theta=0.02), seed=4)
    spy = Mover()
    agent = TrackingAgent(spy, TrackerConfig(sigma_m=0.01))
    agent.reset(sc.static_only(), np.random.default_rng(0))
    while not sim.done:
        obs = sim.observation()
        if not odom:
            obs = Observation(obs.t, obs.robot, obs.obstacles, obs.detections, None)
        sim.step(agent.act(obs))
    return np.array([o.v for ob in spy.log[40:] for o in ob.obstacles if o.name == "P"])


def test_tracks_in_the_odometry_frame_do_not_take_the_localizers_wandering_for_motion():
    in_odom, in_map = _standing_person_speeds(True), _standing_person_speeds(False)
    assert len(in_odom) > 100 and len(in_map) == len(in_odom)
    # in the map frame the wandering estimate moves the person about; odometry is smooth
    assert np.median(in_odom) < np.median(in_map)
    assert np.percentile(in_odom, 95) < 0.5 * np.percentile(in_map, 95)
    assert np.percentile(in_odom, 95) < 0.2  # the tracker's own noise (1 cm detections at 10 Hz)


def test_the_odometry_pose_is_the_true_pose_with_an_exact_drive():
    from anyplan.simulation.simulator import Simulation

    sc = scenario_from_dict(small_scenario_dict(static_obstacles=[]))
    exact = Simulation(sc, SimConfig(time_limit=3.0), seed=1)
    slip = Simulation(sc, SimConfig(time_limit=3.0, actuation_sigma_v=0.1,
                                    actuation_sigma_omega=0.1), seed=1)
    for _ in range(40):
        for sim in (exact, slip):
            assert sim.observation().odom == sim.odom
            sim.step(Command(0.4, 0.3))
        assert exact.odom == exact.state  # the same integration, bit for bit
    # with an execution error odometry integrates the drive's twist, not the ground's: it drifts
    assert 0.0 < np.hypot(slip.odom.x - slip.state.x, slip.odom.y - slip.state.y) < 0.5


def test_a_young_anonymous_track_near_the_robot_is_shown_at_once():
    spy = Spy()
    ag = TrackingAgent(spy)
    ag.reset(scenario_from_dict(small_scenario_dict()), np.random.default_rng(0))
    robot = RobotState(1.0, 3.0, 0.0)  # radius 0.3 m
    near, far = (1.0 + 0.3 + 0.8, 3.0), (4.0, 3.0)  # gaps 0.8 m and 2.7 m
    ag.act(Observation(0.0, robot, (), (Detection(None, 0.0, *near, 0.3),
                                        Detection(None, 0.0, *far, 0.3))))
    first = {(round(o.x, 3), round(o.y, 3)) for o in spy.log[-1].obstacles}
    assert first == {near}  # the near one at its first detection, the far one not yet
    ag.act(Observation(0.1, robot, (), (Detection(None, 0.1, *near, 0.3),
                                        Detection(None, 0.1, *far, 0.3))))
    assert len(spy.log[-1].obstacles) == 2  # confirmed at the second detection
    # with urgent_gap_m = 0 the near one waits for its confirmation too
    spy0 = Spy()
    ag0 = TrackingAgent(spy0, tracker=TrackerConfig(urgent_gap_m=0.0))
    ag0.reset(scenario_from_dict(small_scenario_dict()), np.random.default_rng(0))
    ag0.act(Observation(0.0, robot, (), (Detection(None, 0.0, *near, 0.3),)))
    assert spy0.log[-1].obstacles == ()


def _vanishing_walker(tracker: TrackerConfig, behind_wall: bool):
    """A person walking at 0.5 m/s who leaves the recording (``track`` motion) at 1.5 s in the
    robot's plain view, or at 2.5 s after walking behind a wall at about 1.4 s; the robot, at
    (1, 3), stands still. Returns (the spy's log, the tracking agent)."""
    samples = [[0.0, 0.3, 5.0], [2.5, 1.55, 5.0]] if behind_wall else [[0.0, 2.0, 1.0], [1.5, 2.75, 1.0]]
    d = small_scenario_dict(
        static_obstacles=[{"name": "W", "type": "rectangle", "center": [4.0, 4.0],
                           "size": [6.0, 0.4], "angle": 0.0}],
        dynamic_obstacles=[{"name": "P", "type": "track", "radius": 0.25, "samples": samples}])
    d["sensing"] = {"mode": "tracked"}
    spy = Spy()
    agent = TrackingAgent(spy, tracker)
    simulate(scenario_from_dict(d), agent, seed=0, config=SimConfig(time_limit=3.0))
    return spy.log, agent


def test_a_person_gone_in_plain_view_is_dropped_within_visible_misses_frames():
    log, agent = _vanishing_walker(TrackerConfig(), behind_wall=False)
    shown = [o.t for o in log if any(ob.name == "P" for ob in o.obstacles)]
    # the last detection is at 1.5 s; missed in view at 1.6, 1.7 and 1.8 s: gone at 1.8 s
    assert 1.5 <= max(shown) < 1.8 + 1e-9
    assert agent.tracker.vanished == 1
    # without negative information it coasts drop_after_s (2 s) after its last detection
    log, agent = _vanishing_walker(TrackerConfig(visible_misses=0), behind_wall=False)
    shown = [o.t for o in log if any(ob.name == "P" for ob in o.obstacles)]
    assert max(shown) >= 3.0 - 0.05 and agent.tracker.vanished == 0
    # hidden behind the wall, it coasts (the sensor could not have seen it)
    log, agent = _vanishing_walker(TrackerConfig(), behind_wall=True)
    shown = [o.t for o in log if any(ob.name == "P" for ob in o.obstacles)]
    last_seen = agent.tracker.last_seen
    assert max(shown) >= 3.0 - 0.05 and agent.tracker.vanished == 0 and len(last_seen) == 1
    assert 1.2 <= last_seen[0] <= 1.5


def test_the_simulator_marks_sensor_frames():
    d = small_scenario_dict(static_obstacles=[])
    d["sensing"] = {"mode": "tracked", "rate_hz": 5.0}
    spy = Spy()

    class Frames(TrackingAgent):
        def act(self, obs):
            self.frames.append((obs.t, obs.frame, len(obs.detections)))
            return super().act(obs)

    ag = Frames(spy)
    ag.frames = []
    simulate(scenario_from_dict(d), ag, seed=0, config=SimConfig(time_limit=2.0))
    at = [t for t, f, _ in ag.frames if f]
    assert np.allclose(np.diff(at), 0.2)  # 5 Hz, whatever the control rate
    assert all(n > 0 for t, f, n in ag.frames if f) and all(n == 0 for _, f, n in ag.frames if not f)
