"""Figures for papers: legends, colour bars with units, no clipped or overlapping text, fonts
of 8 pt and more at print size, distinct obstacle colours, every scenario in cost_time, and
SVG/PDF on request. Each figure is checked as saved (the save function is wrapped)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.text import Text

sys.path.insert(0, str(Path(__file__).parents[1] / "experiments"))

import anyplan_bench_test_agents as agents

import anyplan.viz.dovs as viz_dovs
import anyplan.viz.planner as viz_planner
import anyplan.viz.report as viz_report
import anyplan.viz.run as viz_run
from anyplan.agents import make_agent
from anyplan.cli.main import main
from anyplan.simulation import simulate
from anyplan.viz.style import (
    MIN_FONT_PT,
    TEXT_WIDTH_IN,
    layout_problems,
    new_figure,
    qualitative_colors,
    save_figure,
)
from anyplan.world.scenario import scenario_from_dict

agents.register_all()


def crowd(n: int = 26) -> dict:
    """A 15 m x 11 m arena whose ``n`` moving discs all cross the robot's straight route."""
    movers = []
    for i in range(n):
        x = 2.0 + 11.0 * (i + 0.5) / n
        up = i % 2 == 0
        heading = (1 if up else -1) * math.pi / 2
        movers.append({"name": f"D{i + 1}", "start": [x, 1.0 if up else 10.0, heading],
                       "v": 0.1 + 0.01 * (i % 7), "omega": 0.0 if i % 3 else 0.02, "radius": 0.3})
    return {"name": f"crowd-{n}", "time_limit": 40.0, "arena": {"width": 15.0, "height": 11.0},
            "robot": {"start": [1.0, 5.5, 0.0], "goal": [14.0, 5.5], "radius": 0.3, "v_max": 0.5,
                      "omega_max": 0.5, "a_max": 0.5, "alpha_max": 1.0},
            "static_obstacles": [{"name": "narrow", "type": "rectangle", "center": [7.5, 8.5],
                                  "size": [0.25, 2.0]},
                                 {"name": "S2", "type": "circle", "center": [4.0, 3.0], "radius": 0.6}],
            "dynamic_obstacles": movers}


FEW = {**agents.TINY, "name": "few"}


@pytest.fixture
def saved(monkeypatch):
    """Every figure saved by a viz module, with its layout problems, keyed by file name."""
    out: dict[str, tuple[Figure, list[str]]] = {}

    def wrap(fig, path, **kw):
        p = save_figure(fig, path, **kw)
        out[Path(p).name] = (fig, layout_problems(fig))
        return p

    for mod in (viz_run, viz_report, viz_planner, viz_dovs):
        monkeypatch.setattr(mod, "save_figure", wrap)
    return out


def _has_legend(fig: Figure) -> bool:
    return bool(fig.legends) or any(ax.get_legend() is not None for ax in fig.axes)


def _colorbar_labels(fig: Figure) -> list[str]:
    return [ax.get_ylabel() for ax in fig.axes if getattr(ax, "_colorbar", None) is not None
            or ax.get_label() == "<colorbar>"]


def _check(fig: Figure, problems: list[str], *, colorbar: str | None = None) -> None:
    assert problems == [], problems
    assert fig.get_size_inches()[0] <= TEXT_WIDTH_IN + 1e-9  # made at print size
    assert _has_legend(fig)
    if colorbar is not None:
        assert colorbar in _colorbar_labels(fig)


@pytest.mark.parametrize("data", [FEW, crowd(26)], ids=["few", "26-moving"])
def test_run_figure(tmp_path, saved, data):
    sc = scenario_from_dict(data)
    res = simulate(sc, make_agent("straight"), seed=0).to_dict()
    res["virtual_obstacles"] = [{"center": [2.0 + k, 1.5], "side": 0.6, "created_at_s": 2.0 * k}
                                for k in range(3)]
    res.setdefault("extra", {})["fallbacks"] = [{"t": 1.0, "kind": "brake", "predicted_clearance_m": 0.1}]
    viz_run.save_run_figure(sc, res, tmp_path / "run.png")
    fig, problems = saved["run.png"]
    _check(fig, problems, colorbar="time [s]")
    texts = [t.get_text() for t in fig.axes[0].texts]
    # Every moving obstacle is named, and every time label has its unit.
    assert {o.name for o in sc.moving_obstacles} <= set(texts)
    times = [t for t in texts if t[:1].isdigit()]
    assert times and all(t.endswith(" s") for t in times)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert {"virtual obstacle", "fallback", "static obstacle"} <= set(legend)


def test_narrow_obstacle_names_are_dark_on_a_halo(tmp_path, saved):
    sc = scenario_from_dict(crowd(4))
    res = simulate(sc, make_agent("straight"), seed=0).to_dict()
    viz_run.save_run_figure(sc, res, tmp_path / "run.png")
    fig, _ = saved["run.png"]
    (label,) = [t for t in fig.axes[0].texts if t.get_text() == "narrow"]
    assert sum(to_rgb(label.get_color())) < 0.5 and label.get_path_effects()


def test_obstacle_colours_stay_distinct():
    cols = np.array([to_rgb(c) for c in qualitative_colors(40)])
    assert len({tuple(c) for c in np.round(cols, 3)}) == 40
    # Neighbours in the list (obstacles D_k and D_k+1) differ clearly.
    assert np.min(np.linalg.norm(np.diff(cols, axis=0), axis=1)) > 0.15


def test_layout_check_finds_overlaps_clipping_and_small_fonts():
    fig = new_figure((3.5, 2.0))
    ax = fig.add_subplot()
    ax.text(0.5, 0.5, "one", fontsize=9)
    ax.text(0.5, 0.5, "two", fontsize=9)
    fig.text(0.99, 0.5, "clipped at the edge", fontsize=9)
    fig.text(0.1, 0.95, "tiny", fontsize=6)
    problems = " | ".join(layout_problems(fig))
    assert "overlapping: 'one' and 'two'" in problems
    assert "outside the figure: 'clipped at the edge'" in problems
    assert f"font 6 pt < {MIN_FONT_PT:g} pt: 'tiny'" in problems


@pytest.fixture(scope="module")
def five_scenario_db(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("db")
    files = []
    for k in range(5):
        d = dict(FEW, name=f"tiny-{k}")
        d["robot"] = dict(d["robot"], goal=[4.5 + 0.2 * k, 1.2])
        f = tmp / f"tiny-{k}.yaml"
        f.write_text(yaml.safe_dump(d))
        files.append(str(f))
    many = tmp / "crowd.yaml"
    many.write_text(yaml.safe_dump(crowd(26)))
    db = tmp / "r.db"
    assert main(["bench", "--suite", ",".join([*files, str(many)]), "--planners", "straight,half-speed",
                 "--runs", "2", "--jobs", "1", "--db", str(db), "--no-progress"]) == 0
    return db


def test_report_figures(tmp_path, saved, five_scenario_db):
    assert main(["report", str(five_scenario_db), "--out", str(tmp_path)]) == 0
    fig, problems = saved["figure4.png"]
    _check(fig, problems, colorbar="time [s]")
    fig, problems = saved["boxplots.png"]
    _check(fig, problems)
    fig, problems = saved["cost_time.png"]
    _check(fig, problems)
    # All six scenarios, as small multiples, drawn with lines; the title claims no OMPL lines.
    titles = sorted(ax.get_title() for ax in fig.axes if ax.get_title())
    assert titles == sorted([f"tiny-{k}" for k in range(5)] + ["crowd-26"])
    assert all(ax.get_lines() for ax in fig.axes if ax.get_title())
    # (found among the figure's texts: Figure.get_suptitle is matplotlib >= 3.8, the floor 3.7)
    title = [t.get_text() for t in fig.findobj(Text)
             if t.get_text().startswith(("Best solution cost", "No anytime progress"))]
    assert len(title) == 1 and "OMPL" not in title[0]


def test_planner_and_dovs_figures(tmp_path, saved):
    assert main(["plan", "paper-1", "--time", "0.05", "--plot", str(tmp_path / "p.png")]) == 0
    _check(*saved["p.png"])
    assert main(["dovs-plot", "paper-3", "--time", "4", "--out", str(tmp_path / "d.png")]) == 0
    _check(*saved["d.png"])


def _kind(path: Path) -> str:
    head = path.read_bytes()[:400]
    if head.startswith(b"%PDF"):
        return "pdf"
    if head.startswith(b"\x89PNG"):
        return "png"
    return "svg" if b"<svg" in head else "?"


@pytest.mark.parametrize("fmt", ["svg", "pdf"])
def test_format_option(tmp_path, fmt):
    scen = tmp_path / "few.yaml"
    scen.write_text(yaml.safe_dump(FEW))
    assert main(["run", str(scen), "--planner", "straight", "--out", str(tmp_path / "r"),
                 "--format", fmt]) == 0
    assert _kind(tmp_path / "r" / f"run.{fmt}") == fmt and not (tmp_path / "r" / "run.png").exists()
    db = tmp_path / "small.db"
    assert main(["bench", "--suite", str(scen), "--planners", "half-speed", "--runs", "1", "--jobs", "1",
                 "--db", str(db), "--no-progress"]) == 0
    assert main(["report", str(db), "--out", str(tmp_path / "rep"), "--format", fmt]) == 0
    for name in ("figure4", "boxplots", "cost_time"):
        assert _kind(tmp_path / "rep" / f"{name}.{fmt}") == fmt
    assert main(["plan", "paper-1", "--time", "0.05", "--plot", str(tmp_path / "p"), "--format", fmt]) == 0
    assert _kind(tmp_path / f"p.{fmt}") == fmt
    assert main(["dovs-plot", "paper-1", "--time", "1", "--out", str(tmp_path / f"d.{fmt}")]) == 0
    assert _kind(tmp_path / f"d.{fmt}") == fmt


def test_format_conflicting_with_the_suffix_is_one_line(tmp_path, capsys):
    assert main(["plan", "paper-1", "--plot", str(tmp_path / "p.png"), "--format", "svg"]) == 2
    err = capsys.readouterr().err
    assert "--format says svg" in err and err.count("\n") == 1


def test_recorded_tracks_are_drawn_only_while_they_exist(tmp_path, saved):
    data = dict(FEW, dynamic_obstacles=[{"name": "P1", "type": "track", "radius": 0.2,
                                         "samples": [[2.0, 1.0, 2.5], [4.0, 3.0, 2.5]]}])
    sc = scenario_from_dict(data)
    res = simulate(sc, make_agent("straight"), seed=0).to_dict()
    viz_run.save_run_figure(sc, res, tmp_path / "run.png")
    fig, problems = saved["run.png"]
    assert problems == []
    (track,) = [ln for ln in fig.axes[0].get_lines() if ln.get_linestyle() == "--"]
    xs = track.get_xdata()
    # Only the part inside the span [2 s, 4 s]: x from 1 m to 3 m, not its clamped ends.
    assert xs.min() == pytest.approx(1.0, abs=0.11) and xs.max() == pytest.approx(3.0, abs=0.11)
    t_end = res["trajectory"][-1][0]
    assert len(xs) == pytest.approx(2.0 / 0.1 + 1, abs=2) and t_end > 4.0


def test_an_open_track_is_drawn_without_its_jump_back(tmp_path, saved):
    # An open waypoints track jumps back to its first keyframe each period: its dashed line
    # breaks there instead of drawing the jump as a motion (no segment joins the two ends).
    from tests.conftest import small_scenario_dict

    sc = scenario_from_dict(small_scenario_dict(
        arena={"width": 20.0, "height": 6.0}, static_obstacles=[], dynamic_obstacles=[
            {"name": "J", "type": "waypoints", "radius": 0.3,
             "keyframes": [[0.0, 4.0, 1.0], [6.0, 16.0, 1.0], [7.0, 16.0, 5.0]]}]))
    assert sc.moving_obstacles[0].motion.may_jump
    res = simulate(sc, make_agent("straight"), seed=0).to_dict()
    assert res["trajectory"][-1][0] > 7.5  # the run outlasts J's first period
    viz_run.save_run_figure(sc, res, tmp_path / "run.png")
    fig, _ = saved["run.png"]
    (line,) = [ln for ln in fig.axes[0].lines if ln.get_linestyle() == "--"]
    xy = np.asarray(line.get_xydata(), dtype=float)
    gaps = np.flatnonzero(np.isnan(xy[:, 0]))
    assert len(gaps) >= 1
    steps = np.hypot(*np.diff(xy, axis=0).T)
    assert np.nanmax(steps) < 1.0  # the 12 m jump back is not drawn
