"""Scenario fields refused with the right field and limit: duplicate obstacle names, headings
beyond the angle limit, fast ``track`` samples, and ``sensing:`` keys that only ``tracked`` reads."""

from __future__ import annotations

import hashlib
import json

import pytest
import yaml

from anyplan.cli.main import main
from anyplan.errors import ScenarioError, UnknownNameError
from anyplan.simulation.perception import override_sensing
from anyplan.world import load_scenario, scenario_from_dict
from tests.conftest import small_scenario_dict


def _refused(tmp_path, d) -> ScenarioError:
    """The error of loading ``d`` from a file: it names that file, on one line."""
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(d))
    with pytest.raises(ScenarioError) as ei:
        load_scenario(f)
    e = ei.value
    assert e.source == str(f) and str(e).startswith(f"{f}: {e.field}: ") and "\n" not in str(e)
    return e


def _track(name, samples):
    return {"name": name, "type": "track", "radius": 0.3, "samples": samples}


@pytest.mark.parametrize(("statics", "moving", "field", "first"), [
    ([{"name": "S1", "type": "circle", "center": [2.0, 1.0], "radius": 0.3}], None,
     "static_obstacles[1].name", "static_obstacles[0]"),
    ([], [_track("D1", [[0, 6, 1], [1, 6, 2]])], "dynamic_obstacles[1].name", "dynamic_obstacles[0]"),
    ([], [_track("S1", [[0, 6, 1], [1, 6, 2]])], "dynamic_obstacles[1].name", "static_obstacles[0]"),
    # a default name (S2 for the second static obstacle) taken by a moving one
    ([{"type": "circle", "center": [2.0, 1.0], "radius": 0.3}], [_track("S2", [[0, 6, 1], [1, 6, 2]])],
     "dynamic_obstacles[1].name", "static_obstacles[1]"),
])
def test_a_duplicate_obstacle_name_is_told_at_the_obstacle(tmp_path, statics, moving, field, first):
    d = small_scenario_dict()
    d["static_obstacles"] += statics
    d["dynamic_obstacles"] += moving or []
    e = _refused(tmp_path, d)
    assert e.field == field and "is used twice" in e.message and f"also by {first}" in e.message


def test_moving_obstacles_alias_is_named_in_the_duplicate_field(tmp_path):
    d = small_scenario_dict()
    d["moving_obstacles"] = d.pop("dynamic_obstacles") + [_track("D1", [[0, 6, 1], [1, 6, 2]])]
    assert _refused(tmp_path, d).field == "moving_obstacles[1].name"


@pytest.mark.parametrize("theta", [1e5, 1e6, -2e4])
@pytest.mark.parametrize("where", ["robot", "unicycle"])
def test_a_heading_beyond_the_angle_limit_gets_the_angle_limit(tmp_path, theta, where):
    """As a heading of 5000 rad did already: beyond 10,000 rad it got the coordinate limit."""
    d = small_scenario_dict()
    pose = d["robot"]["start"] if where == "robot" else d["dynamic_obstacles"][0]["start"]
    field = "robot.start" if where == "robot" else "dynamic_obstacles[0].start"
    x, y, _ = pose
    pose[2] = theta
    e = _refused(tmp_path, d)
    assert e.field == f"{field}[2]" and "within +-1000 (the stated limit)" in e.message
    pose[2] = 5000.0
    assert _refused(tmp_path, d).message == "must be within +-1000 (the stated limit), got 5000"
    pose[:] = [2e4, y, 0.0]  # the coordinates keep the coordinate limit
    e = _refused(tmp_path, d)
    assert e.field == f"{field}[0]" and "within +-10000 (the stated limit)" in e.message
    pose[:] = [x, y, -1000.0]  # at the limit: accepted
    sc = scenario_from_dict(d)
    assert (sc.robot.start if where == "robot" else sc.moving_obstacles[0].motion.state(0.0))[2] == -1000.0


@pytest.mark.parametrize("samples", [
    [[0, 5, 3.5], [1e-9, 5000, 3.5]],  # about 5e12 m/s
    [[0, 1, 1], [1, 1, 1], [3, 2003, 1]],  # 1001 m/s on the second segment
])
def test_track_samples_are_no_faster_than_the_obstacle_speed_limit(tmp_path, samples):
    d = small_scenario_dict(dynamic_obstacles=[_track("P1", samples)])
    e = _refused(tmp_path, d)
    assert e.field == "dynamic_obstacles[0].samples"
    assert "faster than 1000 m/s (the stated limit)" in e.message
    d["dynamic_obstacles"][0]["samples"] = [[0, 1, 1], [2, 2001, 1]]  # 1000 m/s: the limit itself
    assert scenario_from_dict(d).moving_obstacles[0].motion.max_speed == pytest.approx(1000.0)


_TRACKED_VALUES = {"noise_m": 0.5, "rate_hz": 5.0, "association": "anonymous", "detection_prob": 0.9,
                   "clutter_rate": 1.0, "occlusion": "all"}


@pytest.mark.parametrize("key", list(_TRACKED_VALUES))
@pytest.mark.parametrize("mode", ["oracle", "twist"])
def test_sensing_keys_only_tracked_reads_are_refused_in_other_modes(tmp_path, mode, key):
    from anyplan.world.sensing import TRACKED_ONLY

    assert set(TRACKED_ONLY) == set(_TRACKED_VALUES)
    d = small_scenario_dict(sensing={"mode": mode, key: _TRACKED_VALUES[key]})
    e = _refused(tmp_path, d)
    assert e.field == f"sensing.{key}" and f"mode is '{mode}'" in e.message
    assert "only mode: tracked reads it" in e.message


def test_an_overridden_mode_round_trips_and_keeps_its_hash():
    """A tracked scenario run with --perception twist: its block is written without the keys
    twist does not read, and its content hash (the key of its stored runs) is the one hashed
    before they were refused."""
    sc = scenario_from_dict(small_scenario_dict(sensing={"mode": "tracked", "noise_m": 0.3}))
    twist = override_sensing(sc, "twist")
    assert twist.to_dict()["sensing"] == {"mode": "twist"}
    assert scenario_from_dict(twist.to_dict()).sensing.mode == "twist"
    before = twist.to_dict()
    before["sensing"] = {"mode": "twist", "noise_m": 0.3, "rate_hz": 10.0}  # as to_dict wrote it
    digest = hashlib.sha256(json.dumps(before, sort_keys=True, default=float).encode()).hexdigest()
    assert twist.content_hash() == digest[:16]
    # tracked reads them all, and writes them
    sc = scenario_from_dict(small_scenario_dict(sensing={"mode": "tracked", **_TRACKED_VALUES}))
    assert sc.sensing.noise_m == 0.5 and sc.sensing.occlusion == "all"
    assert scenario_from_dict(sc.to_dict()).sensing == sc.sensing


def test_a_block_stored_before_is_read_without_the_unread_keys():
    from anyplan.world.sensing import without_unread_settings

    old = {"mode": "oracle", "noise_m": 0.05, "rate_hz": 10.0}
    assert without_unread_settings(old) == {"mode": "oracle"}
    tracked = {"mode": "tracked", "noise_m": 0.3}
    assert without_unread_settings(tracked) is tracked
    from anyplan.viz.report import _scenarios

    class Stored:
        def experiments(self):
            return [{"id": 1, "setup": json.dumps(small_scenario_dict(sensing=old))}]

    assert _scenarios(Stored())[1].sensing.mode == "oracle"


def test_an_empty_scenario_name_is_not_the_current_folder():
    for name in ("", "  "):
        with pytest.raises(UnknownNameError, match="unknown scenario"):
            load_scenario(name)


@pytest.mark.parametrize(("mutate", "field"), [
    (lambda d: d["static_obstacles"].append(dict(d["static_obstacles"][0])), "static_obstacles[1].name"),
    (lambda d: d["robot"]["start"].__setitem__(2, 1e6),
     "robot.start[2]: must be within +-1000 (the stated limit)"),
    (lambda d: d.__setitem__("sensing", {"mode": "oracle", "noise_m": 0.5}), "sensing.noise_m"),
    (lambda d: d["dynamic_obstacles"].append(_track("P", [[0, 1, 1], [1e-3, 5, 1]])),
     "dynamic_obstacles[1].samples"),
])
def test_plan_refuses_them_with_one_line_naming_file_and_field(tmp_path, capsys, mutate, field):
    d = small_scenario_dict()
    mutate(d)
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(d))
    assert main(["plan", str(f), "--time", "0.01"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{f}: {field}" in err and "Traceback" not in err
