"""The time lower bound against hand-computed cases."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from anyplan.agents import make_agent
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Circle
from anyplan.planning.time_bound import (
    min_time_from_rest,
    scenario_time_lower_bound,
    time_lower_bound_to_goal,
)
from anyplan.simulation import simulate
from anyplan.world import load_scenario


def test_straight_line_reaches_v_max():
    # 10 m, tolerance 0.2 m: 9.8 m; v 0.5, a 0.5: 0.25 m of acceleration -> 9.8/0.5 + 0.5 = 20.1 s.
    obst = ObstacleSet([], bounds=(0.0, 0.0, 12.0, 4.0))
    t = time_lower_bound_to_goal(obst, (1.0, 2.0), (11.0, 2.0), 0.3, 0.2, 0.5, 0.5)
    assert t == pytest.approx(20.1, abs=1e-9)


def test_short_distance_never_reaches_v_max():
    # 0.3 m - 0.2 m tolerance = 0.1 m < v^2 / 2a = 0.25 m: t = sqrt(2 * 0.1 / 0.5).
    obst = ObstacleSet([], bounds=(0.0, 0.0, 4.0, 4.0))
    t = time_lower_bound_to_goal(obst, (1.0, 2.0), (1.3, 2.0), 0.3, 0.2, 0.5, 0.5)
    assert t == pytest.approx(math.sqrt(0.4), abs=1e-12)
    # Continuity at the switch distance v^2 / 2a: both branches give v / a.
    assert min_time_from_rest(0.25, 0.5, 0.5) == pytest.approx(1.0)
    assert min_time_from_rest(0.25 - 1e-12, 0.5, 0.5) == pytest.approx(1.0)
    assert min_time_from_rest(0.0, 0.5, 0.5) == 0.0


def test_detour_around_one_disc():
    # Disc of radius 1 at the origin, robot radius 0.5: the robot centre keeps 1.5 m from it.
    # From (-3, 0) to (3, 0): two tangents of length sqrt(9 - 2.25) and an arc of 1.5 (pi - 2 a),
    # a = acos(1.5 / 3).
    obst = ObstacleSet([Circle(np.array([0.0, 0.0]), 1.0)], bounds=(-5.0, -5.0, 5.0, 5.0))
    rr = 1.5
    tangent = math.sqrt(9.0 - rr * rr)
    arc = rr * (math.pi - 2.0 * math.acos(rr / 3.0))
    length = 2.0 * tangent + arc
    expected = (length - 0.2) / 0.4 + 0.4 / (2 * 0.4)
    t = time_lower_bound_to_goal(obst, (-3.0, 0.0), (3.0, 0.0), 0.5, 0.2, 0.4, 0.4)
    # The inscribed-arc relaxation is below the true arc by at most r (1 - cos(step / 2)) per
    # step: a lower bound within 1 mm here.
    assert t <= expected + 1e-9
    assert t == pytest.approx(expected, abs=0.001 / 0.4)


def test_no_path_is_none():
    obst = ObstacleSet([Circle(np.array([0.0, 0.0]), 1.0)], bounds=(-5.0, -5.0, 5.0, 5.0))
    assert time_lower_bound_to_goal(obst, (0.0, 0.0), (3.0, 0.0), 0.3, 0.2, 0.4, 0.4) is None


def test_scenario_bound_is_cached_per_robot_and_at_most_a_runs_arrival():
    sc = load_scenario("paper-1")
    b = scenario_time_lower_bound(sc)
    # paper-1: the straight 12 m route is free; (12 - 0.2) / 0.4 + 0.4 / 0.8 = 30.0 s.
    assert b == pytest.approx(30.0, abs=1e-6)
    # cached: the same scenario (an equal copy too) gets the stored object, not a new float
    assert scenario_time_lower_bound(sc) is b
    assert scenario_time_lower_bound(load_scenario("paper-1")) is b
    # the cache is per robot: a slower robot in the same layout gets its own bound,
    # (12 - 0.2) / 0.2 + 0.2 / 0.8 = 59.25 s, not paper-1's
    slow = replace(sc, robot=replace(sc.robot, v_max=0.2))
    assert scenario_time_lower_bound(slow) == pytest.approx(59.25, abs=1e-6)
    assert scenario_time_lower_bound(sc) is b
    # no run arrives earlier: driving straight at the goal without the movers meets the bound
    # (to the 0.05 s step), and seq-bitstar among the movers arrives no earlier
    straight = simulate(sc.static_only(), make_agent("straight"), seed=0)
    planned = simulate(sc, make_agent("seq-bitstar"), seed=0)
    for res in (straight, planned):
        assert res.reached_goal and not res.collision
        assert res.time_to_goal_s >= b - 1e-9
    assert straight.time_to_goal_s == pytest.approx(b, abs=0.05)
