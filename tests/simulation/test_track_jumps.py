"""An open looping track (DynaBARN) jumps back to its first keyframe: the teleport is not a
motion, so the simulator must not test its chord, while the real motion stays tested exactly."""

from __future__ import annotations

import numpy as np

from anyplan.agents.base import Agent
from anyplan.simulation import SimConfig, simulate
from anyplan.world import Command, scenario_from_dict
from anyplan.world.motion import WaypointMotion
from tests.conftest import small_scenario_dict


class StandStill(Agent):
    """Never moves."""

    name = "stand-still"

    def reset(self, scenario, rng):
        pass

    def act(self, obs):
        return Command(0.0, 0.0)


def _scenario(keyframes, start):
    d = small_scenario_dict(
        arena={"width": 12.0, "height": 6.0},
        robot={"start": [*start, 0.0], "goal": [11.0, 5.0], "radius": 0.3, "v_max": 0.5,
               "omega_max": 0.8, "a_max": 0.5, "alpha_max": 1.0},
        static_obstacles=[],
        dynamic_obstacles=[{"name": "W", "type": "waypoints", "keyframes": keyframes,
                            "radius": 0.3}])
    return scenario_from_dict(d)


# Open track along y = 1 from x = 1 to x = 11 in 5 s (2 m/s), then back to x = 1 at once.
OPEN = [[0.0, 1.0, 1.0], [5.0, 11.0, 1.0]]


def test_jumps_of_an_open_track_are_reported_once_each():
    m = WaypointMotion(np.array(OPEN))
    assert m.jumps(0.0, 4.99) == ()
    (j,) = m.jumps(4.96, 5.0)
    assert j.time == 5.0 and tuple(j.before) == (11.0, 1.0) and tuple(j.after) == (1.0, 1.0)
    assert m.jumps(5.0, 5.05) == ()  # the jump at the end of the last step is not seen again
    assert [j.time for j in m.jumps(9.0, 21.0)] == [10.0, 15.0, 20.0]
    closed = WaypointMotion(np.array([[0.0, 1.0, 1.0], [2.0, 3.0, 1.0], [4.0, 1.0, 1.0]]))
    assert closed.jumps(0.0, 100.0) == ()


# Around the robot at (6, 3): up from (2, 3), across at y = 5.5, down to (10, 3) at 2 m/s, then
# back to (2, 3) at once: the jump's chord runs through the robot, the real motion never nearer
# than 2.5 m (centre to centre).
AROUND = [[0.0, 2.0, 3.0], [1.25, 2.0, 5.5], [5.25, 10.0, 5.5], [6.5, 10.0, 3.0]]


def test_the_teleport_is_not_tested_as_a_sweep():
    res = simulate(_scenario(AROUND, (6.0, 3.0)), StandStill(), seed=0,
                   config=SimConfig(time_limit=20.0))  # three jumps
    assert not res.collision
    assert abs(res.min_clearance_m - (2.5 - 0.6)) < 1e-9


def test_the_real_motion_of_an_open_track_still_hits():
    # The same track, the robot on its first leg: hit at the first pass, t = 0.5 s (contact
    # when the centres are 0.6 m apart: the disc at y = 3.4 after 0.2 s).
    res = simulate(_scenario(AROUND, (2.0, 4.0)), StandStill(), seed=0,
                   config=SimConfig(time_limit=20.0))
    assert res.collision and res.collision_with == "W"
    assert abs(res.collision_time_s - 0.2) < 0.051
