"""Scenarios: the arena, the robot and its task, static and moving obstacles.

The YAML schema is a public contract, documented in ``docs/scenarios.md``. Files are read with
a safe loader and validated strictly: an unknown key, a missing key, a wrong type or a value out
of range raises :class:`~anyplan.errors.ScenarioError` naming the file and the field, with the
nearest known key suggested for a misspelling.
"""

from __future__ import annotations

import hashlib
import json
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from anyplan.errors import ScenarioError, UnknownNameError
from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.world import limits as L
from anyplan.world.occupancy import OccupancyMap, load_map
from anyplan.world.robot import RobotSpec
from anyplan.world.schema import (
    MOTION_TYPES,
    OBSTACLE_TYPES,
    Ctx,
    MovingObstacle,
    StaticObstacle,
    parse_moving,
    parse_sensing,
    parse_static,
    typename,
)
from anyplan.world.sensing import SensingSpec
from anyplan.world.yaml_load import YamlLimitError, load_yaml

__all__ = [
    "StaticObstacle",
    "MovingObstacle",
    "Scenario",
    "load_scenario",
    "scenario_from_dict",
    "builtin_scenarios",
    "OBSTACLE_TYPES",
    "MOTION_TYPES",
]


@dataclass(frozen=True)
class Scenario:
    """A complete planning and execution problem (lengths in m, angles in rad, times in s)."""

    name: str
    width: float
    height: float
    robot: RobotSpec
    static_obstacles: tuple[StaticObstacle, ...] = ()
    moving_obstacles: tuple[MovingObstacle, ...] = ()
    description: str = ""
    time_limit: float = 120.0
    source: str = "<dict>"
    #: Perception settings (``sensing:``); None = no block = ``oracle``.
    sensing: SensingSpec | None = None
    #: Lower-left corner (x, y) [m] of the arena.
    origin: tuple[float, float] = (0.0, 0.0)
    #: An occupancy-grid map whose blocked cells are static obstacles too (``static_map:``).
    static_map: OccupancyMap | None = None

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Arena (xmin, ymin, xmax, ymax) [m]."""
        x0, y0 = self.origin
        return (x0, y0, x0 + self.width, y0 + self.height)

    def obstacle_set(self) -> ObstacleSet:
        """The static obstacles, the map's blocked cells (merged into boxes) and the arena
        walls, for exact clearance queries: built once per scenario and cached on it (shared by
        :meth:`static_only`; not pickled, a worker builds its own once)."""
        cache = _cache(self)
        cached = cache.get("obstacle_set")
        if cached is None:
            shapes = [o.shape for o in self.static_obstacles]
            cached = (ObstacleSet(shapes, bounds=self.bounds) if self.static_map is None
                      else self.static_map.obstacle_set(shapes, self.bounds))
            cache["obstacle_set"] = cached
        return cached

    def __getstate__(self) -> dict[str, Any]:
        """The fields, and the content hash if computed (a worker need not hash again)."""
        state = dict(self.__dict__)
        if "content_hash" in _cache(self):
            state[_HASH_KEY] = _cache(self)["content_hash"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        digest = state.pop(_HASH_KEY, None)
        self.__dict__.update(state)
        if digest is not None:
            _cache(self)["content_hash"] = digest

    def nearest_static(self, a: Sequence[float] | np.ndarray,
                       b: Sequence[float] | np.ndarray | None = None) -> str:
        """Name of the static obstacle nearest to point ``a`` (or to segment ``a``-``b``), or
        ``"wall"`` when the arena walls are nearer; for naming what a collision hit."""
        def dist(obs: ObstacleSet) -> float:
            return obs.clearance(a) if b is None else obs.segment_clearance(a, b)

        best, name = dist(ObstacleSet([], bounds=self.bounds)), "wall"
        if self.static_map is not None:
            d = dist(self.static_map.obstacle_set((), None))
            if d < best:
                best, name = d, "map"
        for o in self.static_obstacles:
            d = dist(ObstacleSet([o.shape]))
            if d < best:
                best, name = d, o.name
        return name

    def static_only(self) -> Scenario:
        """The same scenario without its moving obstacles (what a static planner knows)."""
        out = replace(self, moving_obstacles=())
        if "obstacle_set" in _cache(self):
            _cache(out)["obstacle_set"] = _cache(self)["obstacle_set"]
        return out

    def to_dict(self) -> dict[str, Any]:
        """The scenario as a dictionary of the YAML schema (round-trips through the loader)."""
        r = self.robot
        robot: dict[str, Any] = {
            "start": list(r.start), "goal": list(r.goal), "goal_tolerance": r.goal_tolerance,
            "radius": r.radius, "v_max": r.v_max, "omega_max": r.omega_max, "a_max": r.a_max,
            "alpha_max": r.alpha_max,
        }
        if r.sensing_range is not None:
            robot["sensing_range"] = r.sensing_range
        out: dict[str, Any] = {"name": self.name}
        if self.description:
            out["description"] = self.description
        out["time_limit"] = self.time_limit
        out["arena"] = {"width": self.width, "height": self.height}
        if self.origin != (0.0, 0.0):
            out["arena"]["origin"] = list(self.origin)
        if self.static_map is not None:
            out["static_map"] = str(Path(self.static_map.source).resolve())
        out["robot"] = robot
        out["static_obstacles"] = [dict(o.spec) for o in self.static_obstacles]
        out["dynamic_obstacles"] = [dict(o.spec) for o in self.moving_obstacles]
        if self.sensing is not None:
            out["sensing"] = self.sensing.to_dict()
        return _plain(out)

    def content_hash(self) -> str:
        """SHA-256 (hex, 16 chars) of the scenario's canonical JSON, ignoring its source;
        computed once per scenario and cached on it."""
        cache = _cache(self)
        cached = cache.get("content_hash")
        if cached is None:
            d = self.to_dict()
            if self.static_map is not None:
                d["static_map"] = self.static_map.digest()  # the content, not where it lives
            if self.sensing is not None:  # every setting, as hashed before (SensingSpec.identity)
                d["sensing"] = self.sensing.identity()
            blob = json.dumps(d, sort_keys=True, default=float).encode()
            cached = cache["content_hash"] = hashlib.sha256(blob).hexdigest()[:16]
        return str(cached)


#: Per-scenario caches (content hash, obstacle set) by ``id``, dropped with the scenario: the
#: frozen dataclass's ``__dict__`` keeps its fields only (``Scenario(**sc.__dict__)`` works).
_CACHES: dict[int, dict[str, Any]] = {}
_HASH_KEY = "__content_hash__"


def _cache(sc: Scenario) -> dict[str, Any]:
    key = id(sc)
    cache = _CACHES.get(key)
    if cache is None:
        cache = _CACHES[key] = {}
        weakref.finalize(sc, _CACHES.pop, key, None)
    return cache


def _plain(obj: Any) -> Any:
    """Plain Python containers and numbers (numpy scalars and arrays converted), for YAML/JSON."""
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple | np.ndarray):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    return obj


_ROBOT_REQUIRED = ("start", "goal", "radius", "v_max", "omega_max", "a_max", "alpha_max")
_ROBOT_OPTIONAL = ("goal_tolerance", "sensing_range")

def scenario_from_dict(data: Any, source: str = "<dict>") -> Scenario:
    """Build and validate a :class:`Scenario` from a dictionary of the YAML schema.

    Raises:
        ScenarioError: naming ``source`` and the offending field.
    """
    c = Ctx(source)
    top = c.mapping(data, "")
    c.keys(top, "", ("name", "robot"),
           ("arena", "description", "time_limit", "static_obstacles", "dynamic_obstacles",
            "moving_obstacles", "sensing", "static_map"))
    name = c.string(top["name"], "name")
    description = top.get("description")
    if description is None:
        description = ""
    if not isinstance(description, str):
        raise c.fail("description", f"expected a string, got {typename(description)}")
    if len(description) > L.MAX_TEXT_CHARS:
        raise c.fail("description", f"longer than {L.MAX_TEXT_CHARS} characters")
    time_limit = c.number(top.get("time_limit", 120.0), "time_limit", positive=True,
                          hi=L.MAX_TIME_LIMIT_S)

    smap = _static_map(c, top.get("static_map"))
    if "arena" not in top and smap is None:
        raise c.fail("arena", "missing required key (it may be omitted only with static_map)")
    if "arena" in top:
        arena = c.mapping(top["arena"], "arena")
        c.keys(arena, "arena", ("width", "height"), ("origin",))
        width = c.number(arena["width"], "arena.width", positive=True, hi=L.MAX_ARENA_M)
        height = c.number(arena["height"], "arena.height", positive=True, hi=L.MAX_ARENA_M)
        ox, oy = c.vector(arena.get("origin", [0.0, 0.0]), "arena.origin", 2)
        if smap is not None:
            mx0, my0, mx1, my1 = smap.bounds
            if mx1 <= ox or mx0 >= ox + width or my1 <= oy or my0 >= oy + height:
                raise c.fail("static_map", f"the map [{mx0:g}, {mx1:g}] x [{my0:g}, {my1:g}] lies "
                                           f"outside the arena [{ox:g}, {ox + width:g}] x "
                                           f"[{oy:g}, {oy + height:g}] (check its origin or arena.origin)")
    else:
        assert smap is not None
        ox, oy, x1, y1 = smap.bounds
        width, height = x1 - ox, y1 - oy
        if max(width, height) > L.MAX_ARENA_M:
            raise c.fail("static_map", f"the map is {width:g} m x {height:g} m, larger than the "
                                       f"arena limit {L.MAX_ARENA_M:g} m (give a smaller arena)")

    rob = c.mapping(top["robot"], "robot")
    c.keys(rob, "robot", _ROBOT_REQUIRED, _ROBOT_OPTIONAL)
    start = c.pose(rob["start"], "robot.start")
    goal = c.vector(rob["goal"], "robot.goal", 2)
    ranges = {"radius": L.ROBOT_RADIUS_M, **L.ROBOT_LIMITS}
    vals = {k: c.number(rob[k], f"robot.{k}", positive=True, lo=lo, hi=hi)
            for k, (lo, hi) in ranges.items()}
    goal_tol = c.number(rob.get("goal_tolerance", 0.2), "robot.goal_tolerance", positive=True,
                        hi=L.MAX_GOAL_TOLERANCE_M)
    sensing = rob.get("sensing_range")
    sensing_range = None if sensing is None else c.number(sensing, "robot.sensing_range",
                                                           positive=True, hi=L.MAX_COORD_M)
    robot = RobotSpec(start=(start[0], start[1], start[2]), goal=(goal[0], goal[1]),
                      goal_tolerance=goal_tol, sensing_range=sensing_range, **vals)

    statics_raw = c.items(top.get("static_obstacles"), "static_obstacles", L.MAX_STATIC_OBSTACLES)
    statics = tuple(parse_static(c, o, f"static_obstacles[{i}]", i)
                    for i, o in enumerate(statics_raw))
    # The moving obstacles: "dynamic_obstacles" (the paper's word) or its alias "moving_obstacles".
    mkey = "moving_obstacles" if "moving_obstacles" in top else "dynamic_obstacles"
    if "moving_obstacles" in top and "dynamic_obstacles" in top:
        raise c.fail("moving_obstacles", "give the moving obstacles once: moving_obstacles is another "
                     "name for dynamic_obstacles")
    moving_raw = c.items(top.get(mkey), mkey, L.MAX_MOVING_OBSTACLES)
    moving = tuple(parse_moving(c, o, f"{mkey}[{i}]", i)
                   for i, o in enumerate(moving_raw))
    first: dict[str, str] = {}  # an obstacle's name -> the field of the first obstacle with it
    named = [(o.name, f"static_obstacles[{i}]") for i, o in enumerate(statics)] + \
        [(o.name, f"{mkey}[{i}]") for i, o in enumerate(moving)]
    for n, fld in named:
        if n in first:
            raise c.fail(f"{fld}.name", f"obstacle name '{n}' is used twice (also by {first[n]})")
        first[n] = fld

    sc = Scenario(name=name, width=width, height=height, robot=robot, static_obstacles=statics,
                  moving_obstacles=moving, description=description, time_limit=time_limit,
                  source=source, origin=(ox, oy), static_map=smap,
                  sensing=None if top.get("sensing") is None else parse_sensing(c, top["sensing"]))
    _check_task(c, sc)
    return sc


def _check_task(c: Ctx, sc: Scenario) -> None:
    r = sc.robot.radius
    obs = sc.obstacle_set()
    x0, y0, x1, y1 = sc.bounds
    for fld, p in (("robot.start", sc.robot.start[:2]), ("robot.goal", sc.robot.goal)):
        x, y = p
        if not (x0 + r <= x <= x1 - r and y0 + r <= y <= y1 - r):
            raise c.fail(fld, f"({x:g}, {y:g}) is outside the arena [{x0:g}, {x1:g}] x "
                              f"[{y0:g}, {y1:g}] shrunk by the robot radius {r:g}")
        if obs.clearance(p) < r - COLLISION_EPS:
            hit = sc.nearest_static(p)
            if hit == "map" and sc.static_map is not None:
                raise c.fail(fld, f"({x:g}, {y:g}) is within the robot radius {r:g} of an "
                                  f"occupied or unknown cell of the map {sc.static_map.source}")
            raise c.fail(fld, f"({x:g}, {y:g}) is inside static obstacle {hit} inflated by the "
                              f"robot radius {r:g}", obstacle=hit)


def _static_map(c: Ctx, obj: Any) -> OccupancyMap | None:
    """The ``static_map`` key: a map_server YAML path, relative to the scenario file."""
    if obj is None:
        return None
    rel = Path(c.string(obj, "static_map"))
    base = Path(c.source).parent if c.source not in ("<dict>", "") else Path.cwd()
    path = rel if rel.is_absolute() else base / rel
    if not path.is_file():
        raise c.fail("static_map", f"no such map file {path}")
    return load_map(path)


# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------
def builtin_scenarios() -> dict[str, str]:
    """Built-in scenario names mapped to their one-line descriptions."""
    out = {}
    for entry in sorted(resources.files("anyplan.scenarios").iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".yaml"):
            data = yaml.safe_load(entry.read_text())
            out[entry.name[:-5]] = str(data.get("description", "")).strip().splitlines()[0] \
                if data.get("description") else ""
    return out


def load_scenario(name_or_path: str | Path) -> Scenario:
    """Load a built-in scenario by name (``paper-1``) or a YAML file by path.

    Raises:
        ScenarioError: the file is unreadable, not YAML or does not follow the schema.
        UnknownNameError: neither a built-in name nor an existing file (or an empty name).
    """
    s = str(name_or_path)
    if not s.strip():  # Path("") is the current folder: not a scenario the user named
        raise UnknownNameError("scenario", s, list(builtin_scenarios()))
    path = Path(s)
    try:
        exists = path.exists()
    except (OSError, ValueError):  # a name too long, a NUL byte: not a file we can read
        exists = path.suffix in (".yaml", ".yml", ".json") or len(s) > 255 or "\0" in s
    if path.suffix in (".yaml", ".yml", ".json") or exists:
        return _from_text(_read_file(path, s), s)
    res = resources.files("anyplan.scenarios").joinpath(f"{s}.yaml")
    if res.is_file():
        return _from_text(res.read_text(), s)
    raise UnknownNameError("scenario", s, list(builtin_scenarios()))


def _read_file(path: Path, source: str) -> str:
    """The text of a scenario file: a regular file (never a FIFO or device, which could block),
    of at most the loader's document size."""
    import os
    import stat

    from anyplan.world.yaml_load import MAX_DOCUMENT_CHARS

    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ScenarioError(source, "", "no such file") from None
    except (OSError, ValueError) as exc:
        raise ScenarioError(source, "", f"cannot read file ({getattr(exc, 'strerror', None) or exc})") \
            from None
    if stat.S_ISDIR(st.st_mode):
        raise ScenarioError(source, "", "is a folder, not a scenario file")
    if not stat.S_ISREG(st.st_mode):
        raise ScenarioError(source, "", "not a regular file (a pipe or a device?)")
    if st.st_size > MAX_DOCUMENT_CHARS:
        raise ScenarioError(source, "", f"larger than {MAX_DOCUMENT_CHARS} bytes")
    try:
        # O_NONBLOCK: should the file be swapped for a FIFO after the check, open() still
        # returns at once (and the read finds nothing) instead of waiting for a writer.
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as f:
            raw = f.read(MAX_DOCUMENT_CHARS + 1)
    except OSError as exc:
        raise ScenarioError(source, "", f"cannot read file ({exc.strerror})") from None
    if len(raw) > MAX_DOCUMENT_CHARS:
        raise ScenarioError(source, "", f"larger than {MAX_DOCUMENT_CHARS} bytes")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(source, "", f"not UTF-8 text (byte {exc.start})") from None


def _from_text(text: str, source: str) -> Scenario:
    try:
        data = load_yaml(text)
    except YamlLimitError as exc:
        raise ScenarioError(source, exc.field, exc.text) from None
    if data is None:
        raise ScenarioError(source, "", "the file is empty")
    return scenario_from_dict(data, source)
