"""Animations: frame timing, virtual obstacles appear when created, plans follow time, errors."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from anyplan.agents import make_agent
from anyplan.cli.main import main
from anyplan.simulation import simulate
from anyplan.viz.animation import animate_run, check_target, frame_times, state_at
from anyplan.world.scenario import scenario_from_dict

SCENE = {
    "name": "anim", "time_limit": 20.0, "arena": {"width": 6.0, "height": 3.0},
    "robot": {"start": [0.5, 1.2, 0.0], "goal": [5.5, 1.2], "radius": 0.3, "v_max": 0.8,
              "omega_max": 0.8, "a_max": 0.8, "alpha_max": 1.0},
    "dynamic_obstacles": [{"name": "D1", "start": [1.0, 2.6, 0.0], "v": 0.1, "radius": 0.2}],
}


def test_frame_times_play_at_the_requested_speed():
    t, fps = frame_times(10.0, speed=2.0, fps=10.0, max_frames=1000)
    assert fps == 10.0 and t[0] == 0.0 and t[-1] == pytest.approx(10.0)
    assert np.allclose(np.diff(t), 0.2)
    # Too many frames: fewer frames per second, same playback speed (frames still speed/fps apart).
    t, fps = frame_times(100.0, speed=1.0, fps=15.0, max_frames=101)
    assert len(t) == 101 and fps == pytest.approx(1.0)
    assert np.allclose(np.diff(t), 1.0 / fps)


def test_state_interpolates_the_trajectory():
    traj = np.array([[0.0, 0, 0, 0, 0, 0], [1.0, 2, 4, 1.0, 0, 0]])
    assert state_at(traj, 0.5) == pytest.approx((1.0, 2.0, 0.5))


def test_gif_shows_virtual_obstacles_from_their_creation_time(tmp_path):
    sc = scenario_from_dict(SCENE)
    res = simulate(sc, make_agent("straight"), seed=0).to_dict()
    assert res["status"] == "reached"
    t_end = res["trajectory"][-1][0]
    res["virtual_obstacles"] = [{"center": [3.0, 0.5], "side": 0.6, "created_at_s": t_end / 2}]
    res["plans"] = [{"t": 0.0, "path": [[0.5, 1.2], [5.5, 1.2]]}]
    out = animate_run(sc, res, tmp_path / "a.gif", speed=4.0, fps=5.0)
    times, fps = frame_times(t_end, 4.0, 5.0, 600)
    with Image.open(out) as im:
        assert im.n_frames == len(times)
        assert im.info["duration"] == round(1000 / fps)

        def frame(k):
            im.seek(k)
            return np.asarray(im.convert("RGB"), dtype=int)

        n = im.n_frames
        first, last, early = frame(0), frame(n - 1), frame(int(0.25 * (n - 1)))
    # The virtual square's colour: #1e63d6 at alpha 0.45 over white, about (154, 185, 237).
    def square(img):
        return (np.abs(img - np.array([154, 185, 237])) <= 15).all(axis=-1).sum()

    # (The legend's swatch has that colour in every frame.)
    assert square(early) == square(first)
    assert square(last) > square(first) + 100


def test_check_target_errors():
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        check_target("x.avi")
    with pytest.raises(ValueError, match="speed must be > 0"):
        check_target("x.gif", 0.0)


def test_run_animate_bad_suffix_fails_before_simulating(tmp_path, capsys):
    code = main(["run", "paper-1", "--animate", str(tmp_path / "a.txt"), "--out", str(tmp_path / "o"),
                 "--no-plot"])
    assert code == 2
    err = capsys.readouterr().err
    assert "--animate" in err and err.count("\n") == 1
    assert not (tmp_path / "o" / "result.json").exists()


def test_run_animate_writes_a_gif(tmp_path, capsys):
    p = tmp_path / "anim.yaml"
    import yaml

    p.write_text(yaml.safe_dump(SCENE))
    gif = tmp_path / "run.gif"
    assert main(["run", str(p), "--animate", str(gif), "--speed", "8", "--out", str(tmp_path / "o"),
                 "--no-plot"]) == 0
    with Image.open(gif) as im:
        assert im.n_frames > 3
    assert str(gif) in capsys.readouterr().out
