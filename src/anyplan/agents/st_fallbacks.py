"""What ``st-bitstar`` executes when a planned motion may not start: the safety guard's decision
and the fallbacks (``docs/perception.md``, "st-bitstar when the future is unknown").

:class:`SafetyDecisions` is the agent's part that decides: the safety invariant (free to rest,
or stoppable) against the full uncertain discs of the obstacles the robot does not outrun, a
stoppable motion giving way to a freer evasion, and the best fallback of
:func:`~anyplan.agents.evasion.best_fallback` when nothing planned may start. The candidates
and their ranking are :mod:`anyplan.agents.evasion`'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from anyplan.agents.base import Observation
from anyplan.agents.evasion import FallbackRanker, best_fallback, freer_evasion
from anyplan.agents.safety import finite_or_none, reachable_discs
from anyplan.prediction.base import PredictedObstacle
from anyplan.trajectory.kinds import MotionKind
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world.robot import RobotState

__all__ = ["SafetyDecisions"]


class SafetyDecisions:
    """The safety decisions of an ``st-bitstar`` agent (a mixin: it reads the agent's ``spec``,
    ``obstacles``, ``guard``, ``reference``, ``_period``, ``trajectory``, ``record``,
    ``passive_safety``, ``reach_extra_mps``, ``reach_min_speed_mps``, ``swerves``, ``_capped``,
    ``_state_at`` and ``_in_use``)."""

    spec: Any
    obstacles: Any
    guard: Any
    reference: Any
    record: Any
    trajectory: Trajectory | None
    passive_safety: bool
    reach_extra_mps: float
    reach_min_speed_mps: float
    swerves: bool
    _capped: Callable[[list[PredictedObstacle]], list[PredictedObstacle]]  # PlanningPredictions'
    _in_full: Callable[[PredictedObstacle], bool]  # PlanningPredictions'
    _state_at: Callable[[Observation, float], RobotState]  # ReplanningAgent's
    _in_use: Callable[[], Trajectory | None]  # ReplanningAgent's: the motion in use, to keep
    _period: Callable[[], float]  # the check period in force [s] (SpaceTimeBITStarAgent's)

    def _guard(self, obs: Observation, t_switch: float, motion: Trajectory | None,
               safe: list[PredictedObstacle], observed: list[PredictedObstacle],
               reason: str) -> tuple[str, Trajectory | None]:
        """The safety invariant against the predictions ``safe`` (the full uncertain discs of
        the obstacles the robot does not outrun, :meth:`PlanningPredictions._split`): start
        ``motion`` at ``t_switch`` [s] if it is free to rest or stoppable there, else keep the
        current motion if it still is, else the best of :meth:`_evasions`; a stoppable one
        gives way to an evasion that is free where it is not (``freer_evasion``). With
        ``passive_safety``, both must also be passively safe against the reachable discs of
        the ``observed`` predictions (:meth:`_reach`). Returns the decision's kind and
        trajectory."""
        commit = self._period() + max(t_switch - obs.t, 0.0)
        state = self._state_at(obs, t_switch)
        reach = self._reach(observed, t_switch, state)
        # the guard's own fallback is not asked for: _evasions ranks its candidates with more
        dec = self.guard.decide(t_switch, motion, self._in_use(), state, safe, commit, reach,
                                fallback=False)
        if dec.kind in ("motion", "keep"):
            if dec.rule != "stoppable":
                return dec.kind, dec.trajectory
            # stoppable, but struck later: it may stand the robot where the obstacle passes
            better = freer_evasion(self._ranker(), t_switch, state, safe, self._capped(safe),
                                   dec.trajectory, reach)
            if better is None:
                return dec.kind, dec.trajectory
            (kind, tr, clear), why = better, (f"{dec.kind}: stoppable, collision predicted at "
                                              f"{dec.first_collision_s:.2f} s; an evasion is free")
        else:
            (kind, tr, clear), why = self._evasions(t_switch, state, safe, motion,
                                                    self._in_use(), reach), dec.reason or reason
        self.record.fallbacks.append({"t": float(obs.t), "kind": kind, "reason": why,
                                      "predicted_clearance_m": finite_or_none(clear)})
        return kind, tr

    def _reach(self, observed: list[PredictedObstacle], t: float,
               state: RobotState) -> list[PredictedObstacle]:
        """The reachable discs at ``t`` [s] of the ``observed`` predictions whose future is
        unknown (a horizon, no announced motion), with ``passive_safety``; else none."""
        unknown = [o for o in observed if o.until < math.inf] if self.passive_safety else []
        if not unknown:
            return []
        return reachable_discs(unknown, t, np.array([state.x, state.y]), state.theta,
                               self.reach_extra_mps, self.guard.config.horizon_s,
                               self.reach_min_speed_mps)

    def _evasions(self, t: float, state: RobotState, safe: list[PredictedObstacle],
                  motion: Trajectory | None, current: Trajectory | None = None,
                  reach: Sequence[PredictedObstacle] = (), outrun: bool = False
                  ) -> tuple[str, Any, float]:
        """The best fallback from ``state`` at ``t`` [s], with its clearance [m]:
        :func:`anyplan.agents.evasion.best_fallback` against the full predictions ``safe``
        and the capped ones planned against, ``reach`` with ``passive_safety``; ``outrun``:
        the robot outruns every uncertain obstacle (swerves offered, :class:`FallbackRanker`)."""
        return best_fallback(self._ranker(outrun), t, state, safe, self._capped(safe), motion,
                             current, reach)

    def _fallback_rank(self, tr: Any, t: float, full: list[PredictedObstacle],
                       planned: list[PredictedObstacle], reach: Sequence[PredictedObstacle] = ()
                       ) -> tuple[tuple[Any, ...], float]:
        """The ranking key of fallback ``tr`` (:meth:`FallbackRanker.rank
        <anyplan.agents.evasion.FallbackRanker.rank>`) and its clearance [m]."""
        return self._ranker().rank(tr, t, full, planned, reach)

    def _ranker(self, outrun: bool = False) -> FallbackRanker:
        return FallbackRanker(self.spec, self.obstacles, self.guard, self._period(), self.swerves,
                              outrun)

    def _fallback(self, obs: Observation, t_switch: float, preds: list[PredictedObstacle],
                  reason: str) -> Trajectory | None:
        """No motion was found and the one in use is no longer free, and no guard decides
        (certain predictions, or uncertain ones of obstacles the robot all outruns): the best
        fallback (brake or hold, turn away, back off, evade, swerve, or keep the motion in use
        when strictly better; :func:`~anyplan.agents.evasion.best_fallback`), ranked by
        predicted clearance, never a blind brake. Before, braking on the current reference was
        the only fallback: in DynaBARN world 58 (``twist``) the robot braked straight into the path of an
        obstacle that had just turned, its collision predicted 0.9 s ahead, while turning away
        was free. Returns None to keep the motion in use."""
        state = self._state_at(obs, t_switch)
        if not preds:
            tr, _ = self.reference.hold(state, t_switch, 1e4, kind=MotionKind.FALLBACK_HOLD,
                                        stop_rotation=False)
            kind, clear = "brake-hold", math.inf
        else:
            # the guard did not decide: with uncertain discs, the robot outruns every obstacle
            # (none is checked in full: PlanningPredictions._in_full), and swerves are offered as
            # among certain ones
            outrun = not any(self._in_full(o) for o in preds)
            kind, tr, clear = self._evasions(t_switch, state, preds, None, self._in_use(),
                                             outrun=outrun)
        if kind == "keep":
            return None
        self.record.fallbacks.append(
            {"t": float(obs.t), "kind": kind, "reason": reason,
             "predicted_clearance_m": finite_or_none(clear)})
        return tr
