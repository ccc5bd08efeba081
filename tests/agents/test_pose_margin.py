"""The clearance kept for the robot's localization error (``pose_margin_m``): the margin a way
leaves room for (``reachable_margin``, against the corridor's exact width), the robot keeping it
along its run, reduced where a passage is narrower, and bad values."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.agents import make_agent
from anyplan.agents.settings import deterministic_settings
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import rectangle
from anyplan.planning.visgraph import reachable_margin, usable_margin
from anyplan.simulation import SimConfig, simulate
from anyplan.world import scenario_from_dict
from tests.conftest import small_scenario_dict


def _corridor(width: float) -> ObstacleSet:
    """Two walls leaving a gap of ``width`` [m] around y = 0.5 between x = 0 and x = 4; the
    arena's bounds leave no way around them."""
    lo, hi = 0.5 - 0.5 * width, 0.5 + 0.5 * width
    return ObstacleSet([rectangle((2.0, 0.5 * (lo - 1.0)), (4.0, lo + 1.0)),
                        rectangle((2.0, 0.5 * (hi + 2.0)), (4.0, 2.0 - hi))],
                       bounds=(-2.0, -1.0, 6.0, 2.0))


@pytest.mark.parametrize("width", [0.62, 0.7, 0.83, 0.95, 1.1])
def test_the_margin_a_corridor_leaves_room_for(width):
    r, most, tol = 0.3, 0.2, 0.005
    m = reachable_margin(_corridor(width), (-1.0, 0.5), (5.0, 0.5), r, most, tol)
    room = 0.5 * width - r  # on each side of a disc in the middle
    assert m == pytest.approx(min(room, most), abs=tol)
    assert m <= room + 1e-9  # never more than the corridor leaves


def test_no_margin_where_the_disc_does_not_pass_and_all_of_it_where_it_does():
    assert reachable_margin(_corridor(0.55), (-1.0, 0.5), (5.0, 0.5), 0.3, 0.1) == 0.0
    assert reachable_margin(_corridor(2.0), (-1.0, 0.5), (5.0, 0.5), 0.3, 0.1) == 0.1
    assert reachable_margin(_corridor(2.0), (-1.0, 0.5), (5.0, 0.5), 0.3, 0.0) == 0.0


def _around_a_box(width: float = 1.0):
    d = small_scenario_dict(dynamic_obstacles=[], static_obstacles=[
        {"name": "S", "type": "rectangle", "center": [4.0, 3.0], "size": [1.0, width], "angle": 0.0}])
    return scenario_from_dict(d)


@pytest.mark.parametrize("planner", ["seq-bitstar", "st-bitstar", "bitstar"])
def test_the_robot_keeps_the_margin_from_the_static_obstacles(planner):
    sc = _around_a_box()
    cls = type(make_agent(planner))
    runs = {}
    for m in (0.0, 0.1):
        det = {} if planner == "bitstar" else deterministic_settings(cls, planner)  # one plan
        agent = make_agent(planner, **det, pose_margin_m=m)
        runs[m] = simulate(sc, agent, seed=1, config=SimConfig())
        assert runs[m].status == "reached"
    bare, kept = runs[0.0], runs[0.1]
    assert "pose_margin_m" not in bare.extra
    assert kept.extra["pose_margin_m"] == 0.1
    # without it the path hugs the box; with it the robot keeps the margin (plus the smoothing's)
    assert bare.min_clearance_m < 0.08
    assert kept.min_clearance_m >= 0.1 + 0.015 - 1e-3


def test_a_narrow_way_keeps_a_centimetre_of_what_it_leaves():
    # the box fills the arena but for two gaps of 0.75 m: 0.075 m of room each side of the disc
    sc = _around_a_box(width=6.0 - 2 * 0.75)
    agent = make_agent("st-bitstar", **deterministic_settings(type(make_agent("st-bitstar")), "st-bitstar"),
                       pose_margin_m=0.2)
    res = simulate(sc, agent, seed=1, config=SimConfig())
    room = reachable_margin(sc.obstacle_set(), sc.robot.start[:2], sc.robot.goal, 0.3 + 0.03, 0.2)
    assert 0.03 < room < 0.1
    assert res.extra["pose_margin_m"] == pytest.approx(room - 0.01)
    assert res.status == "reached"


@pytest.mark.parametrize("planner", ["st-bitstar", "bitstar"])
@pytest.mark.parametrize("value", [-0.1, float("nan"), float("inf"), "0.1"])
def test_bad_pose_margins_are_refused(planner, value):
    with pytest.raises(ValueError, match="pose_margin_m"):
        make_agent(planner, pose_margin_m=value)


@pytest.mark.parametrize("width", [0.73, 0.83, 1.1])
def test_usable_margin_is_what_is_asked_or_the_room_less_a_centimetre(width):
    walls, ends = _corridor(width), ((-1.0, 0.5), (5.0, 0.5))
    room = reachable_margin(walls, *ends, 0.3, 1.0)
    for wanted in (0.05, 0.1, 0.2):
        got = usable_margin(walls, *ends, 0.3, wanted)
        left = reachable_margin(walls, *ends, 0.3, wanted)
        assert got == (wanted if room >= wanted else pytest.approx(max(left - 0.01, 0.5 * left)))
        assert got <= min(wanted, room) + 1e-9


def test_no_way_no_margin():
    walls = _corridor(0.5)
    assert reachable_margin(walls, np.array([-1.0, 0.5]), np.array([5.0, 0.5]), 0.3, 0.2) == 0.0
