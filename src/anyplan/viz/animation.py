"""Animations of one run: robot, moving obstacles, current plan and virtual obstacles over time.

Each frame shows, at simulated time t, the static scene (:func:`anyplan.viz.run.draw_scenario`),
the robot and its trail, the moving obstacles, the latest plan made at or before t, the virtual
obstacles that exist at t, the time and, at the end, the outcome. Frames are ``speed / fps``
simulated seconds apart (real time x ``speed``); the static scene is drawn once and the moving
artists blitted on the Agg canvas. GIFs are written with Pillow, MP4 through ffmpeg.

``docs/experiments.md``, "Animations: frames".
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
from matplotlib import animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Rectangle

from anyplan.viz.run import draw_scenario
from anyplan.viz.style import halo, new_figure, qualitative_colors
from anyplan.world.scenario import Scenario

__all__ = ["animate_run", "check_target", "frame_times", "ffmpeg_available", "state_at"]

ROBOT_COLOR = "#1f77b4"
PLAN_COLOR = "#222222"
VIRTUAL_FACE = "#1e63d6"


def ffmpeg_available() -> bool:
    """True if matplotlib can write MP4 through ffmpeg."""
    return bool(animation.writers.is_available("ffmpeg"))


def check_target(path: str | Path, speed: float = 4.0) -> None:
    """Raise ValueError unless ``path`` is a writable animation target (.gif, or .mp4 with ffmpeg)
    and ``speed`` > 0; cheap, so callers can check before simulating."""
    suffix = Path(path).suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"animation file must end in .gif or .mp4, got '{Path(path).name}'")
    if suffix == ".mp4" and not ffmpeg_available():
        raise ValueError("MP4 needs ffmpeg on the PATH; install it or write a .gif")
    if not speed > 0.0:
        raise ValueError(f"speed must be > 0, got {speed:g}")


def _write_gif(frames: list[np.ndarray], path: Path, fps: float) -> None:
    from PIL import Image

    imgs = [Image.fromarray(f).convert("P", palette=Image.Palette.ADAPTIVE, colors=128) for f in frames]
    imgs[0].save(path, save_all=True, append_images=imgs[1:], duration=max(int(round(1000 / fps)), 20),
                 loop=0)


def _write_mp4(frames: list[np.ndarray], path: Path, fps: float) -> None:
    import subprocess

    h, w = frames[0].shape[:2]
    cmd = [matplotlib.rcParams["animation.ffmpeg_path"], "-y", "-loglevel", "error", "-f", "rawvideo",
           "-pix_fmt", "rgb24", "-s", f"{w}x{h}", "-r", f"{fps:.6g}", "-i", "-",
           "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-vcodec", "libx264", str(path)]
    proc = subprocess.run(cmd, input=b"".join(f.tobytes() for f in frames), capture_output=True, check=False)
    if proc.returncode != 0:
        raise ValueError(f"ffmpeg failed: {proc.stderr.decode(errors='replace').strip()[:200]}")


def frame_times(t_end: float, speed: float, fps: float, max_frames: int) -> tuple[np.ndarray, float]:
    """Frame times [s] from 0 to ``t_end`` and the frame rate actually used.

    Frames are ``speed / fps`` seconds of simulated time apart; if that gives more than
    ``max_frames`` frames, the frame rate is lowered (the playback speed stays ``speed``).
    """
    if not speed > 0.0 or not fps > 0.0:
        raise ValueError(f"speed and fps must be > 0, got {speed}, {fps}")
    n = int(math.floor(t_end * fps / speed + 1e-9)) + 1
    if n > max_frames:
        fps = max(fps * (max_frames - 1) / max(n - 1, 1), 1e-3)
    step = speed / fps
    times = np.arange(0.0, t_end + 1e-9, step)
    if times[-1] < t_end - 1e-9:
        times = np.append(times, t_end)
    return times, fps


def state_at(traj: np.ndarray, t: float) -> tuple[float, float, float]:
    """Robot (x, y, theta) at time ``t`` [s], interpolated in the trajectory rows [t, x, y, th, ...]."""
    ts = traj[:, 0]
    x = float(np.interp(t, ts, traj[:, 1]))
    y = float(np.interp(t, ts, traj[:, 2]))
    th = float(np.interp(t, ts, np.unwrap(traj[:, 3])))
    return x, y, th


def animate_run(scenario: Scenario, result: Any, path: str | Path, *, speed: float = 4.0,
                fps: float = 15.0, max_frames: int = 600, dpi: int = 80) -> Path:
    """Write an animation of ``result`` on ``scenario`` to ``path`` (``.gif`` or ``.mp4``).

    Args:
        scenario: The scenario that was run (true obstacle motions are drawn).
        result: A :class:`~anyplan.simulation.RunResult` or its ``to_dict()``.
        path: Output file; the suffix chooses the format.
        speed: Playback speed as a multiple of real time.
        fps: Frames per second of the video (lowered if ``max_frames`` would be exceeded).
        max_frames: Upper bound on the number of frames.
        dpi: Resolution.

    Raises:
        ValueError: an unknown suffix, MP4 without ffmpeg, or a non-positive speed/fps.
    """
    check_target(path, speed)
    path = Path(path)
    suffix = path.suffix.lower()
    res = result if isinstance(result, dict) else result.to_dict()
    traj = np.asarray(res["trajectory"], dtype=float).reshape(-1, 6)
    t_end = float(traj[-1, 0])
    times, fps_used = frame_times(t_end, speed, fps, max_frames)

    fig = new_figure((7.5, 7.5 * scenario.height / scenario.width + 0.6))
    ax = fig.add_subplot()
    placer = draw_scenario(ax, scenario)
    r = scenario.robot.radius

    # Virtual obstacles: created hidden, shown from their creation time on.
    virtual = []
    for vo in res.get("virtual_obstacles") or []:
        cx, cy = vo["center"]
        side = float(vo["side"])
        patch = Rectangle((cx - side / 2, cy - side / 2), side, side, fc=VIRTUAL_FACE, ec="#0b3a8a",
                          alpha=0.45, lw=1.0, zorder=3, visible=False)
        ax.add_patch(patch)
        virtual.append((float(vo.get("created_at_s", 0.0)), patch))
    plans = sorted(((float(p["t"]), np.asarray(p["path"], dtype=float)) for p in res.get("plans") or []
                    if len(p.get("path") or []) >= 2), key=lambda p: p[0])
    plan_times = np.array([p[0] for p in plans])
    (plan_line,) = ax.plot([], [], "--", color=PLAN_COLOR, lw=1.6, zorder=4, label="current plan")
    (trail,) = ax.plot([], [], "-", color=ROBOT_COLOR, lw=1.8, zorder=5, label="executed path")
    robot = CirclePatch((0, 0), r, fc=ROBOT_COLOR, ec="black", alpha=0.85, zorder=8)
    ax.add_patch(robot)
    (heading,) = ax.plot([], [], "-", color="white", lw=1.8, zorder=9)
    movers = []
    colors = qualitative_colors(len(scenario.moving_obstacles))
    for k, o in enumerate(scenario.moving_obstacles):
        c = colors[k]
        disc = CirclePatch((0, 0), o.radius, fc=c, ec="black", alpha=0.85, zorder=7)
        ax.add_patch(disc)
        label = ax.text(0, 0, o.name, fontsize=8, ha="center", va="bottom", color=c, weight="bold",
                        zorder=9, path_effects=halo())
        movers.append((o, disc, label))
    clock = ax.text(0.01, 0.99, "", transform=ax.transAxes, ha="left", va="top", fontsize=10,
                    bbox={"fc": "white", "ec": "0.6", "alpha": 0.85}, zorder=10)
    if virtual:
        ax.add_patch(Rectangle((0, 0), 0, 0, fc=VIRTUAL_FACE, alpha=0.45, label="virtual obstacle"))
    ax.legend(loc="lower right", fontsize=8, framealpha=0.85)
    status = res.get("status", "")
    outcome = {"reached": "reached the goal", "timeout": "time limit"}.get(
        status, f"collision with {res.get('collision_with')}" if status == "collision" else status)
    ax.set_title(f"{res.get('planner', '?')} on {scenario.name} (seed {res.get('seed', '?')}), "
                 f"real time x {speed:g}", fontsize=10)

    dynamic: list[Any] = [v[1] for v in virtual] + [plan_line, trail] + \
        [a for _, disc, label in movers for a in (disc, label)] + [robot, heading, clock]
    for a in dynamic:
        a.set_animated(True)

    def update(i: int) -> None:
        t = float(times[i])
        x, y, th = state_at(traj, t)
        robot.center = (x, y)
        heading.set_data([x, x + r * math.cos(th)], [y, y + r * math.sin(th)])
        k = int(np.searchsorted(traj[:, 0], t, side="right"))
        trail.set_data(np.append(traj[:k, 1], x), np.append(traj[:k, 2], y))
        for o, disc, label in movers:
            px, py = o.position(t)
            disc.center = (px, py)
            label.set_position((px, py + o.radius + 0.05))
            disc.set_visible(o.motion.exists(t))
            label.set_visible(o.motion.exists(t))
        if plans:
            j = int(np.searchsorted(plan_times, t, side="right")) - 1
            if j >= 0:
                plan_line.set_data(plans[j][1][:, 0], plans[j][1][:, 1])
            else:
                plan_line.set_data([], [])
        for t0, patch in virtual:
            patch.set_visible(t0 <= t)
        clock.set_text(f"t = {t:5.1f} s" + (f"\n{outcome}" if i == len(times) - 1 else ""))

    # Blitting: draw the static scene once, then only the moving artists on each frame.
    fig.set_dpi(dpi)
    fig.tight_layout()
    placer.layout()
    canvas = fig.canvas
    assert isinstance(canvas, FigureCanvasAgg)  # new_figure's own canvas
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    frames = []
    for i in range(len(times)):
        update(i)
        canvas.restore_region(background)
        for a in dynamic:
            ax.draw_artist(a)
        frames.append(np.asarray(canvas.buffer_rgba())[:, :, :3].copy())
    if suffix == ".gif":
        _write_gif(frames, path, fps_used)
    else:
        _write_mp4(frames, path, fps_used)
    return path
