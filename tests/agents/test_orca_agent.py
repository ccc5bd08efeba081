"""The ``orca`` peer (optional ``pyrvo``): skipped cleanly when the extra is absent."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.simulation import SimConfig, simulate
from anyplan.world import scenario_from_dict
from tests.conftest import small_scenario_dict

pytest.importorskip("pyrvo")


@pytest.mark.parametrize("mode", ["twist", "tracked"])
def test_orca_drives_the_unicycle_to_the_goal_within_its_limits(mode):
    from anyplan.agents import make_agent

    d = small_scenario_dict()
    d["sensing"] = {"mode": mode}
    sc = scenario_from_dict(d)
    res = simulate(sc, make_agent("orca"), seed=0, config=SimConfig(time_limit=40.0))
    assert res.reached_goal and not res.collision
    tr = res.trajectory_array
    assert np.all(np.abs(tr[:, 4]) <= sc.robot.v_max + 1e-12)
    assert np.all(tr[:, 4] >= -1e-12)  # forward only
    assert len(res.planning_times_s) > 10
