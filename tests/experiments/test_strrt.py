"""OMPL's STRRT* peer (optional: skipped unless the ompl 1.7 wheel can be imported).

Set ``ANYPLAN_STRRT_SITE`` to a ``pip install --target`` directory of ``ompl==1.7.0`` to run
these tests beside an ompl 2.0 install.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

from anyplan.experiments.strrt import solve_strrt, strrt_available
from anyplan.geometry.moving import first_contact
from anyplan.world.scenario import scenario_from_dict

SITE = os.environ.get("ANYPLAN_STRRT_SITE")
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not strrt_available(SITE), reason="no ompl 1.7 with STRRTstar")]


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
