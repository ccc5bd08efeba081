"""Pictures of one simulated run: the arena, obstacles, the executed path and what moved.

The robot's path is coloured by time. Moving obstacles are drawn along their whole trajectory
over the run, with their discs (and the robot's) at a few marked times, labelled, so that a
reader can see why the path bends. Virtual static obstacles (Sequential BIT*) are blue squares.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.patches import Circle as CirclePatch  # noqa: E402
from matplotlib.patches import Polygon as PolygonPatch  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from anyplan.geometry.shapes import Circle, Polygon  # noqa: E402
from anyplan.world.scenario import Scenario  # noqa: E402

__all__ = ["draw_scenario", "draw_run", "save_run_figure"]

STATIC_FACE = "#9e9e9e"
STATIC_EDGE = "#424242"
VIRTUAL_FACE = "#1e63d6"
MOVER_COLORS = ["#d62728", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22"]


def draw_scenario(ax: Any, scenario: Scenario, *, labels: bool = True) -> None:
    """Draw the arena, the static obstacles (labelled), the start and the goal on ``ax``."""
    x0, y0, x1, y1 = scenario.bounds
    if scenario.static_map is not None:
        m = scenario.static_map
        mx0, my0, mx1, my1 = m.bounds
        ax.imshow(m.blocked, cmap="Greys", vmin=0, vmax=2, origin="lower", interpolation="nearest",
                  extent=(mx0, mx1, my0, my1), zorder=1)
    ax.add_patch(Rectangle((x0, y0), scenario.width, scenario.height, fill=False, lw=2.0,
                           ec="black", zorder=1))
    for o in scenario.static_obstacles:
        s = o.shape
        if isinstance(s, Circle):
            ax.add_patch(CirclePatch(tuple(s.center), s.radius, fc=STATIC_FACE, ec=STATIC_EDGE,
                                     lw=1.0, zorder=2))
            c = s.center
        else:
            assert isinstance(s, Polygon)
            ax.add_patch(PolygonPatch(s.vertices, closed=True, fc=STATIC_FACE, ec=STATIC_EDGE,
                                      lw=1.0, zorder=2))
            c = s.vertices.mean(axis=0)
        if labels:
            ax.text(c[0], c[1], o.name, ha="center", va="center", fontsize=9, weight="bold",
                    color="white", zorder=3)
    r = scenario.robot
    sx, sy, sth = r.start
    ax.add_patch(CirclePatch((sx, sy), r.radius, fc="none", ec="#2ca02c", lw=1.5, zorder=6))
    ax.annotate("", xy=(sx + 0.6 * math.cos(sth), sy + 0.6 * math.sin(sth)), xytext=(sx, sy),
                arrowprops={"arrowstyle": "->", "color": "#2ca02c", "lw": 1.5}, zorder=6)
    ax.text(sx, sy - r.radius - 0.15, "start", ha="center", va="top", fontsize=8, color="#2ca02c")
    gx, gy = r.goal
    ax.add_patch(CirclePatch((gx, gy), r.goal_tolerance, fc="#2ca02c", ec="none", alpha=0.25,
                             zorder=5))
    ax.plot([gx], [gy], marker="*", ms=14, color="#2ca02c", mec="black", mew=0.6, zorder=7)
    ax.text(gx, gy - 0.35, "goal", ha="center", va="top", fontsize=8, color="#2ca02c")
    ax.set_xlim(x0 - 0.3, x1 + 0.3)
    ax.set_ylim(y0 - 0.3, y1 + 0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def _marked_times(t_end: float, n: int = 4) -> list[float]:
    if t_end <= 0.0:
        return [0.0]
    step = t_end / n
    # Round to a readable step (1, 2, 5 x 10^k seconds).
    mag = 10 ** math.floor(math.log10(step))
    step = min((m * mag for m in (1, 2, 5, 10) if m * mag >= step), default=step)
    return [k * step for k in range(int(t_end / step) + 1)]


def draw_run(ax: Any, scenario: Scenario, result: Any, *, marked_times: Sequence[float] | None = None,
             colorbar: bool = True, title: bool = True) -> None:
    """Draw one run on ``ax``.

    Args:
        ax: A matplotlib axes.
        scenario: The scenario that was run (its true obstacle motions are drawn).
        result: A :class:`~anyplan.simulation.RunResult` or its ``to_dict()`` form.
        marked_times: Times [s] at which to draw the robot and the moving obstacles; by default
            about four round times spread over the run.
        colorbar: Add a time colour bar for the path.
        title: Add a title with the outcome and the metrics.
    """
    res = result if isinstance(result, dict) else result.to_dict()
    draw_scenario(ax, scenario)
    traj = np.asarray(res["trajectory"], dtype=float).reshape(-1, 6)
    t_end = float(traj[-1, 0]) if len(traj) else 0.0
    times = list(marked_times) if marked_times is not None else _marked_times(t_end)
    cmap = plt.get_cmap("viridis")
    norm = plt.Normalize(0.0, max(t_end, 1e-9))

    # Virtual obstacles, drawn below everything that moves.
    for k, vo in enumerate(res.get("virtual_obstacles") or []):
        cx, cy = vo["center"]
        side = float(vo["side"])
        ax.add_patch(Rectangle((cx - side / 2, cy - side / 2), side, side, fc=VIRTUAL_FACE,
                               ec=VIRTUAL_FACE, alpha=0.28, lw=1.2, zorder=2.5,
                               label="virtual obstacle" if k == 0 else None))
        ax.text(cx, cy, f"{vo.get('created_at_s', 0.0):.0f}s", ha="center", va="center",
                fontsize=6, color=VIRTUAL_FACE, zorder=2.6)

    # Moving obstacles: their trajectory over the run and their discs at the marked times.
    ts = np.linspace(0.0, t_end, max(2, int(t_end / 0.1) + 1))
    for j, o in enumerate(scenario.moving_obstacles):
        col = MOVER_COLORS[j % len(MOVER_COLORS)]
        p = o.motion.positions(ts)
        ax.plot(p[:, 0], p[:, 1], ls="--", lw=1.0, color=col, zorder=3)
        for tm in times:
            q = o.motion.position(tm)
            ax.add_patch(CirclePatch(tuple(q), o.radius, fc=col, ec=col, alpha=0.18, zorder=3))
            ax.text(q[0], q[1], f"{tm:g}", ha="center", va="center", fontsize=6, color=col,
                    zorder=3.1)
        q0, q1 = p[0], p[-1]
        ax.add_patch(CirclePatch(tuple(q1), o.radius, fc=col, ec="black", lw=0.8, alpha=0.85,
                                 zorder=4))
        ax.text(q0[0], q0[1] + o.radius + 0.12, o.name, ha="center", va="bottom", fontsize=9,
                weight="bold", color=col, zorder=4)
        if len(p) > 1:
            d = p[-1] - p[-2]
            if np.hypot(*d) > 0:
                ax.annotate("", xy=tuple(q1 + 0.5 * d / np.hypot(*d)), xytext=tuple(q1),
                            arrowprops={"arrowstyle": "->", "color": col, "lw": 1.2}, zorder=4)

    # Executed path coloured by time, and the robot at the marked times.
    if len(traj) > 1:
        pts = traj[:, 1:3]
        segs = np.stack([pts[:-1], pts[1:]], axis=1)
        lc = LineCollection(segs, cmap=cmap, norm=norm, lw=2.4, zorder=5)
        lc.set_array(traj[:-1, 0])
        ax.add_collection(lc)
        if colorbar:
            cb = ax.figure.colorbar(lc, ax=ax, fraction=0.035, pad=0.02)
            cb.set_label("time [s]")
        for tm in times:
            i = int(np.clip(np.searchsorted(traj[:, 0], tm), 0, len(traj) - 1))
            x, y = traj[i, 1:3]
            ax.add_patch(CirclePatch((x, y), scenario.robot.radius, fc="none", ec=cmap(norm(tm)),
                                     lw=1.0, zorder=5.5))
            ax.text(x, y, f"{tm:g}", ha="center", va="center", fontsize=6, color="black",
                    zorder=5.6)

    if res.get("collision"):
        tc = res.get("collision_time_s") or t_end
        i = int(np.clip(np.searchsorted(traj[:, 0], tc), 0, len(traj) - 1))
        ax.plot([traj[i, 1]], [traj[i, 2]], marker="X", ms=14, color="red", mec="black",
                zorder=8)
        ax.text(traj[i, 1], traj[i, 2] + 0.45, f"collision with {res.get('collision_with')}",
                ha="center", color="red", fontsize=9, weight="bold", zorder=8)
    if title:
        ttg = res.get("time_to_goal_s")
        ax.set_title(f"{res['scenario']} / {res['planner']} (seed {res['seed']}): {res['status']}\n"
                     f"path {res['path_length_m']:.2f} m, time to goal "
                     f"{'-' if ttg is None else f'{ttg:.1f} s'}, min clearance "
                     f"{res['min_clearance_m']:.2f} m, {len(res.get('virtual_obstacles') or [])} "
                     f"virtual obstacles", fontsize=9)


def save_run_figure(scenario: Scenario, result: Any, path: str | Path, dpi: int = 130) -> Path:
    """Draw one run and save it as a PNG at ``path``; returns the path."""
    fig, ax = plt.subplots(figsize=(11, 8))
    try:
        draw_run(ax, scenario, result)
        fig.tight_layout()
        fig.savefig(path, dpi=dpi)
    finally:
        plt.close(fig)
    return Path(path)
