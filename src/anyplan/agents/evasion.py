"""Fallbacks of ``st-bitstar``: the candidates when no planned motion may start, and their ranking.

The safety guard (:mod:`anyplan.agents.safety`) offers hold or brake, turn away and back off;
``st-bitstar`` adds the proposed motion, evasions in 8 directions (straight after braking and,
when the robot moves, a smooth curve from its speed and heading) and, last, keeping the motion
in use, and ranks them all by :meth:`FallbackRanker.rank`. ``docs/perception.md``,
"Fallbacks", has the ranking's reasons and measurements.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from anyplan.agents.safety import Escape, SafetyGuard
from anyplan.geometry.collision import ObstacleSet
from anyplan.prediction.base import PredictedObstacle
from anyplan.prediction.collision import PredictedCollision, first_collision, predict_collisions
from anyplan.trajectory.kinds import MotionKind
from anyplan.trajectory.motion import plan_motion, polyline_trajectory, swerve_trajectory
from anyplan.world.robot import RobotSpec, RobotState

__all__ = ["APPROACH_TOL", "EVADE_M", "MIN_EVADE_M", "SWERVES", "SWERVE_S", "FallbackRanker",
           "approach_speed", "best_fallback", "escape_time_s", "free_length", "freer_evasion"]

#: Approach speed [m/s] at a predicted contact below which it counts as none (at rest or
#: moving away; well below the 0.05 m/s robot-caused threshold of
#: :mod:`anyplan.simulation.contact`, which a slow creep at contact would cross on execution).
APPROACH_TOL = 1e-3


#: An evasion drives v_max x 1.5 s, but at least this far [m]: a slow robot (0.4 m/s) would
#: otherwise move 0.6 m, less than the width of a person's disc plus its own.
EVADE_M = 1.5

#: Shortest evasion [m]: a direction whose free run from the robot is shorter is left out.
MIN_EVADE_M = 0.3

#: Swerves: target twists (v / v_max, omega / omega_max), each held for :data:`SWERVE_S`.
SWERVES = ((1.0, 1.0), (1.0, -1.0), (1.0, 0.5), (1.0, -0.5),
           (0.5, 1.0), (0.5, -1.0), (0.5, 0.5), (0.5, -0.5))

#: How long [s] a swerve holds its twist before braking.
SWERVE_S = 1.0

#: Bisection steps of :func:`free_length` (the length is found to ``dist / 2**6``).
_FREE_STEPS = 6


def free_length(obstacles: ObstacleSet, p0: np.ndarray, u: np.ndarray, dist: float,
                radius: float) -> float:
    """The longest run [m], at most ``dist``, that a disc of ``radius`` [m] can drive from
    ``p0`` along the unit direction ``u`` clear of ``obstacles`` (exact segment tests,
    bisection to ``dist / 64``; 0 when it cannot leave ``p0``). An evasion sideways in a
    corridor thus stops short of the wall instead of being dropped.

    Examples:
        A wall whose face is 2 m above a disc of radius 0.5 m: 1.5 m of free run, found to
        3 m / 64 from below.

        >>> from anyplan.geometry.shapes import rectangle
        >>> wall = ObstacleSet([rectangle((5.0, 2.25), (10.0, 0.5))])
        >>> d = free_length(wall, np.array([5.0, 0.0]), np.array([0.0, 1.0]), 3.0, 0.5)
        >>> 1.5 - 3.0 / 64 <= d <= 1.5
        True
    """
    if obstacles.segment_free(p0, p0 + dist * u, radius):
        return float(dist)
    if not obstacles.segment_free(p0, p0, radius):
        return 0.0
    lo, hi = 0.0, float(dist)
    for _ in range(_FREE_STEPS):
        mid = 0.5 * (lo + hi)
        if obstacles.segment_free(p0, p0 + mid * u, radius):
            lo = mid
        else:
            hi = mid
    return lo


#: Times [s] after a predicted contact at which the approach speed is taken too.
_AFTER_CONTACT_S = (0.0, 0.1, 0.2, 0.3)


def approach_speed(tr: Any, hit: PredictedCollision | None) -> float:
    """The robot's largest speed [m/s] towards the obstacle at predicted contact ``hit`` on
    ``tr`` and in the 0.3 s after it (0 without a contact, or at most :data:`APPROACH_TOL`;
    the direction is the one at contact): when every fallback is struck,
    the one that meets the obstacle at rest or moving away, not driving into it, ranks first.

    Examples:
        >>> from anyplan.trajectory.reference import HoldSegment
        >>> from anyplan.trajectory.trajectory import Trajectory
        >>> hold = Trajectory([HoldSegment(0.0, 0.0, 0.0, 0.0, 5.0)], kind="hold")
        >>> hit = PredictedCollision("O", 1.0, np.zeros(2), np.array([0.5, 0.0]), 0.2)
        >>> approach_speed(hold, hit)
        0.0
    """
    if hit is None:
        return 0.0
    u = np.asarray(hit.obstacle_position, dtype=float) - np.asarray(hit.robot_position, dtype=float)
    n = float(np.hypot(*u))
    if n < 1e-9:
        return 0.0
    a = 0.0
    # at contact and just after it (a robot that sets off at the contact drives into it too),
    # the four states in one sample
    end = max(float(tr.t_end), float(hit.t))
    _, _, th, v, _ = tr.sample(np.array([min(float(hit.t) + dt, end) for dt in _AFTER_CONTACT_S]))
    for th_k, v_k in zip(th.tolist(), v.tolist(), strict=True):
        a = max(a, v_k * (math.cos(th_k) * u[0] + math.sin(th_k) * u[1]) / n)
    return a if a > APPROACH_TOL else 0.0


class FallbackRanker:
    """Ranks fallback trajectories of a robot among predicted obstacles.

    Args:
        spec: The robot.
        obstacles: Static obstacles with walls.
        guard: The safety guard (its margin, horizon, sampling and clearance search).
        commit_s: Time [s] a fallback is followed before the robot can act again (the escape
            of the passive-safety check).
        swerves: Offer the :data:`SWERVES` too (arcs entered at the robot's speed, then a
            brake) when no prediction is uncertain (exact twists, announced motions), or when
            ``outrun``.
        outrun: The robot outruns every uncertain obstacle of the predictions ranked against
            (``st-bitstar``'s guard does not decide): swerves as among certain predictions.
    """

    def __init__(self, spec: RobotSpec, obstacles: ObstacleSet, guard: SafetyGuard,
                 commit_s: float, swerves: bool = False, outrun: bool = False) -> None:
        self.swerves = bool(swerves)
        self.outrun = bool(outrun)
        self.spec = spec
        self.obstacles = obstacles
        self.guard = guard
        self.commit_s = float(commit_s)
        #: A predicted contact later than this [s] leaves the robot time to decide again and
        #: still come to rest before it: one check period on the candidate, braking from top
        #: speed, and the next decision's own check period (issue 10's invariant).
        self.react_s = 2.0 * self.commit_s + spec.v_max / max(spec.a_max, 1e-9)
        #: The full discs of the last ranking: (their list, its length, the first disc of each
        #: name, their largest speed bound [m/s] once asked for); the list is not changed
        #: while it is ranked against.
        self._full_memo: tuple[Sequence[PredictedObstacle], int, dict[str, PredictedObstacle],
                               float | None] | None = None

    def rank(self, tr: Any, t: float, full: Sequence[PredictedObstacle],
             planned: Sequence[PredictedObstacle], reach: Sequence[PredictedObstacle] = ()
             ) -> tuple[tuple[Any, ...], float]:
        """The ranking key of fallback ``tr`` from ``t`` [s] (larger is better) and its
        clearance [m] against the ``full`` discs over the guard's horizon.

        Best first: clear of the static obstacles (braking straight ahead beside a wall may
        not be); passively safe against ``reach`` (only when given:
        :func:`~anyplan.agents.safety.reachable_discs`; among those that are not, the one
        whose escape is at rest soonest); free over the horizon against the
        full discs; then free over it against the ``planned`` (capped) discs; then, when the
        planned discs strike it within :attr:`react_s`, met at rest or moving away rather than
        driving into the obstacle, and into every other obstacle met within that time
        (:meth:`_approach`); then the latest first contact
        against the planned discs; then not a swerve (a swerve wins on none of these ties:
        a robot with nothing to escape does not set off on an arc); then the largest
        clearance against the full discs. A hold
        the planned discs run into thus loses to a motion they leave free (standing where an
        obstacle passes is a collision too), a short drive that stops just before an obstacle
        arrives does not beat a hold struck later, and a hold struck soon does not beat driving
        on struck later than :attr:`react_s` (at the next decision the robot can still stop
        short of that contact; the approach speed of so distant a contact says nothing of what
        the robot will do).
        """
        key = _Key(self, tr, t, full, planned, reach)
        clear = key.clearance()  # computed first: the key's third part then reads it
        return (*key.head(), clear), clear

    def _passive(self, tr: Any, t: float, reach: Sequence[PredictedObstacle]) -> tuple[bool, float]:
        """The second part of :meth:`rank`'s key: ``tr`` passively safe against ``reach``
        (True without it), or else how soon [s] its escape is at rest."""
        if not reach:
            return True, 0.0
        cfg, r = self.guard.config, self.spec.radius
        esc = Escape(tr, t + self.commit_s, self.spec, self.obstacles, r)
        ok = first_collision(esc, reach, r, t_from=t, t_until=max(esc.t_rest, t),
                             margin=cfg.margin, sample_dt=cfg.sample_dt) is None
        # none passively safe: the one at rest soonest (the least exposure while moving)
        return ok, 0.0 if ok else -round(esc.t_rest - t, 2)

    def _approach(self, tr: Any, t: float, hit: PredictedCollision,
                  planned: Sequence[PredictedObstacle]) -> float:
        """The largest of the robot's approach speeds [m/s] (:func:`approach_speed`) at the
        first contact ``hit`` and at the first contact with every other obstacle that
        ``planned`` predicts on ``tr`` within :attr:`react_s` of ``t`` [s]. Not the first
        contact's alone: in a crowd one person may graze every candidate first (within the
        margin) while a swerve then drives into another who stands in its way (UCY zara01,
        dense overlay, window 11, ``oracle``, seed 2: the robot drove into a standing person
        it knew of, ranked by its approach to the one who grazed it)."""
        cfg = self.guard.config
        hits = predict_collisions(tr, planned, self.spec.radius, t_from=t, t_until=t + self.react_s,
                                  margin=cfg.margin, sample_dt=cfg.sample_dt)
        return max([approach_speed(tr, hit),
                    *(approach_speed(tr, c) for c in hits if c.obstacle != hit.obstacle)])

    def _struck_within_margin(self, tr: Any, hit: PredictedCollision,
                              full: Sequence[PredictedObstacle]) -> bool:
        """True if the robot at the predicted contact ``hit`` (with a planned disc) is closer
        than the guard's margin to that obstacle's full disc at its largest, by more than the
        clearance search's accuracy (relative speed bound x its time tolerance): the
        clearance :meth:`~anyplan.agents.safety.SafetyGuard.clearance` returns, at most the
        least distance plus that accuracy, is then below the margin too."""
        cfg = self.guard.config
        memo = self._full_memo
        if memo is None or memo[0] is not full or memo[1] != len(full):
            # the first of each name, and the largest speed bound [m/s]: once per ranking (the
            # candidates of one ranking are struck by the same discs)
            first: dict[str, PredictedObstacle] = {}
            for p in full:
                first.setdefault(p.name, p)
            memo = self._full_memo = (full, len(full), first, None)
        o = memo[2].get(hit.obstacle)
        if o is None:
            return False
        gap = (math.hypot(*(np.asarray(hit.robot_position) - np.asarray(hit.obstacle_position)))
               - self.spec.radius - float(getattr(o, "max_radius", o.radius)))
        vmax = memo[3]
        if vmax is None:
            vmax = max(float(p.max_speed) for p in full)
            self._full_memo = (*memo[:3], vmax)
        speed = float(tr.max_speed) + vmax
        return gap + speed * cfg.tol < cfg.margin

    def candidates(self, t: float, state: RobotState, safe: Sequence[PredictedObstacle],
                   motion: Any = None, current: Any = None) -> list[tuple[str, Any]]:
        """``(kind, trajectory)`` of every fallback from ``state`` at ``t`` [s]: the guard's
        (hold or brake, turn away, back off), the proposed ``motion``, driving
        ``v_max x 1.5 s`` in one of 8 directions (or as far as the static obstacles let it,
        :func:`free_length`, at least :data:`MIN_EVADE_M`; with the guard's margin, or the
        clearance the robot has when it is closer to a wall) along a straight line from rest and,
        when the robot moves, along a smooth curve from its speed and heading (obstacles that
        ignore the robot are escaped by moving, not only by stopping), with :attr:`swerves` and
        no uncertain prediction in ``safe`` (or :attr:`outrun`) the :data:`SWERVES` (arcs
        entered at the robot's speed and turn rate within a_max and alpha_max, held
        :data:`SWERVE_S`, then a brake:
        :func:`~anyplan.trajectory.motion.swerve_trajectory`; a differential-drive robot that
        turns in place first stands in the obstacle's way), and, last, keeping ``current``
        (e.g. the curve that clears a wall when braking straight would not)."""
        spec, obstacles = self.spec, self.obstacles
        cands: list[tuple[str, Any]] = [(kind, tr) for kind, tr, _ in
                                        self.guard.candidates(t, state, safe)]
        if motion is not None:
            cands.append(("motion", motion))
        p0 = np.array([state.x, state.y])
        radius = spec.radius + self.guard.config.margin
        clear0 = obstacles.clearance(p0)
        if clear0 < radius:
            # closer to a wall than the margin (a path that hugged it): evasions may keep the
            # clearance the robot has now, down to its bare radius, or none would start
            radius = max(spec.radius, clear0 - 1e-9)
        dist = max(1.5 * spec.v_max, EVADE_M)
        for k in range(8):
            a = state.theta + k * math.pi / 4.0
            u = np.array([math.cos(a), math.sin(a)])
            d = free_length(obstacles, p0, u, dist, radius)
            if d < MIN_EVADE_M:
                continue
            target = p0 + d * u
            tr = polyline_trajectory(np.array([p0, target]), spec, state, t, obstacles, radius)
            if tr.certified_free:
                cands.append(("evade", tr))
            if abs(state.v) > 1e-3:
                tr = plan_motion(np.array([p0, target]), spec, state, obstacles, t,
                                 allow_turn=False)
                if tr.certified_free and tr.feasible:
                    cands.append(("evade", tr))
        if self.swerves and (self.outrun or all(getattr(o, "growth", None) is None for o in safe)):
            for v1, w1 in SWERVES:
                tr = swerve_trajectory(state, spec, obstacles, radius, t, v1 * spec.v_max,
                                       w1 * spec.omega_max, SWERVE_S)
                if tr.certified_free:
                    cands.append(("swerve", tr))
        if current is not None and t < float(current.t_end) - 1e-9:
            cands.append(("keep", current))
        return cands


class _Key:
    """The ranking key of one candidate (:meth:`FallbackRanker.rank`), each part computed when
    first asked for: the clearance and the contacts within the reaction time cost as much as
    the first contact, and a candidate beaten on an earlier part never needs them. A candidate
    the planned discs strike within the margin is not clear of the full ones by it (they hold
    the planned ones): its clearance is then not needed for the key's first four parts
    (:meth:`struck`), only for a final tie (:func:`_best_of`)."""

    def __init__(self, ranker: FallbackRanker, tr: Any, t: float,
                 full: Sequence[PredictedObstacle], planned: Sequence[PredictedObstacle],
                 reach: Sequence[PredictedObstacle]) -> None:
        cfg = ranker.guard.config
        self.ranker, self.tr, self.t, self.full, self.planned = ranker, tr, t, full, planned
        self.h = max(t + cfg.horizon_s, float(tr.t_end), t)
        self.lead = (bool(getattr(tr, "certified_free", True)), ranker._passive(tr, t, reach))
        self.clear: float | None = None
        self._hit: tuple[PredictedCollision | None] | None = None
        self._struck: bool | None = None
        self._first4: tuple[Any, ...] | None = None
        self._head: tuple[Any, ...] | None = None

    def hit(self) -> PredictedCollision | None:
        """The first contact with the planned discs over the horizon, or None."""
        if self._hit is None:
            cfg = self.ranker.guard.config
            self._hit = (first_collision(self.tr, self.planned, self.ranker.spec.radius,
                                         t_from=self.t, t_until=self.h, margin=cfg.margin,
                                         sample_dt=cfg.sample_dt),)
        return self._hit[0]

    def clearance(self) -> float:
        """The clearance [m] against the full discs over the horizon."""
        if self.clear is None:
            self.clear = self.ranker.guard.clearance(self.tr, self.full, self.t, self.h)
        return self.clear

    def struck(self) -> bool:
        """True if the contact with a planned disc already says the clearance is below the
        margin (:meth:`FallbackRanker._struck_within_margin`)."""
        if self._struck is None:
            hit = self.hit()
            self._struck = hit is not None and self.ranker._struck_within_margin(self.tr, hit,
                                                                                 self.full)
        return self._struck

    def bound4(self) -> tuple[Any, ...]:
        """An upper bound of the key's first four parts, exact once :meth:`first4` ran or when
        the contact says the clearance is below the margin."""
        if self._first4 is not None or self.struck():
            return self.first4()
        return (*self.lead, True, self.hit() is None)

    def first4(self) -> tuple[Any, ...]:
        """The key's first four parts (clear of the static obstacles, passively safe, clear of
        the full discs by the margin, free of the planned ones)."""
        if self._first4 is None:
            margin = self.ranker.guard.config.margin
            # a clearance computed already decides (rank); else the contact may, without it
            clear_ok = (self.clear >= margin if self.clear is not None else
                        not self.struck() and self.clearance() >= margin)
            self._first4 = (*self.lead, clear_ok, self.hit() is None)
        return self._first4

    def head(self) -> tuple[Any, ...]:
        """The key's first seven parts (all but the clearance)."""
        if self._head is None:
            ranker, tr, t, hit = self.ranker, self.tr, self.t, self.hit()
            # the approach speed counts only for a contact within the reaction time
            approach = (ranker._approach(tr, t, hit, self.planned)
                        if hit is not None and float(hit.t) - t < ranker.react_s else 0.0)
            self._head = (*self.first4(), -approach, math.inf if hit is None else float(hit.t),
                          getattr(tr, "kind", None) != MotionKind.SWERVE)
        return self._head


def _top4(keys: list[_Key]) -> tuple[tuple[Any, ...], list[_Key]]:
    """The best first four parts of ``keys`` and the keys that have them (in their order),
    computed for those that can still have them only: the best two leading parts first, then
    the others by their upper bound (:meth:`_Key.bound4`), best first."""
    lead = max(k.lead for k in keys)
    alive = [k for k in keys if k.lead == lead]
    best: tuple[Any, ...] | None = None
    for k in sorted(alive, key=_Key.bound4, reverse=True):  # stable: ties keep their order
        if best is not None and k.bound4() < best:
            break
        best = k.first4() if best is None else max(best, k.first4())
    assert best is not None
    return best, [k for k in alive if k._first4 is not None and k._first4 == best]


def best_fallback(ranker: FallbackRanker, t: float, state: RobotState,
                  full: Sequence[PredictedObstacle], planned: Sequence[PredictedObstacle],
                  motion: Any = None, current: Any = None,
                  reach: Sequence[PredictedObstacle] = ()) -> tuple[str, Any, float]:
    """``(kind, trajectory, clearance [m])`` of the best of :meth:`FallbackRanker.candidates`
    by :meth:`FallbackRanker.rank` (the first on a tie: keeping ``current`` is taken only when
    strictly better)."""
    (_, clear), kind, tr = _best_ranked(ranker, t, state, full, planned, motion, current, reach)
    return kind, tr, clear


def _best_ranked(ranker: FallbackRanker, t: float, state: RobotState,
                 full: Sequence[PredictedObstacle], planned: Sequence[PredictedObstacle],
                 motion: Any, current: Any, reach: Sequence[PredictedObstacle]
                 ) -> tuple[tuple[tuple[Any, ...], float], str, Any]:
    """``((key, clearance [m]), kind, trajectory)`` of the best of the candidates (:func:`_best_of`)."""
    cands = ranker.candidates(t, state, full, motion, current)
    return _best_of([_Key(ranker, tr, t, full, planned, reach) for _, tr in cands],
                    [kind for kind, _ in cands])


def _best_of(keys: list[_Key], kinds: list[str]) -> tuple[tuple[tuple[Any, ...], float], str, Any]:
    """``((key, clearance [m]), kind, trajectory)`` of the best candidate (the first on a tie):
    the best of the keys' first four parts (:func:`_top4`), then the best of the first seven
    among the candidates that have them (:meth:`_Key.head`), then among the candidates tied
    there the largest clearance: the same choice as ranking every candidate by its whole key,
    each part computed only for the candidates it can decide."""
    _, tied = _top4(keys)
    top = max(k.head() for k in tied)
    at_top = {id(k) for k in tied if k.head() == top}
    best: tuple[float, str, Any] | None = None
    for k, kind in zip(keys, kinds, strict=True):  # in the candidates' order
        if id(k) not in at_top:
            continue
        clear = k.clearance()
        if best is None or clear > best[0]:
            best = (clear, kind, k.tr)
    assert best is not None
    return ((*top, best[0]), best[0]), best[1], best[2]


def freer_evasion(ranker: FallbackRanker, t: float, state: RobotState,
                  full: Sequence[PredictedObstacle], planned: Sequence[PredictedObstacle],
                  motion: Any, reach: Sequence[PredictedObstacle] = ()
                  ) -> tuple[str, Any, float] | None:
    """The best fallback (:func:`best_fallback`, without ``motion``) when it is free of the
    full or of the planned discs where ``motion`` is not, else None.

    For a motion the guard accepts as *stoppable* (it can brake before its predicted
    collision): the invariant lets it start, but braking on it may stand the robot where the
    obstacle passes, a collision too (measured on the gap worlds with noise, where a slow robot
    waited in a walker's way). An evasion that no disc strikes is better.
    """
    k_motion = _Key(ranker, motion, t, full, planned, reach).first4()
    cands = ranker.candidates(t, state, full, None, None)
    keys = [_Key(ranker, tr, t, full, planned, reach) for _, tr in cands]
    if _top4(keys)[0] <= k_motion:
        return None
    (_, clear), kind, tr = _best_of(keys, [kind for kind, _ in cands])
    return kind, tr, clear


def escape_time_s(spec: RobotSpec) -> float:
    """Time [s] a robot at rest needs to get out of an obstacle's way: a quarter turn
    (reaching omega_max first), then one diameter plus 1 m sideways (reaching v_max first).
    ``st-bitstar`` extrapolates an unannounced motion at least this long: a shorter horizon
    would show a slow robot the collision only once it can no longer leave.

    Examples:
        >>> from anyplan.world.robot import RobotSpec
        >>> jackal = RobotSpec((0.0, 0.0, 0.0), (1.0, 0.0), radius=0.34, v_max=2.0, omega_max=2.0,
        ...                    a_max=2.0, alpha_max=4.0)
        >>> round(escape_time_s(jackal), 2)
        3.13
    """
    return (0.5 * math.pi / spec.omega_max + spec.omega_max / spec.alpha_max
            + (2.0 * spec.radius + 1.0) / spec.v_max + spec.v_max / spec.a_max)
