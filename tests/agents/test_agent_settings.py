"""Every planner's listed settings (``anyplan planners --settings``) can be set, and a value that
would fail inside a run is refused when the agent is built (exit code 2 on the command line)."""

from __future__ import annotations

import importlib.util
import math

import pytest

from anyplan.agents import AGENTS
from anyplan.agents.settings import SettingsError, agent_settings, build_agent_config, parse_set_options

PLANNERS = [p for p in AGENTS.names()
            if p != "orca" or importlib.util.find_spec("pyrvo") is not None]


#: Settings a planner cannot be built without (listed with the default None).
REQUIRED = {"policy": {"policy": "math:hypot"}}


@pytest.mark.parametrize("planner", PLANNERS)
def test_every_listed_setting_accepts_its_listed_default(planner):
    cls = AGENTS.get(planner)
    for name, s in agent_settings(cls).items():
        options = dict(REQUIRED.get(planner, {}))
        options.setdefault(name, s.default)
        build_agent_config(cls, planner, options)


def test_the_planning_delay_cap_is_a_setting_of_the_replanning_planners():
    from anyplan.agents.sequential import SequentialBITStarAgent
    from anyplan.agents.spacetime import SpaceTimeBITStarAgent

    for cls in (SequentialBITStarAgent, SpaceTimeBITStarAgent):
        assert cls(max_delay_s=0.4).max_delay_s == 0.4
        assert cls().max_delay_s == cls().config.max_time_s  # default: the loop's own cap


@pytest.mark.parametrize(("planner", "item", "words"), [
    ("seq-bitstar", "grid_step=0", "grid_step: must be > 0"),
    ("st-bitstar", "grid_step=.nan", "grid_step: must be > 0"),
    ("seq-bitstar", "urgent_s=-1", "urgent_s: must be >= 0"),
    ("seq-bitstar", "min_replan_interval_s=-1", "min_replan_interval_s: must be >= 0"),
    ("st-bitstar", "max_delay_s=0", "max_delay_s: must be > 0"),
    ("bitstar", "control_dt=0", "control_dt: must be > 0"),
    ("bitstar", "control_dt=.nan", "control_dt: must be > 0"),
    ("straight", "heading_gain=-1", "heading_gain: must be > 0"),
    ("straight", "align_tolerance=-1", "align_tolerance: must be >= 0"),
])
def test_a_value_that_would_fail_inside_a_run_is_refused_when_built(planner, item, words):
    with pytest.raises(SettingsError, match=words):
        build_agent_config(AGENTS.get(planner), planner, parse_set_options([item]))


def test_an_integer_beyond_the_float_range_is_refused_in_a_short_line():
    from anyplan.agents.straight import StraightAgent

    # checked_number raised an OverflowError here
    with pytest.raises(ValueError, match=r"^heading_gain: must be > 0, got 1000") as info:
        StraightAgent(heading_gain=10**400)
    assert len(str(info.value)) < 100


@pytest.mark.parametrize(("planner", "item", "shown"), [
    ("straight", "heading_gain=" + "9" * 400, "heading_gain=999"),
    ("straight", "align_tolerance=-" + "9" * 400, "align_tolerance=-999"),
    ("st-bitstar", f"wait_delays_s=[1, {'9' * 400}]", "wait_delays_s=[1, 999"),  # an item of a list
])
def test_a_float_setting_given_an_integer_beyond_the_float_range_is_refused_by_name(planner, item, shown):
    # _coerce's float() raised an OverflowError here
    with pytest.raises(SettingsError) as info:
        build_agent_config(AGENTS.get(planner), planner, parse_set_options([item]))
    msg = str(info.value)
    assert msg.startswith(f"setting {shown}") and "number too large" in msg, msg
    assert len(msg) < 150 and "\n" not in msg


@pytest.mark.parametrize("text", ["9" * 5000, "2020-13-45", "[" * 5000])
def test_yaml_python_cannot_hold_is_refused_by_name(text):
    # an int of more than 4300 digits or a date out of the calendar (ValueError), deep nesting
    # (RecursionError): each escaped as itself before
    with pytest.raises(SettingsError, match=r"^setting heading_gain: cannot read '") as info:
        parse_set_options([f"heading_gain={text}"])
    assert len(str(info.value)) < 120


@pytest.mark.skipif(importlib.util.find_spec("pyrvo") is None, reason="needs the orca extra (pyrvo)")
@pytest.mark.parametrize(("item", "words"), [
    ("safety_m=-1", "safety_m: must be >= 0"), ("period_s=0", "period_s: must be > 0"),
    ("time_horizon_s=.nan", "time_horizon_s: must be > 0"),
    ("max_neighbors=0", "max_neighbors: must be an integer >= 1"),
])
def test_orca_refuses_values_pyrvo_would_choke_on(item, words):
    with pytest.raises(SettingsError, match=words):
        build_agent_config(AGENTS.get("orca"), "orca", parse_set_options([item]))


def test_counts_of_the_tracker_are_whole_numbers_and_its_settings_bounded():
    from anyplan.config import SettingError
    from anyplan.prediction.tracking import TrackerConfig

    assert TrackerConfig(visible_misses=5.0, confirm_hits=3).visible_misses == 5.0
    for name, value in (("visible_misses", 0.5), ("confirm_hits", 2.5)):
        with pytest.raises(SettingError, match=f"{name}: must be a whole number"):
            TrackerConfig(**{name: value})
    # without a bound, sigma_m = 1e300 overflowed halfway through a run
    for name in ("sigma_m", "q_cv", "q_ct", "gate_m", "drop_after_s"):
        with pytest.raises(SettingError, match=name):
            TrackerConfig(**{name: 1e300})
    assert math.isfinite(TrackerConfig(sigma_m=10.0).sigma_m)
