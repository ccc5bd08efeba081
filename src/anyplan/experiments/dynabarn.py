"""DynaBARN worlds as anyplan scenarios.

DynaBARN (A. Nair, F. Jiang, K. Hou, Z. Xu, S. Li, X. Xiao, P. Stone, "DynaBARN: Benchmarking
Metric Ground Navigation in Dynamic Environments", SSRR 2022) has 60 Gazebo worlds (0-19 easy,
20-39 medium, 40-59 hard): three static walls and 5-24 discs (r = 0.5 m) that loop along
time-stamped piecewise-linear tracks. The converter reads the challenge's ``worlds.json`` (data,
not shipped) and writes one scenario per world: moving obstacles of type ``waypoints``
(D1..Dn), coordinates shifted by :data:`SHIFT`, the open +x side closed 1.5 m behind the start,
the challenge's task and a Clearpath Jackal (:data:`JACKAL`).

Frame, arena, task, robot limits and motions: ``docs/experiments.md``, "DynaBARN conventions".
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from anyplan.errors import AnyplanError
from anyplan.world.scenario import scenario_from_dict
from anyplan.world.yaml_load import dump_yaml

__all__ = ["JACKAL", "SHIFT", "ARENA", "DynaBARNError", "default_worlds_path", "load_worlds",
           "parse_worlds", "world_to_scenario", "convert", "tier"]

#: Clearpath Jackal profile (docs/experiments.md, "DynaBARN conventions"), SI units.
JACKAL: dict[str, float] = {"radius": 0.34, "v_max": 2.0, "omega_max": 2.0, "a_max": 2.0,
                            "alpha_max": 4.0, "goal_tolerance": 1.0}
#: Added to DynaBARN (x, y) [m].
SHIFT = (10.5, 10.5)
#: Arena (width, height) [m]: DynaBARN [-10.5, 12.5] x [-10.5, 10.5].
ARENA = (23.0, 21.0)
START = (11.0, 0.0, math.pi)
GOAL = (-9.0, 0.0)
TIME_LIMIT = 100.0


class DynaBARNError(AnyplanError):
    """The worlds file is missing or malformed, or a world index is out of range."""


def tier(index: int) -> str:
    """``easy`` (0-19), ``medium`` (20-39) or ``hard`` (40-59)."""
    return "easy" if index < 20 else "medium" if index < 40 else "hard"


def default_worlds_path(cwd: str | Path | None = None) -> Path:
    """``../shared/benchmarks/dynabarn/worlds.json`` relative to ``cwd`` (default: the current dir)."""
    base = Path.cwd() if cwd is None else Path(cwd)
    return (base / ".." / "shared" / "benchmarks" / "dynabarn" / "worlds.json").resolve()


def load_worlds(path: str | Path) -> list[dict[str, Any]]:
    """The list of worlds in ``path`` (``worlds.json``).

    Raises:
        DynaBARNError: missing, unreadable or not a JSON list of worlds.
    """
    p = Path(path)
    if not p.is_file():
        raise DynaBARNError.about(
            str(p), ": no such file (pass {worlds_file} PATH to the DynaBARN worlds.json)", "worlds_file")
    try:
        data = json.loads(p.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DynaBARNError(f"{p}: not a readable JSON file ({type(exc).__name__})") from None
    if not isinstance(data, list) or not all(isinstance(w, Mapping) for w in data):
        raise DynaBARNError(f"{p}: expected a JSON list of worlds")
    return data


def parse_worlds(spec: str, n_worlds: int = 60,
                 error: type[AnyplanError] = DynaBARNError) -> list[int]:
    """World indices from ``"0-19"``, ``"3,5,40-42"`` or ``"all"``, in order, without repeats.

    Raises:
        error (DynaBARNError by default): a malformed item or an index outside 0..n_worlds-1.
    """
    if spec.strip() == "all":
        return list(range(n_worlds))
    out: list[int] = []
    for item in spec.split(","):
        item = item.strip()
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", item)
        if not m:
            raise error.about("worlds", f": '{item}' is not an index or a range like 0-{n_worlds - 1}")
        a = int(m.group(1))
        b = int(m.group(2)) if m.group(2) else a
        if a > b:
            raise error.about("worlds", f": empty range '{item}'")
        for i in range(a, b + 1):
            if not 0 <= i < n_worlds:
                raise error.about("worlds", f": index {i} is outside 0-{n_worlds - 1}")
            if i not in out:
                out.append(i)
    return out


def _sx(x: float) -> float:
    return float(x) + SHIFT[0]


def _sy(y: float) -> float:
    return float(y) + SHIFT[1]


def _num(obj: Any, where: str) -> float:
    if isinstance(obj, bool) or not isinstance(obj, int | float) or not math.isfinite(obj):
        raise DynaBARNError(f"{where}: expected a finite number, got {obj!r}")
    return float(obj)


def world_to_scenario(world: Mapping[str, Any], profile: Mapping[str, float] | None = None,
                      name: str | None = None) -> dict[str, Any]:
    """The scenario dictionary (our YAML schema) of one DynaBARN world.

    Raises:
        DynaBARNError: a malformed world, naming the field.
    """
    prof = dict(JACKAL if profile is None else profile)
    idx = world.get("world")
    if isinstance(idx, bool) or not isinstance(idx, int):
        raise DynaBARNError(f"world entry: 'world' must be an integer index, got {idx!r}")
    where = f"world {idx}"
    statics = []
    for k, wall in enumerate(world.get("walls") or []):
        try:
            pose, size = wall["pose"], wall["size"]
            cx, cy, yaw = (_num(pose[i], f"{where}.walls[{k}].pose") for i in (0, 1, 5))
            sx, sy = (_num(size[i], f"{where}.walls[{k}].size") for i in (0, 1))
        except (KeyError, IndexError, TypeError):
            raise DynaBARNError(f"{where}.walls[{k}]: expected pose [x, y, z, roll, pitch, yaw] and "
                                "size [sx, sy, sz]") from None
        statics.append({"name": str(wall.get("name", f"wall{k}")), "type": "rectangle",
                        "center": [_sx(cx), _sy(cy)], "size": [sx, sy], "angle": yaw})
    movers = []
    moving = world.get("moving")
    if not isinstance(moving, list) or not moving:
        raise DynaBARNError(f"{where}.moving: expected a non-empty list of obstacles")
    w, h = ARENA
    for k, m in enumerate(moving):
        fld = f"{where}.moving[{k}]"
        if not isinstance(m, Mapping) or "keyframes" not in m:
            raise DynaBARNError(f"{fld}: expected an obstacle with keyframes")
        r = _num(m.get("radius", 0.5), f"{fld}.radius")
        kf = m["keyframes"]
        if not isinstance(kf, list) or len(kf) < 2:
            raise DynaBARNError(f"{fld}.keyframes: expected at least 2 [t, x, y] rows")
        rows = []
        for j, row in enumerate(kf):
            if not isinstance(row, list | tuple) or len(row) != 3:
                raise DynaBARNError(f"{fld}.keyframes[{j}]: expected [t, x, y]")
            t, x, y = (_num(v, f"{fld}.keyframes[{j}]") for v in row)
            X, Y = _sx(x), _sy(y)
            if not (r <= X <= w - r and r <= Y <= h - r):
                raise DynaBARNError(f"{fld}.keyframes[{j}]: ({x:g}, {y:g}) puts the disc outside the "
                                    f"arena [-10.5, 12.5] x [-10.5, 10.5]")
            rows.append([t, X, Y])
        period = m.get("period")
        if period is not None and abs(_num(period, f"{fld}.period") - rows[-1][0]) > 1e-9:
            raise DynaBARNError(f"{fld}: last keyframe time {rows[-1][0]:g} differs from the period "
                                f"{period:g}")
        movers.append({"name": f"D{k + 1}", "type": "waypoints", "keyframes": rows, "radius": r})
    sx0, sy0, th0 = START
    data = {
        "name": name or f"dynabarn-{idx:02d}",
        "description": f"DynaBARN world {idx} ({tier(idx)}), {len(movers)} moving discs on looping "
                       "tracks; Clearpath Jackal; coordinates shifted by (+10.5, +10.5) m.",
        "time_limit": TIME_LIMIT,
        "arena": {"width": w, "height": h},
        "robot": {"start": [_sx(sx0), _sy(sy0), th0], "goal": [_sx(GOAL[0]), _sy(GOAL[1])], **prof},
        "static_obstacles": statics,
        "dynamic_obstacles": movers,
    }
    try:
        scenario_from_dict(data, f"<dynabarn world {idx}>")  # validate (start/goal free, schema)
    except AnyplanError as exc:
        raise DynaBARNError(f"{where}: does not convert to a valid scenario: {exc}") from None
    return data


def convert(worlds_file: str | Path, out_dir: str | Path, worlds: Sequence[int] | str = "0-19",
            profile: Mapping[str, float] | None = None) -> list[Path]:
    """Write ``dynabarn-NN.yaml`` for each selected world into ``out_dir``; returns the paths."""
    data = load_worlds(worlds_file)
    by_index = {w.get("world"): w for w in data}
    n = max((i + 1 for i in by_index if isinstance(i, int)), default=0)
    idx = parse_worlds(worlds, n_worlds=n) if isinstance(worlds, str) else list(worlds)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for i in idx:
        if i not in by_index:
            raise DynaBARNError(f"world {i} is not in {worlds_file}")
        sc = world_to_scenario(by_index[i], profile)
        p = out / f"{sc['name']}.yaml"
        names = ", ".join(f"D{k + 1} = {m.get('name', '?')}" for k, m in enumerate(by_index[i]["moving"]))
        header = ("# Converted by 'anyplan import-dynabarn' from DynaBARN (Nair et al., SSRR 2022),\n"
                  "# BARN Challenge repository data, MIT licence, Copyright (c) 2022 Zifan Xu.\n"
                  "# Frame: DynaBARN (x, y) + (10.5, 10.5) m. See anyplan.experiments.dynabarn.\n"
                  f"# Obstacles (DynaBARN plugin names): {names}\n")
        p.write_text(header + dump_yaml(sc, sort_keys=False, default_flow_style=None, width=100))
        paths.append(p)
    return paths
