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


class _Parked(Agent):
    name = "parked"

    def reset(self, scenario, rng):
        pass

    def act(self, obs):
        return Command(0.0, 0.0)


class _Forward(Agent):
    name = "forward"

    def reset(self, scenario, rng):
        pass

    def act(self, obs):
        return Command(0.5, 0.0)


def test_simulator_classifies_both_sides_of_a_collision():
    # A walker driving into the parked robot from behind: a collision, not robot-caused.
    d = small_scenario_dict(dynamic_obstacles=[{"name": "W", "start": [0.0 + 0.3, 3.0, 0.0], "v": 0.3,
                                                "omega": 0.0, "radius": 0.3}])
    d["robot"]["start"] = [2.0, 3.0, 0.0]
    sc = scenario_from_dict(d)
    res = simulate(sc, _Parked(), seed=0, config=SimConfig(time_limit=10.0))
    assert res.collision and res.collision_with == "W"
    assert res.collision_robot_caused is False
    assert res.collision_approach_speed_mps == pytest.approx(0.0, abs=1e-12)
    # Driving head-on into the box at (4, 5) from below: robot-caused.
    d2 = small_scenario_dict(dynamic_obstacles=[])
    d2["robot"]["start"] = [4.0, 3.0, math.pi / 2]
    d2["robot"]["goal"] = [7.0, 1.0]
    res2 = simulate(scenario_from_dict(d2), _Forward(), seed=0, config=SimConfig(time_limit=10.0))
    assert res2.collision and res2.collision_with == "S1"
    assert res2.collision_robot_caused is True
    assert res2.collision_approach_speed_mps > 0.05
    out = res2.to_dict()
    assert out["collision_robot_caused"] is True


def test_no_collision_gives_none():
    d = small_scenario_dict(dynamic_obstacles=[])
    res = simulate(scenario_from_dict(d), _Parked(), seed=0, config=SimConfig(time_limit=1.0))
    assert not res.collision and res.collision_robot_caused is None
    assert res.collision_approach_speed_mps is None
