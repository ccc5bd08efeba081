"""The steppable simulator (:class:`Simulation`) and agent objects reused across runs."""

from __future__ import annotations

import pytest

from anyplan.agents import make_agent
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.simulator import Simulation
from anyplan.world import load_scenario


def test_stepping_by_hand_gives_the_result_of_simulate():
    sc = load_scenario("paper-1")
    cfg = SimConfig(time_limit=20.0, stop_on_collision=False)
    ref = simulate(sc, make_agent("straight"), seed=2, config=cfg)
    agent = make_agent("straight")
    agent.reset(sc.static_only(), None)
    sim = Simulation(sc, cfg)
    while not sim.done:
        sim.step(agent.act(sim.observation()))
    got = sim.result(agent.name, 2, agent.stats)
    assert ref.collision  # the straight robot hits an obstacle here: the case is not trivial
    assert got.trajectory == ref.trajectory
    assert (got.status, got.collision_with, got.collision_time_s, got.min_clearance_m, got.path_length_m) == \
        (ref.status, ref.collision_with, ref.collision_time_s, ref.min_clearance_m, ref.path_length_m)
    with pytest.raises(RuntimeError, match="over"):
        sim.step(agent.act(sim.observation()))


def test_an_agent_object_reused_for_two_runs_reports_each_run_alone():
    sc = load_scenario("paper-2")
    cfg = SimConfig(time_limit=4.0)
    agent = make_agent("dovs")
    first = simulate(sc, agent, seed=0, config=cfg)
    second = simulate(sc, agent, seed=0, config=cfg)
    fresh = simulate(sc, make_agent("dovs"), seed=0, config=cfg)
    assert len(first.planning_times_s) > 0
    assert len(second.planning_times_s) == len(fresh.planning_times_s) == len(first.planning_times_s)
    assert second.extra == fresh.extra  # counters of selection modes start from zero again
    assert second.trajectory == fresh.trajectory
