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
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.errors import AnyplanError, NumberRefused, ScenarioError, finite_float, one_line, shorten
from anyplan.world import limits as L
from anyplan.world.scenario import scenario_from_dict
from anyplan.world.yaml_load import dump_yaml

__all__ = ["CrowdError", "CrowdOptions", "SERVICE_ROBOT", "PERSON_RADIUS", "FRAME_RATE",
           "MAX_FRAME", "MAX_PERSON_ID", "MAX_NAME_CHARS", "read_obsmat", "crowd_scenarios",
           "import_crowd"]

#: Small service robot: radius [m], v [m/s], omega [rad/s], a [m/s^2], alpha [rad/s^2].
SERVICE_ROBOT: dict[str, float] = {"radius": 0.3, "v_max": 1.0, "omega_max": 1.5, "a_max": 1.0,
                                   "alpha_max": 3.0, "goal_tolerance": 0.3}
#: Radius [m] of a person's disc.
PERSON_RADIUS = 0.25
#: Video frames per second of ETH and UCY.
FRAME_RATE = 25.0
#: Largest frame number: the event-time limit (10^6 s) at 25 frames/s.
MAX_FRAME = FRAME_RATE * L.MAX_EVENT_TIME_S
#: Largest absolute person id (ids are exact in a float).
MAX_PERSON_ID = 10**9
#: Longest ``name`` (the prefix of the scenario names and files) [characters].
MAX_NAME_CHARS = 100
#: Limits of the robot options (``robot`` keys of :class:`CrowdOptions`), as the scenario's
#: (every option must also be > 0).
_ROBOT_RANGES: dict[str, tuple[float, float]] = {"radius": L.ROBOT_RADIUS_M, **L.ROBOT_LIMITS,
                                                 "goal_tolerance": (0.0, L.MAX_GOAL_TOLERANCE_M)}
#: The columns of an obsmat row.
_COLUMNS = ("frame", "person", "x", "z", "y", "vx", "vz", "vy")


class CrowdError(AnyplanError):
    """An unreadable or malformed obsmat file, or bad import options."""


@dataclass(frozen=True)
class CrowdOptions:
    """Import settings (lengths in m, times in s), checked when made (:meth:`check`)."""

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

    def __post_init__(self) -> None:
        self.check()

    def check(self) -> None:
        """Raises CrowdError on an out-of-range option (each checked against its stated limit)."""
        for name, hi in (("window_s", L.MAX_TIME_LIMIT_S), ("step_s", math.inf),
                         ("copy_shift_s", L.MAX_EVENT_TIME_S), ("margin_m", L.MAX_ARENA_M),
                         ("edge_m", L.MAX_ARENA_M), ("sensing_range_m", L.MAX_COORD_M),
                         ("rate_hz", L.MAX_SENSOR_RATE_HZ)):
            _check_range(name, getattr(self, name), 0.0, hi)
        _check_range("noise_m", self.noise_m, 0.0, L.MAX_SIZE_M, zero=True)
        if isinstance(self.copies, bool) or not isinstance(self.copies, int) \
                or not 1 <= self.copies <= L.MAX_CROWD_COPIES:
            raise CrowdError.about("copies", f" must be an integer in [1, {L.MAX_CROWD_COPIES}] "
                                   f"(the stated limit), got {shorten(self.copies)}")
        if self.edge_m >= self.margin_m:
            raise CrowdError.about("edge_m", " must be smaller than {margin_m}", "margin_m")
        for k, v in (self.robot or {}).items():
            if k not in _ROBOT_RANGES:
                raise CrowdError(f"import-crowd: robot: unknown key {shorten(k)} "
                                 f"(known: {', '.join(_ROBOT_RANGES)})")
            lo, hi = _ROBOT_RANGES[k]
            _check_range(f"robot_{k}", v, 0.0, hi, lo=lo)
        r = float({**SERVICE_ROBOT, **(self.robot or {})}["radius"])
        if self.edge_m < r:
            raise CrowdError.about("edge_m", f" must be >= the robot's radius ({{robot_radius}} "
                                   f"{r:g} m), got {self.edge_m:g}", "robot_radius")


def _check_range(name: str, v: Any, floor: float, hi: float, lo: float = 0.0,
                 zero: bool = False) -> None:
    """Option ``name`` is a finite number > ``floor`` (>= with ``zero``), >= ``lo`` and <= ``hi``."""
    try:
        x = finite_float(v, floor, lo_open=not zero)
    except NumberRefused as exc:
        rel = ">=" if zero else ">"
        raise CrowdError.about(name, f" must be a finite number {rel} {floor:g}, got {exc.shown}") from None
    if x < lo or x > hi:
        bounds = f"[{lo:g}, {hi:g}]" if zero or lo > floor else f"({lo:g}, {hi:g}]"
        raise CrowdError.about(name, f" must be in {bounds} (the stated limit), got {x:g}")


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
        rows.append(_check_row(vals, f"{p}: line {i}"))
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


def _check_row(vals: list[float], where: str) -> tuple[float, int, float, float]:
    """(frame, person, x, y) of one obsmat row, each within its stated limit."""
    if len(vals) != 8:
        raise CrowdError(f"{where}: expected 8 finite numbers (frame person x z y vx vz vy), "
                         f"got {len(vals)}")
    for col, v in zip(_COLUMNS, vals, strict=True):
        if not math.isfinite(v):
            raise CrowdError(f"{where}: {col}: expected a finite number, got {v}")
    frame, pid, x, y = vals[0], vals[1], vals[2], vals[4]
    if not 0.0 <= frame <= MAX_FRAME:
        raise CrowdError(f"{where}: frame: must be in [0, {MAX_FRAME:g}] (10^6 s at {FRAME_RATE:g} "
                         f"frames/s, the stated limit), got {frame:g}")
    if pid != int(pid):
        raise CrowdError(f"{where}: person id must be an integer, got {pid:g}")
    if abs(pid) > MAX_PERSON_ID:
        raise CrowdError(f"{where}: person: id must be within +-{MAX_PERSON_ID:g} (the stated "
                         f"limit), got {pid:g}")
    for col, v in (("x", x), ("y", y)):
        if abs(v) > L.MAX_COORD_M:
            raise CrowdError(f"{where}: {col}: must be within +-{L.MAX_COORD_M:g} m (the stated "
                             f"limit), got {v:g}")
    return frame, int(pid), x, y


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
                    options: CrowdOptions | None = None, source: str | None = None
                    ) -> list[dict[str, Any]]:
    """Scenario dictionaries (our YAML schema), one per usable window of the recording.

    Raises:
        CrowdError: options the recording cannot use (more windows than the limit, copies
            that coincide) or a recording or window beyond a stated limit, naming ``source``
            (the obsmat file; default ``name``). An option out of its range is refused when
            the :class:`CrowdOptions` is made.
    """
    opt = options or CrowdOptions()
    src = source or name
    robot = {**SERVICE_ROBOT, **(opt.robot or {})}
    r = robot["radius"]
    if not tracks:
        raise CrowdError(f"{src}: no people")
    allp = np.vstack(list(tracks.values()))
    _check_arena(tracks, allp, opt.margin_m, src)
    xmin, ymin = allp[:, 1].min(), allp[:, 2].min()
    sx, sy = opt.margin_m - xmin, opt.margin_m - ymin
    width = float(allp[:, 1].max() - xmin + 2 * opt.margin_m)
    height = float(allp[:, 2].max() - ymin + 2 * opt.margin_m)
    t_end = float(max(tr[-1, 0] for tr in tracks.values()))
    period = t_end + 0.4  # one annotation interval after the last frame: no two copies' samples meet
    _check_shift(opt, period, src)
    n_win = _count_windows(t_end, opt, src)
    shifted = {pid: np.column_stack([tr[:, 0], tr[:, 1] + sx, tr[:, 2] + sy])
               for pid, tr in tracks.items()}
    along_x = width >= height
    long_side, short_side = (width, height) if along_x else (height, width)
    out = []
    copies = [_copy(shifted, k, opt.copy_shift_s, period) for k in range(opt.copies)]
    for w in range(n_win):
        t0 = w * opt.step_s
        span = f"window {w} ({t0:g}-{t0 + opt.window_s:g} s after the first frame)"
        people = _window_people(copies, t0, opt.window_s)
        if len(people) > L.MAX_MOVING_OBSTACLES:
            copies_, fewer = (f" ({opt.copies} copies)", "fewer {copies} or ") if opt.copies > 1 else ("", "")
            raise CrowdError.about(
                src, f": {span} holds {len(people)} people{copies_}, more than the "
                f"{L.MAX_MOVING_OBSTACLES} moving obstacles of a scenario (the stated limit); use "
                + fewer + "a shorter {window_s}", "copies", "window_s")
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
        except ScenarioError as exc:
            raise CrowdError(f"{src}: {span}: {_who(exc.field, people)}{exc.message}") from None
        except AnyplanError as exc:
            raise CrowdError(f"{src}: {span} does not convert to a valid scenario: {exc}") from None
        out.append(data)
    return out


def _check_arena(tracks: Mapping[int, np.ndarray], allp: np.ndarray, margin: float, src: str) -> None:
    """The arena (the positions' bounding box grown by ``margin``) fits the stated limit."""
    for axis, col in (("x", 1), ("y", 2)):
        lo, hi = float(allp[:, col].min()), float(allp[:, col].max())
        if hi - lo + 2 * margin <= L.MAX_ARENA_M:
            continue
        who = [next(pid for pid, tr in tracks.items() if np.any(tr[:, col] == v)) for v in (lo, hi)]
        raise CrowdError.about(
            src, f": {axis} spans {lo:g} (person {who[0]}) to {hi:g} m (person {who[1]}); with "
            f"{{margin_m}} {margin:g} m the arena would be {hi - lo + 2 * margin:g} m, more than "
            f"the stated limit {L.MAX_ARENA_M:g} m", "margin_m")


def _count_windows(t_end: float, opt: CrowdOptions, src: str) -> int:
    """The number of windows, refused beyond the stated limit before any is made."""
    q = (t_end - opt.window_s) / opt.step_s  # may be huge (a tiny step) or inf, never NaN
    if q < 0.0:  # not one window: an import that writes nothing is refused, not silent
        raise CrowdError.about(src, f": the recording lasts {t_end:g} s, less than one window of "
                               f"{opt.window_s:g} s ({{window_s}})", "window_s")
    if q < 2 * L.MAX_IMPORT_SCENARIOS:
        n = int(math.floor(q + 1e-9)) + 1
        if n <= L.MAX_IMPORT_SCENARIOS:
            return n
        many = str(n)
    else:
        many = f"about {q + 1.0:.3g}" if math.isfinite(q) else "countless"
    raise CrowdError.about(
        src, f": windows of {opt.window_s:g} s ({{window_s}}) every {opt.step_s:g} s ({{step_s}}) "
        f"over the recording's {t_end:g} s make {many} scenarios, more than the stated limit "
        f"{L.MAX_IMPORT_SCENARIOS} per import", "window_s", "step_s")


def _check_shift(opt: CrowdOptions, period: float, src: str) -> None:
    """No copy replays the recording at the times of the first (a shift = a multiple of T)."""
    for k in range(1, opt.copies):
        rem = math.fmod(k * opt.copy_shift_s, period)
        if min(rem, period - rem) < 1e-6:
            raise CrowdError.about(
                src, f": copies 0 and {k} would coincide: {k} x {{copy_shift_s}} {opt.copy_shift_s:g}"
                f" s is a multiple of the recording's length {period:g} s (the shift is cyclic)",
                "copy_shift_s")


def _who(fld: str, people: list[tuple[str, np.ndarray]]) -> str:
    """The person (and copy) a converted scenario's field is about, for a message."""
    m = re.match(r"dynamic_obstacles\[(\d+)\]", fld)
    who = re.fullmatch(r"P(-?\d+)(?:c(\d+)b?)?", people[int(m.group(1))][0]) \
        if m and int(m.group(1)) < len(people) else None
    if who is None:
        return f"{fld}: "
    return f"person {who.group(1)}" + (f" (copy {who.group(2)})" if who.group(2) else "") + ": "


def import_crowd(path: str | Path, out_dir: str | Path, options: CrowdOptions | None = None,
                 name: str | None = None) -> list[Path]:
    """Write one scenario YAML file per window of the obsmat file ``path``; returns the paths."""
    p = Path(path)
    if name is not None:
        _check_name(name)
    tracks = read_obsmat(p)
    base = name or p.stem.replace("_obsmat", "").replace("_", "-")
    scenarios = crowd_scenarios(tracks, base, options, source=str(p))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for sc in scenarios:
        f = out / f"{sc['name']}.yaml"
        f.write_text(f"# Converted by 'anyplan import-crowd' from {one_line(p.name, 200)} (ETH/UCY "
                     "obsmat).\n"
                     + dump_yaml(sc, sort_keys=False, default_flow_style=None, width=100))
        paths.append(f)
    return paths


def _check_name(name: str) -> None:
    """``name`` is a plain file-name stem: the files it names stay in the output folder."""
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_+-][A-Za-z0-9._+-]*", name) \
            or len(name) > MAX_NAME_CHARS:
        raise CrowdError.about("name", f" {shorten(name)}: expected a plain file-name stem (letters, "
                               f"digits and ._+-, not starting with a dot, at most {MAX_NAME_CHARS} "
                               "characters; no path separators)")
