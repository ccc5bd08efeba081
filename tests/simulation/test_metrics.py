"""Crowd metrics against hand computations: minimum distance and discomfort time."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.simulation.metrics import moving_obstacle_metrics
from anyplan.world import scenario_from_dict
from tests.conftest import small_scenario_dict


def _traj(points, dt=0.05):
    return np.array([[i * dt, x, y, 0, 0, 0] for i, (x, y) in enumerate(points)])


def test_passing_person_gives_exact_distance_and_discomfort_time():
    # robot parked at (2, 3), radius 0.3; a person (0.25) walks along y = 3.5 at 1 m/s from x = 0
    d = small_scenario_dict(static_obstacles=[], dynamic_obstacles=[
        {"name": "P", "type": "track", "radius": 0.25, "samples": [[0.0, 0.0, 3.6], [4.0, 4.0, 3.6]]}])
    sc = scenario_from_dict(d)
    m = moving_obstacle_metrics(sc, _traj([(2.0, 3.0)] * 101))
    assert m["min_distance_to_moving_m"] == pytest.approx(0.6 - 0.55)
    # within 0.2 m of the disc: centre distance < 0.75, |x - 2| < sqrt(0.75^2 - 0.6^2) = 0.45
    assert m["discomfort_time_s"] == pytest.approx(2 * 0.45, abs=1e-9)


def test_overlapping_intervals_of_two_people_are_merged_and_spans_are_honoured():
    d = small_scenario_dict(static_obstacles=[], dynamic_obstacles=[
        {"name": "P", "type": "track", "radius": 0.25, "samples": [[0.0, 0.0, 3.6], [4.0, 4.0, 3.6]]},
        {"name": "Q", "type": "track", "radius": 0.25, "samples": [[0.0, 0.0, 2.4], [4.0, 4.0, 2.4]]},
        # R stands on the robot but only exists after the run: ignored
        {"name": "R", "type": "track", "radius": 0.25, "samples": [[9.0, 2.0, 3.0], [10.0, 2.0, 3.0]]}])
    sc = scenario_from_dict(d)
    m = moving_obstacle_metrics(sc, _traj([(2.0, 3.0)] * 101))
    assert m["discomfort_time_s"] == pytest.approx(0.9, abs=1e-9)
    assert m["min_distance_to_moving_m"] == pytest.approx(0.05)
    # a person who stopped 0.15 m from the robot is gone afterwards (no phantom at its last sample)
    d["dynamic_obstacles"] = [{"name": "S", "type": "track", "radius": 0.25,
                               "samples": [[0.0, 4.0, 3.0], [1.0, 2.7, 3.0]]}]
    # the robot waits at x = 0.5 while S exists (until t = 1 s), then drives onto S's last spot
    pts = [(0.5, 3.0)] * 21 + [(0.5 + 2.2 * k / 80, 3.0) for k in range(1, 81)]
    m = moving_obstacle_metrics(scenario_from_dict(d), _traj(pts))
    assert m["min_distance_to_moving_m"] == pytest.approx(2.2 - 0.55)
    assert m["discomfort_time_s"] == 0.0


def test_moving_robot_against_dense_sampling():
    rng = np.random.default_rng(2)
    d = small_scenario_dict(static_obstacles=[], dynamic_obstacles=[
        {"name": f"P{i}", "type": "track", "radius": 0.25,
         # sample times on the step grid: between steps both motions are then straight chords
         "samples": np.column_stack([0.05 * np.sort(rng.choice(101, 4, replace=False)),
                                     rng.uniform(1, 7, 4),
                                     rng.uniform(1, 5, 4)]).tolist()} for i in range(6)])
    sc = scenario_from_dict(d)
    pts = np.column_stack([np.linspace(1, 7, 101), 3 + np.sin(np.linspace(0, 3, 101))])
    tr = _traj(pts)
    m = moving_obstacle_metrics(sc, tr)
    t = np.linspace(0, 5, 500001)
    x, y = np.interp(t, tr[:, 0], tr[:, 1]), np.interp(t, tr[:, 0], tr[:, 2])
    near = np.zeros(len(t), bool)
    best = math.inf
    for o in sc.moving_obstacles:
        p = o.motion.positions(t)
        ex = (t >= o.motion.span[0]) & (t <= o.motion.span[1])
        dd = np.hypot(x - p[:, 0], y - p[:, 1]) - 0.55
        best = min(best, dd[ex].min())
        near |= ex & (dd < 0.2)
    assert m["min_distance_to_moving_m"] == pytest.approx(best, abs=1e-4)
    assert m["discomfort_time_s"] == pytest.approx(near.mean() * 5.0, abs=2e-4)


@pytest.mark.parametrize("period", [7.0, 6.97])  # a jump at a step's end, one inside a step
def test_the_jump_of_an_open_track_is_not_a_motion(period):
    # J runs (4, 1) -> (16, 1) in 6 s, up to (16, 5), then jumps back to (4, 1): the jump's
    # chord passes through (10, 3), where the robot is then; its real motion never comes near
    sc = scenario_from_dict(small_scenario_dict(
        arena={"width": 20.0, "height": 6.0}, static_obstacles=[], dynamic_obstacles=[
            {"name": "J", "type": "waypoints", "radius": 0.3,
             "keyframes": [[0.0, 4.0, 1.0], [6.0, 16.0, 1.0], [period, 16.0, 5.0]]}]))
    m = sc.moving_obstacles[0].motion
    assert m.may_jump and m.jump_times(0.0, 8.0) == [period]
    # the robot dips towards y = 1 (J passes within the discomfort distance at t = 3), then
    # stands at (10, 3) while J jumps
    ts = 0.05 * np.arange(161)
    tr = _traj(np.column_stack([np.full(161, 10.0),
                                3.0 - 1.3 * np.sin(np.pi * np.minimum(ts, 6.0) / 6.0)]))
    got = moving_obstacle_metrics(sc, tr)
    # truth: the robot on its chords, J densely sampled on each piece between its jumps
    t = np.concatenate([np.linspace(a, b, 400001) for a, b in m.continuous_pieces(0.0, 8.0)])
    x, y = np.interp(t, tr[:, 0], tr[:, 1]), np.interp(t, tr[:, 0], tr[:, 2])
    q = m.positions(t)
    dd = np.hypot(x - q[:, 0], y - q[:, 1]) - 0.6
    assert got["min_distance_to_moving_m"] == pytest.approx(dd.min(), abs=1e-4)
    assert dd.min() > 0.0  # (the chord across the jump would give an overlap)
    near = dd < 0.2
    dt = np.diff(t)
    assert got["discomfort_time_s"] == pytest.approx(float(np.sum(dt[near[:-1]])), abs=2e-4)
    assert got["discomfort_time_s"] > 0.3  # J's real pass below the robot
