"""st-bitstar centres its virtual squares on the obstacle (anchor=obstacle): on paper-1 it arrives
within 3 % of the time lower bound, ahead of the paper's robot-anchored squares (seq-bitstar)."""

from __future__ import annotations

from anyplan.agents import make_agent
from anyplan.simulation import simulate
from anyplan.world import load_scenario

FIXED = {"planning_delay": 0.1, "batches_per_plan": 2, "max_time_s": 10.0}


def test_st_bitstar_passes_behind_d1_near_the_time_lower_bound():
    sc = load_scenario("paper-1")
    st = simulate(sc, make_agent("st-bitstar", **FIXED, search_budget_s=None), seed=1)
    seq = simulate(sc, make_agent("seq-bitstar", **FIXED), seed=1)
    assert st.status == "reached" and not st.collision
    assert st.time_over_lower_bound <= 1.03
    assert st.time_to_goal_s < seq.time_to_goal_s
