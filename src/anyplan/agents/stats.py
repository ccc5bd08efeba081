"""Typed statistics records of the built-in agents: what each adds to ``result.json``'s ``extra``.

Every record is a dataclass whose ``to_dict()`` gives the ``extra`` keys in the order the agent
reports them; a field that is None (or an empty optional list) was never reported and is left
out. ``WALL_CLOCK`` lists the keys that hold wall-clock measurements (the agent's
``wall_clock_extra``: ``--deterministic`` results compare equal without them). An agent keeps
its record in ``stats.record`` (:class:`~anyplan.agents.base.AgentStats`).

Records: :class:`SequentialStats` (``seq-bitstar``), :class:`SpaceTimeStats` (``st-bitstar``),
:class:`BITStarStats` (``bitstar``), :class:`DOVSStats` (``dovs``), :class:`TrackerCounts` (the
``tracking`` entry of the perceiving wrapper). ``straight``, ``orca`` and ``policy`` report no ``extra``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

__all__ = ["IMPROVE", "improvement_calls", "StatsRecord", "SequentialStats", "SpaceTimeStats", "BITStarStats",
           "DOVSStats", "TrackerCounts"]

#: The ``extra.reasons`` entry of an ``st-bitstar`` replanning that looks for a motion earlier
#: than the one in use (an improvement call: the robot already drives a safe motion).
IMPROVE = "improve"


def improvement_calls(extra: dict[str, Any], n_calls: int) -> list[bool]:
    """Which of a run's ``n_calls`` planning calls (``planning_times_s``) were improvement
    calls, from its ``extra.reasons`` (one reason a call); all False when the run has no
    reason for every call (an agent that makes none).

    Examples:
        >>> improvement_calls({"reasons": ["initial", IMPROVE, "holding"]}, 3)
        [False, True, False]
        >>> improvement_calls({}, 2)
        [False, False]
    """
    reasons = list(extra.get("reasons") or [])
    if len(reasons) != n_calls:
        return [False] * n_calls
    return [r == IMPROVE for r in reasons]


@dataclass
class TrackerCounts:
    """The perceiving wrapper's ``extra.tracking``: live (confirmed) tracks, dropped tracks,
    tube exits, and with anonymous detections the tracks started and those discarded before
    confirmation (``started``, ``discarded``: written when tracks were started)."""

    tracks: int = 0
    dropped: int = 0
    tube_exits: int = 0
    started: int = 0
    discarded: int = 0

    def to_dict(self) -> dict[str, Any]:
        """The ``result.json`` form."""
        out = {"tracks": self.tracks, "dropped": self.dropped, "tube_exits": self.tube_exits}
        if self.started:
            out.update(started=self.started, discarded=self.discarded)
        return out


@dataclass
class StatsRecord:
    """Base of the records: ``to_dict()`` over :attr:`KEYS`, leaving out what was not reported.

    Attributes:
        tracking: The perceiving wrapper's tracker counts (``tracked`` perception only).
    """

    #: The ``extra`` keys, in order.
    KEYS: ClassVar[tuple[str, ...]] = ()
    #: Keys left out while they are None (or, for lists, empty).
    OPTIONAL: ClassVar[frozenset[str]] = frozenset()
    #: Keys holding wall-clock measurements.
    WALL_CLOCK: ClassVar[tuple[str, ...]] = ()

    tracking: TrackerCounts | None = field(default=None, kw_only=True)

    def to_dict(self) -> dict[str, Any]:
        """The ``result.json`` form."""
        out: dict[str, Any] = {}
        for k in self.KEYS:
            v = getattr(self, k)
            if k in self.OPTIONAL and (v is None or (isinstance(v, list) and not v)):
                continue
            out[k] = v.to_dict() if isinstance(v, TrackerCounts) else v
        return out


_TRACKING = ("tracking_rms_m", "tracking_max_m")


@dataclass
class SequentialStats(StatsRecord):
    """``seq-bitstar``: one entry per replanning in the lists, unless said otherwise.

    Attributes:
        statuses: Count of each replanning status (``collision_free``, ``waiting``, ...).
        iterations: BIT* plans per replanning.
        late_plans: Replannings whose computation outlasted the expected delay (wall clock);
            for ``st-bitstar`` also a decision (guard, fallback) ready after its switch.
        plan_time_s: Wall-clock time [s] of the BIT* searches.
        motion_time_s: Wall-clock time [s] of motion building and prediction.
        replan_times_s: Simulated time [s] of each replanning.
        waits: Replannings that found a delayed departure.
        fallbacks: The safety guard's fallbacks (the guard's own list).
        safety_time_s: Wall-clock time [s] of each safety decision.
        reasons: Why each replanning happened.
        progress: BIT*'s cost against solve time in the first planning, ``[[t_s, cost_m], ...]``.
        safety: Every safety decision in JSON form.
        tracking: The tracker's counts (``tracked`` perception; reported from the first step,
            before the first motion starts).
        tracking_rms_m: RMS distance [m] between robot and reference.
        tracking_max_m: Largest such distance [m].
        reanchored_s: Simulated times [s] at which the robot was found off its reference
            (``reanchor_m``) and a replanning from its own state was asked for (left out
            when empty).
        pose_margin_m: The clearance [m] kept from the static obstacles for the robot's
            localization error (``pose_margin_m``, as the way to the goal allows; left out
            when not asked for).
    """

    KEYS: ClassVar[tuple[str, ...]] = (
        "statuses", "iterations", "late_plans", "plan_time_s", "motion_time_s", "replan_times_s",
        "waits", "fallbacks", "safety_time_s", "reasons", "progress", "safety", "tracking",
        *_TRACKING, "reanchored_s", "pose_margin_m")
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"reasons", "progress", "safety", "tracking",
                                                    *_TRACKING, "reanchored_s", "pose_margin_m"})
    WALL_CLOCK: ClassVar[tuple[str, ...]] = ("plan_time_s", "motion_time_s", "progress",
                                             "late_plans", "safety_time_s")

    statuses: dict[str, int] = field(default_factory=dict)
    iterations: list[int] = field(default_factory=list)
    late_plans: int = 0
    plan_time_s: list[float] = field(default_factory=list)
    motion_time_s: list[float] = field(default_factory=list)
    replan_times_s: list[float] = field(default_factory=list)
    waits: int = 0
    fallbacks: list[dict[str, Any]] = field(default_factory=list)
    safety_time_s: list[float] = field(default_factory=list)
    reasons: list[str] = field(default_factory=list)
    progress: list[list[float]] | None = None
    safety: list[dict[str, Any]] | None = None
    tracking_rms_m: float | None = None
    tracking_max_m: float | None = None
    reanchored_s: list[float] = field(default_factory=list)
    pose_margin_m: float | None = None


@dataclass
class SpaceTimeStats(SequentialStats):
    """``st-bitstar``: the fields of :class:`SequentialStats` it fills, and its own.

    Attributes:
        st_waits_s: Planned wait [s] of each motion started.
        st_timed: Motions started that were re-timed among the moving obstacles.
        st_candidates: Timed candidates per replanning.
        st_pruned: Loop paths left untimed because their untimed motion arrives no earlier than
            a timed candidate, or because the search budget had run out once a candidate was
            timed (each ends its replanning's search).
        st_trapped: Replannings that did not search: a planned disc held every place the robot
            could reach (:func:`~anyplan.prediction.trap.first_trap`), so no motion was free.
        inside_discs: Predicted discs that already held the robot when it planned, shrunk to
            let it leave (uncertain predictions only; left out when None).
    """

    KEYS: ClassVar[tuple[str, ...]] = (
        "statuses", "iterations", "late_plans", "plan_time_s", "motion_time_s", "replan_times_s",
        "waits", "fallbacks", "safety_time_s", "st_waits_s", "st_timed", "st_candidates",
        "st_pruned", "st_trapped", "inside_discs", "reasons", "progress", "safety", "tracking", *_TRACKING,
        "reanchored_s", "pose_margin_m")
    OPTIONAL: ClassVar[frozenset[str]] = SequentialStats.OPTIONAL | {"inside_discs"}

    st_waits_s: list[float] = field(default_factory=list)
    st_timed: int = 0
    st_candidates: list[int] = field(default_factory=list)
    st_pruned: int = 0
    st_trapped: int = 0
    inside_discs: int | None = None


@dataclass
class BITStarStats(StatsRecord):
    """``bitstar`` (one plan): only ``plan_status`` when BIT* failed.

    Attributes:
        plan_status: BIT*'s status.
        bitstar_time_s: Wall-clock time [s] of the BIT* calls.
        motion_time_s: Wall-clock time [s] of the motion building.
        path_cost_m: Cost [m] of BIT*'s path.
        trajectory_kind: How the reference motion was built.
        trajectory_certified_free: Its certification among the static obstacles.
        smoothed_length_m: Length [m] of the smoothed path.
        reference_duration_s: Duration [s] of the reference motion.
        time_lower_bound_s: Its time lower bound [s].
        smoothed_path: At most about 400 points of the smoothed path.
        progress: BIT*'s cost against solve time, ``[[t_s, cost_m], ...]``.
        tracking_rms_m: RMS distance [m] between robot and reference.
        tracking_max_m: Largest such distance [m].
        tracking: The tracker's counts (``tracked`` perception; reported after the tracking
            error, since the motion starts in the first step).
        pose_margin_m: The clearance [m] kept for the localization error (``pose_margin_m``,
            as the way to the goal allows).
    """

    KEYS: ClassVar[tuple[str, ...]] = (
        "plan_status", "bitstar_time_s", "motion_time_s", "path_cost_m", "trajectory_kind",
        "trajectory_certified_free", "smoothed_length_m", "reference_duration_s",
        "time_lower_bound_s", "smoothed_path", "progress", *_TRACKING, "tracking", "pose_margin_m")
    OPTIONAL: ClassVar[frozenset[str]] = frozenset(KEYS)
    WALL_CLOCK: ClassVar[tuple[str, ...]] = ("bitstar_time_s", "motion_time_s", "progress")

    plan_status: str | None = None
    bitstar_time_s: float | None = None
    motion_time_s: float | None = None
    path_cost_m: float | None = None
    trajectory_kind: str | None = None
    trajectory_certified_free: bool | None = None
    smoothed_length_m: float | None = None
    reference_duration_s: float | None = None
    time_lower_bound_s: float | None = None
    smoothed_path: list[list[float]] | None = None
    progress: list[list[float]] | None = None
    tracking_rms_m: float | None = None
    tracking_max_m: float | None = None
    pose_margin_m: float | None = None


@dataclass
class DOVSStats(StatsRecord):
    """``dovs``: its settings, then counts over the control periods.

    Attributes:
        control_period_s: DOVS's control period [s].
        dovs_config: Its settings (``DOVSConfig.to_dict()``).
        selection_modes: How often each velocity-selection mode was used.
        goal_targets: How often each goal-target mode was used.
        tracking: The tracker's counts (``tracked`` perception).
    """

    KEYS: ClassVar[tuple[str, ...]] = ("control_period_s", "dovs_config", "selection_modes",
                                       "goal_targets", "tracking")
    OPTIONAL: ClassVar[frozenset[str]] = frozenset({"selection_modes", "goal_targets",
                                                    "tracking"})

    control_period_s: float | None = None
    dovs_config: dict[str, Any] | None = None
    selection_modes: dict[str, int] | None = None
    goal_targets: dict[str, int] | None = None
