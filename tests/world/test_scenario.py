"""Scenario files: round trip, built-ins and every kind of bad input."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from anyplan.errors import ScenarioError, UnknownNameError
from anyplan.world import builtin_scenarios, load_scenario, scenario_from_dict
from tests.conftest import small_scenario_dict


def test_builtins_are_nested_and_match_table_1():
    assert {"paper-1", "paper-2", "paper-3"} <= set(builtin_scenarios())
    p = [load_scenario(f"paper-{n}") for n in (1, 2, 3)]
    assert [len(s.moving_obstacles) for s in p] == [1, 2, 3]
    for a, b in zip(p, p[1:], strict=False):
        assert a.static_obstacles == b.static_obstacles
        assert a.robot == b.robot
        n = len(a.moving_obstacles)
        assert [o.spec for o in a.moving_obstacles] == [o.spec for o in b.moving_obstacles][:n]
    r = p[2].robot
    assert (r.v_max, r.omega_max, r.a_max, r.alpha_max) == (0.4, 0.4, 0.4, 1.0)
    assert (p[2].width, p[2].height) == (15.0, 11.0)
    d = {o.name: o.motion for o in p[2].moving_obstacles}
    assert (d["D1"].v, d["D1"].omega) == (0.12, 0.0)
    assert (d["D2"].v, d["D2"].omega) == (0.12, -0.14)
    assert (d["D3"].v, d["D3"].omega) == (0.2, 0.0)
    assert 11.5 <= np.hypot(*(np.array(r.goal) - np.array(r.start[:2]))) <= 12.5


def test_each_moving_obstacle_crosses_the_straight_route_in_time():
    """A robot driving the straight route at v_max (ignoring obstacles) meets each of them."""
    sc = load_scenario("paper-3")
    r = sc.robot
    t = np.linspace(0.0, 60.0, 60001)
    a = r.a_max
    t_acc = r.v_max / a
    s = np.where(t < t_acc, 0.5 * a * t**2, 0.5 * a * t_acc**2 + r.v_max * (t - t_acc))
    d = np.array(r.goal) - np.array(r.start[:2])
    L = np.hypot(*d)
    pos = np.array(r.start[:2]) + np.minimum(s, L)[:, None] * d / L
    for o in sc.moving_obstacles:
        gap = np.hypot(*(o.motion.positions(t) - pos).T) - o.radius - r.radius
        assert gap.min() < 0.0, o.name


def test_round_trip_through_yaml(tmp_path):
    sc = load_scenario("paper-3")
    f = tmp_path / "p3.yaml"
    f.write_text(yaml.safe_dump(sc.to_dict()))
    back = load_scenario(f)
    assert back.content_hash() == sc.content_hash()
    assert back.robot == sc.robot


def _err(d, tmp_path=None) -> ScenarioError:
    with pytest.raises(ScenarioError) as ei:
        scenario_from_dict(d, "file.yaml")
    return ei.value


@pytest.mark.parametrize(("mutate", "field", "words"), [
    (lambda d: d["robot"].__setitem__("radius", -0.3), "robot.radius", "> 0"),
    (lambda d: d["robot"].__setitem__("v_max", 0.0), "robot.v_max", "> 0"),
    (lambda d: d["robot"].__setitem__("alpha_max", "fast"), "robot.alpha_max", "number"),
    (lambda d: d["robot"].pop("a_max"), "robot.a_max", "missing"),
    (lambda d: d["robot"].__setitem__("v_mx", 1.0), "robot.v_mx", "did you mean 'v_max'"),
    (lambda d: d.__setitem__("arena", {"width": 8.0}), "arena.height", "missing"),
    (lambda d: d["static_obstacles"][0].__setitem__("type", "rectangel"),
     "static_obstacles[0].type", "did you mean 'rectangle'"),
    (lambda d: d["static_obstacles"][0].__setitem__("size", [1.0, -1.0]),
     "static_obstacles[0].size[1]", "> 0"),
    (lambda d: d["static_obstacles"][0].__setitem__("centre", [1.0, 1.0]),
     "static_obstacles[0].centre", "did you mean 'center'"),
    (lambda d: d["dynamic_obstacles"][0].__setitem__("radius", -1), "dynamic_obstacles[0].radius", "> 0"),
    (lambda d: d["dynamic_obstacles"][0].__setitem__("start", [1, 2]), "dynamic_obstacles[0].start",
     "3 numbers"),
    (lambda d: d["robot"].__setitem__("start", [4.0, 5.0, 0.0]), "robot.start", "inside static obstacle S1"),
    (lambda d: d["robot"].__setitem__("goal", [9.0, 3.0]), "robot.goal", "outside the arena"),
    (lambda d: d["robot"].__setitem__("goal", [7.9, 3.0]), "robot.goal", "outside the arena"),
    (lambda d: d.__setitem__("unknown_top", 1), "unknown_top", "unknown key"),
])
def test_bad_input_names_the_field(mutate, field, words):
    d = copy.deepcopy(small_scenario_dict())
    mutate(d)
    e = _err(d)
    assert e.field == field
    assert words in str(e)
    assert str(e).startswith("file.yaml: ")
    assert "\n" not in str(e)


def test_a_start_or_goal_inside_an_obstacle_names_the_obstacle():
    d = copy.deepcopy(small_scenario_dict())
    d["robot"]["start"] = [4.0, 5.0, 0.0]
    e = _err(d)
    assert (e.field, e.obstacle) == ("robot.start", "S1")
    d["robot"]["start"] = [9.0, 5.0, 0.0]
    assert _err(d).obstacle is None  # outside the arena: about no obstacle


def test_malformed_yaml_and_missing_file(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("name: x\narena: {width: 15, height: [\n")
    with pytest.raises(ScenarioError, match="malformed YAML at line"):
        load_scenario(f)
    with pytest.raises(ScenarioError, match="no such file"):
        load_scenario(tmp_path / "none.yaml")
    f.write_text("")
    with pytest.raises(ScenarioError, match="empty"):
        load_scenario(f)


def test_unknown_builtin_suggests_nearest():
    with pytest.raises(UnknownNameError, match="did you mean 'paper-1'"):
        load_scenario("paper1")


def test_self_intersecting_polygon_is_a_scenario_error():
    d = small_scenario_dict()
    d["static_obstacles"] = [{"name": "S1", "type": "polygon",
                              "points": [[1, 1], [3, 3], [3, 1], [1, 2]]}]
    assert "cross" in str(_err(d))
