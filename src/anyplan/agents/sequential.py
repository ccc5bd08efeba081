"""The ``seq-bitstar`` agent: Sequential BIT* executed online among moving obstacles.

At the start, and whenever a collision with a moving obstacle is predicted on the current
reference motion, the agent runs :class:`~anyplan.planning.sequential.SequentialBITStar` (the
paper's Algorithm 1 with our extensions) with a :class:`~anyplan.trajectory.reference.Departure`
(the reference motions from the state the robot will have when the new motion starts) and
takes up the new motion with Kanayama's tracking law. The online timing policy (planning delay,
late plans, back-off) is :class:`~anyplan.agents.replanning.ReplanningAgent`'s; the safety
invariant (:mod:`anyplan.agents.safety`) decides what is executed (``safety=False``: the paper's
behaviour). Moving obstacles are predicted with a constant twist
(:class:`~anyplan.prediction.ConstantTwistPredictor`). Statistics:
:class:`~anyplan.agents.stats.SequentialStats`. See ``docs/sequential.md``.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from anyplan.agents.base import Observation, checked_number, checked_pose_margin
from anyplan.agents.evasion import FallbackRanker, freer_evasion
from anyplan.agents.replanning import MAX_BACKOFF_S, ReplanningAgent
from anyplan.agents.safety import Decision, SafetyConfig, SafetyGuard, finite_or_none
from anyplan.agents.stats import SequentialStats
from anyplan.agents.warmup import warm_up_kernels
from anyplan.control.kanayama import KanayamaGains
from anyplan.planning.sequential import SequentialBITStar, SequentialConfig, SequentialResult
from anyplan.planning.visgraph import usable_margin
from anyplan.prediction.base import ConstantTwistPredictor, PredictedObstacle
from anyplan.prediction.collision import first_collision
from anyplan.trajectory.reference import ReferenceBuilder
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world.scenario import Scenario

__all__ = ["SequentialBITStarAgent", "MAX_BACKOFF_S", "GIVE_WAY"]

#: The choices of ``give_way`` (:class:`SequentialBITStarAgent`).
GIVE_WAY = ("announced", "always", "never")


class SequentialBITStarAgent(ReplanningAgent):
    """Sequential BIT* with online replanning.

    Args:
        config: Settings of the replanning loop (:class:`SequentialConfig`).
        plan_margin: Extra clearance [m] added to the robot radius for BIT* (static obstacles).
        smooth_margin: Extra clearance [m] the smoothed curve must keep (< plan_margin).
        pose_margin_m: Extra clearance [m] kept from the static obstacles for the robot's
            localization error (2-3 standard deviations of its position, the spread its
            localizer reports): added to ``plan_margin`` and ``smooth_margin``, at reset
            reduced to what the way from the start to the goal allows
            (:func:`~anyplan.planning.visgraph.usable_margin`; the margin taken is
            ``result.extra["pose_margin_m"]``). 0: none.
        check_period_s: How often [s] the current motion is checked against the predictions.
        min_replan_interval_s: Minimum time [s] between two replannings (unless the predicted
            collision is closer than ``urgent_s``).
        urgent_s: Predicted collisions closer than this [s] replan at once.
        planning_delay: ``"measured"`` (wall-clock time of the computation) or a fixed delay [s]
            by which each new motion starts after the replanning decision.
        grid_step: Grid spacing [m] of the velocity profile and of the curve certification.
        gains: Kanayama gains.
        safety: Apply the safety invariant (:mod:`anyplan.agents.safety`).
        safety_config: Its settings (default: margin = the loop's ``margin``).
        reanchor_m: Tracking error [m] beyond which the next motion starts from the robot's
            own state (:class:`~anyplan.agents.replanning.ReplanningAgent`); None: never.
        max_delay_s: Cap [s] on a measured planning delay; None: the loop's ``max_time_s``.
        give_way: When a motion the guard accepts as *stoppable* (it can brake before its
            predicted collision) is struck within the guard's ``horizon_s``, it gives way to
            the best fallback (the guard's, 8 evasions, swerves:
            :func:`~anyplan.agents.evasion.freer_evasion`) that is free of the predictions
            where the motion is not: braking on it would stand the robot where the obstacle
            passes (as ``st-bitstar`` does). ``"announced"`` (default): only while every
            obstacle in view announces its motion (exact predictions); ``"always"``: with
            extrapolated twists too (on DynaBARN more arrivals and more robot-caused
            collisions: ``docs/sequential.md``); ``"never"``: the guard's decision stands.
    """

    name = "seq-bitstar"
    #: Kernel parts this agent uses (:func:`~anyplan.agents.warmup.warm_up_kernels`).
    kernel_parts: tuple[str, ...] = ("bitstar", "motion", "contacts", "sequential")
    config_classes: tuple[Any, ...] = (SequentialConfig,)
    #: A fixed simulated planning delay [s], a batch budget instead of a time budget, and a
    #: wall-clock cap far above any planning time: the run no longer depends on the machine.
    deterministic_settings = {"planning_delay": 0.1, "batches_per_plan": 2,  # noqa: RUF012
                              "max_time_s": 10.0}
    wall_clock_extra = SequentialStats.WALL_CLOCK

    def __init__(self, config: SequentialConfig | None = None, *, plan_margin: float = 0.03,
                 smooth_margin: float = 0.015, check_period_s: float = 0.2,
                 min_replan_interval_s: float = 0.5, urgent_s: float = 3.0,
                 planning_delay: str | float = "measured", grid_step: float = 0.05,
                 gains: KanayamaGains | None = None, safety: bool = True,
                 safety_config: SafetyConfig | None = None, reanchor_m: float | None = 0.2,
                 pose_margin_m: float = 0.0, max_delay_s: float | None = None,
                 give_way: str = "announced", **loop_options: Any) -> None:
        if config is None:
            config = SequentialConfig(**loop_options)
        elif loop_options:
            raise ValueError("give either config or loop options, not both")
        if not 0.0 <= smooth_margin <= plan_margin:
            raise ValueError("smooth_margin: must be in [0, plan_margin]")
        pose_margin_m = checked_pose_margin(pose_margin_m)
        super().__init__(check_period_s=check_period_s,
                         min_replan_interval_s=min_replan_interval_s, urgent_s=urgent_s,
                         planning_delay=planning_delay,
                         max_delay_s=config.max_time_s if max_delay_s is None else max_delay_s,
                         gains=gains, reanchor_m=reanchor_m)
        self.config = config
        self.plan_margin = float(plan_margin)
        self.smooth_margin = float(smooth_margin)
        self.pose_margin_m = pose_margin_m
        self.grid_step = checked_number("grid_step", grid_step, lo_open=True)
        self.safety = bool(safety)
        if give_way not in GIVE_WAY:
            raise ValueError(f"give_way: must be one of {', '.join(GIVE_WAY)}, got {give_way!r}")
        self.give_way = give_way
        self.safety_config = safety_config or SafetyConfig(margin=config.margin,
                                                           recheck_margin=0.5 * config.margin)

    # --- lifecycle -------------------------------------------------------------------------------
    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        warm_up_kernels(self.kernel_parts)  # compile or load now, not inside a timed replanning
        self.spec = scenario.robot
        self.obstacles = scenario.obstacle_set()
        self.rng = rng
        self.predictor = ConstantTwistPredictor()
        spec = self.spec
        # the localization margin, as far as the way to the goal leaves room for it
        extra = (usable_margin(self.obstacles, spec.start[:2], spec.goal,
                               spec.radius + self.plan_margin, self.pose_margin_m)
                 if self.pose_margin_m > 0.0 else None)
        self.loop = SequentialBITStar(self.obstacles, robot_radius=spec.radius,
                                      plan_radius=spec.radius + self.plan_margin + (extra or 0.0),
                                      config=self.config, rng=rng)
        self.reference = ReferenceBuilder(spec=spec, obstacles=self.obstacles,
                                          smooth_margin=self.smooth_margin + (extra or 0.0),
                                          grid_step=self.grid_step)
        self.guard = SafetyGuard(self.spec, self.obstacles, self.safety_config)
        self._reset_timing(self._new_record())
        self.record.pose_margin_m = extra
        self._fallback_active = False
        self._commit_s = self.check_period_s + 0.1

    def _new_record(self) -> SequentialStats:
        return SequentialStats(fallbacks=self.guard.fallbacks)

    # --- planning --------------------------------------------------------------------------------
    def _replan(self, obs: Observation, preds: list[PredictedObstacle], reason: str) -> None:
        """One replanning call, booked whole (:meth:`~ReplanningAgent._whole_call`)."""
        self._whole_call(obs, lambda: self._replan_call(obs, preds, reason))

    def _replan_call(self, obs: Observation, preds: list[PredictedObstacle], reason: str) -> None:
        dt, d, t_ready, state = self._begin_replan(obs)
        t = obs.t
        w0 = time.perf_counter()
        res: SequentialResult = self.loop.replan(np.array([state.x, state.y]),
                                                 np.asarray(self.spec.goal, dtype=float), preds, t,
                                                 self.reference.departing(state, t_ready))
        wall = time.perf_counter() - w0
        self._record_replan(t, wall, res, reason)
        rec = self.record
        rec.plan_time_s.append(res.plan_time_s)
        rec.motion_time_s.append(res.motion_time_s)
        if res.status == "waiting":
            rec.waits += 1
        if rec.progress is None and res.history:
            # BIT*'s cost against solve time in the first planning (OMPL's progress property).
            rec.progress = [[float(a), float(b)] for a, b in res.history]
        if res.motion is None:
            if self.safety:
                self._guarded(obs, None, t_ready, d, preds, res, dt)
            # Keep the current reference (or stay put); try again after a back-off that doubles
            # with each consecutive failure up to MAX_BACKOFF_S, so that a goal no planning
            # reaches costs a bounded fraction of real time.
            self._failures += 1
            self._retry_at = t + min(dt * 2.0 ** (self._failures - 1), MAX_BACKOFF_S)
            return
        self._failures = 0
        # Late plans are re-timed from the state the robot will have when the plan is ready.
        t_switch, motion = self._take_up(
            obs, t_ready, wall, d, dt, res.motion,  # type: ignore[arg-type]
            lambda state, t_s: self.reference.departing(state, t_s)(
                res.path, [v.shape for v in res.virtual_obstacles], res.delay_s))
        assert motion is not None
        if self.safety:
            self._guarded(obs, motion, t_switch, t_switch - t, preds, res, dt)
            return
        self._record_plan(t, t_switch, res)
        self.pending = (t_switch, motion)

    def _record_plan(self, t: float, t_switch: float, res: SequentialResult) -> None:
        self.stats.plans.append({"t": t, "t_start": t_switch, "path": np.asarray(res.path).tolist(),
                                 "status": res.status, "virtual_obstacles": len(res.virtual_obstacles),
                                 "delay_s": res.delay_s})

    def _guarded(self, obs: Observation, motion: Trajectory | None, t_switch: float, delay: float,
                 preds: list[PredictedObstacle], res: SequentialResult, dt: float) -> None:
        """Let the safety guard decide what the robot executes from ``t_switch`` [s]. With the
        measured delay, a decision that would be ready after ``t_switch`` is made again from the
        state the robot has when it is ready (the motion re-timed from there), as a late plan
        is re-timed (:meth:`_take_up`); it counts as a late plan."""
        current, planned = self._in_use(), t_switch
        give_way = self.give_way == "always" or (
            self.give_way == "announced" and all(o.motion is not None for o in obs.obstacles))

        def decide(t_s: float) -> tuple[Any, bool]:
            # Before the agent can act again: one check period, then a replanning's delay.
            self._commit_s = self.check_period_s + (delay if t_s == planned else t_s - obs.t)
            state = self._state_at(obs, t_s)
            m = motion if t_s == planned or motion is None else self.reference.departing(
                state, t_s)(res.path, [v.shape for v in res.virtual_obstacles], res.delay_s)
            dec = self.guard.decide(t_s, m, current, state, preds, self._commit_s)
            if (give_way and dec.rule == "stoppable" and dec.first_collision_s is not None
                    and dec.first_collision_s - t_s <= self.guard.config.horizon_s):
                dec = self._give_way(dec, state, preds)
            return dec, dec.kind != "keep"

        t_switch, dec = self._decide_in_time(obs, t_switch, dt, decide,
                                             (self.guard.decisions, self.guard.fallbacks))
        self.record.safety = self.guard.log()
        if dec.kind == "keep":
            return
        if dec.kind == "motion":
            self._record_plan(obs.t, t_switch, res)
        self._fallback_active = dec.kind not in ("motion", "keep")
        self.pending = (t_switch, dec.trajectory)

    def _give_way(self, dec: Decision, state: Any, preds: list[PredictedObstacle]) -> Decision:
        """``dec`` (a stoppable motion or keep), or the fallback that is free of the predictions
        where it is not (:func:`~anyplan.agents.evasion.freer_evasion`; the predictions are
        certain here: the full and the planned discs are the same), logged in its place (rule
        ``"give_way"``; ``safe``: predicted collision-free over the guard's horizon)."""
        ranker = FallbackRanker(self.spec, self.obstacles, self.guard, self.check_period_s,
                                swerves=True)
        better = freer_evasion(ranker, dec.t, state, preds, preds, dec.trajectory)
        if better is None:
            return dec
        kind, tr, clear = better
        cfg = self.guard.config
        free = first_collision(tr, preds, self.spec.radius, t_from=dec.t,
                               t_until=max(dec.t + cfg.horizon_s, float(tr.t_end)),
                               margin=cfg.margin, sample_dt=cfg.sample_dt) is None
        out = Decision(dec.t, kind, tr, free, "give_way", first_collision_s=dec.first_collision_s,
                       predicted_clearance_m=clear,
                       reason=f"{dec.kind}: stoppable, collision predicted at "
                              f"{dec.first_collision_s:.2f} s; an evasion is free")
        log = self.guard.decisions
        if log and log[-1] is dec:
            log[-1] = out  # one decision per replanning, as the guard logs it
        else:
            log.append(out)
        self.guard.fallbacks.append({"t": float(dec.t), "kind": kind,
                                     "predicted_clearance_m": finite_or_none(clear),
                                     "reason": out.reason})
        return out

    # --- checks ----------------------------------------------------------------------------------
    def _check(self, obs: Observation, preds: list[PredictedObstacle]) -> None:
        t = obs.t
        if self._requested is not None:
            reason, self._requested = self._requested, None
            self._observe_check(obs, preds)
            self._replan(obs, preds, reason)
            return
        new = self._observe_check(obs, preds)
        traj = self.trajectory
        assert traj is not None
        if self._arrived(obs, traj):
            return
        if self.safety and self._fallback_active:
            # Parked by a fallback: try again to get going.
            if (t - self._last_replan >= self.min_replan_interval_s - 1e-9
                    and t >= self._retry_at - 1e-9):
                self._replan(obs, preds, "after a fallback")
            return
        hit = first_collision(traj, preds, self.spec.radius, t_from=t,
                              t_until=max(traj.t_end, t) + 1.0, margin=0.5 * self.config.margin,
                              sample_dt=self.config.prediction_dt)
        if hit is None:
            return
        if self.safety and not self.guard.still_safe(traj, preds, t, self._commit_s):
            self._replan(obs, preds, f"safety: collision with {hit.obstacle} predicted at "
                                     f"{hit.t:.2f} s, the robot must act now")
            return
        urgent = hit.t - t < self.urgent_s
        if not urgent and not new and t - self._last_replan < self.min_replan_interval_s:
            return
        if t < self._retry_at - 1e-9:
            return  # backing off after failed replannings
        self._replan(obs, preds, f"collision with {hit.obstacle} predicted at {hit.t:.2f} s")
