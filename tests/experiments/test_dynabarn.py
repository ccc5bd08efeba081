"""DynaBARN conversion: exact obstacle positions at the keyframes, arena, robot, errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from anyplan.cli.main import main
from anyplan.experiments.dynabarn import (
    JACKAL,
    SHIFT,
    DynaBARNError,
    convert,
    load_worlds,
    parse_worlds,
    world_to_scenario,
)
from anyplan.world.scenario import load_scenario
from tests.conftest import DYNABARN_WORLDS as SHARED
from tests.conftest import needs_dynabarn

WORLD = {"world": 7, "walls": [
    {"name": "back_wall", "pose": [-10.0, 0.0, 0.5, 0, 0, 0], "size": [0.5, 20.0, 1.0]},
    {"name": "top_wall", "pose": [0.0, 10.0, 0.5, 0, 0, 0], "size": [20.0, 0.5, 1.0]},
    {"name": "bottom_wall", "pose": [0.0, -10.0, 0.5, 0, 0, 0], "size": [20.0, 0.5, 1.0]}],
    "moving": [{"name": "o1", "radius": 0.5, "period": 10.3,
                "keyframes": [[0.0, -8.67, -10.0], [1.59, -7.78, -9.33], [5.56, 0.1, 3.3],
                              [10.3, 10.0, 10.0]]},
               {"name": "o2", "radius": 0.5, "period": 4.0,
                "keyframes": [[0.0, 2.0, 2.0], [2.0, 2.0, -2.0], [4.0, 2.0, 2.0]]}]}


def _write(tmp_path, worlds):
    p = tmp_path / "worlds.json"
    p.write_text(json.dumps(worlds))
    return p


def _check_exact(world, scenario):
    for src, mo in zip(world["moving"], scenario.moving_obstacles, strict=True):
        kf = np.array(src["keyframes"], dtype=float)
        want = kf[:, 1:] + np.array(SHIFT)
        period = kf[-1, 0]
        # First loop: exact (bitwise) at every keyframe but the last, which wraps to the first.
        got = mo.motion.positions(kf[:-1, 0])
        assert np.array_equal(got, want[:-1])
        # Just before the end of the loop the track reaches the last keyframe.
        assert np.allclose(mo.motion.position(np.nextafter(period, 0.0)), want[-1], atol=1e-9)
        # Later loops repeat the track (interior keyframes: an open track jumps at the wrap).
        assert np.allclose(mo.motion.positions(kf[1:-1, 0] + 3 * period), want[1:-1], atol=1e-9)
        assert mo.radius == src["radius"]


def test_keyframes_are_exact_through_the_yaml_file(tmp_path):
    (path,) = convert(_write(tmp_path, [WORLD]), tmp_path / "out", [7])
    sc = load_scenario(path)
    _check_exact(WORLD, sc)
    assert sc.name == "dynabarn-07" and sc.time_limit == 100.0
    r = sc.robot
    assert r.v_max == 2.0 and r.radius == JACKAL["radius"] and r.goal_tolerance == 1.0
    assert r.start == (21.5, 10.5, np.pi) and r.goal == (1.5, 10.5)  # (11, 0, pi) -> (-9, 0)
    assert [o.name for o in sc.static_obstacles] == ["back_wall", "top_wall", "bottom_wall"]


@needs_dynabarn
def test_every_shipped_world_converts_exactly_and_fits_the_arena(tmp_path):
    worlds = load_worlds(SHARED)
    assert len(worlds) == 60
    for w in worlds:
        from anyplan.world.scenario import scenario_from_dict

        sc = scenario_from_dict(world_to_scenario(w))
        _check_exact(w, sc)
        for mo in sc.moving_obstacles:
            k = mo.motion.keyframes
            # Between keyframes the track is a segment, so keyframes bound the whole motion.
            assert (k[:, 1] >= mo.radius).all() and (k[:, 1] <= sc.width - mo.radius).all()
            assert (k[:, 2] >= mo.radius).all() and (k[:, 2] <= sc.height - mo.radius).all()


def test_cli_import(tmp_path, capsys):
    src = _write(tmp_path, [WORLD, {**WORLD, "world": 8}])
    assert main(["import-dynabarn", "--worlds-file", str(src), "--worlds", "7-8", "--out",
                 str(tmp_path / "o")]) == 0
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == ["dynabarn-07.yaml", "dynabarn-08.yaml"]
    assert "wrote 2 scenarios" in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "message"), [
    (["--worlds-file", "missing.json"], "missing.json: no such file"),
    (["--worlds", "3-x"], "is not an index or a range"),
    (["--worlds", "90"], "outside 0-59"),
])
def test_cli_errors_are_one_line(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    if "--worlds-file" not in argv:
        argv = [*argv, "--worlds-file", str(_write(tmp_path, [{**WORLD, "world": i} for i in range(60)]))]
    assert main(["import-dynabarn", "--out", "o", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_default_path_missing_is_a_clear_error(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["import-dynabarn", "--out", "o"]) == 2
    assert "worlds.json: no such file" in capsys.readouterr().err


def test_malformed_worlds_name_the_field(tmp_path):
    bad = {**WORLD, "moving": [{"name": "o", "radius": 0.5,
                                "keyframes": [[0.0, 1.0, 2.0], [1.0, 30.0, 0.0]]}]}
    with pytest.raises(DynaBARNError, match=r"world 7\.moving\[0\]\.keyframes\[1\].*outside the arena"):
        world_to_scenario(bad)
    bad = {**WORLD, "moving": [{"radius": 0.5, "period": 9.0,
                                "keyframes": [[0.0, 1.0, 2.0], [1.0, 3.0, 0.0]]}]}
    with pytest.raises(DynaBARNError, match="differs from the period"):
        world_to_scenario(bad)
    assert parse_worlds("0-2,5,1") == [0, 1, 2, 5]
