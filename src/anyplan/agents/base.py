"""The agent interface shared by every planner run in the simulator.

An :class:`Agent` is reset once per run with the static part of a scenario and then asked for a
command at every control step (:meth:`Agent.act`, given an :class:`Observation`). What it reports
goes into :class:`AgentStats`: the common fields, plus a typed statistics record per agent
(:class:`~anyplan.agents.stats.StatsRecord`, e.g. ``SequentialStats``) that becomes
``result.json``'s ``extra``. :data:`AGENTS` is the registry of planner names
(:func:`make_agent`); plugins register through the entry-point group ``anyplan.agents``.
"""

from __future__ import annotations

import abc
import math
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from anyplan.agents.plugins import discover_plugins
from anyplan.agents.stats import StatsRecord
from anyplan.errors import NumberRefused, finite_float, shorten
from anyplan.prediction.base import ObstacleObservation
from anyplan.prediction.detection import Detection
from anyplan.registry import LoadError, Registry
from anyplan.world.robot import Command, RobotState
from anyplan.world.scenario import Scenario

__all__ = ["Observation", "Agent", "AgentStats", "TrackingLog", "TrackedStats", "AGENTS",
           "make_agent", "checked_number", "checked_pose_margin"]


@dataclass(frozen=True)
class Observation:
    """What the agent sees at one control step.

    Attributes:
        t: Simulation time [s].
        robot: The robot's pose and twist.
        obstacles: Moving obstacles currently observed (all of them, or only those within
            ``robot.sensing_range``), with pose and twist (``oracle`` and ``twist`` perception).
        detections: Noisy positions of the obstacles detected at this step (``tracked``
            perception, only on sensor frames; see :mod:`anyplan.simulation.perception`).
        odom: The robot's odometry pose: its start moved by the twist its drive reports, step
            by step (smooth, drifting with an execution error); the pose of ``robot`` is the
            localizer's. None when not given.
        frame: True at a step where the sensor took a frame (``tracked``), its detections
            possibly none: what it did not detect there, it did not see (a tracker's negative
            information). False elsewhere, and when not known (a step with detections is a
            frame all the same).
    """

    t: float
    robot: RobotState
    obstacles: tuple[ObstacleObservation, ...] = ()
    detections: tuple[Detection, ...] = ()
    odom: RobotState | None = None
    frame: bool = False


@dataclass
class AgentStats:
    """What an agent reports about its run; merged into ``result.json``.

    Attributes:
        planning_times_s: Wall-clock time [s] of each planning call.
        replans: Number of replanning events after the first plan.
        virtual_obstacles: Virtual static obstacles created, as dicts
            ``{center: [x, y], side, created_at_s}``.
        plans: Planned paths, as dicts ``{t: creation time [s], path: [[x, y], ...]}``.
        extra: Further fields without a record (plugins; a value may be a record too).
        record: The agent's typed statistics (its ``to_dict()`` comes first in ``result.extra``).
    """

    planning_times_s: list[float] = field(default_factory=list)
    replans: int = 0
    virtual_obstacles: list[dict[str, Any]] = field(default_factory=list)
    plans: list[dict[str, Any]] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)
    record: StatsRecord | None = None

    def extra_dict(self) -> dict[str, Any]:
        """``result.json``'s ``extra``: the record's fields, then :attr:`extra` (records in it
        as their ``to_dict()``)."""
        out: dict[str, Any] = self.record.to_dict() if self.record is not None else {}
        for k, v in self.extra.items():
            out[k] = v.to_dict() if hasattr(v, "to_dict") else v
        return out


class TrackedStats(Protocol):
    """A record with the tracking error fields that :meth:`TrackingLog.add` writes."""

    tracking_rms_m: float | None
    tracking_max_m: float | None


class TrackingLog:
    """Running RMS and maximum distance [m] between the robot and its reference position.

    :meth:`add` writes ``tracking_rms_m`` and ``tracking_max_m`` into an agent's record (or a
    dict).
    """

    def __init__(self) -> None:
        self._sq = 0.0
        self._n = 0
        self._max = 0.0

    def add(self, reference_xy: tuple[float, float], robot: RobotState,
            into: TrackedStats | dict[str, Any]) -> float:
        """Record one control step's error; returns it [m]."""
        err = math.hypot(reference_xy[0] - robot.x, reference_xy[1] - robot.y)
        self._sq += err * err
        self._n += 1
        self._max = max(self._max, err)
        if isinstance(into, dict):
            into["tracking_rms_m"] = math.sqrt(self._sq / self._n)
            into["tracking_max_m"] = self._max
        else:
            into.tracking_rms_m = math.sqrt(self._sq / self._n)
            into.tracking_max_m = self._max
        return err


class Agent(abc.ABC):
    """A method that commands the robot one control step at a time.

    Subclasses implement :meth:`reset` and :meth:`act`. They must not read the moving
    obstacles of the scenario passed to :meth:`reset` (it has none: the simulator passes
    :meth:`Scenario.static_only`); moving obstacles are known only through observations.
    """

    #: Registry name, set by subclasses.
    name: str = "agent"
    #: Dataclasses (or instances: their values are the defaults) whose fields the constructor also
    #: accepts as keywords (``--set`` lists them).
    config_classes: tuple[Any, ...] = ()
    #: Settings that make a run depend only on scenario, settings and seed (``--deterministic``);
    #: ``{}`` for an agent that is deterministic as it is, None for one without such a mode.
    deterministic_settings: dict[str, Any] | None = None
    #: Keys of ``result.extra`` that hold wall-clock measurements (they differ from run to run).
    wall_clock_extra: tuple[str, ...] = ()

    def __init__(self) -> None:
        self.stats = AgentStats()

    @abc.abstractmethod
    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        """Prepare for a run on ``scenario`` (static obstacles only), with its own ``rng``."""

    @abc.abstractmethod
    def act(self, obs: Observation) -> Command:
        """The command for the next control period."""


AGENTS: Registry[type[Agent]] = Registry("planner")
AGENTS.register("straight", "anyplan.agents.straight:StraightAgent")
AGENTS.register("bitstar", "anyplan.agents.bitstar:BITStarAgent")
AGENTS.register("seq-bitstar", "anyplan.agents.sequential:SequentialBITStarAgent")
AGENTS.register("dovs", "anyplan.agents.dovs:DOVSAgent")
AGENTS.register("st-bitstar", "anyplan.agents.spacetime:SpaceTimeBITStarAgent")
AGENTS.register("orca", "anyplan.agents.orca:ORCAAgent")  # optional extra: pyrvo
AGENTS.register("policy", "anyplan.agents.policy:PolicyAgent")  # e.g. trained in anyplan.gym


def checked_number(name: str, value: Any, lo: float = 0.0, *, lo_open: bool = False) -> float:
    """An agent's numeric setting ``name``: ``value`` as a float when it is a finite number
    >= ``lo`` (> ``lo`` with ``lo_open``), so that a bad ``--set`` value is refused when the
    agent is built, not met halfway through a run.

    Raises:
        ValueError: anything else (the message names the setting).

    Examples:
        >>> checked_number("period_s", 0.1, lo_open=True)
        0.1
        >>> checked_number("period_s", 0.0, lo_open=True)
        Traceback (most recent call last):
        ...
        ValueError: period_s: must be > 0, got 0.0
    """
    try:
        return finite_float(value, lo, lo_open=lo_open)
    except NumberRefused:
        raise ValueError(f"{name}: must be {'>' if lo_open else '>='} {lo:g}, got {shorten(value)}") from None


def checked_pose_margin(value: Any) -> float:
    """The ``pose_margin_m`` setting [m] of the agents that keep clearance for a localization
    error (``seq-bitstar``, ``st-bitstar``, ``bitstar``).

    Raises:
        ValueError: not a finite number >= 0 (the message names the setting).
    """
    return checked_number("pose_margin_m", value)


def _discover(registry: Registry[type[Agent]]) -> None:
    discover_plugins(registry)  # third-party agents: entry-point group "anyplan.agents"


AGENTS.set_discovery(_discover)


def make_agent(name: str, **config: Any) -> Agent:
    """A new agent, registered as ``name`` (built-in or plugin), with keyword ``config``.

    Each call builds a fresh object; :func:`~anyplan.simulation.simulate` also starts its
    ``stats`` empty, so nothing carries over from one run to the next.

    Raises:
        UnknownNameError: no planner has that name.
        LoadError: a plugin's module cannot be imported.
        LoadError: the registered object is not an :class:`Agent` class either.
    """
    cls = AGENTS.get(name)
    if not (isinstance(cls, type) and issubclass(cls, Agent)):
        raise LoadError(f"planner '{name}' ({AGENTS.origin(name)}) is not an anyplan.agents.Agent "
                        f"subclass: {cls!r}")
    return cls(**config)
