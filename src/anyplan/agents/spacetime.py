"""The ``st-bitstar`` agent: BIT* paths timed in space-time among the predicted moving obstacles.

Path-velocity decomposition: the path in use is tried first from the robot's new state;
otherwise the Sequential BIT* loop supplies candidate paths (detours around virtual squares),
each smoothed into a reference motion (:class:`~anyplan.trajectory.reference.Departure`) and
**re-timed** (:func:`anyplan.trajectory.spacetime.retime`: the earliest acceleration-bounded
motion along it that avoids the s-t regions of the predicted discs, waits included). A timing
within ``accept_s`` of the untimed arrival ends the search; otherwise the earliest timed arrival
wins. Every motion is verified (:func:`anyplan.trajectory.spacetime.verify`) before it is
executed; when none is, the robot brakes to rest and holds (``extra.fallbacks``). The online
timing policy is :class:`~anyplan.agents.replanning.ReplanningAgent`'s, shared with
``seq-bitstar``. With uncertain (tracked) predictions it plans on a receding horizon against
capped discs, and the safety guard checks each motion against the full discs of the obstacles
it does not outrun (``docs/perception.md``, "st-bitstar when the future is unknown"). Statistics:
:class:`~anyplan.agents.stats.SpaceTimeStats`. See ``docs/spacetime.md``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from anyplan.agents.base import Observation
from anyplan.agents.evasion import escape_time_s
from anyplan.agents.sequential import SequentialBITStarAgent
from anyplan.agents.st_fallbacks import SafetyDecisions
from anyplan.agents.st_predictions import PlanningPredictions
from anyplan.agents.stats import IMPROVE, SpaceTimeStats
from anyplan.geometry.shapes import Shape
from anyplan.planning.sequential import MotionModel, SequentialConfig, SequentialResult
from anyplan.prediction.base import ConstantTwistPredictor, PredictedObstacle
from anyplan.trajectory.kinds import ST_PREFIX, MotionKind
from anyplan.trajectory.path import remaining_path
from anyplan.trajectory.spacetime import RowCache, retime, verify
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world.robot import RobotState
from anyplan.world.scenario import Scenario

__all__ = ["SpaceTimeBITStarAgent"]

_DEFAULT_LOOP = SequentialConfig(max_iterations=8, wait_delays_s=(), max_time_s=0.3, anchor="obstacle",
                                 prove_blocked=True)
_LOOP_FIELDS = frozenset(f.name for f in dataclasses.fields(SequentialConfig))
#: How far ahead [s] a motion in use is checked (a hold lasts "for ever").
_CHECK_HORIZON_S = 60.0
#: Row duration [s] of the s-t maps.
_ROW_H = 0.05


def _followable(tr: Any) -> bool:
    """Whether the robot can follow ``tr`` from its start state within its limits
    (``feasible``) without cutting a static or virtual obstacle (``certified_free``): only
    then is a prediction along ``tr`` one about where the robot goes."""
    return bool(getattr(tr, "feasible", True)) and bool(getattr(tr, "certified_free", True))


class SpaceTimeBITStarAgent(PlanningPredictions, SafetyDecisions, SequentialBITStarAgent):
    """BIT* candidate paths, each timed among the moving obstacles (s-t velocity planning).

    Args:
        config: The Sequential BIT* loop that supplies candidate paths (detours around virtual
            squares); its ``margin`` [m] is the clearance kept from the moving obstacles.
        patience_s: First, each candidate path is timed with arrivals up to this much [s] after
            its untimed motion (short searches; a detour may beat a long wait).
        accept_s: A timed path arriving at most this much [s] after its untimed motion ends the
            search for detours at once; slower ones are kept, and the earliest arrival among all
            timed candidates wins.
        max_wait_s: Longest wait [s] a timing may hold. With certain predictions the loop's
            first (shortest) path is timed with waits up to this at once, and the detours are
            searched by branch and bound (:meth:`_timed_fn`). When no path can be timed, the
            last path (with uncertain predictions, the first and the last) is timed again with
            waits up to this, and the earlier arrival wins.
        search_budget_s: Anytime bound of the search for detours [s] (wall clock): once a path
            is timed, a detour is searched and timed only if it can end within this much of
            the replanning's start (the last search and timing's cost standing for its cost),
            else the best candidate is taken; each replanning times at least one path (with certain
            predictions; None: no budget, as the deterministic settings have it). Without a
            timed path the loop runs on.
        improve_calls: With announced motions, when the motion taken arrives more than
            ``accept_s`` after the earliest untimed one, the next checks search again (reason
            "improve", each on ``improve_budget_s``) with the motion in use as the bound to beat, going
            on with the detours where the budget cut the search; a motion arriving a lattice
            step earlier replaces it. At most this many calls per motion taken (0: never).
        improve_budget_s: ``search_budget_s`` of an improvement call [s] (the robot has a
            safe motion already: about one path per call; None: no budget).
        lattice_dt_s: Approximate step [s] of the velocity lattice.
        horizon_s: Horizon [s] of a prediction extrapolated from the current twist (perception
            ``twist`` or ``tracked``: no announced motion), at least the robot's
            :func:`~anyplan.agents.evasion.escape_time_s`; beyond it the obstacle is not checked
            (receding horizon, see :meth:`_planning_preds`). None: predictions never end.
        announced_horizon_s: With announced motions (``oracle``), paths are planned, timed and
            checked against each obstacle's motion up to this far [s] ahead of each call
            (receding horizon: every check looks this far ahead again, and a collision
            predicted inside it is replanned, long before the robot would need to stop).
            Timing a long path through every obstacle's whole future costs a map of the path's
            whole duration per candidate, and where no such timing exists the robot held at
            rest (100 pacing obstacles: four holding calls at the start, 0.36 s each). None:
            the whole motions (the paper's assumption).
        plan_extra_m: With such predictions, paths are planned and timed against discs whose
            extra radius is capped at this [m]; the safety guard checks every motion against
            the full growth of the obstacles not outrun before it starts. None: no cap.
        guard: ``"growth"``: the horizon and the guard apply to uncertain discs (``tracked``),
            exact twists (``twist``) are planned against in full; ``"horizon"``: both apply to
            every prediction without an announced motion; ``"never"``: the horizon alone.
        outrun_margin_mps: An uncertain obstacle predicted slower than ``v_max`` minus this
            [m/s] is outrun: the guard checks its planned disc, and none when every obstacle in
            view is outrun (``docs/perception.md``, "Which obstacles the guard checks in full";
            1/3 m/s: fleeing gains the 1 m growth cap in the 3 s horizon). None: all in full.
        manoeuvre_accel: A manoeuvre allowance [m/s^2] for exact twists (``twist``): their
            discs grow by ``manoeuvre_accel tau^2 / 2`` up to 1 m (uncertain, so the horizon and
            the guard apply as to tracked ones). 0: planned against in full (the default).
        passive_safety: With unknown futures (``twist``, ``tracked``), every motion started or
            kept must be passively safe: its escape is at rest before any obstacle ahead could
            reach it at its predicted speed + ``reach_extra_mps``
            (:func:`~anyplan.agents.safety.reachable_discs`): one that turns meets a robot at rest.
        reach_extra_mps: Speed [m/s] added to each obstacle's predicted speed for its
            reachable disc.
        reach_min_speed_mps: Least speed [m/s] of a reachable disc's growth, whatever the
            prediction (a person standing still can set off; ISO/TS 15066 assumes 1.6 m/s
            for a walking person). 0: the predicted speed + ``reach_extra_mps`` only.
        swerves: Among the fallbacks, also arcs entered at the robot's speed, then a brake
            (:data:`~anyplan.agents.evasion.SWERVES`), when no prediction is uncertain (exact
            twists, announced motions): a differential-drive robot that turns in place first
            stands in the obstacle's way. Measured (``docs/perception.md``, "Fallbacks"): on
            DynaBARN ``twist`` 339/400 reached against 323/400 without; among uncertain discs
            only when the robot outruns them all.
        twist_check_period_s: How often [s] the motion in use is checked while the obstacles
            in view are predicted from their exact current twists (``twist`` perception: no
            announced motion, no uncertain disc). Each check is the robot's next chance to
            react to a changed prediction (an obstacle that turned); the period is also the
            commitment of the fallbacks and enters their reaction time. Otherwise
            ``check_period_s`` (0.2 s) applies: with announced motions predictions do not
            change, and with tracked obstacles 0.1 s was measured no better. None:
            ``check_period_s`` always. On DynaBARN ``twist`` 0.1 s reached 161/200 with 15
            robot-caused collisions, 0.2 s 149/200 with 32 (``docs/perception.md``).
        extrapolated_iterations: Cap on the loop's paths per replanning while an obstacle in
            view has no announced motion (``twist``, ``tracked``); announced motions keep
            ``max_iterations`` (8). None: ``max_iterations`` always (``docs/perception.md``,
            "Planning time": against 8 over 757 paired runs, no outcome worse, p95 0.6 times).
        **kwargs: Further options of :class:`SequentialBITStarAgent` (planning_delay, ...).
    """

    name = "st-bitstar"
    kernel_parts = ("bitstar", "stmap", "motion", "contacts", "sequential", "spacetime")
    #: Search the loop's candidate paths by branch and bound (:meth:`_timed_fn`) when the
    #: predictions are certain; False times every path of the loop within ``patience_s``.
    branch_and_bound = True
    deterministic_settings = {**SequentialBITStarAgent.deterministic_settings,  # noqa: RUF012
                              "search_budget_s": None, "improve_budget_s": None}
    config_classes = (_DEFAULT_LOOP,)  # its defaults, for the listing of settings
    record: SpaceTimeStats

    def __init__(self, config: SequentialConfig | None = None, *, patience_s: float = 3.0,
                 max_wait_s: float = 30.0, lattice_dt_s: float = 0.25, accept_s: float = 0.5,
                 horizon_s: float | None = 3.0, plan_extra_m: float | None = 0.3,
                 guard: str = "growth", outrun_margin_mps: float | None = 1.0 / 3.0,
                 manoeuvre_accel: float = 0.0,
                 announced_horizon_s: float | None = 30.0,
                 passive_safety: bool = False, reach_extra_mps: float = 0.3,
                 reach_min_speed_mps: float = 0.0, search_budget_s: float | None = 0.02,
                 improve_calls: int = 25, improve_budget_s: float | None = 0.01,
                 twist_check_period_s: float | None = 0.1, swerves: bool = True,
                 extrapolated_iterations: int | None = 4, **kwargs: Any) -> None:
        loop = {k: kwargs.pop(k) for k in list(kwargs) if k in _LOOP_FIELDS}  # e.g. from --set
        if config is None:
            config = dataclasses.replace(_DEFAULT_LOOP, **loop)
        elif loop:
            raise ValueError("give either config or loop options, not both")
        super().__init__(config, **kwargs)
        for name, val in (("patience_s", patience_s), ("max_wait_s", max_wait_s),
                          ("lattice_dt_s", lattice_dt_s)):
            if not (isinstance(val, int | float) and val > 0.0):
                raise ValueError(f"{name}: must be > 0, got {val!r}")
        if horizon_s is not None and not (isinstance(horizon_s, int | float) and horizon_s > 0.0):
            raise ValueError(f"horizon_s: must be > 0 or null, got {horizon_s!r}")
        self.horizon_s = None if horizon_s is None else float(horizon_s)
        if announced_horizon_s is not None and not (isinstance(announced_horizon_s, int | float)
                                                    and announced_horizon_s > 0.0):
            raise ValueError(f"announced_horizon_s: must be > 0 or null, got {announced_horizon_s!r}")
        self.announced_horizon_s = None if announced_horizon_s is None else float(announced_horizon_s)
        if guard not in ("growth", "horizon", "never"):
            raise ValueError(f"guard: 'growth', 'horizon' or 'never', got {guard!r}")
        self.guard_mode = guard
        if outrun_margin_mps is not None and not (isinstance(outrun_margin_mps, int | float)
                                                  and outrun_margin_mps >= 0.0):
            raise ValueError(f"outrun_margin_mps: must be >= 0 or null, got {outrun_margin_mps!r}")
        self.outrun_margin_mps = None if outrun_margin_mps is None else float(outrun_margin_mps)
        for name, val in (("manoeuvre_accel", manoeuvre_accel), ("reach_extra_mps", reach_extra_mps),
                          ("reach_min_speed_mps", reach_min_speed_mps)):
            if not (isinstance(val, int | float) and val >= 0.0):
                raise ValueError(f"{name}: must be >= 0, got {val!r}")
        self.manoeuvre_accel, self.reach_extra_mps = float(manoeuvre_accel), float(reach_extra_mps)
        self.reach_min_speed_mps = float(reach_min_speed_mps)
        for name, flag in (("passive_safety", passive_safety), ("swerves", swerves)):
            if not isinstance(flag, bool):
                raise ValueError(f"{name}: must be true or false, got {flag!r}")
        self.passive_safety, self.swerves = passive_safety, swerves
        cap = extrapolated_iterations
        if cap is not None and (isinstance(cap, bool) or not (isinstance(cap, int) and cap >= 1)):
            raise ValueError(f"extrapolated_iterations: must be an integer >= 1 or null, got {cap!r}")
        self.extrapolated_iterations = cap
        if plan_extra_m is not None and not (isinstance(plan_extra_m, int | float)
                                             and plan_extra_m >= 0.0):
            raise ValueError(f"plan_extra_m: must be >= 0 or null, got {plan_extra_m!r}")
        self.plan_extra_m = None if plan_extra_m is None else float(plan_extra_m)
        if not (isinstance(accept_s, int | float) and 0.0 <= accept_s <= patience_s):
            raise ValueError(f"accept_s: must be in [0, patience_s], got {accept_s!r}")
        self.accept_s = float(accept_s)
        for name, limit in (("search_budget_s", search_budget_s),
                            ("improve_budget_s", improve_budget_s),
                            ("twist_check_period_s", twist_check_period_s)):
            if limit is not None and not (isinstance(limit, int | float) and limit > 0.0):
                raise ValueError(f"{name}: must be > 0 or null, got {limit!r}")
        self.search_budget_s = None if search_budget_s is None else float(search_budget_s)
        self.improve_budget_s = None if improve_budget_s is None else float(improve_budget_s)
        self.twist_check_period_s = (None if twist_check_period_s is None
                                     else float(twist_check_period_s))
        self._search_deadline: float | None = None
        self._call_start = 0.0  # wall clock [s] at the start of this replanning's search
        self._last_build: float | None = None  # wall clock [s] of the last path built
        #: wall clock [s] of the last search and build (the budget's estimate of the next)
        self._last_cycle: float | None = None
        self._stopped_at: list[Any] | None = None  # the squares where the budget stopped the loop
        if not (isinstance(improve_calls, int) and improve_calls >= 0):
            raise ValueError(f"improve_calls: must be an integer >= 0, got {improve_calls!r}")
        self.improve_calls = improve_calls
        #: improvement calls left for the motion in use; whether the budget cut this search;
        #: the earliest untimed arrival [s] of the paths it tried
        self._improve_left, self._cut, self._floor = 0, False, math.inf
        self._chain: list[Any] = []  # the squares of the path the budget cut (improving)
        self.patience_s = float(patience_s)
        self.max_wait_s = float(max_wait_s)
        self.lattice_dt_s = float(lattice_dt_s)

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        super().reset(scenario, rng)  # loads the kernel parts, "spacetime" among them
        # at least the time this robot needs to get out of an obstacle's way from rest
        self.prediction_horizon_s = (None if self.horizon_s is None else
                                     max(self.horizon_s, escape_time_s(self.spec)))
        self.predictor = ConstantTwistPredictor(horizon_s=self.prediction_horizon_s,
                                                manoeuvre_accel=self.manoeuvre_accel)
        self._cands: list[tuple[float, Trajectory, np.ndarray, list[Shape]]] = []
        self._tried: list[tuple[np.ndarray, list[Shape]]] = []
        self._path: np.ndarray | None = None
        self._shapes: list[Shape] = []
        self._preds: list[PredictedObstacle] = []
        self._rows: RowCache | None = None
        #: Nominal motions of this replanning and whether each is free as timed (``_timed_fn``).
        self._nominals: dict[tuple[Any, ...], tuple[Trajectory, bool | None, list[Shape]]] = {}
        #: whether the latest obstacles observed are predicted from exact twists (_period)
        self._exact_twists = False

    def _new_record(self) -> SpaceTimeStats:
        return SpaceTimeStats()

    # --- motions ---------------------------------------------------------------------------------
    def _timed_fn(self, state: RobotState, t_start: float, max_wait_s: float, *,
                  first_wait_s: float | None = None) -> MotionModel:
        """The motion model of the loop: each motion re-timed, the timed ones kept as
        candidates (``self._cands``).

        With ``first_wait_s`` (the Sequential BIT* loop's model) the candidates are searched by
        branch and bound: the first path (no squares: the shortest) is timed with waits up to
        ``first_wait_s``; once a candidate arrives at T, a path whose untimed motion arrives at
        T or later cannot beat it and ends the loop (the loop's later paths go around more
        squares), and an earlier one is timed with waits up to T minus its untimed arrival."""
        nominal_fn = self.reference.departing(state, t_start)
        spec, cfg = self.spec, self.config
        if self._rows is None or not self._rows.on_grid(t_start):
            # the obstacles' s-t rows, for every candidate and every replanning on the grid
            self._rows = RowCache(t_start, _ROW_H)
        self._rows.begin(t_start)

        def build(path: np.ndarray, shapes: Sequence[Shape], delay: float) -> Trajectory:
            now, last = time.perf_counter(), self._last_build
            if delay == 0.0:
                self._last_build = now
                if last is not None:
                    self._last_cycle = now - last
            # anytime: a detour is timed only if it can end within the budget, the last
            # path's cost (its BIT* search, smoothing, timing) taken as its cost
            # (and at least one path per replanning: an improving one makes progress)
            if (first_wait_s is not None and shapes and delay == 0.0 and self._cands
                    and self._search_deadline is not None and last is not None
                    and now + (now - last) > self._search_deadline):
                self.record.st_pruned += 1
                self._cut = True
                return self._best_candidate()[1]  # anytime: the best so far
            if delay == 0.0:
                self._tried.append((np.asarray(path), list(shapes)))
            # The same path, squares and start again (the long waits on a path already tried):
            # the same nominal motion and the same check, not smoothed and checked again.
            key = (t_start, state.x, state.y, state.theta, state.v, state.omega, delay,
                   np.asarray(path, dtype=float).tobytes(), tuple(id(s) for s in shapes))
            memo = self._nominals.get(key)
            if memo is None or any(a is not b for a, b in zip(memo[2], shapes, strict=True)):
                memo = (nominal_fn(path, shapes, delay), None, list(shapes))
                self._nominals[key] = memo
            nominal = memo[0]
            wait = max_wait_s
            if delay == 0.0 and _followable(nominal):
                self._floor = min(self._floor, nominal.t_end)
            if first_wait_s is not None and delay == 0.0 and self._preds:
                if self._cands and _followable(nominal):
                    # a candidate to beat (the path in use, the motion in use, a path timed)
                    best = self._best_candidate()
                    if nominal.t_end >= best[0] - 1e-9:
                        self.record.st_pruned += 1
                        return best[1]  # free: the loop stops, the earliest candidate wins
                    wait = min(first_wait_s, best[0] - nominal.t_end)
                elif not shapes:
                    wait = first_wait_s
            if memo[1] is None and nominal.certified_free and delay == 0.0 and self._preds:
                memo = (nominal, verify(nominal, self._preds, spec.radius, margin=cfg.margin,
                                        t_until=nominal.t_end) is None, memo[2])
                self._nominals[key] = memo
            free = memo[1]
            if not _followable(nominal):
                # A best effort that cuts an obstacle, or that the robot cannot take up from its
                # state (e.g. one starting at 0.03 m/s while the robot drives at 1.5 m/s):
                # never a candidate, its check would not be about the motion executed.
                return nominal
            if delay > 0.0 or not self._preds:
                if not self._preds:
                    self._cands.append((nominal.t_end, nominal, np.asarray(path), list(shapes)))
                return nominal
            if free:
                # Already free as timed for the static world (time-optimal): nothing to re-time.
                self._cands.append((nominal.t_end, nominal, np.asarray(path), list(shapes)))
                return nominal
            res = retime(nominal, self._preds, spec, margin=cfg.margin, max_wait_s=wait,
                         target_dt=self.lattice_dt_s, free_tail_m=spec.arrival_radius,
                         rows=self._rows)
            tr = res.trajectory
            if tr is None:
                return nominal
            if verify(tr, self._preds, spec.radius, margin=cfg.margin,
                      t_until=tr.t_end - self._tail_time(tr)) is not None:
                return nominal
            self._cands.append((tr.t_end, tr, np.asarray(path), list(shapes)))
            # Taken at once (the loop stops) if it is about as fast as the untimed motion;
            # otherwise kept while the loop looks for a detour that arrives earlier.
            return tr if res.delay_s <= self.accept_s else nominal

        return build

    def _out_of_budget(self, squares: Sequence[Any]) -> bool:
        """Before a detour search (the loop's ``stop``): True, and the loop stops, when a path
        is timed already and another search and build, costing what the last one did (or the
        call so far, after its first), would end after the budget; the same anytime rule as
        :meth:`_timed_fn`'s, applied before the search instead of after it. The squares are
        kept: an improvement call goes on from them."""
        deadline, last = self._search_deadline, self._last_build
        if deadline is None or last is None or not self._cands:
            return False
        now = time.perf_counter()
        cost = self._last_cycle if self._last_cycle is not None else now - self._call_start
        if now + cost <= deadline:
            return False
        self.record.st_pruned += 1
        self._cut = True
        self._stopped_at = list(squares)
        return True

    def _is_candidate(self, motion: object) -> bool:
        """True for a timed candidate of this replanning (checked free when it was timed)."""
        return any(c[1] is motion for c in self._cands)

    def _best_candidate(self) -> tuple[float, Trajectory, np.ndarray, list[Shape]]:
        """The timed candidate of this replanning that arrives first (the first among equals)."""
        return min(self._cands, key=lambda c: c[0])

    def _tail_time(self, tr: Trajectory) -> float:
        """Time [s] the motion spends inside ``spec.arrival_radius`` at its end (run over)."""
        seg = tr.segments[-1]
        plan = getattr(seg, "plan", None)
        if plan is None:
            return 0.0
        s_in = plan.s[-1] - self.spec.arrival_radius
        i = int(np.searchsorted(plan.s, s_in))
        return max(0.0, float(plan.t[-1] - plan.t[min(i, len(plan.t) - 1)]))

    # --- planning --------------------------------------------------------------------------------
    def _replan(self, obs: Observation, preds: list[PredictedObstacle], reason: str) -> None:
        """One replanning call, booked whole (:meth:`~ReplanningAgent._whole_call`). Until
        2026-12-03 only the loop and the re-timing were booked: on the recorded crowds
        (``tracked``) the guard's fallback ranking made calls 10-20 times longer than reported."""
        self._whole_call(obs, lambda: self._replan_call(obs, preds, reason))

    def _replan_call(self, obs: Observation, preds: list[PredictedObstacle], reason: str) -> None:
        # BIT* draws from this call's own generator, spawned whether or not the call searches:
        # a call that needs no search leaves the later calls' samples as they were.
        rng = self.rng.spawn(1)[0]
        dt, d, t_ready, state = self._begin_replan(obs)
        t = obs.t
        observed = preds
        preds, safe = self._split(preds, np.array([state.x, state.y]), t_ready)
        uncertain = safe is not None
        # Improving: the motion in use (checked free just before) is the candidate to beat.
        inc = self.trajectory if reason == IMPROVE and self._path is not None else None
        self._cands = [] if inc is None else [(inc.t_end, inc, np.asarray(self._path), list(self._shapes))]
        self._improve_left = self._improve_left - 1 if inc is not None else 0
        self._cut = False
        self._floor = self._floor if inc is not None else math.inf
        self._tried = []
        self._preds = list(preds)
        self._nominals = {}
        w0 = self._call_start = time.perf_counter()
        budget = self.search_budget_s if inc is None else self.improve_budget_s
        self._search_deadline = None if budget is None else w0 + budget
        self._last_build = self._last_cycle = self._stopped_at = None
        res: SequentialResult | None = None
        if inc is None and self._trapped(preds, state, t_ready):
            # every motion from the state meets a planned disc: no search can time one
            res = SequentialResult("collision_predicted", np.zeros((0, 2)), None, [], 0)
        if res is None and inc is None and self._path is not None and len(self._path) >= 2:
            # First the path in use, from where the robot will be: no new search if it can be
            # timed within patience_s.
            rest = remaining_path(self._path, np.array([state.x, state.y]))
            out = self._timed_fn(state, t_ready, self.patience_s)(rest, self._shapes, 0.0)
            self._tried = []
            if self._cands and out is self._cands[-1][1]:
                # as fast as untimed (within accept_s): no search; a slower timing stays a
                # candidate against the loop's paths below
                res = SequentialResult("collision_free", rest, out, [], 0)
        # Long waits are useless with predictions that end before patience_s (nothing is left
        # to wait for), and not tried among uncertain discs (tracked): they end at the horizon,
        # about a second after the waits of patience_s that the loop's timings allowed, and a
        # long wait found a motion in 3 of 1,114 such calls in the crowds, in none of 621 on
        # DynaBARN (docs/spacetime.md).
        long_ok = not (any(o.growth is not None for o in observed)
                       or (uncertain and self.prediction_horizon_s is not None
                           and self.patience_s >= self.prediction_horizon_s))
        long_bound = self.branch_and_bound and not uncertain
        cap = self._loop_cap(observed)
        if res is None:
            # With certain predictions, branch and bound over the loop's paths: the shortest
            # timed with long waits first, the detours only while they can arrive earlier (see
            # _timed_fn). With uncertain ones (tracked) every path of the loop is timed within
            # patience_s, as before: there the bound measured +2 reached but +4 robot-caused
            # collisions in 120 DynaBARN runs (docs/spacetime.md).
            res = self.loop.replan(np.array([state.x, state.y]),
                                   np.asarray(self.spec.goal, dtype=float), preds, t,
                                   self._timed_fn(state, t_ready, self.patience_s,
                                                  first_wait_s=self.max_wait_s if long_bound
                                                  else None),
                                   chain=self._chain if inc is not None else (),
                                   verified=self._is_candidate,
                                   stop=lambda sq: ((cap is not None and len(sq) >= cap)
                                                    or (long_bound and self._out_of_budget(sq))),
                                   rng=rng)
        # an improvement call goes on where the budget cut this one: before a search (the
        # squares it would have searched among) or before a timing (the path's squares)
        self._chain = []
        if self._cut:
            self._chain = (self._stopped_at if self._stopped_at is not None
                           else list(res.virtual_obstacles))
        if not self._cands and self._tried and long_ok:
            # No timing at all: allow long waits on the shortest path (unless the loop gave it
            # them already) and on the last detour.
            build = self._timed_fn(state, t_ready, self.max_wait_s)
            for i in sorted({0, len(self._tried) - 1} - ({0} if long_bound else set())):
                build(*self._tried[i], 0.0)
        motion: Trajectory | None = None
        path, shapes = res.path, [v.shape for v in res.virtual_obstacles]
        if self._cands:
            _, motion, path, shapes = self._best_candidate()
            if inc is not None and motion.t_end > inc.t_end - self.lattice_dt_s:
                motion = inc  # not a lattice step earlier: not worth a new reference
        elif res.collision_free and res.motion is not None and _followable(res.motion):
            motion = res.motion  # type: ignore[assignment]
        wall = time.perf_counter() - w0
        self._record_replan(t, wall, res, reason)
        self.record.st_candidates.append(len(self._cands))
        if motion is not None and motion is inc:
            return  # kept (checked free before this call)
        # Late: the computed motion starts in the past. Re-time from the state the robot will
        # really have, on the same path (no new search).
        # the predictions end as observed (twist, tracked), or on announced_horizon_s
        ends_s = (self.prediction_horizon_s if any(o.until < math.inf for o in observed)
                  else self.announced_horizon_s)
        t_switch, motion = self._take_up(
            obs, t_ready, wall, d, dt, motion,
            lambda state, t_s: self._retime_path(state, t_s, path, shapes, ends_s))
        if (safe is not None and self._guarded_by(safe)) or (
                self.passive_safety and any(o.until < math.inf for o in observed)):
            full, planned, proposed = (preds if safe is None else safe), t_switch, motion

            def guarded(t_s: float) -> tuple[Any, bool]:
                m = proposed if t_s == planned or proposed is None else self._retime_path(
                    self._state_at(obs, t_s), t_s, path, shapes, ends_s)
                kind, tr = self._guard(obs, t_s, m, full, observed, res.status)
                return (kind, tr), kind != "keep"

            t_switch, (kind, motion) = self._decide_in_time(
                obs, t_switch, dt, guarded, (self.record.fallbacks, self.guard.decisions))
            if kind == "keep":
                return
            if kind != "motion":
                self._fallback_active = True
                self.pending = (t_switch, motion)
                return
        if motion is None:
            # (checked at least the fallback horizon ahead: a motion that has ended leaves the
            # robot standing at its end, which is not free when an obstacle is to pass there)
            if (cur := self._in_use()) is not None and verify(
                    cur, preds, self.spec.radius, t_from=t_switch,
                    t_until=max(min(cur.t_end, t_switch + _CHECK_HORIZON_S),
                                t_switch + self.guard.config.horizon_s)) is None:
                return  # the current reference is still free: keep it, try again later

            def fallback(t_s: float) -> tuple[Any, bool]:
                fb = self._fallback(obs, t_s, preds, res.status)
                return fb, fb is not None

            t_switch, fb = self._decide_in_time(obs, t_switch, dt, fallback,
                                                (self.record.fallbacks,))
            if fb is None:
                return  # keeping the motion in use ranks best
            self._fallback_active = True
            self.pending = (t_switch, fb)
            return
        self._fallback_active = False
        self._improve_left = ((self._improve_left if inc is not None else self.improve_calls)
                              if long_bound and all(o.until == math.inf for o in observed)
                              and motion.t_end - self._floor > self.accept_s else 0)
        self._path, self._shapes = np.asarray(path), list(shapes)
        self.record.st_timed += int(motion.kind.startswith(ST_PREFIX))
        self.record.st_waits_s.append(float(motion.info.get("wait_s", 0.0)))
        self.stats.plans.append({"t": t, "t_start": t_switch, "path": np.asarray(path).tolist(),
                                 "status": res.status, "kind": motion.kind,
                                 "virtual_obstacles": len(res.virtual_obstacles),
                                 "arrival_s": float(motion.t_end)})
        self.pending = (t_switch, motion)

    def _retime_path(self, state: RobotState, t_switch: float, path: np.ndarray,
                     shapes: list[Shape], ends_s: float | None) -> Trajectory | None:
        """The timed motion along ``path`` from ``state`` at ``t_switch`` [s], if one exists;
        when the predictions timed against end (``ends_s`` [s] after they were made), with
        waits of at most ``ends_s + patience_s``: nothing is left to wait for after that."""
        if not len(path):
            return None
        self._cands = []
        wait = self.max_wait_s
        if ends_s is not None and any(o.until < math.inf for o in self._preds):
            wait = min(wait, ends_s + self.patience_s)
        self._timed_fn(state, t_switch, wait)(np.asarray(path), shapes, 0.0)
        return self._cands[0][1] if self._cands else None

    def _check(self, obs: Observation, preds: list[PredictedObstacle]) -> None:
        t = obs.t
        if self._requested is not None and t - self._last_replan >= self._period() - 1e-9:
            # e.g. an obstacle left its predicted tube (at most one replanning a check period)
            reason, self._requested = self._requested, None
            self._observe_check(obs, preds)
            if not self._arrived(obs, self.trajectory):  # type: ignore[arg-type]
                self._replan(obs, preds, reason)
            return
        new = self._observe_check(obs, preds)
        traj = self.trajectory
        assert traj is not None
        spec = self.spec
        if self._arrived(obs, traj):
            return
        if ((traj.kind == MotionKind.FALLBACK_HOLD or self._fallback_active)
                and t - self._last_replan >= self.min_replan_interval_s):
            self._replan(obs, preds, "holding")
            return
        # ``_replan`` is given the predictions as observed (``preds``): it splits them itself,
        # so that its guard checks the full discs, not the capped ones planned against.
        planned, safe = self._split(preds, np.array([obs.robot.x, obs.robot.y]), t)
        reach = self._reach(preds, t, obs.robot)
        if ((safe is not None and self._guarded_by(safe)) or reach) and not self.guard.still_safe(
                traj, planned if safe is None else safe, t, self._period() + 0.1, reach):
            self._replan(obs, preds, "safety: the motion in use can no longer stop in time")
            return
        t_until = min(max(traj.t_end, t) + 1.0, t + _CHECK_HORIZON_S)
        end = traj.positions(np.array([traj.t_end]))[0]
        if math.hypot(end[0] - spec.goal[0], end[1] - spec.goal[1]) <= spec.arrival_radius:
            # the run is over inside the goal tolerance: checked as planned (_timed_fn), and
            # as the guard checks it (until arrival)
            t_until = min(traj.t_end - self._tail_time(traj), self.guard.arrival(traj, t))
        hit = verify(traj, planned, spec.radius, t_from=t, t_until=max(t_until, t),
                     margin=0.5 * self.config.margin)
        if hit is None:
            if self._improve_left > 0:
                self._replan(obs, preds, IMPROVE)
            return
        urgent = hit.t - t < self.urgent_s
        if not urgent and not new and t - self._last_replan < self.min_replan_interval_s:
            return
        self._replan(obs, preds, f"collision with {hit.obstacle} predicted at {hit.t:.2f} s")
