"""Pictures of a planning query: obstacles, samples, the BIT* tree, the informed ellipse, path."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Ellipse, Rectangle
from matplotlib.patches import Polygon as PolygonPatch

from anyplan.geometry.shapes import Circle
from anyplan.planning.base import PlanResult
from anyplan.planning.bitstar import PlannerData
from anyplan.planning.problem import Problem
from anyplan.viz.style import COLUMN_WIDTH_IN, LabelPlacer, halo, new_figure, paper_style, save_figure, tight

__all__ = ["draw_planner", "save_planner_figure"]


def _draw_obstacles(ax: Any, problem: Problem) -> None:
    xmin, ymin, xmax, ymax = problem.bounds
    ax.add_patch(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=1.5, color="k"))
    for s in problem.obstacles.shapes:
        if isinstance(s, Circle):
            ax.add_patch(CirclePatch(tuple(s.center), s.radius, color="0.35", zorder=2))
        else:
            ax.add_patch(PolygonPatch(s.vertices, closed=True, color="0.35", zorder=2))


def draw_planner(ax: Any, problem: Problem, result: PlanResult,
                 data: PlannerData | None = None, *, legend: bool = True) -> LabelPlacer:
    """Draw a planning query on ``ax``.

    Args:
        ax: Matplotlib axes.
        problem: The problem (obstacles, walls, start, goal, robot radius).
        result: The planner's result (its path is drawn in red).
        data: BIT*'s planner data (samples, tree, informed ellipse), if any.
        legend: Add a legend inside the axes.

    Returns:
        The placer of the start and goal labels (see :class:`anyplan.viz.style.LabelPlacer`).
    """
    _draw_obstacles(ax, problem)
    ax.plot([], [], "s", color="0.35", label="obstacle")
    if data is not None:
        if len(data.edges):
            ax.add_collection(LineCollection(data.edges, colors="tab:blue", linewidths=0.4,  # type: ignore[arg-type]
                                             alpha=0.6, zorder=3))
            ax.add_line(Line2D([], [], color="tab:blue", lw=0.8, label="tree"))
        if len(data.samples):
            ax.plot(data.samples[:, 0], data.samples[:, 1], ".", ms=1.5, color="tab:gray",
                    zorder=3, label="samples")
        if len(data.vertices):
            ax.plot(data.vertices[:, 0], data.vertices[:, 1], ".", ms=1.5, color="tab:blue",
                    zorder=3)
        if math.isfinite(data.c_best):
            c_min = float(np.hypot(*(data.goal - data.start)))
            centre = (data.start + data.goal) / 2.0
            ang = math.degrees(math.atan2(*(data.goal - data.start)[::-1]))
            minor = math.sqrt(max(data.c_best ** 2 - c_min ** 2, 0.0))
            ax.add_patch(Ellipse(tuple(centre), data.c_best, minor, angle=ang, fill=False,
                                 ls="--", lw=1.0, color="tab:green", zorder=4,
                                 label="informed set"))
    if result.path.shape[0]:
        ax.plot(result.path[:, 0], result.path[:, 1], "-", color="tab:red", lw=2.0, zorder=5,
                label=f"path {result.cost:.3f} m")
    xmin, ymin, xmax, ymax = problem.bounds
    ax.set_xlim(xmin - 0.2, xmax + 0.2)
    ax.set_ylim(ymin - 0.2, ymax + 0.2)
    placer = LabelPlacer(ax)
    for p, c, lab in ((problem.start, "tab:green", "start"), (problem.goal, "tab:orange", "goal")):
        ax.add_patch(CirclePatch(tuple(p), max(problem.radius, 0.05), color=c, zorder=6))
        placer.add(tuple(p), lab, gap_pt=5.0, fontsize=8, path_effects=halo(), zorder=7)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    lb = "" if result.lower_bound is None else f"\nlower bound {result.lower_bound:.3f} m"
    first = ("" if result.first_solution_time_s is None
             else f", first solution {1e3 * result.first_solution_time_s:.1f} ms")
    ax.set_title(f"{result.planner}: {result.status.value}{first}{lb}", fontsize=8)
    if legend:
        ax.legend(loc="upper left", framealpha=0.8)
    placer.layout()
    return placer


def save_planner_figure(problem: Problem, result: PlanResult, path: str | Path,
                        data: PlannerData | None = None) -> None:
    """Write :func:`draw_planner`'s picture to ``path`` (PNG, PDF or SVG by extension), one
    column (3.5 in) wide, the legend below the plot."""
    xmin, ymin, xmax, ymax = problem.bounds
    w = COLUMN_WIDTH_IN
    h = 0.85 * w * (ymax - ymin) / max(xmax - xmin, 1e-9)
    with paper_style():
        handles_rows = 2 + (data is not None)
        fig_h = h + 0.75 + 0.17 * handles_rows
        fig = new_figure((w, fig_h))
        ax = fig.add_subplot()
        placer = draw_planner(ax, problem, result, data, legend=False)
        fig.legend(*ax.get_legend_handles_labels(), loc="lower center", ncol=2, frameon=False)
        tight(fig, (0.0, (0.08 + 0.16 * handles_rows) / fig_h, 1.0, 1.0))
    save_figure(fig, path, placers=[placer])
