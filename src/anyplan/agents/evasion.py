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
            brake) when no prediction is uncertain (exact twists, announced motions).
    """

    def __init__(self, spec: RobotSpec, obstacles: ObstacleSet, guard: SafetyGuard,
                 commit_s: float, swerves: bool = False) -> None:
        self.swerves = bool(swerves)
        self.spec = spec
        self.obstacles = obstacles
        self.guard = guard
        self.commit_s = float(commit_s)
        #: A predicted contact later than this [s] leaves the robot time to decide again and
        #: still come to rest before it: one check period on the candidate, braking from top
        #: speed, and the next decision's own check period (issue 10's invariant).
        self.react_s = 2.0 * self.commit_s + spec.v_max / max(spec.a_max, 1e-9)

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
        head, clear, _ = self.head(tr, t, full, planned, reach, lazy=False)
        assert clear is not None
        return (*head, clear), clear

    def head(self, tr: Any, t: float, full: Sequence[PredictedObstacle],
             planned: Sequence[PredictedObstacle], reach: Sequence[PredictedObstacle] = (),
             lazy: bool = True) -> tuple[tuple[Any, ...], float | None, float]:
        """The first seven parts of :meth:`rank`'s key (all but the clearance), the clearance
        [m] against the ``full`` discs when it was computed (None otherwise) and the end [s]
        of the horizon it is taken over.

        ``lazy``: a candidate the ``planned`` discs strike within the margin is not clear of
        the full ones by it (they hold the planned ones), so its clearance is not computed
        when the struck disc's full size at the contact already says so
        (:meth:`_struck_within_margin`); only a tie on these parts needs it
        (:func:`_best_ranked`). The clearance search costs about as much as the contact
        search, and in a crowd most candidates are struck.
        """
        guard = self.guard
        cfg = guard.config
        h = max(t + cfg.horizon_s, float(tr.t_end), t)
        r = self.spec.radius
        passive: tuple[bool, float] = (True, 0.0)
        if reach:
            esc = Escape(tr, t + self.commit_s, self.spec, self.obstacles, r)
            ok = first_collision(esc, reach, r, t_from=t, t_until=max(esc.t_rest, t),
                                 margin=cfg.margin, sample_dt=cfg.sample_dt) is None
            # none passively safe: the one at rest soonest (the least exposure while moving)
            passive = (ok, 0.0 if ok else -round(esc.t_rest - t, 2))
        hit = first_collision(tr, planned, r, t_from=t, t_until=h, margin=cfg.margin,
                              sample_dt=cfg.sample_dt)
        clear: float | None = None
        if lazy and hit is not None and self._struck_within_margin(tr, hit, full):
            clear_ok = False
        else:
            clear = guard.clearance(tr, full, t, h)
            clear_ok = clear >= cfg.margin
        # the approach speed counts only for a contact within the reaction time
        approach = (self._approach(tr, t, hit, planned)
                    if hit is not None and float(hit.t) - t < self.react_s else 0.0)
        return (bool(getattr(tr, "certified_free", True)), passive, clear_ok,
                hit is None, -approach,
                math.inf if hit is None else float(hit.t),
                getattr(tr, "kind", None) != MotionKind.SWERVE), clear, h

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
        o = next((o for o in full if o.name == hit.obstacle), None)
        if o is None:
            return False
        gap = (math.hypot(*(np.asarray(hit.robot_position) - np.asarray(hit.obstacle_position)))
               - self.spec.radius - float(getattr(o, "max_radius", o.radius)))
        speed = float(tr.max_speed) + max(float(p.max_speed) for p in full)
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
        no uncertain prediction in ``safe`` the :data:`SWERVES` (arcs entered at the robot's
        speed and turn rate within a_max and alpha_max, held :data:`SWERVE_S`, then a brake:
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
        if self.swerves and all(getattr(o, "growth", None) is None for o in safe):
            for v1, w1 in SWERVES:
                tr = swerve_trajectory(state, spec, obstacles, radius, t, v1 * spec.v_max,
                                       w1 * spec.omega_max, SWERVE_S)
                if tr.certified_free:
                    cands.append(("swerve", tr))
        if current is not None and t < float(current.t_end) - 1e-9:
            cands.append(("keep", current))
        return cands


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
    """``((key, clearance [m]), kind, trajectory)`` of the best candidate (the first on a tie):
    the best of the keys' first parts (:meth:`FallbackRanker.head`), then among the candidates
    tied there the largest clearance, computed only for them: the same choice as ranking every
    candidate by its whole key."""
    heads = [(ranker.head(tr, t, full, planned, reach), kind, tr)
             for kind, tr in ranker.candidates(t, state, full, motion, current)]
    top = max(c[0][0] for c in heads)
    best: tuple[float, str, Any] | None = None
    for (head, clear, h), kind, tr in heads:
        if head != top:
            continue
        if clear is None:
            clear = ranker.guard.clearance(tr, full, t, h)
        if best is None or clear > best[0]:
            best = (clear, kind, tr)
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
    k_motion = ranker.head(motion, t, full, planned, reach)[0]
    (k_best, clear), kind, tr = _best_ranked(ranker, t, state, full, planned, None, None, reach)
    if k_best[:4] <= k_motion[:4]:
        return None
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
