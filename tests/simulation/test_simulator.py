"""The simulator: limits on the executed motion, collision detection, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents.base import Agent, Observation
from anyplan.agents.straight import StraightAgent
from anyplan.simulation import SimConfig, simulate
from anyplan.world import Command, load_scenario, scenario_from_dict
from tests.conftest import small_scenario_dict


class GreedyAgent(Agent):
    """Asks for impossible commands: the simulator must clip them."""

    name = "greedy"

    def reset(self, scenario, rng):
        self.rng = rng

    def act(self, obs: Observation) -> Command:
        return Command(float(self.rng.uniform(-10, 10)), float(self.rng.uniform(-10, 10)))


class ObservingAgent(StraightAgent):
    """Records what it is shown."""

    def reset(self, scenario, rng):
        super().reset(scenario, rng)
        self.seen_moving = list(scenario.moving_obstacles)
        self.obs_log = []

    def act(self, obs):
        self.obs_log.append(obs)
        return super().act(obs)


def test_executed_motion_respects_every_limit():
    sc = scenario_from_dict(small_scenario_dict(dynamic_obstacles=[]))
    res = simulate(sc, GreedyAgent(), seed=3, config=SimConfig(dt=0.05, time_limit=20.0))
    tr = res.trajectory_array
    s = sc.robot
    assert np.all(np.abs(tr[:, 4]) <= s.v_max + 1e-12)
    assert np.all(np.abs(tr[:, 5]) <= s.omega_max + 1e-12)
    assert np.all(np.abs(np.diff(tr[:, 4])) <= s.a_max * 0.05 + 1e-12)
    assert np.all(np.abs(np.diff(tr[:, 5])) <= s.alpha_max * 0.05 + 1e-12)
    np.testing.assert_allclose(np.diff(tr[:, 0]), 0.05)


def test_straight_robot_hits_each_paper_obstacle_and_the_collision_is_real():
    sc = load_scenario("paper-1")
    res = simulate(sc, StraightAgent(), seed=0)
    assert res.collision and res.collision_with == "D1"
    assert not res.reached_goal and res.status == "collision"
    # Independent check at the reported time: the discs overlap (within one step of motion).
    tr = res.trajectory_array
    t, x, y = tr[-1, :3]
    d = math.hypot(*(np.array([x, y]) - sc.moving_obstacles[0].position(t)))
    assert d < sc.robot.radius + sc.moving_obstacles[0].radius + 0.05 * (0.4 + 0.12)
    assert res.min_clearance_m < 0.0


def test_collision_with_static_obstacle_and_wall_is_detected():
    d = small_scenario_dict(dynamic_obstacles=[])
    d["static_obstacles"] = [{"name": "S9", "type": "circle", "center": [4.0, 3.0], "radius": 0.5}]
    res = simulate(scenario_from_dict(d), StraightAgent(), seed=0)
    assert res.collision_with == "S9"
    d["static_obstacles"] = []
    d["robot"]["goal"] = [1.0, 5.5]
    d["robot"]["start"] = [1.0, 3.0, math.pi / 2]
    d["robot"]["goal_tolerance"] = 0.1
    sc = scenario_from_dict(d)
    sc = sc.__class__(**{**sc.__dict__, "height": 5.6})
    res = simulate(sc, StraightAgent(), seed=0)
    assert res.collision_with == "wall"


def test_free_run_reaches_goal_with_consistent_metrics():
    sc = load_scenario("paper-1").static_only()
    res = simulate(sc, StraightAgent(), seed=0)
    assert res.reached_goal and not res.collision and res.status == "reached"
    tr = res.trajectory_array
    assert math.hypot(tr[-1, 1] - sc.robot.goal[0], tr[-1, 2] - sc.robot.goal[1]) <= 0.2
    assert res.time_to_goal_s == pytest.approx(tr[-1, 0])
    assert res.path_length_m == pytest.approx(np.sum(np.hypot(*np.diff(tr[:, 1:3], axis=0).T)))
    # No faster than the straight-line bound: distance / v_max.
    dist = math.hypot(12.0, 0.0) - 0.2
    assert res.time_to_goal_s >= dist / sc.robot.v_max
    assert res.min_clearance_m > 0.0


def test_timeout_is_reported():
    sc = load_scenario("paper-1").static_only()
    res = simulate(sc, StraightAgent(), seed=0, config=SimConfig(time_limit=5.0))
    assert res.status == "timeout" and not res.reached_goal and res.time_to_goal_s is None
    assert res.trajectory_array[-1, 0] == pytest.approx(5.0)


def test_agent_never_sees_the_truth_and_sensing_range_filters():
    d = small_scenario_dict()
    d["robot"]["sensing_range"] = 2.0
    sc = scenario_from_dict(d)
    agent = ObservingAgent()
    simulate(sc, agent, seed=0, config=SimConfig(time_limit=6.0))
    assert agent.seen_moving == []
    for ob in agent.obs_log:
        for o in ob.obstacles:
            assert math.hypot(o.x - ob.robot.x, o.y - ob.robot.y) <= 2.0
    assert any(ob.obstacles for ob in agent.obs_log)
    assert any(not ob.obstacles for ob in agent.obs_log)


def test_runs_are_deterministic_for_a_seed():
    sc = scenario_from_dict(small_scenario_dict(dynamic_obstacles=[]))
    a = simulate(sc, GreedyAgent(), seed=7, config=SimConfig(time_limit=5.0))
    b = simulate(sc, GreedyAgent(), seed=7, config=SimConfig(time_limit=5.0))
    c = simulate(sc, GreedyAgent(), seed=8, config=SimConfig(time_limit=5.0))
    assert a.trajectory == b.trajectory
    assert a.trajectory != c.trajectory
    assert a.seed == 7


def test_bad_sim_config():
    with pytest.raises(ValueError, match="dt"):
        SimConfig(dt=0.1)


def test_observations_announce_motions_only_when_configured():
    d = small_scenario_dict()
    d["dynamic_obstacles"][0]["start_time"] = 2.0
    sc = scenario_from_dict(d)
    for announce in (True, False):
        agent = ObservingAgent()
        simulate(sc, agent, seed=0, config=SimConfig(time_limit=1.0, announce_motions=announce))
        o = agent.obs_log[0].obstacles[0]
        assert o.v == 0.0  # waiting for its start time
        assert (o.motion is sc.moving_obstacles[0].motion) == announce


class ConstantCommand(Agent):
    """Asks for the same command every step."""

    name = "constant"

    def __init__(self, v: float) -> None:
        self.v = v

    def reset(self, scenario, rng):
        pass

    def act(self, obs: Observation) -> Command:
        return Command(self.v, 0.0)


def test_a_thin_wall_crossed_between_two_steps_is_a_collision():
    # A robot (r 0.1 m) at 20 m/s (1 m a step; a_max dt = 50 m/s, so it drives at 20 m/s from
    # the first step) heading +x from x = 1.3 along y = 3, a 5 cm wall W at x in [1.975, 2.025]
    # for y in [0, 4]. Closed form: first contact when x + 0.1 = 1.975, at t = 0.575 / 20 =
    # 0.02875 s, inside the first step; both ends of that step (x = 1.3 and x = 2.3) are clear.
    r, speed, dt = 0.1, 20.0, 0.05
    d = small_scenario_dict(
        robot={"start": [1.3, 3.0, 0.0], "goal": [7.0, 5.0], "radius": r, "v_max": speed,
               "omega_max": 0.8, "a_max": 1000.0, "alpha_max": 1.0},
        static_obstacles=[{"name": "W", "type": "rectangle", "center": [2.0, 2.0], "size": [0.05, 4.0]}],
        dynamic_obstacles=[])
    res = simulate(scenario_from_dict(d), ConstantCommand(speed), seed=0,
                   config=SimConfig(dt=dt, time_limit=0.2))
    t_contact = (1.975 - r - 1.3) / speed
    tr = res.trajectory_array
    # The step's ends, independently: both clear of the wall's faces by more than r.
    assert tr[0, 1] == pytest.approx(1.3) and tr[1, 1] == pytest.approx(2.3)
    assert 1.975 - tr[0, 1] > r and tr[1, 1] - 2.025 > r
    assert res.collision and res.collision_with == "W"
    assert res.collision_time_s - dt <= t_contact <= res.collision_time_s
    assert res.collision_time_s == pytest.approx(dt)
    # The chord runs through the wall: clearance 0 - r, not the end point's +0.175 m.
    assert res.min_clearance_m == pytest.approx(-r, abs=1e-9)
    # Head-on into the wall's face at full speed.
    assert res.collision_robot_caused is True
    assert res.collision_approach_speed_mps == pytest.approx(speed)


def test_a_disc_crossing_the_robot_between_two_steps_is_a_collision():
    # A parked robot (r 0.3 m) at (3, 3); a disc F (r 0.1 m) at 20 m/s along y = 3.2, at x = 3
    # at t = 0.125 s, the middle of the step [0.1, 0.15]. Closed form: closest approach 0.2 m
    # (clearance 0.2 - 0.4 = -0.2 m); first contact when dx^2 + 0.2^2 = 0.4^2, at
    # t = 0.125 - sqrt(0.12) / 20 = 0.1077 s. At the step's ends dx = -0.5 and +0.5 m: clearance
    # sqrt(0.29) - 0.4 = +0.139 m, and more at every earlier step end.
    speed, dt, t_mid = 20.0, 0.05, 0.125
    x0 = 3.0 - speed * t_mid
    d = small_scenario_dict(
        robot={"start": [3.0, 3.0, 0.0], "goal": [7.0, 5.0], "radius": 0.3, "v_max": 0.5,
               "omega_max": 0.8, "a_max": 0.5, "alpha_max": 1.0},
        static_obstacles=[],
        dynamic_obstacles=[{"name": "F", "type": "waypoints", "radius": 0.1,
                            "keyframes": [[0.0, x0, 3.2], [0.3, x0 + speed * 0.3, 3.2]]}])
    sc = scenario_from_dict(d)
    res = simulate(sc, ConstantCommand(0.0), seed=0, config=SimConfig(dt=dt, time_limit=0.3))
    t_contact = t_mid - math.sqrt(0.4**2 - 0.2**2) / speed
    # Every step end up to the contact step, independently: clear.
    f = sc.moving_obstacles[0]
    for t in np.arange(0, 4) * dt:
        assert math.hypot(*(f.position(t) - np.array([3.0, 3.0]))) - 0.4 > 0.13
    assert res.collision and res.collision_with == "F"
    assert res.collision_time_s - dt <= t_contact <= res.collision_time_s
    assert res.collision_time_s == pytest.approx(0.15)
    assert res.min_clearance_m == pytest.approx(0.2 - 0.4, abs=1e-9)
