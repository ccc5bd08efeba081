"""Bad input to the importers (``import-crowd``, ``import-barn``, ``import-dynabarn``): one line
naming the file or flag and the field, exit code 2, never a traceback, silence or a hang."""

from __future__ import annotations

import contextlib
import json
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest

from anyplan.cli.main import main
from anyplan.experiments import barn, dynabarn
from anyplan.experiments.crowds import CrowdError, CrowdOptions, crowd_scenarios, read_obsmat

#: A BARN world: the side walls (x = -0.075, -4.425), the back row (y = 0.075) and two cylinders.
BARN_WORLD = {"world": 7, "reference_path_length_m": 11.25, "cylinders": [
    *([-0.075 - 0.15 * i, 0.075, 0.075] for i in range(30)),
    *([x, 0.075 + 0.15 * j, 0.075] for j in range(1, 64) for x in (-0.075, -4.425)),
    [-1.2, 6.0, 0.075], [-3.3, 8.85, 0.075]]}
#: A DynaBARN world: the three walls and two moving discs.
DYN_WORLD = {"world": 7, "walls": [
    {"name": "back_wall", "pose": [-10.0, 0.0, 0.5, 0, 0, 0], "size": [0.5, 20.0, 1.0]},
    {"name": "top_wall", "pose": [0.0, 10.0, 0.5, 0, 0, 0], "size": [20.0, 0.5, 1.0]},
    {"name": "bottom_wall", "pose": [0.0, -10.0, 0.5, 0, 0, 0], "size": [20.0, 0.5, 1.0]}],
    "moving": [{"name": "o1", "radius": 0.5, "period": 10.3,
                "keyframes": [[0.0, -8.67, -10.0], [5.56, 0.1, 3.3], [10.3, 10.0, 10.0]]},
               {"name": "o2", "radius": 0.5, "period": 4.0,
                "keyframes": [[0.0, 2.0, 2.0], [2.0, 2.0, -2.0], [4.0, 2.0, 2.0]]}]}


@contextlib.contextmanager
def _deadline(seconds: float = 20.0) -> Iterator[None]:
    """A hang becomes a failure after ``seconds`` (SIGALRM; the tests run in the main thread)."""
    def fail(signum, frame):  # noqa: ANN001, ANN202
        raise TimeoutError(f"still running after {seconds:g} s")

    old = signal.signal(signal.SIGALRM, fail)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def _refused(capsys, argv: list[str], *words: str) -> str:
    """``anyplan ARGV`` exits 2 with one line holding every word; returns the line."""
    with _deadline():
        assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("anyplan: error: ") and "Traceback" not in err
    for w in words:
        assert w in err, (w, err)
    return err


# ---------------------------------------------------------------------------------------------
# import-crowd
# ---------------------------------------------------------------------------------------------
def _obsmat(tmp_path: Path, rows: list[str], name: str = "rec.txt") -> Path:
    p = tmp_path / name
    p.write_text("\n".join(rows) + "\n")
    return p


def _small(tmp_path: Path, people: int = 3, frames: int = 80) -> Path:
    """``people`` walking side by side, 3 m apart, for ``frames`` annotations (0.4 s apart)."""
    rows = [f"{1 + 10 * k} {pid} {3.0 * pid} 0 {0.05 * k} 0 0 0.125"
            for k in range(frames) for pid in range(1, people + 1)]
    return _obsmat(tmp_path, rows, "small.txt")


def test_small_recording_imports(tmp_path, capsys):
    """The file the bad options below are given to is fine by itself."""
    assert main(["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"),
                 "--window", "10", "--step", "10", "--copies", "2", "--copy-shift", "7"]) == 0
    assert "wrote 3 scenarios" in capsys.readouterr().out


def test_huge_frame_number_is_refused_at_its_line(tmp_path, capsys):
    f = _obsmat(tmp_path, ["1 1 1.0 0 2.0 0 0 0", "11 1 1.5 0 2.0 0 0 0", "1e15 2 1.0 0 2.0 0 0 0",
                           "1.0000000001e15 2 1.2 0 2.0 0 0 0"], "huge_frame.txt")
    _refused(capsys, ["import-crowd", str(f), "--out", str(tmp_path / "o"), "--window", "0.2",
                      "--step", "0.2"], "huge_frame.txt: line 3: frame:", "2.5e+07", "1e+15")


@pytest.mark.parametrize(("argv", "words"), [
    (["--window", "10", "--step", "1e-9"], ("small.txt:", "--window", "--step", "about 2.16e+10",
                                            "limit 1000")),
    (["--window", "10", "--step", "0.0216"], ("small.txt:", "make 1001 scenarios")),
    (["--window", "10", "--step", "5e-324"], ("small.txt:", "--step", "limit 1000")),
    (["--window", "0.2", "--step", "0.01"], ("small.txt:", "--step", "make about 3.14e+03 scenarios")),
    (["--copies", "100000000"], ("--copies", "[1, 100]", "100000000")),
    (["--copies", "101"], ("--copies", "[1, 100]")),
])
def test_window_and_copy_counts_are_refused_at_once(tmp_path, capsys, argv, words):
    _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"), *argv],
             *words)
    assert not (tmp_path / "o").exists()


def test_a_recording_shorter_than_a_window_is_refused_not_written_empty(tmp_path, capsys):
    # 80 annotations 0.4 s apart: 31.6 s, less than one 40 s window ("wrote 0 scenarios", exit 0)
    _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"),
                      "--window", "40"], "small.txt:", "lasts 31.6 s", "less than one window of 40 s",
             "--window")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("shift", ["nan", "0", "-1", "inf", "2e6"])
def test_copy_shift_must_be_finite_and_positive(tmp_path, capsys, shift):
    _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"),
                      "--copies", "2", "--copy-shift", shift], "--copy-shift")
    with pytest.raises(CrowdError, match="copy_shift_s"):
        CrowdOptions(copies=2, copy_shift_s=float(shift)).check()


def test_bad_options_are_refused_when_made_before_any_file_is_read(tmp_path, capsys):
    with pytest.raises(CrowdError, match=r"^noise_m must be a finite number >= 0, got -1"):
        CrowdOptions(noise_m=-1.0)
    _refused(capsys, ["import-crowd", str(tmp_path / "missing.txt"), "--out", str(tmp_path / "o"),
                      "--sensor-noise", "-1"], "--sensor-noise must be a finite number >= 0")
    # an int beyond the float range: an OverflowError before; refused in one short line
    for opts in ({"window_s": 10**400}, {"robot": {"radius": -(10**400)}}):
        with pytest.raises(CrowdError, match=r"^(window_s|robot_radius) must be a finite number > 0, "
                                             r"got -?1000") as info:
            CrowdOptions(**opts)
        assert len(str(info.value)) < 100


def test_copies_that_coincide_are_refused(tmp_path, capsys):
    # The recording lasts 31.6 s, so T = 32 s: copy 2 shifted by 2 x 16 s lies on copy 0.
    _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"), "--copies",
                      "3", "--copy-shift", "16"], "small.txt:", "copies 0 and 2", "--copy-shift")


@pytest.mark.parametrize("name", ["../../escaped", "a/b", "..", ".hidden", "a\\b", "", "x" * 101])
def test_name_must_be_a_plain_stem(tmp_path, capsys, name):
    out = tmp_path / "o" / "x"
    _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(out), "--name", name],
             "--name", "plain file-name stem")
    assert not list(tmp_path.rglob("*.yaml"))


def test_a_plain_name_is_used(tmp_path):
    assert main(["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"), "--window", "10",
                 "--step", "10", "--name", "zara-01.b"]) == 0
    assert (tmp_path / "o" / "zara-01.b-w00.yaml").is_file()


@pytest.mark.parametrize(("row", "words"), [
    ("1 1 nan 0 2.0 0 0 0", ("line 2: x: expected a finite number, got nan",)),
    ("1 1 1 0 2.0 inf 0 0", ("line 2: vx: expected a finite number, got inf",)),
    ("11 1 1 0 -2e4 0 0 0", ("line 2: y: must be within +-10000",)),
    ("-5 1 1 0 2 0 0 0", ("line 2: frame: must be in [0, 2.5e+07]",)),
    ("11 1e12 1 0 2 0 0 0", ("line 2: person: id must be within",)),
])
def test_bad_row_values_name_the_line_and_column(tmp_path, capsys, row, words):
    f = _obsmat(tmp_path, ["1 2 1.0 0 2.0 0 0 0", row])
    with pytest.raises(CrowdError, match=r"rec\.txt: line 2: "):
        read_obsmat(f)
    err = _refused(capsys, ["import-crowd", str(f), "--out", str(tmp_path / "o")], "rec.txt", *words)
    assert "got 8" not in err


def test_huge_coordinate_names_the_file_and_line(tmp_path, capsys):
    f = _obsmat(tmp_path, ["1 1 1.0 0 2.0 0 0 0", "11 1 100000 0 2.0 0 0 0"], "huge_coord.txt")
    err = _refused(capsys, ["import-crowd", str(f), "--out", str(tmp_path / "o"), "--window", "0.2",
                            "--step", "0.2"], "huge_coord.txt: line 2: x:", "100000")
    assert "arena" not in err and "<" not in err


def test_arena_beyond_the_limit_names_the_file_and_the_margin(tmp_path, capsys):
    f = _obsmat(tmp_path, ["1 1 -900 0 2.0 0 0 0", "11 1 -899 0 2.0 0 0 0", "1 2 300 0 2 0 0 0",
                           "11 2 301 0 2 0 0 0"])
    _refused(capsys, ["import-crowd", str(f), "--out", str(tmp_path / "o"), "--window", "0.2",
                      "--step", "0.2"], "rec.txt: x spans -900 (person 1) to 301 m (person 2)",
             "--margin", "limit 1000 m")


@pytest.mark.parametrize(("flag", "value"), [
    ("--sensor-rate", "1e9"), ("--sensor-noise", "1e9"), ("--sensing-range", "1e9"),
    ("--window", "4000"), ("--robot-v-max", "1e9"), ("--robot-radius", "60"),
    ("--robot-goal-tolerance", "nan"),
])
def test_option_limits_are_told_with_the_flag(tmp_path, capsys, flag, value):
    err = _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"), flag,
                            value], f"anyplan: error: {flag} must be")
    assert "<" not in err and "does not convert" not in err


def test_robot_wider_than_the_edge_names_both_flags(tmp_path, capsys):
    _refused(capsys, ["import-crowd", str(_small(tmp_path)), "--out", str(tmp_path / "o"),
                      "--robot-radius", "1.0"], "--edge must be >= the robot's radius (--robot-radius")


def test_too_many_people_in_a_window_names_the_file_and_window(tmp_path, capsys):
    f = _small(tmp_path, people=30)
    err = _refused(capsys, ["import-crowd", str(f), "--out", str(tmp_path / "o"), "--window", "10",
                            "--step", "10", "--copies", "10", "--copy-shift", "3"],
                   "small.txt: window 0 (0-10 s after the first frame) holds 360 people (10 copies)",
                   "--copies", "--window")
    assert "dynamic_obstacles" not in err


def test_window_errors_name_the_source_and_the_person(tmp_path):
    tracks = read_obsmat(_small(tmp_path))
    bad = tracks[2].copy()
    bad[3, 0] = bad[2, 0]  # two samples at one time: only a hand-made track has this
    with pytest.raises(CrowdError, match=r"^rec\.txt: window 0 \(0-10 s after the first frame\): "
                                         r"person 2: "):
        crowd_scenarios({**tracks, 2: bad}, "toy", CrowdOptions(window_s=10.0, step_s=10.0),
                        source="rec.txt")


# ---------------------------------------------------------------------------------------------
# import-dynabarn
# ---------------------------------------------------------------------------------------------
def _json(tmp_path: Path, data: object, name: str = "worlds.json") -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(data))
    return p


def _dyn(capsys, tmp_path, data, *words, worlds="0"):
    src = _json(tmp_path, data)
    err = _refused(capsys, ["import-dynabarn", "--worlds-file", str(src), "--out", str(tmp_path / "o"),
                            "--worlds", worlds], f"{src}: ", *words)
    assert "--worlds" not in err and "dynamic_obstacles" not in err and "<dynabarn" not in err
    assert not (tmp_path / "o").exists()  # nothing written
    return err


@pytest.mark.parametrize(("data", "words"), [
    ([], ("expected a non-empty JSON list of worlds",)),
    ([{**DYN_WORLD, "world": "x"}], ("[0].world: expected an integer index, got 'x'",)),
    ([{k: v for k, v in DYN_WORLD.items() if k != "world"}], ("[0].world: missing",)),
    ([{**DYN_WORLD, "world": -3}], ("[0].world: must be in [0, 999]", "-3")),
    ([{**DYN_WORLD, "world": 10**400}], ("[0].world: must be in [0, 999]",)),
    ([{**DYN_WORLD, "world": 0}, {**DYN_WORLD, "world": 0}], ("world 0 appears twice ([0] and [1])",)),
    ([{**DYN_WORLD, "world": 0, "colour": "red"}], ("world 0: unknown key 'colour'",)),
])
def test_dynabarn_world_indices_and_keys(tmp_path, capsys, data, words):
    _dyn(capsys, tmp_path, data, *words)
    with pytest.raises(dynabarn.DynaBARNError, match=r"worlds\.json: "):
        dynabarn.load_worlds(tmp_path / "worlds.json")


def _moving(change: dict, k: int = 0) -> dict:
    moving = [dict(m) for m in DYN_WORLD["moving"]]
    moving[k].update(change)
    return {**DYN_WORLD, "world": 0, "moving": moving}


def _wall(change: dict) -> dict:
    walls = [dict(w) for w in DYN_WORLD["walls"]]
    walls[1].update(change)
    return {**DYN_WORLD, "world": 0, "walls": walls}


@pytest.mark.parametrize(("world", "words"), [
    (_moving({"radius": -1}), ("world 0.moving[0].radius: expected a positive number, got -1",)),
    (_moving({"radius": 10**400}), ("world 0.moving[0].radius: expected a finite number",)),
    (_moving({"speed": 3}, 1), ("world 0.moving[1]: unknown key 'speed'",)),
    (_moving({"name": "a\nb"}, 1), ("world 0.moving[1].name: expected a name",)),
    (_moving({"keyframes": [[0.0, 2.0, 2.0], [2.0, 2.0, -2.0], [2.0, 2.0, 2.0]], "period": 2.0}, 1),
     ("world 0.moving[1].keyframes", "increase")),
    (_wall({"colour": "red"}), ("world 0.walls[1]: unknown key 'colour'",)),
    (_wall({"size": [20.0, -0.5, 1.0]}), ("world 0.walls[1].size: expected a positive number",)),
    ({**DYN_WORLD, "world": 0, "walls": 5}, ("world 0.walls: expected a list of walls",)),
])
def test_dynabarn_world_errors_name_the_file_and_the_source_field(tmp_path, capsys, world, words):
    _dyn(capsys, tmp_path, [world], *words)


def test_dynabarn_world_to_scenario_names_the_source(tmp_path):
    with pytest.raises(dynabarn.DynaBARNError, match=r"^w\.json: world 0\.moving\[0\]\.radius"):
        dynabarn.world_to_scenario(_moving({"radius": -1}), source="w.json")


@pytest.mark.parametrize(("index", "words"), [
    ("x", "world entry.world: expected an integer index, got 'x'"),
    (-3, "world entry.world: must be in [0, 999] (the stated limit), got -3"),
])
def test_dynabarn_world_to_scenario_checks_the_index_as_load_worlds_does(index, words):
    with pytest.raises(dynabarn.DynaBARNError, match=r"^w\.json: ") as ei:
        dynabarn.world_to_scenario({**DYN_WORLD, "world": index}, source="w.json")
    assert words in str(ei.value)


def test_dynabarn_unknown_keys_of_unconverted_worlds_are_refused_too(tmp_path, capsys):
    _dyn(capsys, tmp_path, [{**DYN_WORLD, "world": 0}, {**DYN_WORLD, "world": 1, "colour": 1}],
         "world 1: unknown key 'colour'")


# ---------------------------------------------------------------------------------------------
# import-barn
# ---------------------------------------------------------------------------------------------
def _barn(capsys, tmp_path, data, *words):
    src = _json(tmp_path, data)
    err = _refused(capsys, ["import-barn", "--source", str(src), "--out", str(tmp_path / "o"),
                            "--no-feasibility"], f"{src}: ", *words)
    assert "robot.start" not in err and "<barn" not in err
    assert not (tmp_path / "o").exists()  # nothing written
    return err


@pytest.mark.parametrize(("command", "flag", "module", "error", "input_name", "dataset"), [
    ("import-barn", "--source", barn, barn.BARNError, "source", "BARN"),
    ("import-dynabarn", "--worlds-file", dynabarn, dynabarn.DynaBARNError, "worlds_file", "DynaBARN"),
])
def test_a_missing_worlds_file_names_the_importers_own_input(tmp_path, capsys, command, flag, module,
                                                             error, input_name, dataset):
    missing = tmp_path / "none.json"
    with pytest.raises(error) as ei:
        module.load_worlds(missing)
    assert str(ei.value) == f"{missing}: no such file (pass {input_name} PATH to the {dataset} worlds.json)"
    assert ei.value.subject == str(missing) and ei.value.also == (input_name,)
    _refused(capsys, [command, flag, str(missing), "--out", str(tmp_path / "o")],
             f"{missing}: no such file (pass {flag} PATH to the {dataset} worlds.json)")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(("data", "words"), [
    ([{**BARN_WORLD, "world": -3}], ("[0].world: must be in [0, 999] (the stated limit), got -3",)),
    ([{**BARN_WORLD, "world": 1000}], ("[0].world: must be in [0, 999]",)),
    ([{**BARN_WORLD, "colour": "red"}], ("world 7: unknown key 'colour'",)),
    ([{**BARN_WORLD, "reference_path_length": 3}],
     ("world 7: unknown key 'reference_path_length'; did you mean 'reference_path_length_m'?",)),
    ([{**BARN_WORLD, "reference_path_length_m": 10**400}],
     ("world 7.reference_path_length_m: expected a finite number",)),
    ([BARN_WORLD, BARN_WORLD], ("world 7 appears twice ([0] and [1])",)),
])
def test_barn_world_indices_and_keys(tmp_path, capsys, data, words):
    _barn(capsys, tmp_path, data, *words)
    with pytest.raises(barn.BARNError, match=r"worlds\.json: "):
        barn.load_worlds(tmp_path / "worlds.json")


@pytest.mark.parametrize(("cylinder", "which"), [
    ([-2.25, 3.0, 0.5], "start (-2.25, 3)"), ([-2.0, 12.8, 0.075], "goal (-2.25, 13)")])
def test_barn_cylinder_on_the_task_names_the_file_and_cylinder(tmp_path, capsys, cylinder, which):
    world = {**BARN_WORLD, "cylinders": [*BARN_WORLD["cylinders"], cylinder]}
    k = len(world["cylinders"]) - 1
    _barn(capsys, tmp_path, [world], f"world 7.cylinders[{k}]: ", f"the challenge's {which}",
          "robot radius 0.34")


def test_world_indices_stay_in_range_and_parse_fast():
    with _deadline(5.0):
        assert dynabarn.parse_worlds("all", 1000) == list(range(1000))
        assert dynabarn.parse_worlds("0-999,5,0-999", 1000) == list(range(1000))
    assert barn.parse_worlds("3,1-2") == [3, 1, 2]
