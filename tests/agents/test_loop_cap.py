"""st-bitstar's loop searches at most ``extrapolated_iterations`` paths per replanning while an
obstacle's future is extrapolated (``twist``, ``tracked``), and the loop's own
``max_iterations`` when every motion is announced; no long waits among uncertain discs."""

from __future__ import annotations

import pytest

from anyplan.agents import AGENTS, make_agent
from anyplan.simulation import simulate
from anyplan.world.scenario import scenario_from_dict
from tests.conftest import DYNABARN_WORLDS as _DYNABARN
from tests.conftest import needs_dynabarn


def _world(i: int, mode: str):
    from anyplan.experiments.dynabarn import load_worlds, world_to_scenario
    from anyplan.simulation.perception import override_sensing

    world = next(w for w in load_worlds(_DYNABARN) if w["world"] == i)
    return override_sensing(scenario_from_dict(world_to_scenario(world)), mode)


def _searches(mode: str, **kw) -> list[int]:
    """BIT* plans of each replanning in DynaBARN world 43 (an obstacle turns into the robot's
    way: some replannings search deep), deterministic, seed 0."""
    cfg = {**AGENTS.get("st-bitstar").deterministic_settings, **kw}
    return simulate(_world(43, mode), make_agent("st-bitstar", **cfg), seed=0).extra["iterations"]


@needs_dynabarn
def test_the_loop_searches_at_most_the_cap_while_a_future_is_extrapolated():
    assert max(_searches("twist", extrapolated_iterations=None)) > 4  # the loop's 8 would go on
    assert max(_searches("twist")) == 4  # the default cap, reached
    assert max(_searches("tracked", extrapolated_iterations=2)) == 2


@needs_dynabarn
def test_announced_motions_keep_the_loops_own_cap():
    its = _searches("oracle")
    assert 4 < max(its) <= AGENTS.get("st-bitstar")().config.max_iterations


def test_bad_caps_are_refused_with_the_settings_name():
    for bad in (0, -1, 2.5, "4", True):
        with pytest.raises(ValueError, match="extrapolated_iterations"):
            make_agent("st-bitstar", extrapolated_iterations=bad)
    assert make_agent("st-bitstar", extrapolated_iterations=None).extrapolated_iterations is None


def _timings(sc, **kw) -> tuple[list[float], int]:
    """The longest wait [s] each timing of a run allowed (``_timed_fn``'s ``max_wait_s``, or its
    ``first_wait_s`` for the branch and bound's first path), and how many replannings timed no
    path; deterministic, seed 0."""
    import anyplan.agents.spacetime as stm

    waits: list[float] = []
    inner = stm.SpaceTimeBITStarAgent._timed_fn

    def spy(self, state, t_start, max_wait_s, *, first_wait_s=None):
        waits.append(max(max_wait_s, first_wait_s or 0.0))
        return inner(self, state, t_start, max_wait_s, first_wait_s=first_wait_s)

    agent = make_agent("st-bitstar", **{**AGENTS.get("st-bitstar").deterministic_settings, **kw})
    mp = pytest.MonkeyPatch()
    mp.setattr(stm.SpaceTimeBITStarAgent, "_timed_fn", spy)
    try:
        simulate(sc, agent, seed=0)
    finally:
        mp.undo()
    return waits, agent.record.st_candidates.count(0)


@needs_dynabarn
def test_no_long_waits_among_uncertain_discs():
    # Tracked obstacles (discs that end at the horizon): the replannings that time no path do
    # not try the long waits (until 2026-12-05 they did: the horizon, 3.1 s for the Jackal,
    # exceeds patience_s). With announced motions the spy sees them (the branch and bound
    # times the shortest path with long waits first).
    long = AGENTS.get("st-bitstar")().max_wait_s
    waits, empty = _timings(_world(43, "tracked"))
    assert empty > 0 and waits and max(waits) < long
    waits, _ = _timings(_world(43, "oracle"))
    assert max(waits) >= long
