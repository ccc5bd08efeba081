"""st-bitstar's loop searches at most ``extrapolated_iterations`` paths per replanning while an
obstacle's future is extrapolated (``twist``, ``tracked``), and the loop's own
``max_iterations`` when every motion is announced."""

from __future__ import annotations

from pathlib import Path

import pytest

from anyplan.agents import AGENTS, make_agent
from anyplan.simulation import simulate
from anyplan.world.scenario import scenario_from_dict

_DYNABARN = Path(__file__).resolve().parents[3] / "shared" / "benchmarks" / "dynabarn" / "worlds.json"
needs_dynabarn = pytest.mark.skipif(not _DYNABARN.is_file(),
                                    reason="shared DynaBARN worlds.json not present")


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
