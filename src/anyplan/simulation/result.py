"""The outcome of one simulated run: :class:`RunResult` (the ``result.json`` contract).

:class:`RunStatus` names how a run ended; it is a string enum, so that ``result.json`` holds the
same plain strings as before (``"reached"``, ``"collision"``, ``"timeout"``, ``"unreachable"``)
and ``status == "reached"`` still holds. :meth:`RunResult.from_dict` is the one reader of a
stored result (the database, the report, the tables and the tests use it);
:meth:`RunResult.to_dict` the one writer. ``wall_clock_fields`` names the fields measured in
wall-clock time, which :func:`without_wall_clock` leaves out for comparisons of reproducible
runs. The fields are listed in ``docs/experiments.md`` (section "The results database").
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from typing import Any

import numpy as np

from anyplan import __version__

__all__ = ["RunStatus", "RunResult", "WALL_CLOCK_FIELDS", "without_wall_clock"]


class RunStatus(enum.StrEnum):
    """How a simulated run ended (``RUNNING`` while it goes on)."""

    RUNNING = "running"
    REACHED = "reached"
    COLLISION = "collision"
    TIMEOUT = "timeout"
    UNREACHABLE = "unreachable"


#: Fields of every result measured in wall-clock time.
WALL_CLOCK_FIELDS: tuple[str, ...] = ("wall_time_s", "planning_times_s")

#: Values of the required fields that an older or partial ``result.json`` may lack.
_MISSING_REQUIRED: dict[str, Any] = {
    "scenario": "", "planner": "", "seed": 0, "reached_goal": False, "collision": False,
    "path_length_m": math.nan, "time_to_goal_s": None, "planning_times_s": [], "replans": 0,
    "min_clearance_m": math.nan, "trajectory": [],
}


@dataclass
class RunResult:
    """The outcome of one simulated run (the ``result.json`` contract).

    Lengths in m, times in s, angles in rad. ``trajectory`` rows are
    ``[t, x, y, theta, v, omega]``, one per simulation step (the first at t = 0).

    ``collision_robot_caused`` (None without a collision) tells whether, at the first contact,
    the robot's velocity had a component of more than 0.05 m/s towards what it hit
    (:mod:`anyplan.simulation.contact`); ``collision_approach_speed_mps`` is that component.
    ``time_lower_bound_s`` is the least time from rest to the edge of the goal tolerance along
    the static shortest path (:func:`anyplan.planning.time_bound.scenario_time_lower_bound`;
    None without a path) and ``time_over_lower_bound`` the time to goal over it.

    ``wall_clock_fields`` names the fields measured in wall-clock time (``wall_time_s``,
    ``planning_times_s`` and the agent's ``extra.*`` timings): they differ from run to run and
    machine to machine. Every other field is a function of the scenario, the planner settings
    and the seed when the planner runs deterministically (``--deterministic``);
    :meth:`reproducible_dict` leaves the wall-clock fields out.
    """

    scenario: str
    planner: str
    seed: int
    reached_goal: bool
    collision: bool
    path_length_m: float
    time_to_goal_s: float | None
    planning_times_s: list[float]
    replans: int
    min_clearance_m: float
    trajectory: list[list[float]]
    status: RunStatus = RunStatus.TIMEOUT
    collision_with: str | None = None
    collision_time_s: float | None = None
    virtual_obstacles: list[dict[str, Any]] = field(default_factory=list)
    plans: list[dict[str, Any]] = field(default_factory=list)
    scenario_hash: str = ""
    dt_s: float = 0.05
    wall_time_s: float = 0.0
    anyplan_version: str = __version__
    extra: dict[str, Any] = field(default_factory=dict)
    collision_robot_caused: bool | None = None
    collision_approach_speed_mps: float | None = None
    time_lower_bound_s: float | None = None
    time_over_lower_bound: float | None = None
    #: Smallest robot-to-moving-obstacle surface distance [m] (None without moving obstacles)
    #: and time [s] within 0.2 m of one (:mod:`anyplan.simulation.metrics`).
    min_distance_to_moving_m: float | None = None
    discomfort_time_s: float = 0.0
    wall_clock_fields: list[str] = field(default_factory=lambda: list(WALL_CLOCK_FIELDS))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable dictionary (the ``result.json`` form; statuses as plain strings)."""
        return dict(_jsonable(asdict(self)))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunResult:
        """The result of a ``result.json`` dictionary (also an older or partial one).

        The one reader of stored results: keys that are not fields (e.g. the runner's
        ``agent_name``) are ignored, a missing field takes its default (for the required ones:
        empty, zero, False, or NaN for the lengths), ``null`` stays None, and ``status`` becomes
        a :class:`RunStatus` (an unknown status string is kept as it is).
        """
        known = {f.name for f in fields(cls)}
        kw: dict[str, Any] = {**_MISSING_REQUIRED}
        kw.update((k, v) for k, v in data.items() if k in known)
        status = kw.get("status", RunStatus.TIMEOUT)
        try:
            kw["status"] = RunStatus(status)
        except ValueError:
            kw["status"] = status
        for name in ("planning_times_s", "trajectory", "virtual_obstacles", "plans",
                     "wall_clock_fields"):
            if name in kw and kw[name] is None:
                kw[name] = []
        if kw.get("extra") is None:
            kw["extra"] = {}
        return cls(**kw)

    def reproducible_dict(self) -> dict[str, Any]:
        """:meth:`to_dict` without the wall-clock fields."""
        return without_wall_clock(self.to_dict())

    @property
    def trajectory_array(self) -> np.ndarray:
        """The trajectory as an array, shape (N, 6)."""
        return np.asarray(self.trajectory, dtype=float).reshape(-1, 6)


def without_wall_clock(result: dict[str, Any]) -> dict[str, Any]:
    """A ``result.json`` dictionary without the fields it lists in ``wall_clock_fields``."""
    out = dict(result)
    out["extra"] = dict(out.get("extra") or {})
    for name in result.get("wall_clock_fields", WALL_CLOCK_FIELDS):
        if name.startswith("extra."):
            out["extra"].pop(name[len("extra."):], None)
        else:
            out.pop(name, None)
    return out


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, enum.Enum):
        return obj.value
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.floating | float):
        x = float(obj)
        return x if math.isfinite(x) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj
