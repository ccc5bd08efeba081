"""BARN conversion: exact cylinder positions, arena, robot, task, feasibility, errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from anyplan.cli.main import main
from anyplan.experiments.barn import (
    ARENA,
    INDEX_FILE,
    JACKAL,
    SHIFT,
    BARNError,
    convert,
    feasibility,
    load_index,
    load_worlds,
    parse_worlds,
    world_to_scenario,
)
from anyplan.geometry.shapes import Circle
from anyplan.world.scenario import load_scenario, scenario_from_dict
from tests.conftest import BARN_WORLDS as SHARED


def _walls() -> list[list[float]]:
    """BARN's walls: the side columns (x = -0.075, -4.425) and the back row (y = 0.075)."""
    xs = [-0.075 - 0.15 * i for i in range(30)]
    cyl = [[x, 0.075, 0.075] for x in xs]
    cyl += [[x, 0.075 + 0.15 * j, 0.075] for j in range(1, 64) for x in (-0.075, -4.425)]
    return cyl


def _row(y: float, gap: int) -> list[list[float]]:
    """A row of cylinders across the field at ``y`` with ``gap`` consecutive ones removed around
    the middle: the free width between the neighbours' surfaces is 0.15 * gap m."""
    xs = [-0.225 - 0.15 * i for i in range(28)]
    lo = 14 - gap // 2
    return [[x, y, 0.075] for i, x in enumerate(xs) if not lo <= i < lo + gap]


WORLD = {"world": 7, "reference_path_length_m": 11.25,
         "cylinders": [*_walls(), [-1.234567891, 6.02, 0.075], [-3.3, 8.85, 0.075]]}


def _write(tmp_path, worlds, name="worlds.json"):
    p = tmp_path / name
    p.write_text(json.dumps(worlds))
    return p


def _check_exact(world, sc):
    assert len(sc.static_obstacles) == len(world["cylinders"])
    for k, (src, ob) in enumerate(zip(world["cylinders"], sc.static_obstacles, strict=True)):
        assert ob.name == f"c{k}" and isinstance(ob.shape, Circle)
        want = np.array(src[:2]) + np.array(SHIFT)
        assert np.array_equal(np.asarray(ob.shape.center), want)  # bitwise
        assert ob.shape.radius == src[2]


def test_cylinders_are_exact_through_the_yaml_file(tmp_path):
    (path,) = convert(_write(tmp_path, [WORLD]), tmp_path / "out", [7])
    sc = load_scenario(path)
    _check_exact(WORLD, sc)
    assert sc.name == "barn-007" and sc.time_limit == 100.0
    assert (sc.width, sc.height) == ARENA == (4.5, 14.0)
    r = sc.robot
    assert r.start == (2.25, 3.0, 1.57) and r.goal == (2.25, 13.0)  # BARN (-2.25, 3) -> (-2.25, 13)
    assert r.goal_tolerance == 1.0 and r.v_max == 2.0
    assert (r.omega_max, r.a_max, r.alpha_max) == (4.0, 20.0, 25.0)


def test_the_disc_contains_the_jackal_footprint():
    assert JACKAL["radius"] >= math.hypot(0.508 / 2, 0.430 / 2)
    assert JACKAL["radius"] - math.hypot(0.508 / 2, 0.430 / 2) < 0.01  # and not much more


def _check_shipped(worlds):
    for w in worlds:
        sc = scenario_from_dict(world_to_scenario(w))
        _check_exact(w, sc)
        c = np.array([o.shape.center for o in sc.static_obstacles])
        rad = np.array([o.shape.radius for o in sc.static_obstacles])
        assert (c - rad[:, None] >= -1e-12).all()
        assert (c[:, 0] + rad <= sc.width + 1e-12).all() and (c[:, 1] + rad <= sc.height).all()
        assert sc.robot.goal[1] > c[:, 1].max() + 1.0  # the goal lies past the field's far end


@pytest.mark.skipif(not SHARED.is_file(), reason="shared BARN worlds.json not present")
def test_shipped_worlds_convert_exactly_and_fit_the_arena():
    worlds = load_worlds(SHARED)
    assert [w["world"] for w in worlds] == list(range(300))
    _check_shipped([worlds[0], worlds[157], worlds[299]])


@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_file(), reason="shared BARN worlds.json not present")
def test_every_shipped_world_converts_exactly_and_fits_the_arena():
    _check_shipped(load_worlds(SHARED))


def test_feasibility_follows_the_gap_width():
    def fe(gap):
        w = {"world": 1, "reference_path_length_m": 10.0, "cylinders": [*_walls(), *_row(7.0, gap)]}
        return feasibility(scenario_from_dict(world_to_scenario(w)))

    wide, narrow = fe(5), fe(4)  # free widths 0.75 m and 0.60 m against the disc's 0.68 m
    assert wide.status == "feasible" and 10.0 <= wide.lower_m <= wide.path_m < 10.5
    assert narrow.status == "infeasible" and narrow.lower_m == math.inf


def test_cli_import_writes_the_index(tmp_path, capsys):
    blocked = {"world": 8, "reference_path_length_m": 12.5,
               "cylinders": [*_walls(), *_row(7.0, 4)]}
    src = _write(tmp_path, [WORLD, blocked])
    assert main(["import-barn", "--source", str(src), "--worlds", "7-8", "--out",
                 str(tmp_path / "o")]) == 0
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == [
        "barn-007.yaml", "barn-008.yaml", INDEX_FILE]
    out = capsys.readouterr().out
    assert "wrote 2 scenarios" in out and "feasible for the 0.34 m disc: 1/2; not: barn-008" in out
    idx = load_index(tmp_path / "o")
    assert idx["barn-007"]["feasibility"] == "feasible"
    assert idx["barn-008"]["feasibility"] == "infeasible"
    assert idx["barn-008"]["reference_path_length_m"] == 12.5
    assert idx["barn-008"]["optimal_time_s"] == 6.25
    # A second import of another world keeps the first ones in the index.
    assert main(["import-barn", "--source", str(src), "--worlds", "7", "--no-feasibility",
                 "--out", str(tmp_path / "o")]) == 0
    assert set(load_index(tmp_path / "o")) == {"barn-007", "barn-008"}


@pytest.mark.parametrize(("argv", "message"), [
    (["--source", "missing.json"], "missing.json: no such file"),
    (["--worlds", "3-x"], "is not an index or a range"),
    (["--worlds", "9-5"], "empty range"),
    (["--worlds", "300"], "outside 0-299"),
])
def test_cli_errors_are_one_line(tmp_path, capsys, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    if "--source" not in argv:
        argv = [*argv, "--source", str(_write(tmp_path, [{**WORLD, "world": i} for i in range(300)]))]
    assert main(["import-barn", "--out", "o", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_default_source_missing_is_a_clear_error(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["import-barn", "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert "worlds.json: no such file (pass --source" in err and err.count("\n") == 1


@pytest.mark.parametrize(("change", "message"), [
    ({"cylinders": [[-1.0, 6.0]]}, r"world 7\.cylinders\[0\]: expected \[x, y, radius\]"),
    ({"cylinders": [[-1.0, 6.0, -0.1]]}, r"world 7\.cylinders\[0\]\.radius: expected a positive"),
    ({"cylinders": [[-1.0, "6", 0.075]]}, r"world 7\.cylinders\[0\]: expected a finite number"),
    ({"cylinders": [[1.0, 6.0, 0.075]]}, r"world 7\.cylinders\[0\]: .*outside the arena"),
    ({"cylinders": []}, r"world 7\.cylinders: expected a non-empty list"),
    ({"reference_path_length_m": None}, r"world 7\.reference_path_length_m: expected a finite"),
    ({"world": "7"}, r"\[0\]\.world: expected an integer"),
])
def test_malformed_worlds_name_file_and_field(tmp_path, capsys, change, message):
    src = _write(tmp_path, [{**WORLD, **change}])
    with pytest.raises(BARNError, match=r"worlds\.json: .*" + message):
        load_worlds(src)
    assert main(["import-barn", "--source", str(src), "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_bad_files_and_worlds(tmp_path):
    with pytest.raises(BARNError, match="not a readable JSON file"):
        load_worlds(_text(tmp_path, "{"))
    with pytest.raises(BARNError, match="expected a non-empty JSON list"):
        load_worlds(_write(tmp_path, {"world": 1}))
    with pytest.raises(BARNError, match="world 7 appears twice"):
        load_worlds(_write(tmp_path, [WORLD, WORLD]))
    with pytest.raises(BARNError, match="world 5 is not in"):
        convert(_write(tmp_path, [WORLD]), tmp_path / "o", [5])
    on_start = {**WORLD, "cylinders": [*WORLD["cylinders"], [-2.25, 3.0, 0.075]]}
    with pytest.raises(BARNError, match=r"world 7\.cylinders\[158\]: .*the challenge's start"):
        world_to_scenario(on_start)
    with pytest.raises(BARNError, match="no such file"):
        load_index(tmp_path)
    assert parse_worlds("0-2,5,1") == [0, 1, 2, 5] and len(parse_worlds("all")) == 300


def _text(tmp_path, text):
    p = tmp_path / "bad.json"
    p.write_text(text)
    return p
