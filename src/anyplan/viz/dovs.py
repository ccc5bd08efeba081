"""Pictures of one DOVS decision: the (omega, v) plane like Figure 2 of Lorente et al. (IJRR 2018).

Left, the world at that instant: the arena, the robot, the moving obstacles with their
predicted motion over the horizon, the path driven so far and the arc of the chosen command.
Right, the robot's velocity space: the forbidden regions (DOVs) of each obstacle in its own
colour, the extra area forbidden by merging them into per-ray hulls, the dynamic window, the
goal command and the chosen command.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.artist import Artist
from matplotlib.colors import to_rgba
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch

from anyplan.baselines.dovs.model import arc_points, to_world_frame
from anyplan.baselines.dovs.planner import Decision
from anyplan.baselines.dovs.window import vs_v_max
from anyplan.viz.run import draw_scenario
from anyplan.viz.style import (
    TEXT_WIDTH_IN,
    halo,
    new_figure,
    paper_style,
    qualitative_colors,
    save_figure,
    tight,
)
from anyplan.world.scenario import Scenario

__all__ = ["draw_velocity_space", "draw_decision_world", "save_dovs_figure"]

STATIC_COLOR = "#616161"
HULL_COLOR = "#bdbdbd"


def draw_velocity_space(ax: Any, decision: Decision, *, resolution: int = 241, legend: bool = True,
                        title: bool = True) -> list[Any]:
    """Draw the (omega, v) plane of ``decision`` on ``ax`` (omega horizontal, as in the paper);
    returns the legend handles (drawn beside the axes if ``legend``)."""
    colors = qualitative_colors(len(decision.obstacles) + 1)
    model, cfg = decision.model, decision.model.cfg
    wm, vm = cfg.omega_max, cfg.v_max
    ws = np.linspace(-wm, wm, resolution)
    vs = np.linspace(0.0, vm, max(resolution * 2 // 3, 50))
    W, V = np.meshgrid(ws, vs)
    w, v = W.ravel(), V.ravel()
    inside = v <= vs_v_max(w, cfg) + 1e-12
    by_src, names = model.forbidden_by_source(v, w)
    merged = model.forbidden(v, w)
    img = np.ones(W.shape + (4,))
    img[..., 3] = 0.0
    any_src = np.zeros(len(v), dtype=bool)
    handles: list[Artist] = []
    hull_only = merged & ~np.any(by_src, axis=1) & inside
    if np.any(hull_only):
        img.reshape(-1, 4)[hull_only] = to_rgba(HULL_COLOR, 0.9)
        handles.append(Patch(fc=HULL_COLOR, label="forbidden by the per-ray hull"))
    flat = img.reshape(-1, 4)
    for j, name in enumerate(names):
        m = by_src[:, j] & inside
        if not np.any(m):
            continue
        color = STATIC_COLOR if name == "static map" else colors[j % len(colors)]
        rgba = np.array(to_rgba(color, 0.55))
        fresh = m & ~any_src
        both = m & any_src
        flat[fresh] = rgba
        flat[both] = 0.5 * flat[both] + 0.5 * rgba
        flat[both, 3] = 0.8
        any_src |= m
        ob = next((o for o in decision.obstacles if o.name == name), None)
        label = f"DOV of {name}" + (f" ({ob.kind})" if ob is not None else " (braking rule)")
        handles.append(Patch(fc=to_rgba(color, 0.55), label=label))
    ax.imshow(img, origin="lower", extent=(-wm, wm, 0.0, vm), aspect="auto", interpolation="nearest",
              zorder=1)
    # Velocity space border.
    tri_w = np.linspace(-wm, wm, 201)
    ax.plot(tri_w, vs_v_max(tri_w, cfg), color="black", lw=1.5, zorder=3)
    ax.plot([-wm, wm], [0.0, 0.0], color="black", lw=1.5, zorder=3)
    # Dynamic window.
    dw = decision.window.vertices()
    ax.plot(dw[:, 0], dw[:, 1], color="#1f77b4", lw=1.8, zorder=4)
    handles.append(Line2D([], [], color="#1f77b4", lw=1.8, label="dynamic window"))
    cv, cw = decision.window.candidates(cfg)
    bad = model.forbidden(cv, cw)
    ax.scatter(cw[~bad], cv[~bad], s=5, color="#2ca02c", zorder=5, lw=0)
    ax.scatter(cw[bad], cv[bad], s=5, color="#d62728", zorder=5, lw=0)
    handles.append(Line2D([], [], ls="none", marker="o", ms=3, color="#2ca02c", label="free window sample"))
    handles.append(Line2D([], [], ls="none", marker="o", ms=3, color="#d62728",
                          label="forbidden window sample"))
    # Commands.
    g = decision.goal
    tv, tw = g.target
    ax.plot([tw], [min(tv, vm)], marker="*", ms=16, color="#2ca02c", mec="black", mew=0.8, zorder=7,
            ls="none")
    handles.append(Line2D([], [], ls="none", marker="*", ms=12, color="#2ca02c", mec="black",
                          label=f"goal command ({g.mode.replace('_', ' ')})"))
    v0, w0 = decision.velocity
    ax.plot([w0], [v0], marker="o", ms=8, mfc="white", mec="black", mew=1.2, zorder=7, ls="none")
    handles.append(Line2D([], [], ls="none", marker="o", ms=7, mfc="white", mec="black",
                          label="current velocity"))
    s = decision.selection
    ax.plot([s.omega], [s.v], marker="X", ms=11, color="#1f77b4", mec="black", mew=0.8, zorder=8,
            ls="none")
    handles.append(Line2D([], [], ls="none", marker="X", ms=10, color="#1f77b4", mec="black",
                          label=f"chosen command ({s.mode})"))
    if s.escape_to is not None:
        ax.plot([s.escape_to[1]], [s.escape_to[0]], marker="D", ms=7, color="#ffbf00", mec="black",
                zorder=7, ls="none")
        handles.append(Line2D([], [], ls="none", marker="D", ms=6, color="#ffbf00", mec="black",
                              label="escape velocity"))
    ax.set_xlim(-wm * 1.03, wm * 1.03)
    ax.set_ylim(-0.02 * vm, vm * 1.08)
    ax.set_xlabel(r"turn rate $\omega$ [rad/s]  (left turn > 0)")
    ax.set_ylabel("linear speed $v$ [m/s]")
    ax.grid(True, lw=0.4, alpha=0.5, zorder=0)
    if legend:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8,
                  frameon=False, borderaxespad=0.0)
    if title:
        ax.set_title(f"DOVS velocity space: chosen (v, $\\omega$) = ({s.v:.3f} m/s, {s.omega:+.3f} "
                     f"rad/s)\nperiod T = {cfg.control_period_s:g} s, horizon $T_h$ = "
                     f"{cfg.time_horizon_s:g} s, merge = {cfg.merge}, {s.n_free} of {s.n_candidates} "
                     "window samples free", fontsize=8)
    return handles


def draw_decision_world(ax: Any, scenario: Scenario, decision: Decision,
                        trajectory: np.ndarray | None = None, *, legend: bool = True) -> Any:
    """Draw the arena, the robot, the obstacles' predicted motion and the chosen arc; returns
    the :class:`~anyplan.viz.style.LabelPlacer` of the names (see :func:`draw_scenario`)."""
    cfg = decision.model.cfg
    colors = qualitative_colors(len(decision.obstacles) + 1)
    placer = draw_scenario(ax, scenario, labels=True)
    if trajectory is not None and len(trajectory) > 1:
        ax.plot(trajectory[:, 1], trajectory[:, 2], color="#1f77b4", lw=1.5, zorder=6,
                label="path so far")
    pose = decision.pose
    Th = cfg.time_horizon_s
    ts = np.linspace(0.0, Th, 81)
    for j, ob in enumerate(decision.obstacles):
        color = colors[j % len(colors)]
        if ob.kind == "static":
            x, y, _ = to_world_frame(pose, ob.x, ob.y)
            ax.add_patch(CirclePatch((float(x), float(y)), ob.radius, fc="none", ec=color, ls=":",
                                     zorder=6))
            continue
        if ob.kind == "linear":
            px = ob.x + ob.v * ts * math.cos(ob.theta)
            py = ob.y + ob.v * ts * math.sin(ob.theta)
        else:
            r = ob.v / ob.omega
            th = ob.theta + ob.omega * ts
            px = ob.x + r * (np.sin(th) - math.sin(ob.theta))
            py = ob.y - r * (np.cos(th) - math.cos(ob.theta))
        wx, wy, _ = to_world_frame(pose, px, py)
        ax.plot(wx, wy, color=color, ls="--", lw=1.2, zorder=6)
        rho = ob.radius - cfg.safety_factor * cfg.robot_radius
        ax.add_patch(CirclePatch((float(wx[0]), float(wy[0])), rho, fc=color, ec="black", alpha=0.8,
                                 zorder=7))
        ax.add_patch(CirclePatch((float(wx[0]), float(wy[0])), ob.radius, fc="none", ec=color,
                                 ls=":", lw=1.0, zorder=7))
        placer.add((float(wx[0]), float(wy[0])), ob.name, gap_pt=5.0, fontsize=8, color=color,
                   weight="bold", zorder=8, path_effects=halo())
    s = decision.selection
    if s.v > 1e-9:
        ss = np.linspace(0.0, s.v * Th, 81)
        ax_, ay_ = arc_points(s.omega / s.v, ss)
        wx, wy, _ = to_world_frame(pose, ax_, ay_)
        ax.plot(wx, wy, color="#1f77b4", ls=":", lw=2.0, zorder=8,
                label=f"chosen arc over {Th:g} s")
    ax.add_patch(CirclePatch(pose[:2], cfg.robot_radius, fc="#1f77b4", ec="black", zorder=9))
    ax.annotate("", xy=(pose[0] + 0.7 * math.cos(pose[2]), pose[1] + 0.7 * math.sin(pose[2])),
                xytext=pose[:2], arrowprops={"arrowstyle": "->", "color": "black", "lw": 1.5},
                zorder=10)
    if legend:
        ax.legend(loc="lower left", fontsize=8, framealpha=0.9)
    placer.layout()
    return placer


def save_dovs_figure(scenario: Scenario, decision: Decision, t: float, path: str | Path, *,
                     trajectory: np.ndarray | Sequence[Sequence[float]] | None = None,
                     note: str = "", dpi: int = 300) -> Path:
    """Write the two-panel picture of ``decision`` (taken at time ``t`` [s]) to ``path`` (PNG,
    SVG or PDF by the suffix), 7.16 in wide with the legends below the panels."""
    traj = None if trajectory is None else np.asarray(trajectory, dtype=float).reshape(-1, 6)
    cfg, s = decision.model.cfg, decision.selection
    v0, w0 = decision.velocity
    with paper_style():
        fig_h = 4.8
        fig = new_figure((TEXT_WIDTH_IN, fig_h))
        a1, a2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.3, 1.0]})
        placer = draw_decision_world(a1, scenario, decision, traj, legend=False)
        a1.set_title(f"{scenario.name} at t = {t:.2f} s:\nrobot v = {v0:.3f} m/s, "
                     f"$\\omega$ = {w0:+.3f} rad/s" + (f"\n{note}" if note else ""))
        handles = draw_velocity_space(a2, decision, legend=False, title=False)
        a2.set_title(f"velocity space: chosen v = {s.v:.3f} m/s,\n$\\omega$ = {s.omega:+.3f} rad/s "
                     f"({s.n_free} of {s.n_candidates} samples free)")
        world = a1.get_legend_handles_labels()
        fig.legend(world[0] + handles, world[1] + [h.get_label() for h in handles],
                   loc="lower center", ncol=2, frameon=False)
        fig.suptitle(f"DOVS decision: period T = {cfg.control_period_s:g} s, horizon $T_h$ = "
                     f"{cfg.time_horizon_s:g} s, merge = {cfg.merge}")
        rows = math.ceil((len(world[0]) + len(handles)) / 2)
        tight(fig, (0.0, (0.1 + 0.165 * rows) / fig_h, 1.0, 1.0))
    return save_figure(fig, path, placers=[placer], dpi=dpi)
