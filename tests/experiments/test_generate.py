"""Random scenarios: valid, reproducible, and their moving obstacles really cross the route."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.experiments.generate import random_scenario, random_suite, route_is_connected
from anyplan.experiments.suites import SuiteError, resolve_suite
from anyplan.world.scenario import scenario_from_dict


@pytest.mark.parametrize("seed", range(6))
def test_generated_scenarios_are_valid(seed):
    sc = random_scenario(seed, name=f"g{seed}")
    assert 1 <= len(sc.moving_obstacles) <= 6
    # Round-trips through the strict schema loader (start and goal free, fields valid).
    assert scenario_from_dict(sc.to_dict()).content_hash() == sc.content_hash()
    assert route_is_connected(sc)
    r = sc.robot
    start, goal = np.array(r.start[:2]), np.array(r.goal)
    route = goal - start
    for o in sc.moving_obstacles:
        p0 = o.position(0.0)
        assert o.radius <= p0[0] <= sc.width - o.radius and o.radius <= p0[1] <= sc.height - o.radius
        for q in (start, goal):
            assert np.hypot(*(p0 - q)) >= o.radius + r.radius + 0.5
        # The obstacle's centre passes within 1 mm of the straight start-goal segment.
        ts = np.linspace(0.0, 120.0, 24001)
        P = o.motion.positions(ts)
        s = np.clip(((P - start) @ route) / (route @ route), 0.0, 1.0)
        d = np.hypot(*(P - (start + s[:, None] * route)).T)
        assert d.min() < 1e-3 + 0.3 * 120.0 / 24000


def test_generation_is_reproducible_and_counts_are_honoured():
    a = random_suite(5, per_count=1)
    b = random_suite(5, per_count=1)
    assert [s.content_hash() for s in a] == [s.content_hash() for s in b]
    assert [len(s.moving_obstacles) for s in a] == [1, 2, 3, 4, 5, 6]
    assert len({s.name for s in a}) == 6
    assert random_suite(6, counts=[1])[0].content_hash() != a[0].content_hash()


def test_an_obstacle_ignored_by_a_straight_robot_is_met_near_its_crossing_time():
    """The crossing time is when a straight-driving robot gets there (within a few seconds)."""
    sc = random_scenario(11, n_moving=1)
    r = sc.robot
    start, goal = np.array(r.start[:2]), np.array(r.goal)
    o = sc.moving_obstacles[0]
    ts = np.linspace(0.0, 120.0, 12001)
    P = o.motion.positions(ts)
    u = (goal - start) / np.linalg.norm(goal - start)
    d = np.abs((P - start) @ np.array([-u[1], u[0]]))
    k = int(np.argmin(d))
    along = float((P[k] - start) @ u)
    t_robot = along / r.v_max
    assert t_robot - 0.1 <= ts[k] <= t_robot + r.v_max / (2 * r.a_max) + 2.0 + 0.1
    assert not math.isnan(along)


def test_suites(tmp_path, tiny_file):
    assert [s.name for s in resolve_suite("paper")] == ["paper-1", "paper-2", "paper-3"]
    assert len(resolve_suite("random", random_seed=1, per_count=1)) == 6
    assert [s.name for s in resolve_suite(str(tiny_file.parent))] == ["tiny"]
    assert [s.name for s in resolve_suite(f"{tiny_file},paper-1")] == ["tiny", "paper-1"]
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(SuiteError, match=r"no \.yaml"):
        resolve_suite(str(empty))
