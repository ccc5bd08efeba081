"""OMPL's STRRT* peer (optional: its runs are skipped unless the ompl 1.7 wheel can be imported;
its motion validator's test of the moving obstacles needs no ompl).

Set ``ANYPLAN_STRRT_SITE`` to a ``pip install --target`` directory of ``ompl==1.7.0`` to run
these tests beside an ompl 2.0 install.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from anyplan.experiments.strrt import _clear_of_movers, solve_strrt, strrt_available
from anyplan.geometry.moving import first_contact
from anyplan.world.motion import UnicycleMotion, WaypointMotion
from anyplan.world.scenario import scenario_from_dict

SITE = os.environ.get("ANYPLAN_STRRT_SITE")
needs_ompl = pytest.mark.skipif(not strrt_available(SITE), reason="no ompl 1.7 with STRRTstar")


@pytest.mark.slow
@needs_ompl
def test_strrt_solves_a_crossing_exactly():
    sc = scenario_from_dict({
        "name": "strrt-crossing", "time_limit": 60.0, "arena": {"width": 8.0, "height": 4.0},
        "robot": {"start": [1.0, 2.0, 0.0], "goal": [7.0, 2.0], "radius": 0.3, "v_max": 0.5,
                  "omega_max": 1.0, "a_max": 0.5, "alpha_max": 1.0},
        "static_obstacles": [{"name": "B", "type": "rectangle", "center": [4.0, 3.6],
                              "size": [1.0, 0.8]}],
        "dynamic_obstacles": [{"name": "X", "start": [4.0, 0.4, math.pi / 2], "v": 0.3,
                               "radius": 0.3}]}, "<test>")
    out = solve_strrt(sc, 1.0, seed=0, site=SITE)
    assert out["solved"], out
    p = np.array(out["path"])
    assert np.allclose(p[0], [1.0, 2.0, 0.0])
    assert np.allclose(p[-1, :2], [7.0, 2.0])
    dt = np.diff(p[:, 2])
    assert np.all(dt > 0.0)
    assert np.all(np.hypot(*np.diff(p[:, :2], axis=0).T) / dt <= 0.5 * (1 + 1e-6))
    mover = sc.moving_obstacles[0].motion
    for a, b in zip(p[:-1], p[1:], strict=True):
        def robot(t, a=a, b=b):
            u = ((np.asarray(t) - a[2]) / (b[2] - a[2]))[:, None]
            return a[:2] + u * (b[:2] - a[:2])

        assert first_contact(robot, mover.positions, 0.5 + 0.3, 0.6, a[2], b[2]) is None
    assert out["goal_edge_s"] <= out["arrival_s"]
    assert out["arrival_s"] >= 6.0 / 0.5  # no faster than straight at v_max


def test_the_motion_validator_checks_between_the_jumps_of_an_open_track():
    # The robot waits at (10, 3) from t = 2 to t = 9. B's open track starts 0.55 m from it
    # (within the 0.6 m reach), leaves at 2 m/s and jumps back onto the robot at t = 5.01,
    # clear again 0.025 s later: between two points of first_contact's initial scan, and no
    # speed bound holds across the jump. The validator must search each piece between jumps.
    b = WaypointMotion(np.array([[0.0, 10.55, 3.0], [1.0, 12.55, 3.0], [5.01, 14.0, 3.0]]))
    assert b.jump_times(2.0, 9.0) == [5.01]
    ts = np.linspace(2.0, 9.0, 700001)
    assert np.min(np.hypot(*(b.positions(ts) - (10.0, 3.0)).T)) < 0.6  # the truth: a contact
    assert not _clear_of_movers([(b, 0.3)], 0.3, (10.0, 3.0, 2.0), (10.0, 3.0, 9.0), 0.0)
    # before the jump (and for a motion that never jumps) nothing changes
    assert _clear_of_movers([(b, 0.3)], 0.3, (10.0, 3.0, 2.0), (10.0, 3.0, 5.0), 0.0)
    line = UnicycleMotion(4.0, 3.0, 0.0, 0.5)  # reaches 0.6 m from (10, 3) at t = 10.8
    assert _clear_of_movers([(line, 0.3)], 0.3, (10.0, 3.0, 2.0), (10.0, 3.0, 10.7), 0.0)
    assert not _clear_of_movers([(line, 0.3)], 0.3, (10.0, 3.0, 2.0), (10.0, 3.0, 10.9), 0.0)
    assert not _clear_of_movers([(line, 0.3)], 0.3, (10.0, 3.0, 2.0), (7.5, 3.0, 7.0), 0.5)
