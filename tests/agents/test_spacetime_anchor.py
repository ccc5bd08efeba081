"""st-bitstar centres its virtual squares on the obstacle (anchor=obstacle): on paper-1 it arrives
within 3 % of the time lower bound, ahead of the paper's robot-anchored squares (seq-bitstar)."""

from __future__ import annotations

import numpy as np

from anyplan.agents import make_agent
from anyplan.simulation import simulate
from anyplan.world import load_scenario

FIXED = {"planning_delay": 0.1, "batches_per_plan": 2, "max_time_s": 10.0}


def test_st_bitstar_passes_in_front_of_d1_near_the_time_lower_bound():
    sc = load_scenario("paper-1")
    st = simulate(sc, make_agent("st-bitstar", **FIXED, search_budget_s=None), seed=1)
    seq = simulate(sc, make_agent("seq-bitstar", **FIXED), seed=1)
    assert st.status == "reached" and not st.collision
    # In front of D1 (docs/spacetime.md), not behind it: D1 walks up the line x = 5 (+y, from
    # y = 4.39 at 0.12 m/s). When the robot crosses that line, D1 has not yet reached the
    # crossing point: along D1's direction of motion, the robot is ahead of D1 by more than
    # the two radii (0.3 + 0.3).
    d1 = next(o for o in sc.moving_obstacles if o.name == "D1")
    tr = st.trajectory_array  # rows (t, x, y, ...)
    k = int(np.argmax(tr[:, 1] >= 5.0))
    assert tr[k - 1, 1] < 5.0 <= tr[k, 1]  # the first step at or past the line
    heading = np.array([np.cos(d1.motion.theta0), np.sin(d1.motion.theta0)])
    ahead = float((tr[k, 1:3] - d1.motion.positions(np.array([tr[k, 0]]))[0]) @ heading)
    assert ahead > d1.radius + sc.robot.radius
    assert st.time_over_lower_bound <= 1.03
    assert st.time_to_goal_s < seq.time_to_goal_s
