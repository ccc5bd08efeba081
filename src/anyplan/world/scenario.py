"""Scenarios: the arena, the robot and its task, static and moving obstacles.

The YAML schema is a public contract, documented in ``docs/scenarios.md``. Files are read with
a safe loader and validated strictly: an unknown key, a missing key, a wrong type or a value out
of range raises :class:`~anyplan.errors.ScenarioError` naming the file and the field, with the
nearest known key suggested for a misspelling.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from anyplan.errors import ScenarioError, UnknownNameError
from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.geometry.shapes import Circle, Polygon, Shape, rectangle
from anyplan.world.motion import Motion, TrackMotion, UnicycleMotion, WaypointMotion
from anyplan.world.robot import RobotSpec
from anyplan.world.sensing import SensingSpec

__all__ = [
    "StaticObstacle",
    "MovingObstacle",
    "Scenario",
    "load_scenario",
    "scenario_from_dict",
    "builtin_scenarios",
]


@dataclass(frozen=True)
class StaticObstacle:
    """A named static shape."""

    name: str
    shape: Shape
    spec: Mapping[str, Any] = field(compare=False, repr=False, default_factory=dict)


@dataclass(frozen=True)
class MovingObstacle:
    """A named disc of ``radius`` [m] following ``motion``."""

    name: str
    radius: float
    motion: Motion
    spec: Mapping[str, Any] = field(compare=False, repr=False, default_factory=dict)

    def position(self, t: float) -> np.ndarray:
        """Centre [m] at time ``t`` [s], shape (2,)."""
        return self.motion.position(t)


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

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Arena (xmin, ymin, xmax, ymax) [m]."""
        return (0.0, 0.0, self.width, self.height)

    def obstacle_set(self) -> ObstacleSet:
        """The static obstacles and the arena walls, for exact clearance queries."""
        return ObstacleSet([o.shape for o in self.static_obstacles], bounds=self.bounds)

    def nearest_static(self, a: Sequence[float] | np.ndarray,
                       b: Sequence[float] | np.ndarray | None = None) -> str:
        """Name of the static obstacle nearest to point ``a`` (or to segment ``a``-``b``), or
        ``"wall"`` when the arena walls are nearer; for naming what a collision hit."""
        def dist(obs: ObstacleSet) -> float:
            return obs.clearance(a) if b is None else obs.segment_clearance(a, b)

        best, name = dist(ObstacleSet([], bounds=self.bounds)), "wall"
        for o in self.static_obstacles:
            d = dist(ObstacleSet([o.shape]))
            if d < best:
                best, name = d, o.name
        return name

    def static_only(self) -> Scenario:
        """The same scenario without its moving obstacles (what a static planner knows)."""
        return replace(self, moving_obstacles=())

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
        out["robot"] = robot
        out["static_obstacles"] = [dict(o.spec) for o in self.static_obstacles]
        out["dynamic_obstacles"] = [dict(o.spec) for o in self.moving_obstacles]
        if self.sensing is not None:
            out["sensing"] = self.sensing.to_dict()
        return _plain(out)

    def content_hash(self) -> str:
        """SHA-256 (hex, 16 chars) of the scenario's canonical JSON, ignoring its source."""
        blob = json.dumps(self.to_dict(), sort_keys=True, default=float).encode()
        return hashlib.sha256(blob).hexdigest()[:16]


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


# --------------------------------------------------------------------------------------------
# Validation helpers
# --------------------------------------------------------------------------------------------
class _Ctx:
    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, fld: str, msg: str) -> ScenarioError:
        return ScenarioError(self.source, fld, msg)

    def mapping(self, obj: Any, fld: str) -> Mapping[str, Any]:
        if not isinstance(obj, Mapping):
            raise self.fail(fld, f"expected a mapping, got {_typename(obj)}")
        return obj

    def keys(self, obj: Mapping[str, Any], fld: str, required: Sequence[str],
             optional: Sequence[str] = ()) -> None:
        known = list(required) + list(optional)
        for key in obj:
            if key not in known:
                close = difflib.get_close_matches(str(key), known, n=1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                raise self.fail(_join(fld, str(key)), f"unknown key{hint} (known: {', '.join(known)})")
        for key in required:
            if key not in obj:
                raise self.fail(_join(fld, key), "missing required key")

    def number(self, obj: Any, fld: str, *, positive: bool = False, nonneg: bool = False) -> float:
        if isinstance(obj, bool) or not isinstance(obj, int | float):
            raise self.fail(fld, f"expected a number, got {_typename(obj)}")
        x = float(obj)
        if not math.isfinite(x):
            raise self.fail(fld, f"must be finite, got {x}")
        if positive and not x > 0.0:
            raise self.fail(fld, f"must be > 0, got {x:g}")
        if nonneg and x < 0.0:
            raise self.fail(fld, f"must be >= 0, got {x:g}")
        return x

    def vector(self, obj: Any, fld: str, n: int) -> tuple[float, ...]:
        if not isinstance(obj, list | tuple) or len(obj) != n:
            raise self.fail(fld, f"expected a list of {n} numbers, got {_short(obj)}")
        return tuple(self.number(v, f"{fld}[{i}]") for i, v in enumerate(obj))

    def string(self, obj: Any, fld: str) -> str:
        if not isinstance(obj, str) or not obj:
            raise self.fail(fld, f"expected a non-empty string, got {_typename(obj)}")
        return obj


def _join(a: str, b: str) -> str:
    return f"{a}.{b}" if a else b


def _typename(obj: Any) -> str:
    return "nothing" if obj is None else type(obj).__name__


def _short(obj: Any) -> str:
    s = repr(obj)
    return s if len(s) <= 40 else s[:37] + "..."


# --------------------------------------------------------------------------------------------
# Parsing
# --------------------------------------------------------------------------------------------
_ROBOT_REQUIRED = ("start", "goal", "radius", "v_max", "omega_max", "a_max", "alpha_max")
_ROBOT_OPTIONAL = ("goal_tolerance", "sensing_range")


def _parse_static(c: _Ctx, obj: Any, fld: str, index: int) -> StaticObstacle:
    m = c.mapping(obj, fld)
    if "type" not in m:
        raise c.fail(_join(fld, "type"), "missing required key (rectangle, circle or polygon)")
    kind = m["type"]
    name = c.string(m.get("name", f"S{index + 1}"), _join(fld, "name"))
    shape: Shape
    try:
        if kind == "rectangle":
            c.keys(m, fld, ("type", "center", "size"), ("name", "angle"))
            center = c.vector(m["center"], _join(fld, "center"), 2)
            size = c.vector(m["size"], _join(fld, "size"), 2)
            for i, s in enumerate(size):
                if not s > 0.0:
                    raise c.fail(f"{_join(fld, 'size')}[{i}]", f"must be > 0, got {s:g}")
            angle = c.number(m.get("angle", 0.0), _join(fld, "angle"))
            shape = rectangle(center, size, angle)
        elif kind == "circle":
            c.keys(m, fld, ("type", "center", "radius"), ("name",))
            center = c.vector(m["center"], _join(fld, "center"), 2)
            shape = Circle(center, c.number(m["radius"], _join(fld, "radius"), positive=True))
        elif kind == "polygon":
            c.keys(m, fld, ("type", "points"), ("name",))
            pts = m["points"]
            if not isinstance(pts, list) or len(pts) < 3:
                raise c.fail(_join(fld, "points"), "expected a list of at least 3 [x, y] points")
            verts = [c.vector(p, f"{_join(fld, 'points')}[{i}]", 2) for i, p in enumerate(pts)]
            shape = Polygon(np.array(verts))
        else:
            close = difflib.get_close_matches(str(kind), ["rectangle", "circle", "polygon"], n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise c.fail(_join(fld, "type"),
                         f"unknown obstacle type '{kind}'{hint} (known: rectangle, circle, polygon)")
    except ScenarioError:
        raise
    except ValueError as exc:  # geometric validation of the shape itself
        raise c.fail(fld, str(exc)) from None
    spec = dict(m)
    spec["name"] = name
    return StaticObstacle(name, shape, spec)


def _parse_moving(c: _Ctx, obj: Any, fld: str, index: int) -> MovingObstacle:
    m = c.mapping(obj, fld)
    kind = m.get("type", "unicycle")
    name = c.string(m.get("name", f"D{index + 1}"), _join(fld, "name"))
    motion: Motion
    if kind == "unicycle":
        c.keys(m, fld, ("start", "v", "radius"), ("name", "type", "omega", "start_time"))
        x0, y0, th0 = c.vector(m["start"], _join(fld, "start"), 3)
        v = c.number(m["v"], _join(fld, "v"))
        omega = c.number(m.get("omega", 0.0), _join(fld, "omega"))
        t0 = c.number(m.get("start_time", 0.0), _join(fld, "start_time"), nonneg=True)
        motion = UnicycleMotion(x0, y0, th0, v, omega, t0)
    elif kind == "waypoints":
        c.keys(m, fld, ("type", "keyframes", "radius"), ("name",))
        kf = m["keyframes"]
        if not isinstance(kf, list) or len(kf) < 2:
            raise c.fail(_join(fld, "keyframes"), "expected a list of at least 2 [t, x, y] rows")
        rows = [c.vector(r, f"{_join(fld, 'keyframes')}[{i}]", 3) for i, r in enumerate(kf)]
        try:
            motion = WaypointMotion(np.array(rows))
        except ValueError as exc:
            raise c.fail(_join(fld, "keyframes"), str(exc)) from None
    elif kind == "track":
        motion = _parse_track(c, m, fld)
    else:
        close = difflib.get_close_matches(str(kind), ["unicycle", "waypoints", "track"], n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise c.fail(_join(fld, "type"),
                     f"unknown motion type '{kind}'{hint} (known: unicycle, waypoints, track)")
    radius = c.number(m["radius"], _join(fld, "radius"), positive=True)
    spec = dict(m)
    spec["name"] = name
    return MovingObstacle(name, radius, motion, spec)


def _parse_track(c: _Ctx, m: Mapping[str, Any], fld: str) -> Motion:
    c.keys(m, fld, ("type", "samples", "radius"), ("name",))
    rows_raw = m["samples"]
    if not isinstance(rows_raw, list) or len(rows_raw) < 2:
        raise c.fail(_join(fld, "samples"), "expected a list of at least 2 [t, x, y] rows")
    rows = [c.vector(r, f"{_join(fld, 'samples')}[{i}]", 3) for i, r in enumerate(rows_raw)]
    try:
        return TrackMotion(np.array(rows))
    except ValueError as exc:
        raise c.fail(_join(fld, "samples"), str(exc)) from None


def _parse_sensing(c: _Ctx, obj: Any) -> SensingSpec:
    m = c.mapping(obj, "sensing")
    c.keys(m, "sensing", ("mode",), ("noise_m", "rate_hz"))
    mode = c.string(m["mode"], "sensing.mode")
    noise = c.number(m.get("noise_m", SensingSpec.noise_m), "sensing.noise_m", nonneg=True)
    rate = c.number(m.get("rate_hz", SensingSpec.rate_hz), "sensing.rate_hz", positive=True)
    try:
        return SensingSpec(mode, noise, rate)
    except ValueError as exc:
        raise c.fail("sensing.mode", str(exc)) from None


def scenario_from_dict(data: Any, source: str = "<dict>") -> Scenario:
    """Build and validate a :class:`Scenario` from a dictionary of the YAML schema.

    Raises:
        ScenarioError: naming ``source`` and the offending field.
    """
    c = _Ctx(source)
    top = c.mapping(data, "")
    c.keys(top, "", ("name", "arena", "robot"),
           ("description", "time_limit", "static_obstacles", "dynamic_obstacles", "sensing"))
    name = c.string(top["name"], "name")
    description = top.get("description", "") or ""
    if not isinstance(description, str):
        raise c.fail("description", "expected a string")
    time_limit = c.number(top.get("time_limit", 120.0), "time_limit", positive=True)

    arena = c.mapping(top["arena"], "arena")
    c.keys(arena, "arena", ("width", "height"))
    width = c.number(arena["width"], "arena.width", positive=True)
    height = c.number(arena["height"], "arena.height", positive=True)

    rob = c.mapping(top["robot"], "robot")
    c.keys(rob, "robot", _ROBOT_REQUIRED, _ROBOT_OPTIONAL)
    start = c.vector(rob["start"], "robot.start", 3)
    goal = c.vector(rob["goal"], "robot.goal", 2)
    vals = {k: c.number(rob[k], f"robot.{k}", positive=True)
            for k in ("radius", "v_max", "omega_max", "a_max", "alpha_max")}
    goal_tol = c.number(rob.get("goal_tolerance", 0.2), "robot.goal_tolerance", positive=True)
    sensing = rob.get("sensing_range")
    sensing_range = None if sensing is None else c.number(sensing, "robot.sensing_range",
                                                           positive=True)
    robot = RobotSpec(start=(start[0], start[1], start[2]), goal=(goal[0], goal[1]),
                      goal_tolerance=goal_tol, sensing_range=sensing_range, **vals)

    statics_raw = top.get("static_obstacles") or []
    if not isinstance(statics_raw, list):
        raise c.fail("static_obstacles", "expected a list")
    statics = tuple(_parse_static(c, o, f"static_obstacles[{i}]", i)
                    for i, o in enumerate(statics_raw))
    moving_raw = top.get("dynamic_obstacles") or []
    if not isinstance(moving_raw, list):
        raise c.fail("dynamic_obstacles", "expected a list")
    moving = tuple(_parse_moving(c, o, f"dynamic_obstacles[{i}]", i)
                   for i, o in enumerate(moving_raw))
    names = [o.name for o in statics] + [o.name for o in moving]
    for i, n in enumerate(names):
        if n in names[:i]:
            raise c.fail("name", f"obstacle name '{n}' is used twice")

    sc = Scenario(name=name, width=width, height=height, robot=robot, static_obstacles=statics,
                  moving_obstacles=moving, description=description, time_limit=time_limit,
                  source=source,
                  sensing=None if top.get("sensing") is None else _parse_sensing(c, top["sensing"]))
    _check_task(c, sc)
    return sc


def _check_task(c: _Ctx, sc: Scenario) -> None:
    r = sc.robot.radius
    obs = sc.obstacle_set()
    for fld, p in (("robot.start", sc.robot.start[:2]), ("robot.goal", sc.robot.goal)):
        x, y = p
        if not (r <= x <= sc.width - r and r <= y <= sc.height - r):
            raise c.fail(fld, f"({x:g}, {y:g}) is outside the arena [0, {sc.width:g}] x "
                              f"[0, {sc.height:g}] shrunk by the robot radius {r:g}")
        if obs.clearance(p) < r - COLLISION_EPS:
            hit = sc.nearest_static(p)
            raise c.fail(fld, f"({x:g}, {y:g}) is inside static obstacle {hit} inflated by the "
                              f"robot radius {r:g}")


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
        UnknownNameError: neither a built-in name nor an existing file.
    """
    s = str(name_or_path)
    path = Path(s)
    if path.suffix in (".yaml", ".yml", ".json") or path.exists():
        if not path.exists():
            raise ScenarioError(s, "", "no such file")
        try:
            text = path.read_text()
        except (OSError, UnicodeDecodeError) as exc:
            raise ScenarioError(s, "", f"cannot read file ({exc.__class__.__name__})") from None
        return _from_text(text, s)
    res = resources.files("anyplan.scenarios").joinpath(f"{s}.yaml")
    if res.is_file():
        return _from_text(res.read_text(), s)
    raise UnknownNameError("scenario", s, list(builtin_scenarios()))


def _from_text(text: str, source: str) -> Scenario:
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown place"
        problem = getattr(exc, "problem", None) or "malformed YAML"
        raise ScenarioError(source, "", f"malformed YAML at {where}: {problem}") from None
    if data is None:
        raise ScenarioError(source, "", "the file is empty")
    return scenario_from_dict(data, source)
