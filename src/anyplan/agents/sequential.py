"""The ``seq-bitstar`` agent: Sequential BIT* executed online among moving obstacles.

At the start, and whenever a collision with a moving obstacle is predicted on the current
reference motion, the agent runs :class:`~anyplan.planning.sequential.SequentialBITStar` (the
paper's Algorithm 1 with our extensions) and takes up the new motion with Kanayama's tracking law.

Planning takes time, and that time passes in the simulation too: a replanning that starts at
time t plans from the state the robot will have at ``t + d`` on its current reference, where
``d`` is the expected planning time rounded up to the control period, and the robot keeps
following its current reference until then. With ``planning_delay="measured"`` (the default)
``d`` is predicted from the previous planning times and checked against the wall-clock time of
the actual computation: when the computation took longer, the switch waits for it (the new
reference then starts slightly behind the robot's pose; Kanayama's law absorbs the offset). A
fixed ``planning_delay`` in seconds makes runs reproducible for a seed, independent of the
machine.

**The safety invariant** (:mod:`anyplan.agents.safety`) wraps what the agent executes: a new
motion is only taken up when it is predicted collision-free until it ends at rest, or when the
robot can still brake to rest on it without a predicted collision after the time it needs to act
again (check period + planning delay). Otherwise the agent keeps its current motion if that one
still passes, or takes the fallback (brake, hold, turn away, back off) with the largest predicted
clearance; fallbacks are listed in ``stats.extra["fallbacks"]`` and every decision in
``stats.extra["safety"]``. Algorithm 1 itself is unchanged; ``safety=False`` turns the
invariant off (the paper's behaviour: a motion with a predicted collision is taken when no
collision-free one is found).

Moving obstacles are known through observations only; their motion is predicted with a constant
twist (:class:`~anyplan.prediction.ConstantTwistPredictor`), which is exact for the paper's
obstacles. With ``robot.sensing_range`` set, obstacles appear when they come into range and the
next check replans around them.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from anyplan.agents.base import Agent, AgentStats, Observation, TrackingLog
from anyplan.agents.safety import HoldSegment, SafetyConfig, SafetyGuard
from anyplan.agents.warmup import warm_up_kernels
from anyplan.control.kanayama import KanayamaController, KanayamaGains
from anyplan.geometry.shapes import Shape
from anyplan.planning.sequential import SequentialBITStar, SequentialConfig, SequentialResult
from anyplan.prediction.base import ConstantTwistPredictor, PredictedObstacle
from anyplan.prediction.collision import first_collision
from anyplan.trajectory.motion import brake_to_rest, continue_from, plan_motion
from anyplan.trajectory.trajectory import BrakeSegment, Trajectory
from anyplan.world.robot import Command, RobotState
from anyplan.world.scenario import Scenario

__all__ = ["SequentialBITStarAgent", "HoldSegment"]


#: Longest wait [s] between two replannings after repeated failures.
MAX_BACKOFF_S = 2.0


class SequentialBITStarAgent(Agent):
    """Sequential BIT* with online replanning.

    Args:
        config: Settings of the replanning loop (:class:`SequentialConfig`).
        plan_margin: Extra clearance [m] added to the robot radius for BIT* (static obstacles).
        smooth_margin: Extra clearance [m] the smoothed curve must keep (< plan_margin).
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
    """

    name = "seq-bitstar"
    #: Kernel parts this agent uses (:func:`~anyplan.agents.warmup.warm_up_kernels`).
    kernel_parts = ("bitstar", "motion", "sequential")
    config_classes = (SequentialConfig,)
    #: A fixed simulated planning delay [s], a batch budget instead of a time budget, and a
    #: wall-clock cap far above any planning time: the run no longer depends on the machine.
    deterministic_settings = {"planning_delay": 0.1, "batches_per_plan": 2,  # noqa: RUF012
                              "max_time_s": 10.0}
    wall_clock_extra = ("plan_time_s", "motion_time_s", "progress", "late_plans", "safety_time_s")

    def __init__(self, config: SequentialConfig | None = None, *, plan_margin: float = 0.03,
                 smooth_margin: float = 0.015, check_period_s: float = 0.2,
                 min_replan_interval_s: float = 0.5, urgent_s: float = 3.0,
                 planning_delay: str | float = "measured", grid_step: float = 0.05,
                 gains: KanayamaGains | None = None, safety: bool = True,
                 safety_config: SafetyConfig | None = None, **loop_options: Any) -> None:
        super().__init__()
        if config is None:
            config = SequentialConfig(**loop_options)
        elif loop_options:
            raise ValueError("give either config or loop options, not both")
        if not 0.0 <= smooth_margin <= plan_margin:
            raise ValueError("smooth_margin: must be in [0, plan_margin]")
        if not check_period_s > 0.0:
            raise ValueError(f"check_period_s: must be > 0, got {check_period_s}")
        if planning_delay != "measured" and not (isinstance(planning_delay, int | float)
                                                 and planning_delay >= 0.0):
            raise ValueError(f"planning_delay: 'measured' or a delay >= 0 s, got {planning_delay!r}")
        self.config = config
        self.plan_margin = float(plan_margin)
        self.smooth_margin = float(smooth_margin)
        self.check_period_s = float(check_period_s)
        self.min_replan_interval_s = float(min_replan_interval_s)
        self.urgent_s = float(urgent_s)
        self.planning_delay = planning_delay
        self.grid_step = float(grid_step)
        self.gains = gains or KanayamaGains()
        self.safety = bool(safety)
        self.safety_config = safety_config or SafetyConfig(margin=config.margin,
                                                           recheck_margin=0.5 * config.margin)

    # --- lifecycle -------------------------------------------------------------------------------
    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        warm_up_kernels(self.kernel_parts)  # compile or load now, not inside a timed replanning
        self.stats = AgentStats()
        self.spec = scenario.robot
        self.obstacles = scenario.obstacle_set()
        self.rng = rng
        self.predictor = ConstantTwistPredictor()
        self.loop = SequentialBITStar(self.obstacles, self.spec.radius,
                                      self.spec.radius + self.plan_margin, None, self.config, rng)
        self.controller = KanayamaController(self.spec, self.gains, 0.05)
        self.trajectory: Trajectory | None = None
        self.pending: tuple[float, Trajectory] | None = None
        self._dt: float | None = None
        self._last_t: float | None = None
        self._last_check = -math.inf
        self._last_replan = -math.inf
        self._failures = 0  # consecutive replannings without a motion
        self._retry_at = -math.inf  # no replanning before this time [s] (back-off)
        self._seen: set[str] = set()
        self._requested: str | None = None
        self.tracking = TrackingLog()
        self.guard = SafetyGuard(self.spec, self.obstacles, self.safety_config)
        self.executed: list[tuple[float, Trajectory]] = []  # (switch time [s], trajectory)
        self._fallback_active = False
        self._commit_s = self.check_period_s + 0.1
        ex = self.stats.extra
        ex.update({"statuses": {}, "iterations": [], "late_plans": 0, "plan_time_s": [],
                   "motion_time_s": [], "replan_times_s": [], "waits": 0,
                   "fallbacks": self.guard.fallbacks, "safety_time_s": []})

    # --- motions ---------------------------------------------------------------------------------
    def _motion_fn(self, state: RobotState, t_start: float):  # noqa: ANN202
        spec = self.spec
        margin = min(self.smooth_margin,
                     max(self.obstacles.clearance((state.x, state.y)) - spec.radius, 0.0))

        def build(path: np.ndarray, shapes: list[Shape], delay: float) -> Trajectory:
            obst = self.obstacles.with_shapes(shapes) if shapes else self.obstacles
            if delay <= 0.0:
                return plan_motion(path, spec, state, obst, t_start, margin=margin, grid_step=self.grid_step)
            segs, t, rest, _ = brake_to_rest(state, spec, obst, spec.radius + margin, t_start)
            if abs(rest.omega) > 1e-9:  # turning in place: stop the rotation at alpha_max too
                stop = BrakeSegment(rest.x, rest.y, rest.theta, 0.0, rest.omega, spec.a_max,
                                    spec.alpha_max, t)
                segs.append(stop)
                t = stop.t1
                rest = RobotState(*(float(v[0]) for v in stop.sample(np.array([t]))))
            segs.append(HoldSegment(rest.x, rest.y, rest.theta, t, t + delay))
            rest = RobotState(rest.x, rest.y, rest.theta, 0.0, 0.0)
            p = continue_from(np.array([rest.x, rest.y]), np.asarray(path, dtype=float), obst,
                              spec.radius + margin)
            tail = plan_motion(p, spec, rest, obst, t + delay, margin=margin, grid_step=self.grid_step)
            return Trajectory(segs + tail.segments, kind="wait+" + tail.kind, feasible=tail.feasible,
                              lower_bound_s=tail.lower_bound_s, polyline=tail.polyline,
                              info=tail.info, certified_free=tail.certified_free)

        return build

    # --- planning --------------------------------------------------------------------------------
    def _expected_delay(self, dt: float) -> float:
        if self.planning_delay != "measured":
            d = float(self.planning_delay)
        else:
            # 1.5 x the longest of the last five replannings, within [0.1 s, max_time_s]: an
            # outlier must not park the robot on a stale reference for long; a replanning that
            # takes longer than expected is re-timed when it ends (see _replan).
            recent = self.stats.planning_times_s[-5:]
            d = min(max(1.5 * max(recent), 0.1), self.config.max_time_s) if recent else 0.1
        return max(dt, math.ceil(d / dt - 1e-9) * dt)

    def _state_at(self, obs: Observation, t: float) -> RobotState:
        """The state the robot will have at time ``t`` [s]: on its reference, or at rest."""
        if self.trajectory is None:
            r = obs.robot
            return RobotState(r.x, r.y, r.theta, 0.0, 0.0)
        return self.trajectory.state(t)

    def _replan(self, obs: Observation, preds: list[PredictedObstacle], reason: str) -> None:
        dt = self._dt or 0.05
        t = obs.t
        d = self._expected_delay(dt)
        t_ready = t + d
        state = self._state_at(obs, t_ready)
        w0 = time.perf_counter()
        res: SequentialResult = self.loop.replan(np.array([state.x, state.y]),
                                                 np.asarray(self.spec.goal, dtype=float), preds, t,
                                                 self._motion_fn(state, t_ready))
        wall = time.perf_counter() - w0
        self._last_replan = t
        st = self.stats
        st.planning_times_s.append(wall)
        if self.trajectory is not None or len(st.planning_times_s) > 1:
            st.replans += 1
        ex = st.extra
        ex["statuses"][res.status] = ex["statuses"].get(res.status, 0) + 1
        ex["iterations"].append(res.iterations)
        ex["plan_time_s"].append(res.plan_time_s)
        ex["motion_time_s"].append(res.motion_time_s)
        ex["replan_times_s"].append(t)
        ex.setdefault("reasons", []).append(reason)
        if res.status == "waiting":
            ex["waits"] += 1
        st.virtual_obstacles.extend(v.to_dict() for v in res.virtual_obstacles)
        if "progress" not in ex and res.history:
            # BIT*'s cost against solve time in the first planning (OMPL's progress property).
            ex["progress"] = [[float(a), float(b)] for a, b in res.history]
        if res.motion is None:
            if self.safety:
                self._guarded(obs, None, t_ready, d, preds, res)
            # Keep the current reference (or stay put); try again after a back-off that doubles
            # with each consecutive failure up to MAX_BACKOFF_S, so that a goal no planning
            # reaches costs a bounded fraction of real time.
            self._failures += 1
            self._retry_at = t + min(dt * 2.0 ** (self._failures - 1), MAX_BACKOFF_S)
            return
        self._failures = 0
        motion: Trajectory = res.motion  # type: ignore[assignment]
        t_switch = t_ready
        if self.planning_delay == "measured" and wall > d + 1e-9:
            # Late: the computation outlasted the expected delay. The robot went on with its
            # current reference (or stayed at rest) meanwhile, so the new motion is re-timed
            # from the state it will have when the new plan is really ready. The re-timing
            # time counts as planning time too.
            w1 = time.perf_counter()
            ex["late_plans"] += 1
            t_switch = t + math.ceil(wall / dt - 1e-9) * dt
            state = self._state_at(obs, t_switch)
            shapes = [v.shape for v in res.virtual_obstacles]
            motion = self._motion_fn(state, t_switch)(res.path, shapes, res.delay_s)
            st.planning_times_s[-1] = wall + (time.perf_counter() - w1)
        if self.safety:
            self._guarded(obs, motion, t_switch, t_switch - t, preds, res)
            return
        self._record_plan(t, t_switch, res)
        self.pending = (t_switch, motion)

    def _record_plan(self, t: float, t_switch: float, res: SequentialResult) -> None:
        self.stats.plans.append({"t": t, "t_start": t_switch, "path": np.asarray(res.path).tolist(),
                                 "status": res.status, "virtual_obstacles": len(res.virtual_obstacles),
                                 "delay_s": res.delay_s})

    def _guarded(self, obs: Observation, motion: Trajectory | None, t_switch: float, delay: float,
                 preds: list[PredictedObstacle], res: SequentialResult) -> None:
        """Let the safety guard decide what the robot executes from ``t_switch`` [s]."""
        w0 = time.perf_counter()
        # Before the agent can act again: one check period, then a replanning's delay.
        self._commit_s = self.check_period_s + delay
        current = self.trajectory
        state = self._state_at(obs, t_switch)
        dec = self.guard.decide(t_switch, motion, current, state, preds, self._commit_s)
        wall = time.perf_counter() - w0
        self.stats.planning_times_s[-1] += wall  # the decision is part of the planning call
        ex = self.stats.extra
        ex["safety_time_s"].append(wall)
        ex["safety"] = self.guard.log()
        if dec.kind == "keep":
            return
        if dec.kind == "motion":
            self._record_plan(obs.t, t_switch, res)
        self._fallback_active = dec.kind not in ("motion", "keep")
        self.pending = (t_switch, dec.trajectory)

    # --- control ---------------------------------------------------------------------------------
    def act(self, obs: Observation) -> Command:
        if self._last_t is not None and obs.t > self._last_t:
            self._dt = obs.t - self._last_t
            self.controller.dt = self._dt
        self._last_t = obs.t
        t = obs.t
        preds = self.predictor.predict(obs.obstacles)
        if self.pending is not None and t >= self.pending[0] - 1e-9:
            self._switch()
        if self.trajectory is None and self.pending is None:
            # The first plan: the robot stays at rest while it is computed.
            if t < self._retry_at - 1e-9:
                return Command(0.0, 0.0)
            self._replan(obs, preds, "initial")
            self._last_check = t
            self._seen = {p.name for p in preds}
            if self.pending is not None and t >= self.pending[0] - 1e-9:
                self._switch()
        elif (self.trajectory is not None and self.pending is None
              and (t - self._last_check >= self.check_period_s - 1e-9
                   or self._requested is not None)):
            self._check(obs, preds)
        traj = self.trajectory
        if traj is None:
            return Command(0.0, 0.0)
        ref = traj.state(t)
        self.tracking.add((ref.x, ref.y), obs.robot, self.stats.extra)
        return self.controller.command(traj, obs.robot, t)

    def request_replan(self, reason: str) -> None:
        """Replan at the next step (e.g. an obstacle left its predicted tube)."""
        self._requested = reason

    def _switch(self) -> None:
        assert self.pending is not None
        self.trajectory = self.pending[1]
        self.executed.append(self.pending)
        self.pending = None

    def _check(self, obs: Observation, preds: list[PredictedObstacle]) -> None:
        t = obs.t
        if self._requested is not None:
            reason, self._requested = self._requested, None
            self._last_check = t
            self._seen |= {p.name for p in preds}
            self._replan(obs, preds, reason)
            return
        self._last_check = t
        traj = self.trajectory
        assert traj is not None
        names = {p.name for p in preds}
        new = names - self._seen
        self._seen |= names
        if t >= traj.t_end and math.hypot(obs.robot.x - self.spec.goal[0],
                                          obs.robot.y - self.spec.goal[1]) <= self.spec.goal_tolerance:
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
