"""What ``st-bitstar`` plans against, and what its safety guard checks, from the predictions.

Certain predictions (announced motions; exact twists with ``guard="growth"``) are planned
against in full, announced motions up to ``announced_horizon_s`` ahead. Uncertain ones
(tracked: discs that grow with the horizon) are planned and timed against discs whose extra
radius is capped at ``plan_extra_m``, on a receding horizon, while the safety guard checks the
full growth of the obstacles the robot does not outrun (``_outruns``; ``docs/perception.md``,
"st-bitstar when the future is unknown"). When one planned disc holds every place the robot
can reach, no search is made (``_trapped``). What the predictions are also sets the check
period in force (``_period``) and, while some future is extrapolated, the cap on the loop's
paths (``_loop_cap``). :class:`PlanningPredictions` is the agent's part that makes these views.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from anyplan.prediction.base import PredictedObstacle, RadiusGrowth, centres_of
from anyplan.prediction.trap import first_trap
from anyplan.world.robot import RobotState

__all__ = ["PlanningPredictions"]

#: Gap [m] a predicted disc that already holds the robot is shrunk to (``_planning_preds``).
_INSIDE_GAP_M = 0.02
#: How far ahead [s] a trap is looked for (the robot's reach outgrows every disc well before).
_TRAP_HORIZON_S = 10.0


class PlanningPredictions:
    """The views of the predictions an ``st-bitstar`` agent plans with (a mixin: it reads the
    agent's ``spec``, ``config.margin``, ``guard_mode``, ``plan_extra_m``,
    ``outrun_margin_mps``, ``announced_horizon_s`` and ``record``)."""

    spec: Any
    config: Any
    record: Any
    guard_mode: str
    plan_extra_m: float | None
    outrun_margin_mps: float | None
    announced_horizon_s: float | None
    extrapolated_iterations: int | None
    twist_check_period_s: float | None
    check_period_s: float
    _exact_twists: bool
    #: :meth:`_capped`'s answers for the latest predictions: (cap [m], {id of a prediction:
    #: (it, its capped disc)}).
    _capped_memo: tuple[float, dict[int, tuple[PredictedObstacle, PredictedObstacle]]] | None = None

    def _planning_preds(self, preds: list[PredictedObstacle], p: np.ndarray,
                        t: float) -> list[PredictedObstacle]:
        """The predictions planned against from the robot's position ``p`` at ``t`` [s].

        Unchanged unless some prediction has a horizon (``until``: no announced motion). Then
        (1) a prediction that cannot come within reach of the robot before its horizon (both at
        their top speeds) is left out, and (2) a predicted disc that already holds the robot at
        ``t`` is shrunk to leave it just outside (by ``_INSIDE_GAP_M``): being inside is not the
        robot's doing, and a motion that leaves the disc must not look colliding at its start
        (holding still, or going deeper, still does as the disc comes on or grows).
        """
        if not preds or all(o.until == math.inf for o in preds):
            return preds  # the same object: certain predictions
        r, v, m = self.spec.radius, self.spec.v_max, self.config.margin
        out = []
        centres = centres_of(preds, np.array([t]))[:, 0]
        for o, q in zip(preds, centres, strict=True):
            if o.until < t:
                continue
            d = float(np.hypot(*(q - p)))
            if d - (v + o.max_speed) * (o.until - t) - r - m - o.max_radius > 0.0:
                continue  # out of reach within the horizon
            gap = d - r - m - float(o.radius_at(t))
            if gap < _INSIDE_GAP_M:
                cut = _INSIDE_GAP_M - gap
                base = max(o.radius - cut, 0.0)
                g = o.growth
                if g is not None and cut > o.radius - base:
                    g = RadiusGrowth(g.t0, g.taus, np.maximum(g.values - (cut - o.radius + base), 0.0))
                o = PredictedObstacle(o.name, base, o.motion, g, o.until)
                self.record.inside_discs = (self.record.inside_discs or 0) + 1
            out.append(o)
        return out

    def _split(self, preds: list[PredictedObstacle], p: np.ndarray, t: float
               ) -> tuple[list[PredictedObstacle], list[PredictedObstacle] | None]:
        """The predictions planned and timed against from ``p`` at ``t`` [s], and those the
        safety guard checks (None when every prediction is certain: no guard): the full discs,
        but the planned (capped) one of an obstacle the robot outruns (:meth:`_outruns`)."""
        announced = bool(preds) and all(o.until == math.inf for o in preds)
        preds = self._certain(preds)
        if announced:
            return self._announced(preds, t), None
        safe = self._planning_preds(preds, p, t)
        if safe is preds:
            return preds, None
        planned = self._capped(safe)
        if self.outrun_margin_mps is not None:
            safe = [c if self._outruns(o) else o for o, c in zip(safe, planned, strict=True)]
        return planned, safe

    def _outruns(self, o: PredictedObstacle) -> bool:
        """Whether the robot outruns the uncertain prediction ``o``: its top speed exceeds the
        obstacle's predicted speed by more than ``outrun_margin_mps`` (None: never). Fleeing,
        the robot then leaves the disc's growth behind within the horizon (the default, 1/3
        m/s, gains the 1 m growth cap in the 3 s horizon), so a late reaction to a turn, at its
        next check, is in time: the guard checks the disc planned against, not the full one."""
        m = self.outrun_margin_mps
        return (m is not None and o.growth is not None
                and o.max_speed < self.spec.v_max - m)

    def _announced(self, preds: list[PredictedObstacle], t: float) -> list[PredictedObstacle]:
        """Announced motions on the receding horizon ``announced_horizon_s`` from ``t`` [s]:
        each prediction ends there (``until``), so that a timing no longer has to thread a
        long path through every obstacle's whole future (the motion in use is checked again
        at every check, each time up to the horizon from then). None: in full."""
        h = self.announced_horizon_s
        if h is None:
            return preds
        return [dataclasses.replace(o, until=t + h) for o in preds]

    def _certain(self, preds: list[PredictedObstacle]) -> list[PredictedObstacle]:
        """With ``guard="growth"``, exact-twist predictions (no uncertain disc: ``twist``
        perception) are planned against in full, as announced ones (no horizon): measured on
        DynaBARN, the receding horizon helped only with uncertain discs."""
        if (self.guard_mode != "growth" or not preds
                or any(o.growth is not None or o.until == math.inf for o in preds)):
            return preds
        return [dataclasses.replace(o, until=math.inf) for o in preds]

    def _guarded_by(self, safe: list[PredictedObstacle]) -> bool:
        """Whether the safety guard decides what starts: predictions with uncertain discs of
        obstacles the robot does not outrun (``guard="growth"``, tracked perception), any with
        a horizon (``"horizon"``), or never."""
        if self.guard_mode == "horizon":
            return True
        return self.guard_mode == "growth" and any(self._in_full(o) for o in safe)

    def _in_full(self, o: PredictedObstacle) -> bool:
        """Whether the guard checks the full growth of ``o``: uncertain, and not outrun."""
        return o.growth is not None and not self._outruns(o)

    def _capped(self, preds: list[PredictedObstacle]) -> list[PredictedObstacle]:
        """``preds`` with their extra radius capped at ``plan_extra_m`` (what paths are planned
        and timed against; the safety guard keeps the full growth)."""
        c = self.plan_extra_m
        if c is None:
            return preds
        # Each prediction's capped disc is kept while its predictions are in use: the safety
        # guard caps the predictions the planning capped, some of them capped already
        # (:meth:`_split`), and gets the same objects, so the contact searches' caches of
        # prediction sets serve both (the entry holds the prediction, so its ``id`` is live).
        seen = self._capped_memo[1] if self._capped_memo and self._capped_memo[0] == c else {}
        out, fresh, hits = [], {}, 0
        for o in preds:
            if o.growth is None or o.growth.max_extra <= c:
                out.append(o)
                continue
            old = seen.get(id(o))
            if old is not None and old[0] is o:
                hits += 1
                capped = old[1]
            else:
                capped = PredictedObstacle(o.name, o.radius, o.motion, o.growth.capped(c), o.until)
            fresh[id(o)] = (o, capped)
            out.append(capped)
        # new predictions (no hit) replace the kept ones; the same ones add to them
        self._capped_memo = (c, {**seen, **fresh} if hits or not fresh else fresh)
        return out

    def _trapped(self, preds: list[PredictedObstacle], state: RobotState, t: float) -> bool:
        """Whether a planned disc holds every place the robot can reach from ``state`` at
        ``t`` [s] (:func:`~anyplan.prediction.trap.first_trap`, against the contact distance
        of the candidates' check) before any motion could end near the goal: then no motion
        from there is free, and every search and timing would be in vain (counted in
        ``st_trapped``)."""
        spec = self.spec
        to_goal = math.hypot(spec.goal[0] - state.x, spec.goal[1] - state.y)
        trap = first_trap(preds, (state.x, state.y), state.v, t, spec.radius, spec.v_max,
                          spec.a_max, self.config.margin, _TRAP_HORIZON_S,
                          reach_cap_m=to_goal - spec.arrival_radius)
        self.record.st_trapped += trap is not None
        return trap is not None

    def _note_predictions(self, preds: list[PredictedObstacle]) -> None:
        """Whether the obstacles in view are predicted from exact twists (``twist``: their
        predictions end, without uncertain discs), from the latest step that observed any."""
        if preds:
            self._exact_twists = all(o.until < math.inf and o.growth is None for o in preds)

    def _period(self) -> float:
        """The check period in force [s]: ``twist_check_period_s`` while the obstacles in view
        are predicted from exact twists, else ``check_period_s``."""
        if self._exact_twists and self.twist_check_period_s is not None:
            return self.twist_check_period_s
        return self.check_period_s

    def _loop_cap(self, observed: list[PredictedObstacle]) -> int | None:
        """The cap on the loop's paths in this replanning: ``extrapolated_iterations`` while an
        obstacle in view has no announced motion (its prediction ends: ``twist``, ``tracked``),
        else None (the loop's own ``max_iterations``). A deep search for detours threads paths
        between guesses; measured, it bought nothing there (``docs/perception.md``)."""
        if any(o.until < math.inf for o in observed):
            return self.extrapolated_iterations
        return None
