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

import difflib
import json
import math
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from anyplan.errors import AnyplanError, NumberRefused, ScenarioError, finite_float, shorten
from anyplan.world import limits as L
from anyplan.world.scenario import scenario_from_dict
from anyplan.world.yaml_load import dump_yaml

__all__ = ["JACKAL", "SHIFT", "ARENA", "DynaBARNError", "default_worlds_path", "load_worlds",
           "read_worlds", "parse_worlds", "world_to_scenario", "convert", "tier", "world_index",
           "check_keys", "finite", "converted_error"]

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
    """The list of worlds in ``path`` (``worlds.json``), each with a distinct index in range
    and known keys (their contents are checked by :func:`world_to_scenario`).

    Raises:
        DynaBARNError: missing, unreadable, not a non-empty JSON list of worlds, a bad,
            missing or repeated world index or an unknown key (naming the file and the field).
    """
    return read_worlds(path, DynaBARNError, "worlds_file", "DynaBARN",
                       lambda w, where: check_keys(w, _WORLD_KEYS, where, DynaBARNError))


def read_worlds(path: str | Path, error: type[AnyplanError], option: str, dataset: str,
                check: Callable[[Mapping[str, Any], str], None]) -> list[dict[str, Any]]:
    """The worlds of a challenge's ``worlds.json`` (``dataset``: ``DynaBARN``, ``BARN``): a
    non-empty JSON list, each item with a distinct :func:`world_index` and passing ``check``
    (given the world and ``FILE: world N`` to name it in its errors).

    Raises:
        error: missing (the message names the input ``option``, e.g. ``worlds_file``),
            unreadable, not a non-empty JSON list, a bad or repeated index, or what ``check``
            raises.
    """
    p = Path(path)
    if not p.is_file():
        raise error.about(str(p), f": no such file (pass {{{option}}} PATH to the {dataset} worlds.json)",
                          option)
    try:
        data = json.loads(p.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise error(f"{p}: not a readable JSON file ({type(exc).__name__})") from None
    if not isinstance(data, list) or not data:
        raise error(f"{p}: expected a non-empty JSON list of worlds")
    seen: dict[int, int] = {}
    for k, w in enumerate(data):
        idx = world_index(w, f"{p}: [{k}]", error)
        check(w, f"{p}: world {idx}")
        if idx in seen:
            raise error(f"{p}: world {idx} appears twice ([{seen[idx]}] and [{k}])")
        seen[idx] = k
    return data


#: Keys of a world, a wall and a moving obstacle in ``worlds.json``.
_WORLD_KEYS = ("world", "walls", "moving")
_WALL_KEYS = ("name", "pose", "size")
_MOVING_KEYS = ("name", "radius", "period", "keyframes")


def world_index(w: Any, where: str, error: type[AnyplanError]) -> int:
    """The ``world`` index of the world ``w`` (``where`` names it, e.g. ``FILE: [3]`` for item
    3 of a worlds file): an integer in [0, MAX_IMPORT_SCENARIOS - 1]."""
    if not isinstance(w, Mapping):
        raise error(f"{where}: expected a world object, got {shorten(w)}")
    if "world" not in w:
        raise error(f"{where}.world: missing (expected an integer index)")
    idx = w["world"]
    if isinstance(idx, bool) or not isinstance(idx, int):
        raise error(f"{where}.world: expected an integer index, got {shorten(idx)}")
    if not 0 <= idx < L.MAX_IMPORT_SCENARIOS:
        raise error(f"{where}.world: must be in [0, {L.MAX_IMPORT_SCENARIOS - 1}] (the stated "
                    f"limit), got {shorten(idx)}")
    return idx


def check_keys(obj: Mapping[str, Any], known: Iterable[str], where: str,
               error: type[AnyplanError]) -> None:
    """Refuses a key of ``obj`` not in ``known``, naming it (and the nearest known one)."""
    names = list(known)
    for key in obj:
        if key not in names:
            close = difflib.get_close_matches(str(key), names, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise error(f"{where}: unknown key {shorten(key)}{hint} (known: {', '.join(names)})")


def parse_worlds(spec: str, n_worlds: int = 60,
                 error: type[AnyplanError] = DynaBARNError) -> list[int]:
    """World indices from ``"0-19"``, ``"3,5,40-42"`` or ``"all"``, in order, without repeats.

    Raises:
        error (DynaBARNError by default): a malformed item or an index outside 0..n_worlds-1.
    """
    if spec.strip() == "all":
        return list(range(n_worlds))
    out: list[int] = []
    seen: set[int] = set()
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
            if i not in seen:
                seen.add(i)
                out.append(i)
    return out


def _sx(x: float) -> float:
    return float(x) + SHIFT[0]


def _sy(y: float) -> float:
    return float(y) + SHIFT[1]


def finite(obj: Any, where: str, error: type[AnyplanError], positive: bool = False,
           hi: float = L.MAX_COORD_M) -> float:
    """A JSON number: finite, within +-``hi`` (``positive``: in (0, hi])."""
    try:
        return finite_float(obj, 0.0 if positive else -hi, hi, lo_open=positive)
    except NumberRefused as exc:
        if exc.kind in ("type", "overflow", "nonfinite"):
            raise error(f"{where}: expected a finite number, got {shorten(obj)}") from None
        if positive and exc.kind == "low":
            raise error(f"{where}: expected a positive number, got {exc.shown}") from None
        raise error(f"{where}: must be within +-{hi:g} (the stated limit), got {exc.shown}") from None


def _num(obj: Any, where: str, positive: bool = False, hi: float = L.MAX_COORD_M) -> float:
    return finite(obj, where, DynaBARNError, positive, hi)


def _name(obj: Any, where: str) -> str:
    if not isinstance(obj, str) or not obj or not obj.isprintable() or len(obj) > 200:
        raise DynaBARNError(f"{where}: expected a name (printable, 1-200 characters), got "
                            f"{shorten(obj)}")
    return obj


def converted_error(exc: AnyplanError, where: str, fields: Mapping[str, str],
                    error: type[AnyplanError]) -> AnyplanError:
    """An error of the converted scenario told in the worlds file's terms: ``where`` (file and
    world) and, for an obstacle, the source field (``fields``: ``static_obstacles`` -> ``walls``)."""
    if isinstance(exc, ScenarioError):
        m = re.match(r"(static_obstacles|dynamic_obstacles)(\[\d+\].*)", exc.field)
        if m and m.group(1) in fields:
            return error(f"{where}.{fields[m.group(1)]}{m.group(2)}: {exc.message}")
        return error(f"{where}: does not convert to a valid scenario: {exc.field}: {exc.message}")
    return error(f"{where}: does not convert to a valid scenario: {exc}")


def world_to_scenario(world: Mapping[str, Any], profile: Mapping[str, float] | None = None,
                      name: str | None = None, source: str | Path | None = None) -> dict[str, Any]:
    """The scenario dictionary (our YAML schema) of one DynaBARN world.

    Raises:
        DynaBARNError: a malformed world, naming the file (``source``), the world and the field.
    """
    prof = dict(JACKAL if profile is None else profile)
    pre = f"{source}: " if source is not None else ""
    idx = world_index(world, f"{pre}world entry", DynaBARNError)
    where = f"{pre}world {idx}"
    check_keys(world, _WORLD_KEYS, where, DynaBARNError)
    walls = world.get("walls")
    if walls is not None and not isinstance(walls, list):
        raise DynaBARNError(f"{where}.walls: expected a list of walls, got {shorten(walls)}")
    statics = []
    for k, wall in enumerate(walls or []):
        if not isinstance(wall, Mapping):
            raise DynaBARNError(f"{where}.walls[{k}]: expected a wall with pose [x, y, z, roll, "
                                f"pitch, yaw] and size [sx, sy, sz], got {shorten(wall)}")
        check_keys(wall, _WALL_KEYS, f"{where}.walls[{k}]", DynaBARNError)
        try:
            pose, size = wall["pose"], wall["size"]
            cx, cy = (_num(pose[i], f"{where}.walls[{k}].pose") for i in (0, 1))
            yaw = _num(pose[5], f"{where}.walls[{k}].pose", hi=L.MAX_ANGLE_RAD)
            sx, sy = (_num(size[i], f"{where}.walls[{k}].size", True, L.MAX_SIZE_M) for i in (0, 1))
        except (KeyError, IndexError, TypeError):
            raise DynaBARNError(f"{where}.walls[{k}]: expected pose [x, y, z, roll, pitch, yaw] and "
                                "size [sx, sy, sz]") from None
        statics.append({"name": _name(wall.get("name", f"wall{k}"), f"{where}.walls[{k}].name"),
                        "type": "rectangle", "center": [_sx(cx), _sy(cy)], "size": [sx, sy],
                        "angle": yaw})
    movers = []
    moving = world.get("moving")
    if not isinstance(moving, list) or not moving:
        raise DynaBARNError(f"{where}.moving: expected a non-empty list of obstacles")
    w, h = ARENA
    for k, m in enumerate(moving):
        fld = f"{where}.moving[{k}]"
        if not isinstance(m, Mapping) or "keyframes" not in m:
            raise DynaBARNError(f"{fld}: expected an obstacle with keyframes")
        check_keys(m, _MOVING_KEYS, fld, DynaBARNError)
        if "name" in m:
            _name(m["name"], f"{fld}.name")
        r = _num(m.get("radius", 0.5), f"{fld}.radius", True, L.MAX_SIZE_M)
        kf = m["keyframes"]
        if not isinstance(kf, list) or len(kf) < 2:
            raise DynaBARNError(f"{fld}.keyframes: expected at least 2 [t, x, y] rows")
        rows = []
        for j, row in enumerate(kf):
            if not isinstance(row, list | tuple) or len(row) != 3:
                raise DynaBARNError(f"{fld}.keyframes[{j}]: expected [t, x, y]")
            t = _num(row[0], f"{fld}.keyframes[{j}]", hi=L.MAX_EVENT_TIME_S)
            x, y = (_num(v, f"{fld}.keyframes[{j}]") for v in row[1:])
            X, Y = _sx(x), _sy(y)
            if not (r <= X <= w - r and r <= Y <= h - r):
                raise DynaBARNError(f"{fld}.keyframes[{j}]: ({x:g}, {y:g}) puts the disc outside the "
                                    f"arena [-10.5, 12.5] x [-10.5, 10.5]")
            rows.append([t, X, Y])
        if m.get("period") is not None:
            period = _num(m["period"], f"{fld}.period", hi=L.MAX_EVENT_TIME_S)
            if abs(period - rows[-1][0]) > 1e-9:
                raise DynaBARNError(f"{fld}: last keyframe time {rows[-1][0]:g} differs from the "
                                    f"period {period:g}")
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
        raise converted_error(exc, where, {"static_obstacles": "walls", "dynamic_obstacles": "moving"},
                              DynaBARNError) from None
    return data


def convert(worlds_file: str | Path, out_dir: str | Path, worlds: Sequence[int] | str = "0-19",
            profile: Mapping[str, float] | None = None) -> list[Path]:
    """Write ``dynabarn-NN.yaml`` for each selected world into ``out_dir``; returns the paths."""
    data = load_worlds(worlds_file)
    by_index = {w["world"]: w for w in data}
    n = max(by_index) + 1
    idx = parse_worlds(worlds, n_worlds=n) if isinstance(worlds, str) else list(worlds)
    for i in idx:
        if i not in by_index:
            raise DynaBARNError(f"world {i} is not in {worlds_file}")
    # Every selected world converts before anything is written.
    scenarios = [(i, world_to_scenario(by_index[i], profile, source=worlds_file)) for i in idx]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, sc in scenarios:
        p = out / f"{sc['name']}.yaml"
        names = ", ".join(f"D{k + 1} = {m.get('name', '?')}" for k, m in enumerate(by_index[i]["moving"]))
        header = ("# Converted by 'anyplan import-dynabarn' from DynaBARN (Nair et al., SSRR 2022),\n"
                  "# BARN Challenge repository data, MIT licence, Copyright (c) 2022 Zifan Xu.\n"
                  "# Frame: DynaBARN (x, y) + (10.5, 10.5) m. See anyplan.experiments.dynabarn.\n"
                  f"# Obstacles (DynaBARN plugin names): {names}\n")
        p.write_text(header + dump_yaml(sc, sort_keys=False, default_flow_style=None, width=100))
        paths.append(p)
    return paths
