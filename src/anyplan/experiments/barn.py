"""BARN's 300 static worlds as anyplan scenarios.

BARN (D. Perille, A. Truong, X. Xiao, P. Stone, "Benchmarking Metric Ground Navigation", SSRR
2020; the BARN Challenge) has 300 Gazebo worlds of static cylinders. The converter reads the
challenge's ``worlds.json`` (data, not shipped with anyplan) and writes one scenario per world:
one static ``circle`` per cylinder, BARN's x shifted by :data:`SHIFT`, the challenge's start,
goal and time limit, a Clearpath Jackal as a 0.34 m disc (:data:`JACKAL`), and the visibility
graph's verdict on the world's feasibility for that disc (:func:`feasibility`).

Frame, arena, task, robot limits and feasibility: ``docs/experiments.md``, "BARN conventions".
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from anyplan.errors import AnyplanError, ScenarioError
from anyplan.experiments import dynabarn
from anyplan.world.scenario import Scenario, scenario_from_dict
from anyplan.world.yaml_load import dump_yaml

__all__ = ["JACKAL", "SHIFT", "ARENA", "START", "GOAL", "TIME_LIMIT", "N_WORLDS", "INDEX_FILE",
           "BARNError", "Feasibility", "default_source", "load_worlds", "parse_worlds",
           "world_to_scenario", "feasibility", "convert", "load_index", "scenario_name"]

#: Clearpath Jackal profile (docs/experiments.md, "BARN conventions"), SI units.
JACKAL: dict[str, float] = {"radius": 0.34, "v_max": 2.0, "omega_max": 4.0, "a_max": 20.0,
                            "alpha_max": 25.0, "goal_tolerance": 1.0}
#: Added to BARN (x, y) [m].
SHIFT = (4.5, 0.0)
#: Arena (width, height) [m]: BARN [-4.5, 0] x [0, 14].
ARENA = (4.5, 14.0)
#: The challenge's start (x, y, heading) and goal (x, y) in BARN's frame [m, rad].
START = (-2.25, 3.0, 1.57)
GOAL = (-2.25, 13.0)
TIME_LIMIT = 100.0
N_WORLDS = 300
#: Written by :func:`convert` beside the scenario files.
INDEX_FILE = "barn-index.json"


class BARNError(AnyplanError):
    """The worlds file is missing or malformed, or a world index is out of range."""


def scenario_name(index: int) -> str:
    """``barn-NNN``."""
    return f"barn-{index:03d}"


def default_source(cwd: str | Path | None = None) -> Path:
    """``../shared/benchmarks/barn/worlds.json`` relative to ``cwd`` (default: the current dir)."""
    base = Path.cwd() if cwd is None else Path(cwd)
    return (base / ".." / "shared" / "benchmarks" / "barn" / "worlds.json").resolve()


def _num(obj: Any, where: str, positive: bool = False) -> float:
    return dynabarn.finite(obj, where, BARNError, positive)


#: Keys of a world in ``worlds.json``.
_WORLD_KEYS = ("world", "cylinders", "reference_path_length_m")


def _check_world(w: Mapping[str, Any], where: str) -> None:
    dynabarn.check_keys(w, _WORLD_KEYS, where, BARNError)
    _num(w.get("reference_path_length_m"), f"{where}.reference_path_length_m", positive=True)
    cyl = w.get("cylinders")
    if not isinstance(cyl, list) or not cyl:
        raise BARNError(f"{where}.cylinders: expected a non-empty list of [x, y, radius]")
    width, height = ARENA
    for j, c in enumerate(cyl):
        f = f"{where}.cylinders[{j}]"
        if not isinstance(c, list | tuple) or len(c) != 3:
            raise BARNError(f"{f}: expected [x, y, radius], got {c!r}")
        x, y = _num(c[0], f), _num(c[1], f)
        r = _num(c[2], f"{f}.radius", positive=True)
        X, Y = x + SHIFT[0], y + SHIFT[1]
        if not (r <= X + 1e-9 and width - r + 1e-9 >= X and r <= Y + 1e-9 and height - r + 1e-9 >= Y):
            raise BARNError(f"{f}: ({x:g}, {y:g}) r {r:g} puts the cylinder outside the arena "
                            "[-4.5, 0] x [0, 14]")


def load_worlds(path: str | Path) -> list[dict[str, Any]]:
    """The validated list of worlds in ``path`` (``worlds.json``).

    Raises:
        BARNError: missing, unreadable, not a JSON list of worlds, or a malformed world (naming
            the file, the world and the field).
    """
    return dynabarn.read_worlds(path, BARNError, "source", "BARN", _check_world)


def parse_worlds(spec: str, n_worlds: int = N_WORLDS) -> list[int]:
    """World indices from ``"0-299"``, ``"3,5,40-42"`` or ``"all"``, in order, without repeats.

    Raises:
        BARNError: a malformed item or an index outside 0..n_worlds-1.
    """
    return dynabarn.parse_worlds(spec, n_worlds, error=BARNError)


def world_to_scenario(world: Mapping[str, Any], profile: Mapping[str, float] | None = None,
                      name: str | None = None, source: str | Path | None = None) -> dict[str, Any]:
    """The scenario dictionary (our YAML schema) of one BARN world (validated by
    :func:`load_worlds`).

    Raises:
        BARNError: the world does not make a valid scenario (e.g. a cylinder on the start),
            naming the file (``source``), the world and the cylinder.
    """
    prof = dict(JACKAL if profile is None else profile)
    idx = int(world["world"])
    names = [f"c{k}" for k in range(len(world["cylinders"]))]
    statics = [{"name": n, "type": "circle",
                "center": [float(c[0]) + SHIFT[0], float(c[1]) + SHIFT[1]], "radius": float(c[2])}
               for n, c in zip(names, world["cylinders"], strict=True)]
    sx, sy, th = START
    data = {
        "name": name or scenario_name(idx),
        "description": f"BARN world {idx}: {len(statics)} static cylinders; Clearpath Jackal; "
                       f"reference path {float(world['reference_path_length_m']):g} m; "
                       "BARN x shifted by +4.5 m.",
        "time_limit": TIME_LIMIT,
        "arena": {"width": ARENA[0], "height": ARENA[1]},
        "robot": {"start": [sx + SHIFT[0], sy + SHIFT[1], th],
                  "goal": [GOAL[0] + SHIFT[0], GOAL[1] + SHIFT[1]], **prof},
        "static_obstacles": statics,
    }
    where = (f"{source}: " if source is not None else "") + f"world {idx}"
    try:
        scenario_from_dict(data, f"<barn world {idx}>")  # validate (start/goal free, schema)
    except AnyplanError as exc:
        raise _converted_error(exc, where, world, float(prof["radius"]), names) from None
    return data


def _converted_error(exc: AnyplanError, where: str, world: Mapping[str, Any],
                     radius: float, names: list[str]) -> AnyplanError:
    """A scenario error told in the worlds file's terms: a cylinder (the obstacle named
    ``names[K]``) on the start or goal as ``world N.cylinders[K]``, in BARN's frame."""
    if isinstance(exc, ScenarioError) and exc.obstacle in names \
            and exc.field in ("robot.start", "robot.goal"):
        k = names.index(exc.obstacle)
        x, y, r = (float(v) for v in world["cylinders"][k])
        which, (px, py) = ("start", START[:2]) if exc.field == "robot.start" else ("goal", GOAL)
        return BARNError(f"{where}.cylinders[{k}]: ({x:g}, {y:g}) r {r:g} is within the robot "
                         f"radius {radius:g} of the challenge's {which} ({px:g}, {py:g})")
    return dynabarn.converted_error(exc, where, {"static_obstacles": "cylinders"}, BARNError)


@dataclass(frozen=True)
class Feasibility:
    """Whether the robot's disc can reach the goal of a scenario (static obstacles only).

    Attributes:
        status: ``feasible``, ``infeasible`` (proven) or ``uncertain``.
        lower_m: Visibility-graph lower bound on the shortest path [m] (inf if none).
        path_m: Length of the exact-checked visibility-graph path [m] (inf if none).
    """

    status: str
    lower_m: float
    path_m: float


def feasibility(scenario: Scenario) -> Feasibility:
    """Feasibility of ``scenario`` for its robot's disc, by the visibility graph (see the module
    docstring). The goal counts as the goal point itself (not its tolerance disc)."""
    from anyplan.planning.problem import Problem
    from anyplan.planning.status import PlannerStatus
    from anyplan.planning.visgraph import shortest_path

    r = scenario.robot
    prob = Problem.create(scenario.obstacle_set(), r.start[:2], r.goal, r.radius)
    feas = shortest_path(prob, variant="feasible")
    if feas.status == PlannerStatus.EXACT_SOLUTION:
        low = shortest_path(prob, variant="lower")
        return Feasibility("feasible", float(low.cost), float(feas.cost))
    low = shortest_path(prob, variant="lower")
    if low.status == PlannerStatus.EXACT_SOLUTION:
        return Feasibility("uncertain", float(low.cost), math.inf)
    return Feasibility("infeasible", math.inf, math.inf)


def _fin(x: float) -> float | None:
    return round(x, 6) if math.isfinite(x) else None


def convert(source: str | Path, out_dir: str | Path, worlds: Sequence[int] | str | None = None,
            profile: Mapping[str, float] | None = None, check_feasibility: bool = True
            ) -> list[Path]:
    """Write ``barn-NNN.yaml`` for each selected world (default: every world in the file) into
    ``out_dir``, and the index
    :data:`INDEX_FILE` (per scenario: world, reference path length, the challenge's optimal
    time, and the feasibility unless ``check_feasibility`` is False); returns the YAML paths.

    An existing index in ``out_dir`` is merged (entries of other worlds are kept).
    """
    data = load_worlds(source)
    by_index = {w["world"]: w for w in data}
    n = max(by_index) + 1
    if worlds is None:
        idx = sorted(by_index)
    else:
        idx = parse_worlds(worlds, n_worlds=n) if isinstance(worlds, str) else list(worlds)
    for i in idx:
        if i not in by_index:
            raise BARNError(f"world {i} is not in {source}")
    # Every selected world converts before anything is written.
    scenarios = [(i, world_to_scenario(by_index[i], profile, source=source)) for i in idx]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    index_path = out / INDEX_FILE
    index: dict[str, Any] = {}
    if index_path.is_file():
        try:
            index = dict(json.loads(index_path.read_text()).get("scenarios", {}))
        except (json.JSONDecodeError, AttributeError, TypeError, ValueError):
            index = {}
    paths = []
    for i, sc in scenarios:
        p = out / f"{sc['name']}.yaml"
        ref = float(by_index[i]["reference_path_length_m"])
        header = ("# Converted by 'anyplan import-barn' from BARN (Perille et al., SSRR 2020), BARN\n"
                  "# Challenge repository data, MIT licence, Copyright (c) 2022 Zifan Xu.\n"
                  "# Frame: BARN (x + 4.5, y) m. See anyplan.experiments.barn.\n"
                  f"# Challenge reference path length: {ref:g} m (optimal time {ref / 2.0:g} s).\n")
        p.write_text(header + dump_yaml(sc, sort_keys=False, default_flow_style=None, width=100))
        entry: dict[str, Any] = {"world": i, "reference_path_length_m": ref,
                                 "optimal_time_s": ref / 2.0,
                                 "cylinders": len(by_index[i]["cylinders"]),
                                 "robot_radius_m": float(sc["robot"]["radius"])}
        if check_feasibility:
            f = feasibility(scenario_from_dict(sc, str(p)))
            entry.update(feasibility=f.status, visgraph_lower_m=_fin(f.lower_m),
                         visgraph_path_m=_fin(f.path_m))
        index[sc["name"]] = entry
        paths.append(p)
    doc = {"source": "BARN (Perille et al., SSRR 2020), converted by anyplan import-barn",
           "scenarios": dict(sorted(index.items()))}
    index_path.write_text(json.dumps(doc, indent=1) + "\n")
    return paths


def load_index(path: str | Path) -> dict[str, dict[str, Any]]:
    """The scenarios of a :data:`INDEX_FILE` (a file, or the folder holding it).

    Raises:
        BARNError: missing or malformed.
    """
    p = Path(path)
    if p.is_dir():
        p = p / INDEX_FILE
    if not p.is_file():
        raise BARNError(f"{p}: no such file (written by 'anyplan import-barn')")
    try:
        doc = json.loads(p.read_text())
        scen = doc["scenarios"]
        if not isinstance(scen, dict) or not all(isinstance(v, dict) for v in scen.values()):
            raise TypeError
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError):
        raise BARNError(f"{p}: scenarios: expected the index written by 'anyplan import-barn'") \
            from None
    return scen
