"""The safety invariant for agents that plan among moving obstacles, and its fallbacks.

The robot only starts a motion M at t_s when M is predicted collision-free until it ends at rest
or arrives at the goal ("free to rest"), or when its *escape* (follow M until
``t_s + commit_s``, then brake to rest at a_max and alpha_max, :class:`Escape`) is predicted free
until the robot stands and clears the static obstacles ("stoppable"); ``commit_s`` is the time
the agent needs to act again. Otherwise :class:`SafetyGuard` keeps the current motion if it
still passes, or takes the fallback (``brake``/``hold``, ``turn_away``, ``back_off``) with the
largest certified predicted clearance over a horizon among those whose moving part is
predicted free. Predictions: :func:`anyplan.prediction.collision.first_collision` with the robot
radius plus ``margin``.
Every decision is logged (:attr:`SafetyGuard.decisions`, JSON form :meth:`SafetyGuard.log`).
Rule, API and tests: ``docs/sequential.md`` ("The safety invariant and its fallbacks").
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from anyplan.config import setting, validate
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.moving import closest_approach
from anyplan.geometry.se2 import dot2
from anyplan.prediction.base import (
    PredictedObstacle,
    RadiusGrowth,
    centres_of,
    continuous_pieces_of,
    jump_times_of,
)
from anyplan.prediction.collision import first_collision
from anyplan.trajectory.motion import brake_to_rest, come_to_rest, polyline_trajectory
from anyplan.trajectory.reference import HoldSegment
from anyplan.trajectory.trajectory import BrakeSegment, Trajectory
from anyplan.world.motion import JUMP_SLACK_S, UnicycleMotion
from anyplan.world.robot import RobotSpec, RobotState

__all__ = ["SafetyConfig", "Decision", "Escape", "SafetyGuard", "FALLBACK_KINDS", "reachable_discs",
           "finite_or_none"]

#: The fallback kinds, in order of preference when their clearances tie.
FALLBACK_KINDS = ("hold", "brake", "turn_away", "back_off")
_EPS_V = 1e-6  # [m/s] below this the robot counts as at rest


@dataclass(frozen=True)
class SafetyConfig:
    """Settings of the safety guard (times in s, lengths in m).

    Attributes:
        margin: Extra clearance [m] between the robot's reference and each predicted disc in the
            decisions (absorbs the tracking error).
        recheck_margin: Margin [m] of :meth:`SafetyGuard.still_safe` (smaller: hysteresis).
        horizon_s: Horizon [s] of the predicted clearance that ranks the fallbacks.
        offsets_m: Distances [m] tried by ``turn_away`` and ``back_off``.
        sample_dt: Resampling step [s] of the certified predictor (None: on the motion itself).
        tol: Time accuracy [s] of the clearance search.
    """

    margin: float = setting(0.05, lo=0.0, unit="m", doc="clearance to each predicted disc")
    recheck_margin: float = setting(0.025, lo=0.0, unit="m", doc="margin of still_safe")
    horizon_s: float = setting(5.0, lo=0.0, lo_open=True, unit="s", doc="fallback ranking horizon")
    offsets_m: tuple[float, ...] = setting((0.6, 1.2), lo=0.0, lo_open=True, unit="m",
                                           doc="turn_away / back_off distances")
    sample_dt: float | None = setting(0.02, lo=0.0, lo_open=True, unit="s",
                                      doc="predictor resampling step (None: exact)")
    tol: float = setting(1e-3, lo=0.0, lo_open=True, unit="s", doc="clearance search accuracy")

    def __post_init__(self) -> None:
        validate(self)


class Escape:
    """Follow ``motion`` until ``t_commit`` [s], then brake to rest (a TimedMotion).

    Attributes:
        t_rest: Time [s] the robot is at rest.
        static_free: The braking path clears the static obstacles.
    """

    def __init__(self, motion: Any, t_commit: float, spec: RobotSpec, obstacles: ObstacleSet,
                 radius: float) -> None:
        self.motion = motion
        self.t_commit = float(min(max(t_commit, motion.t_start), motion.t_end))
        st = motion.state(self.t_commit)
        segs, t_rest, _, free = brake_to_rest(st, spec, obstacles, radius, self.t_commit)
        self.brake: BrakeSegment | None = segs[0] if segs else None  # type: ignore[assignment]
        self.t_rest = float(t_rest)
        self.static_free = bool(free)
        self.t_start = float(motion.t_start)
        self.t_end = self.t_rest
        self.max_speed = float(motion.max_speed)

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Positions (N, 2) [m] at absolute times ``t`` [s]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        p = self.motion.positions(np.minimum(t, self.t_commit))
        if self.brake is not None:
            late = t > self.t_commit
            if late.any():
                x, y, _, _, _ = self.brake.sample(np.minimum(t[late], self.brake.t1))
                p[late, 0], p[late, 1] = x, y
        return p


@dataclass
class Decision:
    """One decision of the guard.

    Attributes:
        t: Time [s] the chosen trajectory starts.
        kind: ``"motion"``, ``"keep"``, a fallback kind (:data:`FALLBACK_KINDS`), or
            ``"unsafe"`` (neither passes, and ``decide(fallback=False)`` asked for no
            fallback).
        trajectory: What the robot executes from ``t``.
        safe: True when ``trajectory`` satisfies the rule from ``t`` (free to rest, or stoppable);
            for a fallback, when its moving part is predicted collision-free.
        rule: ``"free_to_rest"``, ``"stoppable"``, ``"fallback"``, ``"unsafe"``, or
            ``"give_way"`` (an agent's fallback in place of a stoppable motion, e.g.
            ``seq-bitstar``'s ``give_way``).
        t_commit: For ``stoppable``: the time [s] the escape starts braking.
        t_rest: Time [s] the robot is at rest on the checked motion (escape or fallback).
        first_collision_s: First predicted collision [s] of the proposed motion (None if free).
        predicted_clearance_m: For a fallback: its predicted clearance [m] over the horizon.
        candidates: For a fallback: ``(kind, moving_free, clearance [m])`` of every candidate.
        reason: Why a fallback was needed.
    """

    t: float
    kind: str
    trajectory: Any
    safe: bool
    rule: str
    t_commit: float | None = None
    t_rest: float | None = None
    first_collision_s: float | None = None
    predicted_clearance_m: float | None = None
    candidates: list[tuple[str, bool, float]] = field(default_factory=list)
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON form (without the trajectory)."""
        out: dict[str, Any] = {"t": self.t, "kind": self.kind, "safe": self.safe, "rule": self.rule}
        for k in ("t_commit", "t_rest", "first_collision_s", "predicted_clearance_m"):
            v = getattr(self, k)
            if v is not None:
                out[k] = float(v) if math.isfinite(v) else None
        if self.reason:
            out["reason"] = self.reason
        return out


class SafetyGuard:
    """Checks proposed motions against the rule and chooses fallbacks (see the module docstring).

    Args:
        spec: The robot.
        obstacles: Static obstacles with walls.
        config: Settings.
    """

    def __init__(self, spec: RobotSpec, obstacles: ObstacleSet,
                 config: SafetyConfig | None = None) -> None:
        self.spec = spec
        self.obstacles = obstacles
        self.config = config or SafetyConfig()
        self.decisions: list[Decision] = []
        self.fallbacks: list[dict[str, Any]] = []
        self._tracks_memo: tuple[tuple[Any, ...], np.ndarray, _Tracks] | None = None

    # --- checks ------------------------------------------------------------------------------
    def _hit(self, motion: Any, preds: Sequence[PredictedObstacle], t0: float, t1: float,
             margin: float) -> Any:
        if t1 <= t0 or not preds:
            return None
        return first_collision(motion, preds, self.spec.radius, t_from=t0, t_until=t1,
                               margin=margin, sample_dt=self.config.sample_dt)

    def arrival(self, motion: Any, t: float) -> float:
        """When ``motion`` arrives within the robot's ``arrival_radius`` of the goal (half the
        goal tolerance), where the run is over: the first of its samples from ``t`` [s] there
        (every 20 ms, or 4000 samples over a longer motion), never before the true arrival; inf
        if it does not end there."""
        goal = np.asarray(self.spec.goal, dtype=float)
        reach = self.spec.arrival_radius
        t_end = float(motion.t_end)
        if t_end < t or math.hypot(*(motion.positions(np.array([t_end]))[0] - goal)) > reach:
            return math.inf
        ts = np.append(np.arange(t, t_end, max(0.02, (t_end - t) / 4000.0)), t_end)
        p = motion.positions(ts)
        return float(ts[np.argmax(np.hypot(p[:, 0] - goal[0], p[:, 1] - goal[1]) <= reach)])

    def check(self, motion: Any, preds: Sequence[PredictedObstacle], t: float, commit_s: float,
              margin: float | None = None, reach: Sequence[PredictedObstacle] = ()
              ) -> tuple[str, float | None, float | None, float | None]:
        """Whether ``motion`` may be started (or kept) at ``t`` [s].

        A motion that ends at the goal is checked until it arrives (:meth:`arrival`): the run
        is over there, as in the planners' own checks of a path's end at the goal, so a contact
        predicted later, at rest at the goal, neither forbids it nor makes it merely stoppable.
        With ``reach`` (discs that contain everywhere an obstacle whose future is unknown can
        be, :func:`reachable_discs`), the motion must also be *passively safe*: its escape
        brings the robot to rest before any of them can touch it, so that a collision with an
        obstacle that leaves its prediction finds the robot at rest, not driving into it
        (Macek, Vasquez, Fraichard & Siegwart, "Towards safe vehicle navigation in dynamic
        urban scenarios", Automatika 2009; Bouraine, Fraichard & Salhi, "Provably safe
        navigation for mobile robots with limited field-of-views in dynamic environments",
        Autonomous Robots 2012).

        Returns:
            ``(rule, t_commit, t_rest, first_collision_s)`` with rule ``"free_to_rest"``,
            ``"stoppable"`` or ``"unsafe"``.
        """
        m = self.config.margin if margin is None else margin
        t_end = max(float(motion.t_end), t)
        hit = self._hit(motion, preds, t, min(t_end, self.arrival(motion, t)), m)
        if hit is None and not reach:
            return "free_to_rest", None, t_end, None
        esc = Escape(motion, t + commit_s, self.spec, self.obstacles, self.spec.radius)
        if reach and self._hit(esc, reach, t, esc.t_rest, m) is not None:
            return "unsafe", esc.t_commit, esc.t_rest, None if hit is None else hit.t
        if hit is None:
            return "free_to_rest", None, t_end, None
        if esc.static_free and self._hit(esc, preds, t, esc.t_rest, m) is None:
            return "stoppable", esc.t_commit, esc.t_rest, hit.t
        return "unsafe", esc.t_commit, esc.t_rest, hit.t

    def still_safe(self, current: Any, preds: Sequence[PredictedObstacle], t: float,
                   commit_s: float, reach: Sequence[PredictedObstacle] = ()) -> bool:
        """True if the current motion still satisfies the rule from ``t`` [s] (with the
        re-check margin; passively safe against ``reach``, see :meth:`check`)."""
        if current is None:
            return True
        return self.check(current, preds, t, commit_s, self.config.recheck_margin,
                          reach)[0] != "unsafe"

    # --- decisions ---------------------------------------------------------------------------
    def decide(self, t: float, motion: Any, current: Any, state: RobotState,
               preds: Sequence[PredictedObstacle], commit_s: float,
               reach: Sequence[PredictedObstacle] = (), fallback: bool = True) -> Decision:
        """Start ``motion``, keep ``current``, or fall back (see the module docstring).

        Args:
            t: Time [s] at which the chosen trajectory starts.
            motion: The proposed motion (a Trajectory from ``state`` at ``t``), or None.
            current: What the robot executes now, or None (at rest before the first plan).
            state: The robot's state at ``t`` (on ``current``, or its own).
            preds: Predicted moving obstacles.
            commit_s: Time [s] before the agent can act again.
            reach: Reachable discs a started or kept motion must be passively safe against
                (:meth:`check`); the fallbacks are ranked against ``preds``.
            fallback: False: when neither passes, return an ``"unsafe"`` decision without a
                trajectory (for a caller that chooses its own fallback) instead of the
                guard's fallback.
        """
        reason = "no motion proposed"
        if motion is not None and not getattr(motion, "feasible", True):
            # The robot cannot take it up from its state (plan_motion's best effort): what is
            # predicted along it is not where the robot goes.
            reason = "proposed motion: infeasible from the robot's state"
        elif motion is not None:
            rule, tc, tr, fc = self.check(motion, preds, t, commit_s, reach=reach)
            if rule != "unsafe":
                return self._log(Decision(t, "motion", motion, True, rule, tc, tr, fc))
            reason = ("proposed motion: cannot stop before an obstacle could reach it"
                      if fc is None else
                      f"proposed motion: collision predicted at {fc:.2f} s, cannot stop before it")
        if current is not None and t < current.t_end + 1e-9:
            rule, tc, tr, fc = self.check(current, preds, t, commit_s, reach=reach)
            if rule != "unsafe":
                return self._log(Decision(t, "keep", current, True, rule, tc, tr, fc))
        if not fallback:
            return Decision(t, "unsafe", None, False, "unsafe", reason=reason)
        return self._log(self.fallback(t, state, preds, reason))

    def _log(self, d: Decision) -> Decision:
        self.decisions.append(d)
        if d.kind in FALLBACK_KINDS:
            self.fallbacks.append({"t": float(d.t), "kind": d.kind,
                                   "predicted_clearance_m": finite_or_none(d.predicted_clearance_m)})
        return d

    def log(self) -> list[dict[str, Any]]:
        """Every decision in JSON form."""
        return [d.to_dict() for d in self.decisions]

    # --- fallbacks ---------------------------------------------------------------------------
    def clearance(self, motion: Any, preds: Sequence[PredictedObstacle], t0: float,
                  t1: float) -> float:
        """Certified minimum distance [m] between the robot's disc on ``motion`` and every
        predicted disc over [t0, t1] [s] (inf without predictions; negative when they overlap).
        A disc whose radius grows with the horizon counts with its largest radius (a lower
        bound on the clearance). A motion that jumps (an open track) is searched piece by
        piece between its jumps (:meth:`~anyplan.world.motion.Motion.continuous_pieces`): its
        speed bound holds only there."""
        best = math.inf
        r = self.spec.radius
        p0 = motion.positions(np.array([t0]))[0]
        # Branch and bound on samples: an obstacle whose certified lower bound on the sampled
        # grid (distance on [t_i, t_i+1] >= (d_i + d_i+1 - L dt) / 2) exceeds another's sampled
        # minimum (an upper bound on its own) cannot be the nearest: it is not searched.
        ts = np.linspace(t0, t1, max(2, int(math.ceil((t1 - t0) / 0.1)) + 1))
        pm = motion.positions(ts)
        bounds: list[tuple[float, float]] = []
        if preds:
            # every obstacle at once, element by element the operations of one at a time
            q, ro_max, vo, until = self._tracks_at(preds, ts)
            d = np.hypot(pm[None, :, 0] - q[:, :, 0], pm[None, :, 1] - q[:, :, 1]) \
                - ro_max[:, None] - r
            d[ts[None, :] > np.minimum(t1, until)[:, None] + 0.1] = math.inf
            lbs = 0.5 * (d[:, :-1] + d[:, 1:]
                         - (float(motion.max_speed) + vo)[:, None] * np.diff(ts)[None, :])
            _unbound_jumps(lbs, preds, ts, until)
            gone = np.minimum(t1, until) < t0
            lows = np.where(gone, math.inf, lbs.min(axis=1))
            dm = np.where(gone, math.inf, d.min(axis=1))
            bounds = list(zip(lows.tolist(), dm.tolist(), strict=True))
        cutoff = min((b[1] for b in bounds), default=math.inf)
        for o, (lo, _) in zip(preds, bounds, strict=True):
            if lo > cutoff + 1e-6:
                continue
            t1o = min(t1, float(getattr(o, "until", math.inf)))  # up to the prediction's horizon
            if t1o < t0:
                continue
            speed = float(motion.max_speed) + float(o.max_speed)
            ro = _max_radius(o)
            for a, b in continuous_pieces_of(o, t0, t1o):  # [(t0, t1o)] without a jump
                pa = p0 if a == t0 else motion.positions(np.array([a]))[0]
                qa = o.positions(np.array([a]))[0]
                lb = math.hypot(*(pa - qa)) - speed * (b - a) - r - ro
                if lb >= best:
                    continue  # cannot come closer than the best so far
                _, d = closest_approach(motion.positions, o.positions, speed, a, b,
                                        tol=self.config.tol)
                best = min(best, d - r - ro)
        return best

    def _tracks_at(self, preds: Sequence[PredictedObstacle], ts: np.ndarray) -> _Tracks:
        """Every prediction's centres (n, len(ts), 2) [m] at ``ts``, largest radii, speed
        bounds [m/s] and horizons [s]. The last answer is kept: the candidates of one fallback
        ranking ask for the same predictions on the same grid (the entry holds the predictions,
        so an ``id`` seen here is the same live object)."""
        memo = self._tracks_memo
        if memo is not None and len(memo[0]) == len(preds) and memo[1].shape == ts.shape \
                and np.array_equal(memo[1], ts) and all(
                    a is b for a, b in zip(memo[0], preds, strict=True)):
            return memo[2]
        out = _tracks(preds, ts)
        self._tracks_memo = (tuple(preds), ts.copy(), out)
        return out

    def candidates(self, t: float, state: RobotState,
                   preds: Sequence[PredictedObstacle]) -> list[tuple[str, Trajectory, float]]:
        """The fallback trajectories from ``state`` at ``t`` [s], as ``(kind, trajectory,
        time at rest [s])``: brake (or hold), then turn_away and back_off targets that keep the
        static clearance."""
        spec, cfg = self.spec, self.config
        h = t + cfg.horizon_s
        segs, t_rest, rest, free = come_to_rest(state, spec, self.obstacles, spec.radius, t)
        moving = abs(state.v) > _EPS_V
        # certified_free: whether braking straight ahead clears the static obstacles (at speed
        # beside a wall, it may not: the motion in use would have curved away)
        hold = Trajectory(segs + [HoldSegment(rest.x, rest.y, rest.theta, t_rest, max(h, t_rest))],
                          kind="brake" if moving else "hold", certified_free=bool(free))
        out: list[tuple[str, Trajectory, float]] = [("brake" if moving else "hold", hold, t_rest)]
        if not preds:
            return out
        # The threat: the predicted obstacle that comes nearest to the robot braking in place.
        p_rest = np.array([rest.x, rest.y])
        ts = np.linspace(t, h, 41)
        pr = hold.positions(ts)
        u = _threat(preds, ts, pr, p_rest)
        if u is None or math.hypot(*u) < 1e-9:
            return out
        u = u / math.hypot(*u)
        perp = np.array([-u[1], u[0]])
        radius = spec.radius + cfg.margin
        for kind, dirs in (("turn_away", (perp, -perp)), ("back_off", (-u,))):
            for dvec in dirs:
                for dist in cfg.offsets_m:
                    target = p_rest + dist * dvec
                    if not self.obstacles.segment_free(p_rest, target, radius):
                        continue
                    tr = polyline_trajectory(np.array([p_rest, target]), spec, state, t,
                                             self.obstacles, radius)
                    if tr.certified_free:
                        out.append((kind, tr, float(tr.t_end)))
        return out

    def fallback(self, t: float, state: RobotState, preds: Sequence[PredictedObstacle],
                 reason: str = "") -> Decision:
        """The best fallback from ``state`` at ``t`` [s] (not logged; :meth:`decide` logs)."""
        h = t + self.config.horizon_s
        scored = []
        for i, (kind, tr, t_rest) in enumerate(self.candidates(t, state, preds)):
            moving_free = self._hit(tr, preds, t, t_rest, self.config.margin) is None
            clear = self.clearance(tr, preds, t, max(h, t_rest))
            scored.append((bool(tr.certified_free), moving_free, clear, -FALLBACK_KINDS.index(kind),
                           -i, kind, tr, t_rest))
        # a fallback that runs into a static obstacle ranks last: that collision is certain
        best = max(scored, key=lambda s: s[:5])
        cands = [(s[5], bool(s[1]), float(s[2])) for s in scored]
        return Decision(t, best[5], best[6], bool(best[1]), "fallback", None, best[7], None,
                        float(best[2]), cands, reason)


def reachable_discs(preds: Sequence[PredictedObstacle], t: float, p: np.ndarray, heading: float,
                    extra_speed: float, horizon_s: float, min_speed: float = 0.0
                    ) -> list[PredictedObstacle]:
    """Discs [m] that contain, from ``t`` [s] on, every position an obstacle of ``preds`` can
    reach whatever it does, if its speed stays within ``max(its predicted speed +
    extra_speed, min_speed)`` [m/s] (``min_speed``: e.g. a person standing still can set off
    at walking speed): centred where it is predicted at ``t``, with its radius there, growing
    at that speed up to ``horizon_s`` [s] (then held). Only obstacles not behind the robot at
    ``p``, heading ``heading`` [rad], are kept: one behind it meets a robot moving away (or at
    rest), which is not the robot driving into it.
    """
    u = np.array([math.cos(heading), math.sin(heading)])
    out = []
    for o, q in zip(preds, centres_of(preds, np.array([t]))[:, 0], strict=True):
        if float(getattr(o, "until", math.inf)) < t:
            continue
        if dot2(q - p, u) < 0.0:
            continue
        speed = max(float(o.max_speed) + extra_speed, min_speed)
        growth = RadiusGrowth(t, np.array([0.0, horizon_s]), np.array([0.0, speed * horizon_s]))
        out.append(PredictedObstacle(o.name, float(o.radius_at(t)),
                                     UnicycleMotion(float(q[0]), float(q[1]), 0.0, 0.0), growth))
    return out


def _threat(preds: Sequence[PredictedObstacle], ts: np.ndarray, pr: np.ndarray,
            p_rest: np.ndarray) -> np.ndarray | None:
    """From ``p_rest`` [m] to the predicted obstacle that comes nearest (centre distance less
    its largest radius) to the robot at ``pr`` (len(ts), 2) [m] at times ``ts`` [s], where it
    is then (the first such obstacle and time; None if none is predicted at ``ts``)."""
    u: np.ndarray | None = None
    # every obstacle at once, element by element the operations of a search one obstacle at
    # a time that keeps the first strictly nearer one
    q, ro, _, until = _tracks(preds, ts)
    d = np.hypot(pr[None, :, 0] - q[:, :, 0], pr[None, :, 1] - q[:, :, 1]) - ro[:, None]
    d[ts[None, :] > until[:, None]] = math.inf
    k = np.argmin(d, axis=1)
    dk = d[np.arange(len(preds)), k]
    if np.isnan(dk).any():  # NaN never wins the comparison one at a time: as there
        best = math.inf
        for i, di in enumerate(dk.tolist()):
            if di < best:
                best, u = di, preds[i].positions(ts[k[i]:k[i] + 1])[0] - p_rest
    elif float(dk.min()) < math.inf:
        i = int(np.argmin(dk))
        u = preds[i].positions(ts[k[i]:k[i] + 1])[0] - p_rest
    return u


#: Predictions on a time grid: centres (n, T, 2), largest radii, speed bounds, horizons.
_Tracks = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _tracks(preds: Sequence[PredictedObstacle], ts: np.ndarray) -> _Tracks:
    """Every prediction's centres (n, len(ts), 2) [m] at ``ts`` [s], largest radii [m], speed
    bounds [m/s] and horizons [s]."""
    q = centres_of(preds, ts)
    ro = np.array([_max_radius(o) for o in preds])
    vo = np.array([float(o.max_speed) for o in preds])
    until = np.array([float(getattr(o, "until", math.inf)) for o in preds])
    return q, ro, vo, until


def _unbound_jumps(lbs: np.ndarray, preds: Sequence[PredictedObstacle], ts: np.ndarray,
                   until: np.ndarray) -> None:
    """Set to -inf the lower bounds ``lbs`` (n, len(ts) - 1) [m] of the grid intervals of
    ``ts`` [s] that hold (within :data:`JUMP_SLACK_S`) a jump of a prediction up to its
    horizon ``until`` [s]: a speed bound does not hold across a jump."""
    for k, o in enumerate(preds):
        for jt in jump_times_of(o, float(ts[0]) - JUMP_SLACK_S, min(float(ts[-1]), float(until[k]))):
            i0 = int(np.searchsorted(ts, jt - JUMP_SLACK_S)) - 1
            i1 = int(np.searchsorted(ts, jt + JUMP_SLACK_S, side="right"))
            lbs[k, max(i0, 0):max(min(i1, lbs.shape[1]), 0)] = -math.inf


def _max_radius(o: Any) -> float:
    return float(getattr(o, "max_radius", o.radius))


def finite_or_none(x: float | None) -> float | None:
    """``x`` as a float, or None when it is None or not finite (for JSON records)."""
    if x is None:
        return None
    return float(x) if math.isfinite(x) else None
