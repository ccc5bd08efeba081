"""The parts of the scenario schema: the validation context, obstacles and their registries.

:class:`Ctx` checks one field of a scenario dictionary and raises
:class:`~anyplan.errors.ScenarioError` naming the source and the field. A static obstacle's
``type:`` selects its parser in :data:`OBSTACLE_TYPES` (``rectangle``, ``circle``,
``polygon``), a moving obstacle's ``type:`` its motion parser in :data:`MOTION_TYPES`
(``unicycle``, ``waypoints``, ``track``): a new type is one registered parser
``(ctx, mapping, field) -> Shape | Motion``. :func:`~anyplan.world.scenario.scenario_from_dict`
assembles the whole scenario. The schema is documented in ``docs/scenarios.md``.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from anyplan.errors import NumberRefused, ScenarioError, finite_float, shorten
from anyplan.geometry.shapes import Circle, Polygon, Shape, rectangle
from anyplan.registry import Registry
from anyplan.world import limits as L
from anyplan.world.motion import Motion, TrackMotion, UnicycleMotion, WaypointMotion
from anyplan.world.sensing import MAX_CLUTTER_RATE, MODES, TRACKED_ONLY, SensingError, SensingSpec

__all__ = ["StaticObstacle", "MovingObstacle", "Ctx", "OBSTACLE_TYPES", "MOTION_TYPES",
           "parse_static", "parse_moving", "parse_sensing", "join_field", "typename"]


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


# --------------------------------------------------------------------------------------------
# Validation helpers
# --------------------------------------------------------------------------------------------
class Ctx:
    """Checks of the fields of one scenario dictionary; failures name ``source`` and the field."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, fld: str, msg: str, obstacle: str | None = None) -> ScenarioError:
        return ScenarioError(self.source, fld, msg, obstacle)

    def mapping(self, obj: Any, fld: str) -> Mapping[str, Any]:
        if not isinstance(obj, Mapping):
            raise self.fail(fld, f"expected a mapping, got {typename(obj)}")
        return obj

    def keys(self, obj: Mapping[str, Any], fld: str, required: Sequence[str],
             optional: Sequence[str] = ()) -> None:
        known = list(required) + list(optional)
        for key in obj:
            if key not in known:
                close = difflib.get_close_matches(str(key), known, n=1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                raise self.fail(join_field(fld, shorten(key, 40).strip("'")),
                                f"unknown key{hint} (known: {', '.join(known)})")
        for key in required:
            if key not in obj:
                raise self.fail(join_field(fld, key), "missing required key")

    def number(self, obj: Any, fld: str, *, positive: bool = False, nonneg: bool = False,
               lo: float | None = None, hi: float | None = None) -> float:
        """A finite number; ``lo``/``hi`` are the stated limits (inclusive), ``hi`` also
        bounds the magnitude when ``lo`` is None."""
        try:
            x = finite_float(obj, 0.0 if positive or nonneg else -math.inf, lo_open=positive)
        except NumberRefused as exc:
            raise self.fail(fld, f"expected a number, got {typename(obj)}" if exc.kind == "type"
                            else str(exc)) from None
        if lo is not None and x < lo:
            raise self.fail(fld, f"must be >= {lo:g} (the stated limit), got {x:g}")
        if hi is not None and (x > hi or (lo is None and x < -hi)):
            bound = f"<= {hi:g}" if lo is not None or positive or nonneg else f"within +-{hi:g}"
            raise self.fail(fld, f"must be {bound} (the stated limit), got {x:g}")
        return x

    def vector(self, obj: Any, fld: str, n: int, hi: float = L.MAX_COORD_M) -> tuple[float, ...]:
        if not isinstance(obj, list | tuple) or len(obj) != n:
            raise self.fail(fld, f"expected a list of {n} numbers, got {_short(obj)}")
        return tuple(self.number(v, f"{fld}[{i}]", hi=hi) for i, v in enumerate(obj))

    def pose(self, obj: Any, fld: str) -> tuple[float, float, float]:
        """A pose ``[x, y, theta]``: coordinates within the coordinate limit, the heading within
        the angle limit."""
        if not isinstance(obj, list | tuple) or len(obj) != 3:
            raise self.fail(fld, f"expected a list of 3 numbers, got {_short(obj)}")
        x, y = (self.number(v, f"{fld}[{i}]", hi=L.MAX_COORD_M) for i, v in enumerate(obj[:2]))
        return x, y, self.number(obj[2], f"{fld}[2]", hi=L.MAX_ANGLE_RAD)

    def string(self, obj: Any, fld: str) -> str:
        if not isinstance(obj, str) or not obj:
            raise self.fail(fld, f"expected a non-empty string, got {typename(obj)}")
        if len(obj) > L.MAX_TEXT_CHARS:
            raise self.fail(fld, f"longer than {L.MAX_TEXT_CHARS} characters")
        return obj

    def items(self, obj: Any, fld: str, most: int) -> list[Any]:
        """A list (None or a missing key: empty) of at most ``most`` items."""
        if obj is None:
            return []
        if not isinstance(obj, list):
            raise self.fail(fld, f"expected a list, got {typename(obj)}")
        if len(obj) > most:
            raise self.fail(fld, f"more than {most} items (the stated limit), got {len(obj)}")
        return obj


def join_field(a: str, b: str) -> str:
    """The dotted path of field ``b`` inside ``a`` (``b`` alone when ``a`` is the top)."""
    return f"{a}.{b}" if a else b


def typename(obj: Any) -> str:
    """The type of a user's value in words (``nothing`` for None)."""
    return "nothing" if obj is None else type(obj).__name__


def _short(obj: Any) -> str:
    return shorten(obj, 40)


# --------------------------------------------------------------------------------------------
# Parsing
# --------------------------------------------------------------------------------------------


def _rectangle(c: Ctx, m: Mapping[str, Any], fld: str) -> Shape:
    c.keys(m, fld, ("type", "center", "size"), ("name", "angle"))
    center = c.vector(m["center"], join_field(fld, "center"), 2)
    size = c.vector(m["size"], join_field(fld, "size"), 2, hi=L.MAX_SIZE_M)
    for i, s in enumerate(size):
        if not s > 0.0:
            raise c.fail(f"{join_field(fld, 'size')}[{i}]", f"must be > 0, got {s:g}")
    angle = c.number(m.get("angle", 0.0), join_field(fld, "angle"), hi=L.MAX_ANGLE_RAD)
    return rectangle((center[0], center[1]), (size[0], size[1]), angle)


def _circle(c: Ctx, m: Mapping[str, Any], fld: str) -> Shape:
    c.keys(m, fld, ("type", "center", "radius"), ("name",))
    center = c.vector(m["center"], join_field(fld, "center"), 2)
    return Circle(np.array(center), c.number(m["radius"], join_field(fld, "radius"), positive=True,
                                             hi=L.MAX_SIZE_M))


def _polygon(c: Ctx, m: Mapping[str, Any], fld: str) -> Shape:
    c.keys(m, fld, ("type", "points"), ("name",))
    pts = m["points"]
    if not isinstance(pts, list) or len(pts) < 3:
        raise c.fail(join_field(fld, "points"), "expected a list of at least 3 [x, y] points")
    c.items(pts, join_field(fld, "points"), L.MAX_POLYGON_POINTS)
    return Polygon(np.array([c.vector(p, f"{join_field(fld, 'points')}[{i}]", 2) for i, p in enumerate(pts)]))


def _unicycle(c: Ctx, m: Mapping[str, Any], fld: str) -> Motion:
    c.keys(m, fld, ("start", "v", "radius"), ("name", "type", "omega", "start_time"))
    x0, y0, th0 = c.pose(m["start"], join_field(fld, "start"))
    v = c.number(m["v"], join_field(fld, "v"), hi=L.MAX_OBSTACLE_SPEED)
    omega = c.number(m.get("omega", 0.0), join_field(fld, "omega"), hi=L.MAX_OBSTACLE_TURN_RATE)
    t0 = c.number(m.get("start_time", 0.0), join_field(fld, "start_time"), nonneg=True,
                  hi=L.MAX_EVENT_TIME_S)
    return UnicycleMotion(x0, y0, th0, v, omega, t0)


def _timed_rows(c: Ctx, m: Mapping[str, Any], fld: str, key: str) -> list[tuple[float, ...]]:
    """The ``[t, x, y]`` rows under ``key`` of a timed motion (``waypoints`` keyframes, ``track``
    samples): at least 2, each checked, times increasing (:func:`_check_rows`)."""
    c.keys(m, fld, ("type", key, "radius"), ("name",))
    raw = m[key]
    sub = join_field(fld, key)
    if not isinstance(raw, list) or len(raw) < 2:
        raise c.fail(sub, "expected a list of at least 2 [t, x, y] rows")
    c.items(raw, sub, L.MAX_KEYFRAMES)
    rows = [c.vector(r, f"{sub}[{i}]", 3, hi=L.MAX_EVENT_TIME_S) for i, r in enumerate(raw)]
    _check_rows(c, rows, sub)
    return rows


def _timed_motion(c: Ctx, m: Mapping[str, Any], fld: str, key: str,
                  kind: type[WaypointMotion] | type[TrackMotion]) -> Motion:
    """A ``waypoints`` (``keyframes``) or ``track`` (``samples``) motion whose segments are no
    faster than the moving obstacles' speed limit."""
    rows = _timed_rows(c, m, fld, key)
    try:
        motion = kind(np.array(rows))
        speed = motion.max_speed
    except (ValueError, FloatingPointError) as exc:
        raise c.fail(join_field(fld, key), str(exc)) from None
    if not speed <= L.MAX_OBSTACLE_SPEED:
        raise c.fail(join_field(fld, key), f"a segment is faster than {L.MAX_OBSTACLE_SPEED:g} m/s "
                     f"(the stated limit), got {speed:.6g} m/s")
    return motion


def _waypoints(c: Ctx, m: Mapping[str, Any], fld: str) -> Motion:
    return _timed_motion(c, m, fld, "keyframes", WaypointMotion)


#: Static obstacle types of the schema (``type:``): name -> parser ``(ctx, mapping, field)``.
OBSTACLE_TYPES: Registry[Callable[[Ctx, Mapping[str, Any], str], Shape]] = Registry("obstacle type")
#: Motion types of moving obstacles (``type:``, default ``unicycle``): name -> parser.
MOTION_TYPES: Registry[Callable[[Ctx, Mapping[str, Any], str], Motion]] = Registry("motion type")
OBSTACLE_TYPES.register("rectangle", _rectangle)
OBSTACLE_TYPES.register("circle", _circle)
OBSTACLE_TYPES.register("polygon", _polygon)


def _lookup(c: Ctx, reg: Registry[Any], kind: Any, fld: str) -> Any:
    if isinstance(kind, str) and kind in reg:
        return reg.get(kind)
    known = reg.names()
    close = difflib.get_close_matches(str(kind), known, n=1)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    raise c.fail(join_field(fld, "type"), f"unknown {reg.kind} '{kind}'{hint} (known: {', '.join(known)})")


def parse_static(c: Ctx, obj: Any, fld: str, index: int) -> StaticObstacle:
    """Static obstacle number ``index`` (field ``fld``); its ``type`` selects the parser."""
    m = c.mapping(obj, fld)
    if "type" not in m:
        raise c.fail(join_field(fld, "type"), "missing required key (rectangle, circle or polygon)")
    name = c.string(m.get("name", f"S{index + 1}"), join_field(fld, "name"))
    parse = _lookup(c, OBSTACLE_TYPES, m["type"], fld)
    try:
        shape = parse(c, m, fld)
    except ScenarioError:
        raise
    except ValueError as exc:  # geometric validation of the shape itself
        raise c.fail(fld, str(exc)) from None
    spec = dict(m)
    spec["name"] = name
    return StaticObstacle(name, shape, spec)


def parse_moving(c: Ctx, obj: Any, fld: str, index: int) -> MovingObstacle:
    """Moving obstacle number ``index`` (field ``fld``); its ``type`` selects the motion parser."""
    m = c.mapping(obj, fld)
    kind = m.get("type", "unicycle")
    name = c.string(m.get("name", f"D{index + 1}"), join_field(fld, "name"))
    motion = _lookup(c, MOTION_TYPES, kind, fld)(c, m, fld)
    radius = c.number(m["radius"], join_field(fld, "radius"), positive=True, hi=L.MAX_SIZE_M)
    spec = dict(m)
    spec["name"] = name
    return MovingObstacle(name, radius, motion, spec)


def _check_rows(c: Ctx, rows: list[tuple[float, ...]], fld: str) -> None:
    """Rows (t, x, y): times in [0, MAX_EVENT_TIME_S], coordinates within +-MAX_COORD_M."""
    for i, (t, x, y) in enumerate(rows):
        c.number(t, f"{fld}[{i}][0]", nonneg=True, hi=L.MAX_EVENT_TIME_S)
        c.number(x, f"{fld}[{i}][1]", hi=L.MAX_COORD_M)
        c.number(y, f"{fld}[{i}][2]", hi=L.MAX_COORD_M)


def _parse_track(c: Ctx, m: Mapping[str, Any], fld: str) -> Motion:
    return _timed_motion(c, m, fld, "samples", TrackMotion)


MOTION_TYPES.register("unicycle", _unicycle)
MOTION_TYPES.register("waypoints", _waypoints)
MOTION_TYPES.register("track", _parse_track)


def parse_sensing(c: Ctx, obj: Any) -> SensingSpec:
    """The ``sensing:`` block."""
    m = c.mapping(obj, "sensing")
    c.keys(m, "sensing", ("mode",), TRACKED_ONLY)  # every setting but the mode is tracked's
    mode = c.string(m["mode"], "sensing.mode")
    if mode in MODES and mode != "tracked":
        for key in TRACKED_ONLY:
            if key in m:
                raise c.fail(f"sensing.{key}", f"only mode: tracked reads it, and this block's "
                                               f"mode is '{mode}' (remove the key, or set mode: tracked)")
    noise = c.number(m.get("noise_m", SensingSpec.noise_m), "sensing.noise_m", nonneg=True,
                     hi=L.MAX_SIZE_M)
    rate = c.number(m.get("rate_hz", SensingSpec.rate_hz), "sensing.rate_hz", positive=True,
                    hi=L.MAX_SENSOR_RATE_HZ)
    assoc = c.string(m.get("association", SensingSpec.association), "sensing.association")
    prob = c.number(m.get("detection_prob", SensingSpec.detection_prob), "sensing.detection_prob",
                    positive=True, hi=1.0)
    clutter = c.number(m.get("clutter_rate", SensingSpec.clutter_rate), "sensing.clutter_rate",
                       nonneg=True, hi=MAX_CLUTTER_RATE)
    occlusion = c.string(m.get("occlusion", SensingSpec.occlusion), "sensing.occlusion")
    try:
        return SensingSpec(mode, noise, rate, assoc, prob, clutter, occlusion)
    except SensingError as exc:
        raise c.fail(f"sensing.{exc.field}", str(exc)) from None
