"""Pictures of one simulated run: the arena, obstacles, the executed path and what moved.

The robot's path is coloured by time (colour bar in seconds). Moving obstacles are drawn along
their whole trajectory over the run, with their discs (and the robot's) at a few marked times,
labelled with the time in seconds where a label fits without covering another one. Every moving
obstacle has its own colour and its name beside its start; static obstacles carry their names
in dark text on a light halo. Virtual static obstacles (Sequential BIT*) are blue squares, the
planner's fallbacks (``result.extra["fallbacks"]``, if any) black triangles on the path.

Figures are made at print size (:mod:`anyplan.viz.style`): fonts of 8 pt and more at 7.16 in wide.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch, Rectangle
from matplotlib.patches import Polygon as PolygonPatch

from anyplan.geometry.shapes import Circle, Polygon
from anyplan.viz.style import (
    TEXT_WIDTH_IN,
    LabelPlacer,
    halo,
    new_figure,
    paper_style,
    qualitative_colors,
    save_figure,
    tight,
)
from anyplan.world.scenario import Scenario

__all__ = ["draw_scenario", "draw_run", "run_legend_handles", "run_figure", "save_run_figure"]

STATIC_FACE = "#b0b0b0"
STATIC_EDGE = "#424242"
VIRTUAL_FACE = "#1e63d6"
GOAL_COLOR = "#2ca02c"
PATH_CMAP = "viridis"
TEXT_DARK = "#1a1a1a"


def draw_scenario(ax: Any, scenario: Scenario, *, labels: bool = True,
                  placer: LabelPlacer | None = None) -> LabelPlacer:
    """Draw the arena, the static obstacles (named), the start and the goal on ``ax``.

    Names go through ``placer`` (a new one if None), centred on the obstacle when they fit and
    beside it otherwise; call its ``layout()`` once the figure is laid out (:func:`draw_run` and
    the save functions do). Returns the placer.
    """
    placer = placer or LabelPlacer(ax)
    x0, y0, x1, y1 = scenario.bounds
    if scenario.static_map is not None:
        m = scenario.static_map
        mx0, my0, mx1, my1 = m.bounds
        ax.imshow(m.blocked, cmap="Greys", vmin=0, vmax=2, origin="lower", interpolation="nearest",
                  extent=(mx0, mx1, my0, my1), zorder=1)
    ax.add_patch(Rectangle((x0, y0), scenario.width, scenario.height, fill=False, lw=1.2,
                           ec="black", zorder=1))
    for o in scenario.static_obstacles:
        s = o.shape
        if isinstance(s, Circle):
            ax.add_patch(CirclePatch(tuple(s.center), s.radius, fc=STATIC_FACE, ec=STATIC_EDGE,
                                     lw=0.8, zorder=2))
            c = s.center
        else:
            assert isinstance(s, Polygon)
            ax.add_patch(PolygonPatch(s.vertices, closed=True, fc=STATIC_FACE, ec=STATIC_EDGE,
                                      lw=0.8, zorder=2))
            c = s.vertices.mean(axis=0)
        if labels:
            placer.add(c, o.name, center=True, fontsize=8, color=TEXT_DARK, zorder=9,
                       path_effects=halo())
    r = scenario.robot
    sx, sy, sth = r.start
    ax.add_patch(CirclePatch((sx, sy), r.radius, fc="none", ec=GOAL_COLOR, lw=1.2, zorder=6))
    ax.annotate("", xy=(sx + 0.6 * math.cos(sth), sy + 0.6 * math.sin(sth)), xytext=(sx, sy),
                arrowprops={"arrowstyle": "->", "color": GOAL_COLOR, "lw": 1.2}, zorder=6)
    gx, gy = r.goal
    ax.add_patch(CirclePatch((gx, gy), r.goal_tolerance, fc=GOAL_COLOR, ec="none", alpha=0.25,
                             zorder=5))
    ax.plot([gx], [gy], marker="*", ms=10, color=GOAL_COLOR, mec="black", mew=0.5, zorder=7,
            ls="none")
    if labels:
        placer.add((sx, sy), "start", gap_pt=6.0, fontsize=8, color="#1b6e1b", zorder=9,
                   path_effects=halo())
        placer.add((gx, gy), "goal", gap_pt=6.0, fontsize=8, color="#1b6e1b", zorder=9,
                   path_effects=halo())
    ax.set_xlim(x0 - 0.3, x1 + 0.3)
    ax.set_ylim(y0 - 0.3, y1 + 0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return placer


def _marked_times(t_end: float, n: int = 4) -> list[float]:
    if t_end <= 0.0:
        return [0.0]
    step = t_end / n
    # Round to a readable step (1, 2, 5 x 10^k seconds).
    mag = 10 ** math.floor(math.log10(step))
    step = min((m * mag for m in (1, 2, 5, 10) if m * mag >= step), default=step)
    return [k * step for k in range(int(t_end / step) + 1)]


def _darker(color: Any, f: float = 0.65) -> tuple[float, float, float]:
    from matplotlib.colors import to_rgb

    r, g, b = to_rgb(color)
    return (r * f, g * f, b * f)


def _fallbacks(res: dict[str, Any]) -> list[dict[str, Any]]:
    extra = res.get("extra") or {}
    fb = extra.get("fallbacks") if isinstance(extra, dict) else None
    return [f for f in fb or [] if isinstance(f, dict) and "t" in f]


def draw_run(ax: Any, scenario: Scenario, result: Any, *, marked_times: Sequence[float] | None = None,
             colorbar: bool = True, title: bool = True, t_max: float | None = None,
             time_labels: bool = True, placer: LabelPlacer | None = None) -> LabelPlacer:
    """Draw one run on ``ax``; returns the :class:`LabelPlacer` holding its labels (already
    placed; place them again with ``layout()`` if the figure's layout changes afterwards).

    Args:
        ax: A matplotlib axes.
        scenario: The scenario that was run (its true obstacle motions are drawn).
        result: A :class:`~anyplan.simulation.RunResult` or its ``to_dict()`` form.
        marked_times: Times [s] at which to draw the robot and the moving obstacles; by default
            about four round times spread over the run.
        colorbar: Add a time colour bar [s] for the path.
        title: Add a title with the outcome and the metrics.
        t_max: Upper end [s] of the time colour scale (default: the run's end), so that several
            panels can share one colour bar.
        time_labels: Write the marked times beside the robot and the obstacles.
        placer: Label placer to add to (a new one if None).
    """
    res = result if isinstance(result, dict) else result.to_dict()
    placer = draw_scenario(ax, scenario, placer=placer)
    traj = np.asarray(res["trajectory"], dtype=float).reshape(-1, 6)
    t_end = float(traj[-1, 0]) if len(traj) else 0.0
    times = list(marked_times) if marked_times is not None else _marked_times(t_end)
    norm = Normalize(0.0, max(t_max if t_max is not None else t_end, 1e-9))
    import matplotlib

    cmap = matplotlib.colormaps[PATH_CMAP]
    colors = qualitative_colors(len(scenario.moving_obstacles))
    many = len(scenario.moving_obstacles) > 8

    for vo in res.get("virtual_obstacles") or []:
        cx, cy = vo["center"]
        side = float(vo["side"])
        ax.add_patch(Rectangle((cx - side / 2, cy - side / 2), side, side, fc=VIRTUAL_FACE,
                               ec=VIRTUAL_FACE, alpha=0.28, lw=1.0, zorder=2.5))

    # Moving obstacles: their trajectory over the run and their discs at the marked times.
    ts = np.linspace(0.0, t_end, max(2, int(t_end / 0.1) + 1))
    time_requests: list[tuple[Any, str, Any]] = []
    for j, o in enumerate(scenario.moving_obstacles):
        col = colors[j]
        lo, hi = o.motion.span  # a recorded track exists only within its span
        alive = (ts >= lo) & (ts <= hi)
        if not np.any(alive):
            continue
        p = o.motion.positions(ts[alive])
        line = p
        if o.motion.may_jump:  # an open track's jump back is not a motion: break the line there
            cut = np.searchsorted(ts[alive], o.motion.jump_times(float(ts[alive][0]),
                                                                 float(ts[alive][-1])))
            line = np.insert(p, cut, np.nan, axis=0)
        ax.plot(line[:, 0], line[:, 1], ls="--", lw=0.9, color=col, zorder=3)
        for tm in times:
            if not o.motion.exists(tm):
                continue
            q = o.motion.position(tm)
            ax.add_patch(CirclePatch(tuple(q), o.radius, fc=col, ec=col, alpha=0.18, zorder=3))
            if time_labels and not many:
                time_requests.append((q, f"{tm:g} s", _darker(col)))
        q1 = p[-1]
        ax.add_patch(CirclePatch(tuple(q1), o.radius, fc=col, ec="black", lw=0.6, alpha=0.85,
                                 zorder=4))
        placer.add(p[0], o.name, gap_pt=4.0, fontsize=8, weight="bold",
                   color=_darker(col, 0.8), zorder=9, path_effects=halo())
        if len(p) > 1:
            d = p[-1] - p[-2]
            if np.hypot(*d) > 0:
                ax.annotate("", xy=tuple(q1 + 0.5 * d / np.hypot(*d)), xytext=tuple(q1),
                            arrowprops={"arrowstyle": "->", "color": col, "lw": 1.0}, zorder=4)

    # Executed path coloured by time, and the robot at the marked times.
    robot_requests: list[tuple[Any, str, Any]] = []
    if len(traj) > 1:
        pts = traj[:, 1:3]
        segs = np.stack([pts[:-1], pts[1:]], axis=1)
        # An (N, 2, 2) array of segments (the stubs ask for a sequence of them).
        lc = LineCollection(segs, cmap=cmap, norm=norm, lw=2.0, zorder=5)  # type: ignore[arg-type]
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
            if time_labels:
                robot_requests.append(((x, y), f"{tm:g} s", TEXT_DARK))
    for xy, text, col in robot_requests + time_requests:
        placer.add(xy, text, gap_pt=5.0, fontsize=8, color=col, zorder=8.5, path_effects=halo())

    for fb in _fallbacks(res):
        i = int(np.clip(np.searchsorted(traj[:, 0], float(fb["t"])), 0, len(traj) - 1))
        ax.plot([traj[i, 1]], [traj[i, 2]], marker="v", ms=6, color="black", mec="white", mew=0.6,
                ls="none", zorder=7.5)

    if res.get("collision"):
        tc = res.get("collision_time_s") or t_end
        i = int(np.clip(np.searchsorted(traj[:, 0], tc), 0, len(traj) - 1))
        ax.plot([traj[i, 1]], [traj[i, 2]], marker="X", ms=10, color="red", mec="black",
                zorder=8, ls="none")
        placer.requests.insert(0, ((float(traj[i, 1]), float(traj[i, 2])),
                                   f"collision with {res.get('collision_with')}", 6.0,
                                   {"fontsize": 8, "weight": "bold", "color": "#b00000", "zorder": 9,
                                    "path_effects": halo()}, False))
    if title:
        ttg = res.get("time_to_goal_s")
        ax.set_title(f"{res['scenario']} / {res['planner']} (seed {res['seed']}): {res['status']}\n"
                     f"path {res['path_length_m']:.2f} m, time to goal "
                     f"{'-' if ttg is None else f'{ttg:.1f} s'}, min. clearance "
                     f"{res['min_clearance_m']:.2f} m, {len(res.get('virtual_obstacles') or [])} "
                     f"virtual obstacles", fontsize=8)
    placer.layout()
    return placer


def run_legend_handles(*, virtual: bool = True, fallbacks: bool = False, collision: bool = False,
                       mover_color: str = "#d62728") -> list[Any]:
    """Legend entries for the symbols of :func:`draw_run`."""
    h = [Line2D([], [], color="#3b528b", lw=2.0, label="robot path (colour: time)"),
         Line2D([], [], ls="none", marker="o", ms=7, mfc="none", mec="#3b528b",
                label="robot at marked times"),
         Line2D([], [], color=mover_color, ls="--", lw=0.9, label="moving obstacle track"),
         Line2D([], [], ls="none", marker="o", ms=7, color=mover_color, alpha=0.3,
                label="obstacle at marked times"),
         Line2D([], [], ls="none", marker="o", ms=7, color=mover_color, mec="black",
                label="obstacle at the end"),
         Patch(fc=STATIC_FACE, ec=STATIC_EDGE, label="static obstacle"),
         Line2D([], [], ls="none", marker="*", ms=9, color=GOAL_COLOR, mec="black", label="goal")]
    if virtual:
        h.append(Patch(fc=VIRTUAL_FACE, alpha=0.28, ec=VIRTUAL_FACE, label="virtual obstacle"))
    if fallbacks:
        h.append(Line2D([], [], ls="none", marker="v", ms=6, color="black", label="fallback"))
    if collision:
        h.append(Line2D([], [], ls="none", marker="X", ms=8, color="red", mec="black",
                        label="collision"))
    return h


def run_figure(scenario: Scenario, result: Any, *, width_in: float = TEXT_WIDTH_IN
               ) -> tuple[Figure, list[LabelPlacer]]:
    """A print-size figure of one run (path, colour bar in s, legend below); returns the figure
    and its label placers (pass them to :func:`anyplan.viz.style.save_figure`)."""
    res = result if isinstance(result, dict) else result.to_dict()
    with paper_style():
        ax_h = width_in * 0.74 * (scenario.height + 0.6) / (scenario.width + 0.6)
        fig_h = ax_h + 1.45
        fig = new_figure((width_in, fig_h))
        ax = fig.add_subplot()
        placer = draw_run(ax, scenario, res)
        handles = run_legend_handles(virtual=bool(res.get("virtual_obstacles")),
                                     fallbacks=bool(_fallbacks(res)), collision=bool(res.get("collision")))
        fig.legend(handles=handles, loc="lower center", ncol=3, frameon=False,
                   bbox_to_anchor=(0.5, 0.0))
        tight(fig, (0.0, (0.62 if len(handles) <= 9 else 0.78) / fig_h, 1.0, 1.0))
        placer.layout()
    return fig, [placer]


def save_run_figure(scenario: Scenario, result: Any, path: str | Path, dpi: int = 300) -> Path:
    """Draw one run and save it at ``path`` (PNG, SVG or PDF by the suffix); returns the path."""
    fig, placers = run_figure(scenario, result)
    return save_figure(fig, path, placers=placers, dpi=dpi)
