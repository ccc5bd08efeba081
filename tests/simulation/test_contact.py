"""Robot-caused collisions: the pure classification on hand-made contacts, and in the simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents.base import Agent
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Circle, rectangle
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.contact import (
    approach_speed,
    disc_contact,
    nearest_obstacle_point,
    robot_caused,
    static_contact,
)
from anyplan.world import Command, scenario_from_dict
from tests.conftest import small_scenario_dict


def test_head_on_is_robot_caused():
    # Robot at the origin driving +x at 0.4 m/s, obstacle centre 0.6 m ahead.
    assert approach_speed((0.4, 0.0), (0.0, 0.0), (0.6, 0.0)) == pytest.approx(0.4)
    assert robot_caused((0.4, 0.0), (0.0, 0.0), (0.6, 0.0))


def test_rear_ended_while_parked_is_not():
    assert not robot_caused((0.0, 0.0), (0.0, 0.0), (-0.6, 0.0))
    # Creeping away from an obstacle that catches up: negative component.
    assert approach_speed((0.2, 0.0), (0.0, 0.0), (-0.6, 0.0)) == pytest.approx(-0.2)
    assert not robot_caused((0.2, 0.0), (0.0, 0.0), (-0.6, 0.0))


def test_side_swipe_is_not():
    # Driving +x while the obstacle is met from the side (+y): no component towards it.
    assert approach_speed((0.4, 0.0), (0.0, 0.0), (0.0, 0.6)) == pytest.approx(0.0, abs=1e-15)
    assert not robot_caused((0.4, 0.0), (0.0, 0.0), (0.0, 0.6))


def test_grazing_is_decided_by_the_threshold():
    # 0.4 m/s at 5 degrees into the obstacle: 0.035 m/s towards it, below 0.05 m/s.
    ang = math.radians(5.0)
    v = (0.4 * math.cos(ang), 0.4 * math.sin(ang))
    assert approach_speed(v, (0.0, 0.0), (0.0, 0.6)) == pytest.approx(0.4 * math.sin(ang))
    assert not robot_caused(v, (0.0, 0.0), (0.0, 0.6))
    # At 10 degrees it is 0.069 m/s: robot-caused.
    ang = math.radians(10.0)
    assert robot_caused((0.4 * math.cos(ang), 0.4 * math.sin(ang)), (0.0, 0.0), (0.0, 0.6))


def test_nearest_points_are_exact():
    obst = ObstacleSet([Circle(np.array([5.0, 5.0]), 1.0), rectangle((2.0, 2.0), (1.0, 1.0))],
                       bounds=(0.0, 0.0, 10.0, 10.0))
    np.testing.assert_allclose(nearest_obstacle_point(obst, (5.0, 7.0)), [5.0, 6.0])
    np.testing.assert_allclose(nearest_obstacle_point(obst, (2.0, 3.0)), [2.0, 2.5])
    np.testing.assert_allclose(nearest_obstacle_point(obst, (9.5, 4.0)), [10.0, 4.0])


def test_contact_instants():
    obst = ObstacleSet([rectangle((5.0, 0.0), (2.0, 2.0))])  # face at x = 4
    s = static_contact(obst, np.array([0.0, 0.0]), np.array([4.0, 0.0]), 0.3)
    assert 4.0 * s == pytest.approx(3.7, abs=1e-9)
    # Discs: relative speed 1 m/s from 2 m apart, reach 0.6 m -> contact at 1.4 s.
    t = disc_contact(np.zeros(2), np.array([0.5, 0.0]), np.array([2.0, 0.0]),
                     np.array([-0.5, 0.0]), 0.6, 0.0, 2.0)
    assert t == pytest.approx(1.4)


class _Straight(Agent):
    """Commands one forward speed ``v`` [m/s] (0: parked) and no turn, whatever it sees."""

    name = "straight-on"

    def __init__(self, v: float) -> None:
        super().__init__()
        self.v = v

    def reset(self, scenario, rng):
        pass

    def act(self, obs):
        return Command(self.v, 0.0)


def test_simulator_classifies_both_sides_of_a_collision():
    # A walker driving into the parked robot from behind: a collision, not robot-caused.
    d = small_scenario_dict(dynamic_obstacles=[{"name": "W", "start": [0.0 + 0.3, 3.0, 0.0], "v": 0.3,
                                                "omega": 0.0, "radius": 0.3}])
    d["robot"]["start"] = [2.0, 3.0, 0.0]
    sc = scenario_from_dict(d)
    res = simulate(sc, _Straight(0.0), seed=0, config=SimConfig(time_limit=10.0))
    assert res.collision and res.collision_with == "W"
    assert res.collision_robot_caused is False
    assert res.collision_approach_speed_mps == pytest.approx(0.0, abs=1e-12)
    # Driving head-on into the box at (4, 5) from below: robot-caused.
    d2 = small_scenario_dict(dynamic_obstacles=[])
    d2["robot"]["start"] = [4.0, 3.0, math.pi / 2]
    d2["robot"]["goal"] = [7.0, 1.0]
    res2 = simulate(scenario_from_dict(d2), _Straight(0.5), seed=0, config=SimConfig(time_limit=10.0))
    assert res2.collision and res2.collision_with == "S1"
    assert res2.collision_robot_caused is True
    assert res2.collision_approach_speed_mps > 0.05
    out = res2.to_dict()
    assert out["collision_robot_caused"] is True


def test_no_collision_gives_none():
    d = small_scenario_dict(dynamic_obstacles=[])
    res = simulate(scenario_from_dict(d), _Straight(0.0), seed=0, config=SimConfig(time_limit=1.0))
    assert not res.collision and res.collision_robot_caused is None
    assert res.collision_approach_speed_mps is None


def test_the_contact_is_classified_at_the_contact_instant_not_at_the_steps_start():
    # The robot (r 0.2 m) drives +x at 1 m/s from (1, 3) (a_max dt = 1 m/s: at full speed from
    # the first step); a disc D (r 0.05 m, reach 0.25 m) moves at w = (-4, -5) m/s. It is placed
    # so that the two first touch at t_c = 0.24 s (inside the step [0.2, 0.25]) with the disc
    # at 120 degrees from the robot's heading, behind its centre: D(t_c) = p(t_c) + 0.25 n,
    # n = (cos 120, sin 120). The relative velocity w - u = (-5, -5) enters the circle there
    # ((w - u) . n < 0), so on that straight relative line t_c is the first contact. At contact
    # the robot moves away from the disc: approach speed u . n = -0.5 m/s, not robot-caused.
    # At the step's start (0.04 s earlier) the disc was still ahead of the robot's centre.
    dt, t_c, reach = 0.05, 0.24, 0.25
    u, w = np.array([1.0, 0.0]), np.array([-4.0, -5.0])
    n = np.array([math.cos(math.radians(120.0)), math.sin(math.radians(120.0))])
    p_c = np.array([1.0, 3.0]) + u * t_c
    q0 = p_c + reach * n - w * t_c  # the disc at t = 0
    assert float((w - u) @ n) < 0.0
    d = small_scenario_dict(
        robot={"start": [1.0, 3.0, 0.0], "goal": [7.0, 3.0], "radius": 0.2, "v_max": 1.0,
               "omega_max": 0.8, "a_max": 20.0, "alpha_max": 1.0},
        static_obstacles=[],
        dynamic_obstacles=[{"name": "D", "type": "waypoints", "radius": 0.05,
                            "keyframes": [[0.0, *q0], [1.0, *(q0 + w)]]}])
    res = simulate(scenario_from_dict(d), _Straight(1.0), seed=0, config=SimConfig(dt=dt, time_limit=0.5))
    assert res.collision and res.collision_with == "D"
    assert res.collision_time_s - dt <= t_c <= res.collision_time_s
    assert res.collision_time_s == pytest.approx(0.25)
    assert res.collision_approach_speed_mps == pytest.approx(float(u @ n), abs=1e-6)  # -0.5
    assert res.collision_robot_caused is False
    # The same classification at the step's start would differ: robot-caused (+0.18 m/s).
    t0 = res.collision_time_s - dt
    assert robot_caused(u, np.array([1.0, 3.0]) + u * t0, q0 + w * t0)
