"""Recorded pedestrian crowds (ETH/UCY ``obsmat`` files) as anyplan scenarios.

ETH (Pellegrini et al., ICCV 2009) and UCY (Lerner et al., Eurographics 2007) record people as
rows ``frame person x z y vx vz vy`` every 0.4 s. Each person becomes a moving obstacle of type
``track`` (a 0.25 m disc, exact at each sample, linear in between, present only within its
samples); people are replayed, not reactive. A *window* ``[t0, t0 + length]`` of the recording
is one scenario, with a robot crossing the scene along its longer side where nobody walks;
``copies`` overlays shifted copies for denser crowds.

Time, frame, the robot's crossing line and the copies: ``docs/perception.md``, "Recorded
crowds: conventions".
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.errors import AnyplanError
from anyplan.world.scenario import scenario_from_dict
from anyplan.world.yaml_load import dump_yaml

__all__ = ["CrowdError", "CrowdOptions", "SERVICE_ROBOT", "PERSON_RADIUS", "FRAME_RATE",
           "read_obsmat", "crowd_scenarios", "import_crowd"]

#: Small service robot: radius [m], v [m/s], omega [rad/s], a [m/s^2], alpha [rad/s^2].
SERVICE_ROBOT: dict[str, float] = {"radius": 0.3, "v_max": 1.0, "omega_max": 1.5, "a_max": 1.0,
                                   "alpha_max": 3.0, "goal_tolerance": 0.3}
#: Radius [m] of a person's disc.
PERSON_RADIUS = 0.25
#: Video frames per second of ETH and UCY.
FRAME_RATE = 25.0


class CrowdError(AnyplanError):
    """An unreadable or malformed obsmat file, or bad import options."""


@dataclass(frozen=True)
class CrowdOptions:
    """Import settings (lengths in m, times in s)."""

    window_s: float = 40.0
    step_s: float = 40.0
    margin_m: float = 1.5
    edge_m: float = 0.8
    copies: int = 1
    copy_shift_s: float = 37.0
    sensing_range_m: float = 8.0
    noise_m: float = 0.05
    rate_hz: float = 10.0
    robot: Mapping[str, float] | None = None

    def check(self) -> None:
        """Raises CrowdError on an out-of-range option."""
        for name in ("window_s", "step_s", "margin_m", "edge_m", "sensing_range_m", "rate_hz"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise CrowdError.about(name, f" must be > 0, got {v:g}")
        if not (math.isfinite(self.noise_m) and self.noise_m >= 0.0):
            raise CrowdError.about("noise_m", f" must be >= 0 m, got {self.noise_m:g}")
        if self.copies < 1:
            raise CrowdError.about("copies", f" must be >= 1, got {self.copies}")
        if self.edge_m >= self.margin_m:
            raise CrowdError.about("edge_m", " must be smaller than {margin_m}", "margin_m")
        for k, v in (self.robot or {}).items():
            if not (math.isfinite(v) and v > 0.0):
                raise CrowdError(f"import-crowd: robot {k} must be > 0, got {v:g}")


def read_obsmat(path: str | Path) -> dict[int, np.ndarray]:
    """Tracks of an obsmat file: person id -> rows (t [s], x [m], y [m]), sorted by time.

    Raises:
        CrowdError: missing file, a row that is not 8 finite numbers, a repeated frame of a person.
    """
    p = Path(path)
    if not p.is_file():
        raise CrowdError(f"{p}: no such file")
    try:
        lines = p.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise CrowdError(f"{p}: cannot read file ({type(exc).__name__})") from None
    rows = []
    for i, line in enumerate(lines, 1):
        parts = line.split()
        if not parts:
            continue
        try:
            vals = [float(v) for v in parts]
        except ValueError:
            raise CrowdError(f"{p}: line {i}: expected 8 numbers (frame person x z y vx vz vy), "
                             f"got '{line.strip()[:40]}'") from None
        if len(vals) != 8 or not all(math.isfinite(v) for v in vals):
            raise CrowdError(f"{p}: line {i}: expected 8 finite numbers (frame person x z y vx vz "
                             f"vy), got {len(vals)}")
        if vals[1] != int(vals[1]):
            raise CrowdError(f"{p}: line {i}: person id must be an integer, got {vals[1]:g}")
        rows.append((vals[0], int(vals[1]), vals[2], vals[4]))
    if not rows:
        raise CrowdError(f"{p}: no rows")
    f0 = min(r[0] for r in rows)
    tracks: dict[int, list[tuple[float, float, float]]] = {}
    for f, pid, x, y in rows:
        tracks.setdefault(pid, []).append(((f - f0) / FRAME_RATE, x, y))
    out = {}
    for pid, tr in tracks.items():
        a = np.array(sorted(tr))
        if np.any(np.diff(a[:, 0]) <= 0.0):
            raise CrowdError(f"{p}: person {pid}: the same frame appears twice")
        out[pid] = a
    return out


def _copy(tracks: Mapping[int, np.ndarray], k: int, shift: float,
          period: float) -> list[tuple[str, np.ndarray]]:
    """Copy k of the recording: times moved by ``-k * shift`` modulo ``period`` (a track cut by
    the wrap becomes two, the second named with a ``b``)."""
    out = []
    for pid in sorted(tracks):
        tr = tracks[pid].copy()
        name = f"P{pid}" if k == 0 else f"P{pid}c{k}"
        if k == 0:
            out.append((name, tr))
            continue
        tr[:, 0] = np.mod(tr[:, 0] - k * shift, period)
        cut = np.flatnonzero(np.diff(tr[:, 0]) < 0.0)
        if len(cut):
            out.append((name, tr[: cut[0] + 1]))
            out.append((name + "b", tr[cut[0] + 1:]))
        else:
            out.append((name, tr))
    return out


def _window_people(copies: list[list[tuple[str, np.ndarray]]], t0: float,
                   length: float) -> list[tuple[str, np.ndarray]]:
    people = []
    for tracks in copies:
        for name, tr in tracks:
            m = (tr[:, 0] >= t0 - 1e-9) & (tr[:, 0] <= t0 + length + 1e-9)
            if m.sum() < 2:
                continue
            s = tr[m].copy()
            s[:, 0] = np.maximum(s[:, 0] - t0, 0.0)  # no -1e-14 from the subtraction
            people.append((name, s))
    return people


def _occupancy(people: list[tuple[str, np.ndarray]], p: np.ndarray, reach: float,
               t_grid: np.ndarray) -> np.ndarray:
    """Per person, the time [s] (on t_grid) spent within ``reach`` of point p."""
    dt = t_grid[1] - t_grid[0]
    out = []
    for _, s in people:
        m = (t_grid >= s[0, 0]) & (t_grid <= s[-1, 0])
        x = np.interp(t_grid[m], s[:, 0], s[:, 1])
        y = np.interp(t_grid[m], s[:, 0], s[:, 2])
        out.append(float(np.count_nonzero(np.hypot(x - p[0], y - p[1]) < reach)) * dt)
    return np.array(out)


def crowd_scenarios(tracks: Mapping[int, np.ndarray], name: str,
                    options: CrowdOptions | None = None) -> list[dict[str, Any]]:
    """Scenario dictionaries (our YAML schema), one per usable window of the recording."""
    opt = options or CrowdOptions()
    opt.check()
    robot = {**SERVICE_ROBOT, **(opt.robot or {})}
    r = robot["radius"]
    allp = np.vstack(list(tracks.values()))
    xmin, ymin = allp[:, 1].min(), allp[:, 2].min()
    sx, sy = opt.margin_m - xmin, opt.margin_m - ymin
    width = float(allp[:, 1].max() - xmin + 2 * opt.margin_m)
    height = float(allp[:, 2].max() - ymin + 2 * opt.margin_m)
    shifted = {pid: np.column_stack([tr[:, 0], tr[:, 1] + sx, tr[:, 2] + sy])
               for pid, tr in tracks.items()}
    t_end = float(max(tr[-1, 0] for tr in tracks.values()))
    along_x = width >= height
    long_side, short_side = (width, height) if along_x else (height, width)
    out = []
    period = t_end + 0.4  # one annotation interval after the last frame: no two copies' samples meet
    copies = [_copy(shifted, k, opt.copy_shift_s, period) for k in range(opt.copies)]
    n_win = int(math.floor((t_end - opt.window_s) / opt.step_s + 1e-9)) + 1
    for w in range(max(n_win, 0)):
        t0 = w * opt.step_s
        people = _window_people(copies, t0, opt.window_s)
        grid = np.arange(0.0, opt.window_s + 1e-9, 0.1)
        chosen = None
        for off in [0.0] + [s * k for k in range(1, int(short_side / 2)) for s in (1.0, -1.0)]:
            lat = 0.5 * short_side + off
            if not r + 0.1 <= lat <= short_side - r - 0.1:
                continue
            a, b = opt.edge_m, long_side - opt.edge_m
            start = np.array([a, lat] if along_x else [lat, a])
            goal = np.array([b, lat] if along_x else [lat, b])
            early = grid[grid <= 2.0]
            if people and _occupancy(people, start, r + PERSON_RADIUS + 0.5, early).max() > 0.0:
                continue
            if people and _occupancy(people, goal, r + PERSON_RADIUS, grid).max() > 2.0:
                continue
            chosen = (start, goal)
            break
        if chosen is None:
            continue
        start, goal = chosen
        heading = math.atan2(goal[1] - start[1], goal[0] - start[0])
        movers = [{"name": n, "type": "track", "radius": PERSON_RADIUS,
                   "samples": [[float(v) for v in row] for row in s]} for n, s in people]
        data = {
            "name": f"{name}-w{w:02d}" + (f"-x{opt.copies}" if opt.copies > 1 else ""),
            "description": f"Recorded crowd {name}, window {t0:g}-{t0 + opt.window_s:g} s, "
                           f"{len(people)} people replayed"
                           + (f" ({opt.copies} copies shifted by {opt.copy_shift_s:g} s)"
                              if opt.copies > 1 else "")
                           + f"; positions shifted by ({sx:.6g}, {sy:.6g}) m.",
            "time_limit": opt.window_s,
            "arena": {"width": width, "height": height},
            "robot": {"start": [float(start[0]), float(start[1]), heading],
                      "goal": [float(goal[0]), float(goal[1])], **robot,
                      "sensing_range": opt.sensing_range_m},
            "static_obstacles": [],
            "dynamic_obstacles": movers,
            "sensing": {"mode": "tracked", "noise_m": opt.noise_m, "rate_hz": opt.rate_hz},
        }
        try:
            scenario_from_dict(data, f"<{data['name']}>")
        except AnyplanError as exc:
            raise CrowdError(f"{name}: window {w} does not convert to a valid scenario: {exc}") from None
        out.append(data)
    return out


def import_crowd(path: str | Path, out_dir: str | Path, options: CrowdOptions | None = None,
                 name: str | None = None) -> list[Path]:
    """Write one scenario YAML file per window of the obsmat file ``path``; returns the paths."""
    p = Path(path)
    tracks = read_obsmat(p)
    base = name or p.stem.replace("_obsmat", "").replace("_", "-")
    scenarios = crowd_scenarios(tracks, base, options)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for sc in scenarios:
        f = out / f"{sc['name']}.yaml"
        f.write_text(f"# Converted by 'anyplan import-crowd' from {p.name} (ETH/UCY obsmat).\n"
                     + dump_yaml(sc, sort_keys=False, default_flow_style=None, width=100))
        paths.append(f)
    return paths
