"""Pictures of a planning query: obstacles, samples, the BIT* tree, the informed ellipse, path."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg", force=False)

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.patches import Circle as CirclePatch  # noqa: E402
from matplotlib.patches import Ellipse, Rectangle  # noqa: E402
from matplotlib.patches import Polygon as PolygonPatch  # noqa: E402

from anyplan.geometry.shapes import Circle  # noqa: E402
from anyplan.planning.base import PlanResult  # noqa: E402
from anyplan.planning.bitstar import PlannerData  # noqa: E402
from anyplan.planning.problem import Problem  # noqa: E402

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
                 data: PlannerData | None = None) -> None:
    """Draw a planning query on ``ax``.

    Args:
        ax: Matplotlib axes.
        problem: The problem (obstacles, walls, start, goal, robot radius).
        result: The planner's result (its path is drawn in red).
        data: BIT*'s planner data (samples, tree, informed ellipse), if any.
    """
    _draw_obstacles(ax, problem)
    if data is not None:
        if len(data.edges):
            ax.add_collection(LineCollection(data.edges, colors="tab:blue", linewidths=0.4,
                                             alpha=0.6, zorder=3, label="tree"))
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
    for p, c, lab in ((problem.start, "tab:green", "start"), (problem.goal, "tab:orange", "goal")):
        ax.add_patch(CirclePatch(tuple(p), max(problem.radius, 0.05), color=c, zorder=6))
        ax.annotate(lab, tuple(p), xytext=(4, 4), textcoords="offset points", fontsize=8)
    xmin, ymin, xmax, ymax = problem.bounds
    ax.set_xlim(xmin - 0.2, xmax + 0.2)
    ax.set_ylim(ymin - 0.2, ymax + 0.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    lb = "" if result.lower_bound is None else f", lower bound {result.lower_bound:.3f} m"
    first = ("" if result.first_solution_time_s is None
             else f", first solution {1e3 * result.first_solution_time_s:.1f} ms")
    ax.set_title(f"{result.planner}: {result.status.value}{first}{lb}", fontsize=9)
    ax.legend(loc="upper left", fontsize=7, framealpha=0.8)


def save_planner_figure(problem: Problem, result: PlanResult, path: str | Path,
                        data: PlannerData | None = None) -> None:
    """Write :func:`draw_planner`'s picture to ``path`` (PNG, PDF or SVG by extension)."""
    xmin, ymin, xmax, ymax = problem.bounds
    w = 9.0
    h = max(3.0, w * (ymax - ymin) / max(xmax - xmin, 1e-9))
    fig, ax = plt.subplots(figsize=(w, h + 0.6))
    try:
        draw_planner(ax, problem, result, data)
        fig.tight_layout()
        fig.savefig(path, dpi=130)
    finally:
        plt.close(fig)
