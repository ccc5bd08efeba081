"""``import-crowd``: obsmat parsing, windows, the robot's task, exact replay, bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from anyplan.cli.main import main
from anyplan.experiments.crowds import (
    FRAME_RATE,
    PERSON_RADIUS,
    CrowdError,
    CrowdOptions,
    crowd_scenarios,
    read_obsmat,
)
from anyplan.world import load_scenario, scenario_from_dict
from tests.conftest import CROWDS


def _write_obsmat(path: Path, n_people=6, n_frames=200, seed=0) -> dict[int, np.ndarray]:
    rng = np.random.default_rng(seed)
    rows, truth = [], {}
    for pid in range(1, n_people + 1):
        f0 = int(rng.integers(0, 50)) * 10 + 1
        n = int(rng.integers(20, n_frames))
        x0, y0 = rng.uniform(0, 6), rng.uniform(0, 12)
        vx, vy = rng.uniform(-1, 1, 2)
        tr = []
        for k in range(n):
            f = f0 + 10 * k
            x, y = x0 + vx * 0.4 * k + 0.05 * np.sin(k), y0 + vy * 0.4 * k
            rows.append(f"{f:.7e} {pid:.7e} {x:.7e} 0.0000000e+00 {y:.7e} {vx:.7e} 0 {vy:.7e}")
            tr.append((f, x, y))
        truth[pid] = np.array(tr)
    path.write_text("\n".join(rows) + "\n")
    return truth


def test_windows_replay_every_sample_exactly(tmp_path):
    f = tmp_path / "toy_obsmat.txt"
    truth = _write_obsmat(f)
    tracks = read_obsmat(f)
    f0 = min(tr[0, 0] for tr in truth.values())
    for pid, tr in truth.items():
        np.testing.assert_array_equal(tracks[pid][:, 0], (tr[:, 0] - f0) / FRAME_RATE)
        np.testing.assert_allclose(tracks[pid][:, 1:], tr[:, 1:], rtol=0, atol=1e-6)
    opt = CrowdOptions(window_s=20.0, step_s=10.0)
    scs = crowd_scenarios(tracks, "toy", opt)
    assert scs
    allp = np.vstack(list(tracks.values()))
    shift = opt.margin_m - allp[:, 1:].min(axis=0)
    for d in scs:
        sc = scenario_from_dict(d)
        assert sc.sensing is not None and sc.sensing.mode == "tracked"
        assert sc.robot.radius == 0.3 and sc.robot.v_max == 1.0 and sc.robot.sensing_range == 8.0
        t0 = float(d["name"].split("-w")[1][:2]) * opt.step_s
        for o in sc.moving_obstacles:
            assert o.radius == PERSON_RADIUS
            pid = int(o.name[1:])
            src = tracks[pid]
            m = (src[:, 0] >= t0 - 1e-9) & (src[:, 0] <= t0 + opt.window_s + 1e-9)
            samples = o.motion.samples
            np.testing.assert_allclose(samples[:, 0], src[m, 0] - t0, atol=1e-9)
            # exact at every sample: the scenario's position is the recorded one, shifted
            np.testing.assert_allclose(o.motion.positions(samples[:, 0]), src[m, 1:] + shift,
                                       atol=1e-9)
        # the start is clear of everybody during the first two seconds
        st = np.array(sc.robot.start[:2])
        for t in np.arange(0.0, 2.0, 0.05):
            for o in sc.moving_obstacles:
                if o.motion.exists(t):
                    assert np.hypot(*(o.position(t) - st)) > sc.robot.radius + PERSON_RADIUS


def test_copies_make_the_crowd_denser(tmp_path):
    f = tmp_path / "toy_obsmat.txt"
    _write_obsmat(f)
    tracks = read_obsmat(f)
    one = crowd_scenarios(tracks, "toy", CrowdOptions(window_s=20.0, step_s=20.0))
    four = crowd_scenarios(tracks, "toy", CrowdOptions(window_s=20.0, step_s=20.0, copies=4,
                                                        copy_shift_s=7.0))
    n1 = sum(len(d["dynamic_obstacles"]) for d in one)
    n4 = sum(len(d["dynamic_obstacles"]) for d in four)
    assert n4 > 2 * n1


@pytest.mark.parametrize(("line", "words"), [
    ("1 2 3 4", "line 2: expected 8 finite numbers"),
    ("1 2 3 0 x 0 0 0", "line 2: expected 8 numbers"),
    ("1 2 3 0 nan 0 0 0", "line 2"),
])
def test_malformed_obsmat_row_is_one_line_exit_2(tmp_path, capsys, line, words):
    f = tmp_path / "bad.txt"
    f.write_text("1 1 0.5 0 0.5 0 0 0\n" + line + "\n")
    with pytest.raises(CrowdError, match=words):
        read_obsmat(f)
    assert main(["import-crowd", str(f), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.txt" in err and words.split(":")[0] in err


def test_bad_options_exit_2(tmp_path, capsys):
    f = tmp_path / "toy.txt"
    _write_obsmat(f)
    assert main(["import-crowd", str(f), "--out", str(tmp_path / "o"), "--sensor-noise", "-1"]) == 2
    assert "--sensor-noise" in capsys.readouterr().err
    assert main(["import-crowd", str(tmp_path / "nope.txt"), "--out", str(tmp_path / "o")]) == 2
    assert "no such file" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.skipif(not CROWDS.is_dir(), reason="shared crowd recordings not present")
def test_real_recordings_import(tmp_path):
    assert main(["import-crowd", str(CROWDS / "ucy_zara01_obsmat.txt"), "--out", str(tmp_path)]) == 0
    paths = sorted(tmp_path.glob("*.yaml"))
    assert len(paths) >= 5
    sc = load_scenario(paths[0])
    assert len(sc.moving_obstacles) > 5
