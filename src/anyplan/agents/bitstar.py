"""The ``bitstar`` agent: plan once with BIT* among the static obstacles, then drive.

The static part of the method of Roy, Harchowdhury & Vachhani ("Anytime Planning: A Motion
Planner for Dynamic Environment", §4): BIT* (Gammell, Srinivasa & Barfoot 2015) plans a shortest
path among the static obstacles; the path is smoothed with a cubic spline and given a reference
motion within the robot's limits (:func:`anyplan.trajectory.plan_motion`); Kanayama's tracking
law follows it (:mod:`anyplan.control`). Moving obstacles are ignored: this agent is the baseline
that shows what Sequential BIT* adds.

Clearance margins: BIT* plans for a disc ``plan_margin`` larger than the robot, the smoothed curve
must keep ``smooth_margin`` (< plan_margin) beyond the robot radius, and the tracking error (a few
micrometres in simulation) must stay below ``smooth_margin``. The slack between the two margins is
what lets the spline round the corners of BIT*'s path without cutting into an obstacle.
"""

from __future__ import annotations

import time

import numpy as np

from anyplan.agents.base import (
    Agent,
    AgentStats,
    Observation,
    TrackingLog,
    checked_number,
    checked_pose_margin,
)
from anyplan.agents.stats import BITStarStats
from anyplan.agents.warmup import warm_up_kernels
from anyplan.control.kanayama import KanayamaController, KanayamaGains
from anyplan.trajectory.motion import plan_motion
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world.robot import Command, RobotState
from anyplan.world.scenario import Scenario

__all__ = ["BITStarAgent"]


class BITStarAgent(Agent):
    """Plan once with BIT*, smooth, profile and track.

    Args:
        time_budget_s: Wall-clock budget [s] of the BIT* call.
        plan_margin: Extra clearance [m] added to the robot radius for BIT*.
        smooth_margin: Extra clearance [m] the smoothed curve must keep.
        max_attempts: BIT* calls (each with twice the previous budget) before giving up.
        gains: Kanayama gains (defaults: :class:`~anyplan.control.KanayamaGains`).
        control_dt: Control period [s] assumed before the second observation reveals it.
        pose_margin_m: Extra clearance [m] kept from the obstacles for the robot's localization
            error, added to both margins as far as the way to the goal leaves room for it
            (:func:`~anyplan.planning.visgraph.usable_margin`; as ``seq-bitstar``'s). 0: none.
    """

    name = "bitstar"
    #: Kernel parts this agent uses (:func:`~anyplan.agents.warmup.warm_up_kernels`).
    kernel_parts = ("bitstar", "motion")
    wall_clock_extra = BITStarStats.WALL_CLOCK

    def __init__(self, time_budget_s: float = 0.5, plan_margin: float = 0.03,
                 smooth_margin: float = 0.015, max_attempts: int = 3,
                 gains: KanayamaGains | None = None, control_dt: float = 0.05,
                 pose_margin_m: float = 0.0) -> None:
        super().__init__()
        if not time_budget_s > 0.0:
            raise ValueError(f"time_budget_s must be > 0 s, got {time_budget_s}")
        if not 0.0 <= smooth_margin <= plan_margin:
            raise ValueError("smooth_margin must be in [0, plan_margin]")
        self.pose_margin_m = checked_pose_margin(pose_margin_m)
        if max_attempts < 1:
            raise ValueError(f"max_attempts must be >= 1, got {max_attempts}")
        self.time_budget_s = float(time_budget_s)
        self.plan_margin = float(plan_margin)
        self.smooth_margin = float(smooth_margin)
        self.max_attempts = int(max_attempts)
        self.gains = gains or KanayamaGains()
        self.control_dt = checked_number("control_dt", control_dt, lo_open=True)
        self.trajectory: Trajectory | None = None

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        warm_up_kernels(self.kernel_parts)  # compile or load now, not inside the timed planning
        self.record = BITStarStats()
        self.stats = AgentStats(record=self.record)
        self.scenario = scenario
        self.spec = scenario.robot
        self.obstacles = scenario.obstacle_set()
        self.rng = rng
        self.trajectory = None
        self.failed = False
        self.controller = KanayamaController(self.spec, self.gains, self.control_dt)
        self._last_t: float | None = None
        self.tracking = TrackingLog()

    # --- planning -----------------------------------------------------------------------------
    def _plan(self, obs: Observation) -> None:
        from anyplan.planning import plan

        spec, r = self.spec, obs.robot
        start = (r.x, r.y)
        extra = 0.0
        if self.pose_margin_m > 0.0:  # the localization margin the way to the goal leaves room for
            from anyplan.planning.visgraph import usable_margin

            extra = usable_margin(self.obstacles, start, spec.goal, spec.radius + self.plan_margin,
                                  self.pose_margin_m)
            self.record.pose_margin_m = extra
        # Keep the margin only where the start allows it (a start hugging an obstacle).
        margin = min(self.plan_margin + extra,
                     max(self.obstacles.clearance(start) - spec.radius, 0.0))
        smooth_margin = min(self.smooth_margin + extra, margin)
        t0 = time.perf_counter()
        budget = self.time_budget_s
        res = None
        for _ in range(self.max_attempts):
            res = plan(self.obstacles, start, spec.goal, spec.radius + margin, planner="bitstar",
                       time_budget_s=budget, rng=self.rng)
            if res.solved:
                break
            budget *= 2.0
        t1 = time.perf_counter()
        if res is None or not res.solved:
            self.stats.planning_times_s.append(t1 - t0)
            self.failed = True
            self.record.plan_status = None if res is None else res.status.value
            return
        path = np.asarray(res.path, dtype=float)
        traj = plan_motion(path, spec, r, self.obstacles, obs.t, margin=smooth_margin)
        t2 = time.perf_counter()
        self.trajectory = traj
        self.stats.planning_times_s.append(t2 - t0)
        self.stats.plans.append({"t": obs.t, "path": path.tolist()})
        rec = self.record
        rec.plan_status = res.status.value
        rec.bitstar_time_s = t1 - t0
        rec.motion_time_s = t2 - t1
        rec.path_cost_m = float(res.cost)
        rec.trajectory_kind = traj.kind
        rec.trajectory_certified_free = traj.certified_free
        rec.smoothed_length_m = traj.length
        rec.reference_duration_s = traj.duration
        rec.time_lower_bound_s = traj.lower_bound_s
        rec.smoothed_path = traj.path[:: max(1, len(traj.path) // 400)].tolist()
        # BIT*'s cost against its own solve time, [[t_s, cost_m], ...] (OMPL's progress).
        rec.progress = [[float(t), float(c)] for t, c in res.history]

    # --- control ------------------------------------------------------------------------------
    def act(self, obs: Observation) -> Command:
        if self._last_t is not None and obs.t > self._last_t:
            self.controller.dt = obs.t - self._last_t
        self._last_t = obs.t
        if self.trajectory is None and not self.failed:
            self._plan(obs)
        traj = self.trajectory
        if traj is None:
            return Command(0.0, 0.0)
        ref = traj.state(obs.t)
        self.tracking.add((ref.x, ref.y), obs.robot, self.record)
        return self.controller.command(traj, obs.robot, obs.t)

    def reference_state(self, t: float) -> RobotState | None:
        """The reference state at time ``t`` [s], or None before planning."""
        if self.trajectory is None:
            return None
        return self.trajectory.state(t)
