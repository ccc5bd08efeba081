"""Minimal scene and run drawing, used only when :mod:`anyplan.viz.run` is not importable."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.patches import Rectangle

from anyplan.geometry.shapes import Circle
from anyplan.world.scenario import Scenario

__all__ = ["draw_scenario", "draw_run"]


def draw_scenario(ax: Any, scenario: Scenario, **_: Any) -> None:
    """Arena, static obstacles, start and goal."""
    x0, y0, x1, y1 = scenario.bounds
    if scenario.static_map is not None:
        m = scenario.static_map
        mx0, my0, mx1, my1 = m.bounds
        ax.imshow(m.blocked, cmap="Greys", vmin=0, vmax=2, origin="lower", interpolation="nearest",
                  extent=(mx0, mx1, my0, my1), zorder=1)
    ax.add_patch(Rectangle((x0, y0), scenario.width, scenario.height, fill=False, lw=2.0, ec="black"))
    for o in scenario.static_obstacles:
        s = o.shape
        if isinstance(s, Circle):
            ax.add_patch(CirclePatch(tuple(s.center), s.radius, fc="#9e9e9e", ec="#424242"))
        else:
            ax.add_patch(PolygonPatch(s.vertices, closed=True, fc="#9e9e9e", ec="#424242"))
    r = scenario.robot
    ax.plot([r.start[0]], [r.start[1]], "o", color="#2ca02c")
    ax.plot([r.goal[0]], [r.goal[1]], "*", ms=12, color="#2ca02c", mec="black")
    ax.set_xlim(x0 - 0.3, x1 + 0.3)
    ax.set_ylim(y0 - 0.3, y1 + 0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def draw_run(ax: Any, scenario: Scenario, result: Any, **_: Any) -> None:
    """Scene, executed path, obstacle tracks over the run and virtual obstacles."""
    res = result if isinstance(result, dict) else result.to_dict()
    draw_scenario(ax, scenario)
    traj = np.asarray(res["trajectory"], dtype=float).reshape(-1, 6)
    for vo in res.get("virtual_obstacles") or []:
        (cx, cy), side = vo["center"], float(vo["side"])
        ax.add_patch(Rectangle((cx - side / 2, cy - side / 2), side, side, fc="#1e63d6", alpha=0.45))
    ts = traj[:, 0]
    for o in scenario.moving_obstacles:
        p = o.motion.positions(ts)
        ax.plot(p[:, 0], p[:, 1], "--", color="#d62728", lw=1)
        ax.add_patch(CirclePatch(tuple(p[-1]), o.radius, fc="#d62728", alpha=0.6))
    ax.plot(traj[:, 1], traj[:, 2], "-", color="#1f77b4", lw=2)
