"""The online timing policy shared by the replanning agents (``seq-bitstar``, ``st-bitstar``).

:class:`ReplanningAgent` decides *when* to plan and *when* a new motion takes over; subclasses
decide *what* to plan (:meth:`ReplanningAgent._replan`) and when the current motion needs it
(:meth:`ReplanningAgent._check`). Planning takes simulated time: a replanning decided at t plans
from the state the robot will have at ``t + d`` on its current reference, d being the expected
planning delay rounded up to the control period (``planning_delay``: ``"measured"`` or fixed
seconds); a computation that outlasts d switches later (a *late plan*). The motion in use is
re-checked every ``check_period_s`` and tracked with Kanayama's law; a robot found farther than
``reanchor_m`` from its reference plans from its own state instead. The bookkeeping of one
replanning (statuses, reasons, counts) lives in :meth:`ReplanningAgent._record_replan`, into a
:class:`~anyplan.agents.stats.SequentialStats` record. See ``docs/sequential.md`` ("Online
execution").
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from anyplan.agents.base import Agent, AgentStats, Observation, TrackingLog, checked_number
from anyplan.agents.stats import SequentialStats
from anyplan.control.kanayama import KanayamaController, KanayamaGains
from anyplan.geometry.se2 import wrap_angle
from anyplan.prediction.base import ConstantTwistPredictor, PredictedObstacle
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world.robot import Command, RobotSpec, RobotState

__all__ = ["ReplanningAgent", "MAX_BACKOFF_S", "REANCHOR_RAD"]

#: Longest wait [s] between two replannings after repeated failures.
MAX_BACKOFF_S = 2.0

#: Heading error [rad] beyond which the robot is off its reference (``reanchor_m``).
REANCHOR_RAD = 0.3


class ReplanningAgent(Agent):
    """Replans online and tracks the reference (see the module docstring).

    Args:
        check_period_s: How often [s] the current motion is checked against the predictions.
        min_replan_interval_s: Minimum time [s] between two replannings (unless the predicted
            collision is closer than ``urgent_s``).
        urgent_s: Predicted collisions closer than this [s] replan at once.
        planning_delay: ``"measured"`` (from the wall-clock time of the computation) or a fixed
            delay [s] by which each new motion starts after the replanning decision.
        max_delay_s: Cap [s] on the measured delay.
        gains: Kanayama gains.
        reanchor_m: Tracking error [m] beyond which the robot is *off its reference* (also when
            its heading is more than :data:`REANCHOR_RAD` off): the next motion then starts
            from the robot's own state, its twist held until the switch, instead of the
            reference's, and a replanning is asked for. None: always from the reference.
    """

    record: SequentialStats
    spec: RobotSpec
    predictor: ConstantTwistPredictor

    def __init__(self, *, check_period_s: float = 0.2, min_replan_interval_s: float = 0.5,
                 urgent_s: float = 3.0, planning_delay: str | float = "measured",
                 max_delay_s: float = 0.5, gains: KanayamaGains | None = None,
                 reanchor_m: float | None = 0.2) -> None:
        super().__init__()
        if not check_period_s > 0.0:
            raise ValueError(f"check_period_s: must be > 0, got {check_period_s}")
        if planning_delay != "measured" and not (isinstance(planning_delay, int | float)
                                                 and planning_delay >= 0.0):
            raise ValueError(f"planning_delay: 'measured' or a delay >= 0 s, got {planning_delay!r}")
        self.check_period_s = float(check_period_s)
        self.min_replan_interval_s = checked_number("min_replan_interval_s", min_replan_interval_s)
        self.urgent_s = checked_number("urgent_s", urgent_s)
        self.planning_delay = planning_delay
        self.max_delay_s = checked_number("max_delay_s", max_delay_s, lo_open=True)
        self.gains = gains or KanayamaGains()
        if reanchor_m is not None and not (isinstance(reanchor_m, int | float) and reanchor_m > 0.0):
            raise ValueError(f"reanchor_m: must be > 0 or null, got {reanchor_m!r}")
        self.reanchor_m = None if reanchor_m is None else float(reanchor_m)

    # --- lifecycle -------------------------------------------------------------------------------
    def _reset_timing(self, record: SequentialStats) -> None:
        """Start a run: empty stats with ``record``, no motion, nothing pending."""
        self.record = record
        self.stats = AgentStats(record=record)
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
        self._off_reference = False  # the robot is off its reference at this step (reanchor_m)
        self.tracking = TrackingLog()
        self.executed: list[tuple[float, Trajectory]] = []  # (switch time [s], trajectory)
        self._call_start = 0.0  # wall clock [s] at the start of the replanning call
        self._late_mark = 0  # late_plans at its start (a late call counts once)

    # --- timing ----------------------------------------------------------------------------------
    def _expected_delay(self, dt: float) -> float:
        if self.planning_delay != "measured":
            d = float(self.planning_delay)
        else:
            # 1.5 x the longest of the last five replannings, within [0.1 s, max_delay_s]: an
            # outlier must not park the robot on a stale reference for long; a replanning that
            # takes longer than expected is re-timed when it ends (see _late_switch).
            recent = self.stats.planning_times_s[-5:]
            d = min(max(1.5 * max(recent), 0.1), self.max_delay_s) if recent else 0.1
        return max(dt, math.ceil(d / dt - 1e-9) * dt)

    def _state_at(self, obs: Observation, t: float) -> RobotState:
        """The state the robot will have at time ``t`` [s]: on its reference, or at rest; off
        its reference (``reanchor_m``), its own pose moved on with its twist held."""
        r = obs.robot
        if self.trajectory is None:
            return RobotState(r.x, r.y, r.theta, 0.0, 0.0)
        if self._off_reference:
            return r.moved(r.v, r.omega, max(t - obs.t, 0.0))
        return self.trajectory.state(t)

    def _note_tracking(self, obs: Observation, traj: Trajectory) -> None:
        """Log this step's tracking error and note whether the robot is off its reference
        (``reanchor_m``); if it is, ask for a replanning (from the robot's own state)."""
        ref = traj.state(obs.t)
        r = obs.robot
        err = self.tracking.add((ref.x, ref.y), r, self.record)
        off = self.reanchor_m is not None and (
            err > self.reanchor_m or abs(float(wrap_angle(r.theta - ref.theta))) > REANCHOR_RAD)
        if off and not self._off_reference:
            self.record.reanchored_s.append(float(obs.t))  # once an excursion
        if (off and self.pending is None and self._requested is None
                and obs.t - self._last_replan >= self._period() - 1e-9):
            # (again each check period while it lasts: a replanning may find nothing to start)
            self.request_replan(f"off the reference by {err:.2f} m: "
                                "the next motion starts from the robot's own state")
        self._off_reference = off

    def _in_use(self) -> Trajectory | None:
        """The motion in use, as a candidate to keep: None while the robot is off it
        (``reanchor_m``), since what is checked along it is not where the robot goes."""
        return None if self._off_reference else self.trajectory

    def _begin_replan(self, obs: Observation) -> tuple[float, float, float, RobotState]:
        """``(dt, d, t_ready, state)``: the control period, the expected delay, the time the new
        motion will start and the robot's state then."""
        dt = self._dt or 0.05
        d = self._expected_delay(dt)
        t_ready = obs.t + d
        return dt, d, t_ready, self._state_at(obs, t_ready)

    def _late_switch(self, t: float, wall: float, d: float, dt: float) -> float | None:
        """The later switch time [s] of a measured replanning that outlasted ``d`` [s] (counted
        in ``late_plans``), or None when it was on time."""
        if self.planning_delay == "measured" and wall > d + 1e-9:
            self._count_late()
            return t + math.ceil(wall / dt - 1e-9) * dt
        return None

    def _count_late(self) -> None:
        """Count this replanning call in ``late_plans`` (once)."""
        if self.record.late_plans == self._late_mark:
            self.record.late_plans += 1

    def _whole_call(self, obs: Observation, call: Callable[[], None]) -> None:
        """Run one replanning ``call()`` and book its whole wall-clock time in
        ``planning_times_s`` (and so in the measured delay of the next calls): the planning,
        a late re-timing, the safety guard and the fallbacks. A decision ready after its own
        switch time is late too (:meth:`_late_decision`)."""
        w0 = self._call_start = time.perf_counter()
        times = self.stats.planning_times_s
        n, pending = len(times), self.pending
        self._late_mark = self.record.late_plans
        call()
        if len(times) > n:
            times[-1] = wall = time.perf_counter() - w0
            if (self.planning_delay == "measured" and self.pending is not None
                    and self.pending is not pending and wall > self.pending[0] - obs.t + 1e-9):
                self._count_late()

    def _late_decision(self, obs: Observation, t_switch: float, dt: float) -> float | None:
        """With a measured planning delay, the later switch time [s] (on the control grid of
        period ``dt`` [s]) of a decision for ``t_switch`` [s] that this call, begun at
        ``obs.t``, is still computing at ``t_switch`` (counted in ``late_plans``); None when it
        is ready in time. The robot follows its reference until then, so the caller makes the
        decision again from the state it has at that time, as a late plan is re-timed
        (:meth:`_take_up`); the second pass's own time is booked but not charged to the
        switch, as the re-timing's is not."""
        if self.planning_delay != "measured":
            return None
        elapsed = time.perf_counter() - self._call_start
        if elapsed <= t_switch - obs.t + 1e-9:
            return None
        self._count_late()
        return obs.t + math.ceil(elapsed / dt - 1e-9) * dt

    def _decide_in_time(self, obs: Observation, t_switch: float, dt: float,
                        decide: Callable[[float], tuple[Any, bool]],
                        logs: Sequence[list[Any]]) -> tuple[float, Any]:
        """A safety decision for the switch at ``t_switch`` [s]: ``decide(t_s)`` returns the
        decision for a switch at ``t_s`` and whether it switches anything. One that would be
        ready after ``t_switch`` (:meth:`_late_decision`) is made again for the later switch
        time, what the first pass appended to ``logs`` dropped. Its time goes to
        ``safety_time_s``. Returns (switch time [s], decision)."""
        g0 = time.perf_counter()
        marks = [len(log) for log in logs]
        out, switches = decide(t_switch)
        late = self._late_decision(obs, t_switch, dt) if switches else None
        if late is not None:
            for log, mark in zip(logs, marks, strict=True):
                del log[mark:]
            t_switch = late
            out, _ = decide(late)
        self.record.safety_time_s.append(time.perf_counter() - g0)
        return t_switch, out

    def _take_up(self, obs: Observation, t_ready: float, wall: float, d: float, dt: float,
                 motion: Trajectory | None,
                 retime: Callable[[RobotState, float], Trajectory | None]
                 ) -> tuple[float, Trajectory | None]:
        """When and what the robot takes up: ``motion`` at ``t_ready`` [s]; or, when the
        replanning (``wall`` [s]) outlasted the expected delay ``d`` [s], ``retime(state,
        t_switch)`` from the state the robot will have at the later switch time (the robot went
        on with its current reference meanwhile; the re-timing is booked with the whole call,
        :meth:`_whole_call`)."""
        late = self._late_switch(obs.t, wall, d, dt)
        if late is None:
            return t_ready, motion
        return late, retime(self._state_at(obs, late), late)

    def _record_replan(self, t: float, wall: float, res: Any, reason: str) -> None:
        """Book one replanning at ``t`` [s] that took ``wall`` [s] with result ``res`` (a
        :class:`~anyplan.planning.sequential.SequentialResult`)."""
        self._last_replan = t
        st, rec = self.stats, self.record
        st.planning_times_s.append(wall)
        if self.trajectory is not None or len(st.planning_times_s) > 1:
            st.replans += 1
        rec.statuses[res.status] = rec.statuses.get(res.status, 0) + 1
        rec.iterations.append(res.iterations)
        rec.replan_times_s.append(t)
        rec.reasons.append(reason)
        st.virtual_obstacles.extend(v.to_dict() for v in res.virtual_obstacles)

    # --- control ---------------------------------------------------------------------------------
    def act(self, obs: Observation) -> Command:
        if self._last_t is not None and obs.t > self._last_t:
            self._dt = obs.t - self._last_t
            self.controller.dt = self._dt
        self._last_t = obs.t
        t = obs.t
        preds = self.predictor.predict(obs.obstacles)
        self._note_predictions(preds)
        if self.pending is not None and t >= self.pending[0] - 1e-9:
            self._switch()
        noted = self.trajectory is not None
        if noted:
            self._note_tracking(obs, self.trajectory)  # type: ignore[arg-type]
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
              and (t - self._last_check >= self._period() - 1e-9
                   or self._requested is not None or self._new_within_reach(obs, preds))):
            self._check(obs, preds)
        traj = self.trajectory
        if traj is None:
            return Command(0.0, 0.0)
        if not noted:
            self._note_tracking(obs, traj)
        return self.controller.command(traj, obs.robot, t)

    def request_replan(self, reason: str) -> None:
        """Replan at the next step (e.g. an obstacle left its predicted tube)."""
        self._requested = reason

    def _switch(self) -> None:
        assert self.pending is not None
        self.trajectory = self.pending[1]
        self.executed.append(self.pending)
        self.pending = None

    def _observe_check(self, obs: Observation, preds: list[PredictedObstacle]) -> bool:
        """Start a periodic check at ``obs.t``: note the obstacles seen; True if one is new."""
        self._last_check = obs.t
        names = {p.name for p in preds}
        new = names - self._seen
        self._seen |= names
        return bool(new)

    def _new_within_reach(self, obs: Observation, preds: list[PredictedObstacle]) -> bool:
        """Whether an obstacle not seen before is close enough to meet the robot before the
        next periodic check and a brake from there could end: its gap to the robot's disc
        [m] at most (robot speed + its speed) x (check period + braking time). Then the motion
        in use is checked at once, not up to a period later: a person stepping out 0.7 m
        ahead of a robot at 1 m/s (ETH hotel window 7, seed 2) was seen 0.1 s before the
        check, and the robot stopped 2 mm too late. Obstacles first seen farther away wait
        for the period, as before: on DynaBARN ``tracked`` checking at once whatever the
        distance (12-20 m, out from behind walls) shifted every later check, and 231 of 400
        runs reached against 249."""
        new = [p for p in preds if p.name not in self._seen]
        if not new:
            return False
        r, spec = obs.robot, self.spec
        v = abs(r.v)
        window = self._period() + v / spec.a_max
        for p in new:
            q = p.positions(np.array([obs.t]))[0]
            gap = math.hypot(q[0] - r.x, q[1] - r.y) - spec.radius - p.radius
            if gap <= (v + p.max_speed) * window:
                return True
        return False

    def _arrived(self, obs: Observation, traj: Trajectory) -> bool:
        """The motion is over and the robot within the goal tolerance."""
        spec = self.spec
        return obs.t >= traj.t_end and math.hypot(obs.robot.x - spec.goal[0],
                                                  obs.robot.y - spec.goal[1]) <= spec.goal_tolerance

    # --- what subclasses provide -----------------------------------------------------------------
    def _note_predictions(self, preds: list[PredictedObstacle]) -> None:
        """Called with each step's predictions before anything is decided (nothing here)."""

    def _period(self) -> float:
        """The period [s] of the checks of the motion in use: ``check_period_s``."""
        return self.check_period_s

    def _replan(self, obs: Observation, preds: list[PredictedObstacle], reason: str) -> None:
        raise NotImplementedError

    def _check(self, obs: Observation, preds: list[PredictedObstacle]) -> None:
        raise NotImplementedError
