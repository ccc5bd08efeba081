"""The simulator: one loop that serves every agent alike.

Each step of ``dt`` seconds the agent gets an :class:`~anyplan.agents.base.Observation` (its
pose and twist, and the moving obstacles it can see) and returns a command; the command is
clipped to the robot's limits and the unicycle integrated exactly; the moving obstacles follow
their true motions; collisions are tested over the whole step (chords, exactly), not only at
its end. The run ends at the goal, at the first collision or at the time limit, or at once with
status ``unreachable`` when the goal is proven out of reach
(:func:`~anyplan.simulation.feasibility.goal_unreachable`).

One step in detail: ``docs/experiments.md``, "The simulator: one step".
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from anyplan.agents.base import Agent, AgentStats, Observation
from anyplan.agents.perceiving import TrackingAgent
from anyplan.config import SettingError, setting, validate
from anyplan.errors import UnknownNameError
from anyplan.geometry.collision import COLLISION_EPS
from anyplan.geometry.moving import closest_approach_straight
from anyplan.planning.time_bound import scenario_time_lower_bound
from anyplan.prediction.base import ObstacleObservation
from anyplan.simulation.actuation import ActuationNoise
from anyplan.simulation.contact import (
    approach_speed,
    disc_contact,
    nearest_obstacle_point,
    robot_caused,
    static_contact,
    step_pieces,
)
from anyplan.simulation.feasibility import goal_unreachable
from anyplan.simulation.localization import LocalizationError
from anyplan.simulation.metrics import moving_obstacle_metrics
from anyplan.simulation.perception import (
    Sensor,
    effective_sensing,
    observe_exact,
    tracking_configs,
    with_tracking,
)
from anyplan.simulation.result import WALL_CLOCK_FIELDS, RunResult, RunStatus, without_wall_clock
from anyplan.world.limits import MAX_SIM_STEPS, MAX_TIME_LIMIT_S, MIN_DT_S
from anyplan.world.robot import Command, RobotState, step
from anyplan.world.scenario import Scenario

__all__ = ["SimConfig", "RunResult", "RunStatus", "Simulation", "simulate", "observe",
           "WALL_CLOCK_FIELDS", "without_wall_clock"]


@dataclass(frozen=True)
class SimConfig:
    """Simulation settings.

    Attributes:
        dt: Step and control period [s], in [0.001, 0.05].
        time_limit: Maximum simulated time [s], at most 3600; None uses the scenario's
            ``time_limit``. A run has at most ``MAX_SIM_STEPS`` steps (see :meth:`steps`).
        stop_on_collision: End the run at the first collision.
        announce_motions: Observations carry each visible obstacle's motion model (the paper's
            assumption: the obstacles' motion is known). Off, agents get only the current pose
            and twist and must extrapolate (a constant twist is then wrong at the corners of a
            waypoint track and before a ``start_time``). Off turns a scenario's ``oracle``
            sensing into ``twist``; the scenario's ``sensing:`` block chooses the mode otherwise
            (:mod:`anyplan.simulation.perception`).
        check_feasibility: Before the first step, end the run with status ``unreachable`` when
            the visibility graph proves the goal out of reach.
        actuation_sigma_v, actuation_sigma_omega: The robot drives its achieved twist with a
            correlated error of these spreads [m/s, rad/s] at full motion, smaller as it moves
            less, none at rest (:class:`~anyplan.simulation.actuation.ActuationNoise`; seeded
            by the run's seed, recorded in ``result.extra["actuation"]``); 0 and 0: exactly.
        localization_sigma_xy, localization_sigma_theta: The agent sees its pose off by a
            slowly wandering error of these spreads [m per axis, rad], and what its sensor sees
            off with it (:class:`~anyplan.simulation.localization.LocalizationError`; seeded by
            the run's seed, recorded in ``result.extra["localization"]``); 0 and 0: exactly.
        tracker: With ``tracked`` perception, settings of the robot's tracker and of its
            uncertain discs as ``(name, value)`` pairs (``anyplan run --tracker KEY=VALUE``;
            the names: :func:`~anyplan.simulation.perception.tracking_setting_names`); the
            defaults elsewhere. The run records the settings it used in
            ``result.extra["perception"]["tracker"]``.

    Invalid values raise :class:`~anyplan.config.SettingError` naming the field (``SimConfig.dt``).
    """

    dt: float = setting(0.05, lo=MIN_DT_S, hi=0.05, unit="s", doc="step and control period")
    time_limit: float | None = setting(None, lo=0.0, lo_open=True, hi=MAX_TIME_LIMIT_S, unit="s",
                                       doc="simulated time limit; None: the scenario's")
    stop_on_collision: bool = setting(True, doc="end the run at the first collision")
    announce_motions: bool = setting(True, doc="observations carry the obstacles' motion models")
    check_feasibility: bool = setting(True, doc="end at once when the goal is proven unreachable")
    tracker: tuple[tuple[str, float], ...] = ()
    actuation_sigma_v: float = setting(0.0, lo=0.0, unit="m/s",
                                       doc="speed error's spread at full motion (0: exact)")
    actuation_sigma_omega: float = setting(0.0, lo=0.0, unit="rad/s",
                                           doc="turn-rate error's spread at full motion (0: exact)")
    localization_sigma_xy: float = setting(0.0, lo=0.0, unit="m",
                                           doc="position estimate's error spread per axis (0: exact)")
    localization_sigma_theta: float = setting(0.0, lo=0.0, unit="rad",
                                              doc="heading estimate's error spread (0: exact)")

    @property
    def actuation(self) -> tuple[float, float]:
        """``(actuation_sigma_v, actuation_sigma_omega)`` [m/s, rad/s]."""
        return self.actuation_sigma_v, self.actuation_sigma_omega

    @property
    def localization(self) -> tuple[float, float]:
        """``(localization_sigma_xy, localization_sigma_theta)`` [m, rad]."""
        return self.localization_sigma_xy, self.localization_sigma_theta

    def __post_init__(self) -> None:
        validate(self)
        try:
            tracking_configs(dict(self.tracker), 0.05)
        except UnknownNameError as exc:
            raise SettingError("SimConfig", "tracker", str(exc)) from None

    def steps(self, scenario_time_limit: float) -> int:
        """Number of simulation steps of a run (``ValueError`` beyond ``MAX_SIM_STEPS``)."""
        limit = self.time_limit if self.time_limit is not None else scenario_time_limit
        n = int(math.ceil(limit / self.dt - 1e-9))
        if n > MAX_SIM_STEPS:
            raise ValueError(f"time limit {limit:g} s / dt {self.dt:g} s = {n} steps, more than "
                             f"the limit of {MAX_SIM_STEPS}")
        return n


def observe(scenario: Scenario, t: float, robot: RobotState,
            announce: bool = True) -> tuple[ObstacleObservation, ...]:
    """The moving obstacles visible at time ``t`` [s] (within the sensing range, if any); with
    ``announce`` each observation carries the obstacle's motion model
    (:func:`anyplan.simulation.perception.observe_exact`)."""
    return observe_exact(scenario, t, robot, announce)


class Simulation:
    """The simulator as a steppable object: one control step per :meth:`step`.

    :func:`simulate` drives it with an agent; a Gymnasium environment (:mod:`anyplan.gym`) drives
    it with actions. The physics, the collision test and the metrics are the same.

    Args:
        scenario: The full scenario (truth).
        config: Simulation settings.
        seed: Seed of the sensor's noise (perception modes with noise) and of the robot's
            execution and localization errors (``actuation_sigma_*``, ``localization_sigma_*``).

    Attributes:
        t: Simulation time [s] of the current state.
        state: The robot's current pose and twist.
        done: True once the run is over (goal, collision with ``stop_on_collision``, time limit).
        status: ``"running"``, then ``"reached"``, ``"collision"`` or ``"timeout"``.
        trajectory: Rows ``[t, x, y, theta, v, omega]``, one per step so far.
    """

    def __init__(self, scenario: Scenario, config: SimConfig | None = None, seed: int = 0) -> None:
        cfg = config or SimConfig()
        self.scenario = scenario
        self.config = cfg
        self.dt = cfg.dt
        self.time_limit_s = cfg.time_limit if cfg.time_limit is not None else scenario.time_limit
        self.n_max = cfg.steps(scenario.time_limit)
        #: True when the visibility graph proves the goal out of reach: the run ends at once.
        self.unreachable = bool(cfg.check_feasibility and goal_unreachable(scenario))
        if self.unreachable:
            self.n_max = 0  # nothing to simulate
        spec = scenario.robot
        self._obstacles = scenario.obstacle_set()
        self._movers = scenario.moving_obstacles
        self.state = RobotState(*spec.start, 0.0, 0.0)
        #: The odometry pose: the start moved by the drive's twist each step (the true pose
        #: unless the robot has an execution error).
        self.odom = self.state
        self.t = 0.0
        self.steps = 0
        self.trajectory: list[list[float]] = [[0.0, self.state.x, self.state.y, self.state.theta, 0.0, 0.0]]
        self.path_length_m = 0.0
        self.collision_with: str | None = None
        self.collision_time_s: float | None = None
        self.collision_robot_caused: bool | None = None
        self.collision_approach_speed_mps: float | None = None
        self._contact: tuple[float | None, bool | None] = (None, None)
        self.reached = False
        self.time_to_goal_s: float | None = None
        self.last_step_clearance_m = self._obstacles.clearance((self.state.x, self.state.y)) - spec.radius
        self.min_clearance_m = min(math.inf, self.last_step_clearance_m)
        if self._movers:
            self._p_obs = np.array([o.position(0.0) for o in self._movers])
            self._radii = np.array([o.radius for o in self._movers])
            d0 = (np.hypot(self._p_obs[:, 0] - self.state.x, self._p_obs[:, 1] - self.state.y)
                  - self._radii - spec.radius)
            alive0 = [o.motion.exists(0.0) for o in self._movers]
            if any(alive0):
                self.min_clearance_m = min(self.min_clearance_m, float(d0[alive0].min()))
        else:
            self._p_obs = np.zeros((0, 2))
            self._radii = np.zeros(0)
        self.last_hit: str | None = None
        self.sensor = Sensor(scenario, effective_sensing(scenario, cfg.announce_motions), seed)
        self.actuation = (ActuationNoise(cfg.actuation_sigma_v, cfg.actuation_sigma_omega, seed)
                          if cfg.actuation_sigma_v > 0.0 or cfg.actuation_sigma_omega > 0.0 else None)
        self.localization = (LocalizationError(*cfg.localization, seed)
                             if any(x > 0.0 for x in cfg.localization) else None)
        self.done = False
        self._check_goal()

    def _at_goal(self) -> bool:
        g = self.scenario.robot
        return math.hypot(self.state.x - g.goal[0], self.state.y - g.goal[1]) <= g.goal_tolerance

    def _check_goal(self) -> None:
        """End the run at the goal, or (after the last step) at the time limit."""
        if self.done:
            return
        if self.steps < self.n_max:
            if self._at_goal():
                self.reached, self.time_to_goal_s, self.done = True, self.t, True
        else:
            if self._at_goal():
                self.reached, self.time_to_goal_s = True, self.t
            self.done = True

    @property
    def status(self) -> RunStatus:
        """``running``, ``collision``, ``reached``, ``timeout`` or ``unreachable``."""
        if self.unreachable:
            return RunStatus.UNREACHABLE
        if self.collision_with is not None:
            return RunStatus.COLLISION
        if self.reached:
            return RunStatus.REACHED
        return RunStatus.TIMEOUT if self.done else RunStatus.RUNNING

    def observation(self) -> Observation:
        """What an agent sees now (call it once per step: a sensor may keep state): with a
        localization error, its pose as it believes it, and what it senses placed from there."""
        frames = self.sensor.frames
        seen, detections = self.sensor.observe(self.t, self.state)
        frame = self.sensor.frames != frames
        loc = self.localization
        if loc is None:
            return Observation(self.t, self.state, seen, detections, self.odom, frame)
        return Observation(self.t, loc.estimate(self.state), loc.observed(self.state, seen),
                           loc.detected(self.state, detections), self.odom, frame)

    def step(self, cmd: Command) -> None:
        """Clip ``cmd`` to the robot's limits, integrate one step, move the obstacles, test the
        step for collisions and update the metrics.

        Raises:
            RuntimeError: the run is over.
        """
        if self.done:
            raise RuntimeError("the simulation is over; make a new Simulation")
        spec = self.scenario.robot
        r = spec.radius
        dt = self.dt
        state = self.state
        new = step(spec, state, cmd, dt) if self.actuation is None else self.actuation.step(
            spec, state, cmd, dt)
        # odometry integrates the drive's twist as the exact step does (the same pose, bit for
        # bit, without an execution error)
        self.odom = self.odom.moved(new.v, new.omega, dt)
        t0, t_new = self.t, (self.steps + 1) * dt
        a = np.array([state.x, state.y])
        b = np.array([new.x, new.y])
        self.path_length_m += float(np.hypot(*(b - a)))
        # Static obstacles and walls: exact clearance of the step's chord.
        c_static = self._obstacles.segment_clearance(a, b) - r
        step_clear = c_static
        hit = None
        u = (b - a) / dt  # the robot's velocity over the step's chord [m/s]
        first = self.collision_with is None
        if c_static < -COLLISION_EPS:
            hit = self.scenario.nearest_static(a, b)
            if first:
                pc = a + static_contact(self._obstacles, a, b, r) * (b - a)
                q = nearest_obstacle_point(self._obstacles, pc)
                self._contact = (approach_speed(u, pc, q), robot_caused(u, pc, q))
        if self._movers:
            p_obs, radii = self._p_obs, self._radii
            p_new = np.array([o.position(t_new) for o in self._movers])
            for j, o in enumerate(self._movers):
                lo, hi = o.motion.span  # a recorded track exists only within its span
                s0, s1 = max(t0, lo) - t0, min(t_new, hi) - t0
                if s1 < s0:
                    continue
                for q0, w, ps0, ps1 in step_pieces(o.motion.jumps(t0, t_new), p_obs[j], p_new,
                                                   j, t0, dt, s0, s1):
                    _, d = closest_approach_straight(a, u, q0, w, ps0, ps1)
                    c = d - r - radii[j]
                    if c < step_clear:
                        step_clear = c
                    if c < -COLLISION_EPS and hit is None:
                        hit = o.name
                        if first:
                            tc = disc_contact(a, u, q0, w, r + radii[j], ps0, ps1)
                            pc, q = a + u * tc, q0 + w * tc
                            self._contact = (approach_speed(u, pc, q), robot_caused(u, pc, q))
            self._p_obs = p_new
        self.last_step_clearance_m = float(step_clear)
        self.min_clearance_m = min(self.min_clearance_m, step_clear)
        self.state, self.t = new, t_new
        self.steps += 1
        self.trajectory.append([self.t, new.x, new.y, new.theta, new.v, new.omega])
        if self.localization is not None:
            self.localization.step(dt)
        self.last_hit = hit
        if hit is not None and self.collision_with is None:
            self.collision_with, self.collision_time_s = hit, self.t
            self.collision_approach_speed_mps, self.collision_robot_caused = self._contact
            if self.config.stop_on_collision:
                self.done = True
                return
        self._check_goal()

    def result(self, planner: str, seed: int, stats: AgentStats | None = None,
               wall_time_s: float = 0.0) -> RunResult:
        """The run so far as a :class:`RunResult`."""
        st = AgentStats() if self.unreachable or stats is None else stats
        collided = self.collision_with is not None
        reached = self.reached
        status = (RunStatus.UNREACHABLE if self.unreachable else RunStatus.COLLISION if collided
                  else RunStatus.REACHED if reached else RunStatus.TIMEOUT)
        bound = scenario_time_lower_bound(self.scenario)
        near = moving_obstacle_metrics(self.scenario, np.asarray(self.trajectory))
        ttg = self.time_to_goal_s if reached else None
        return RunResult(
            scenario=self.scenario.name,
            planner=planner,
            seed=int(seed),
            reached_goal=reached and not (collided and self.config.stop_on_collision),
            collision=collided,
            path_length_m=self.path_length_m,
            time_to_goal_s=self.time_to_goal_s if reached else None,
            planning_times_s=list(st.planning_times_s),
            replans=int(st.replans),
            min_clearance_m=float(self.min_clearance_m),
            trajectory=self.trajectory,
            status=status,
            collision_with=self.collision_with,
            collision_time_s=self.collision_time_s,
            virtual_obstacles=list(st.virtual_obstacles),
            plans=list(st.plans),
            scenario_hash=self.scenario.content_hash(),
            dt_s=self.dt,
            wall_time_s=wall_time_s,
            extra={**st.extra_dict(), "perception": self.sensor.record(),
                   **({} if self.actuation is None else {"actuation": self.actuation.record()}),
                   **({} if self.localization is None else {"localization": self.localization.record()})},
            collision_robot_caused=self.collision_robot_caused if collided else None,
            collision_approach_speed_mps=self.collision_approach_speed_mps if collided else None,
            time_lower_bound_s=bound,
            time_over_lower_bound=(ttg / bound if ttg is not None and bound is not None and bound > 0.0
                                   else None),
            min_distance_to_moving_m=near["min_distance_to_moving_m"],
            discomfort_time_s=float(near["discomfort_time_s"] or 0.0),
        )


def simulate(scenario: Scenario, agent: Agent, seed: int = 0,
             config: SimConfig | None = None) -> RunResult:
    """Run ``agent`` on ``scenario`` until the goal, a collision or the time limit.

    Args:
        scenario: The full scenario (the agent only gets its static part).
        agent: The agent; it is reset here, and its ``stats`` start empty, so that an agent
            object used for several runs reports each run alone.
        seed: Seed of the agent's random generator (recorded in the result).
        config: Simulation settings.
    """
    wall0 = time.perf_counter()
    sim = Simulation(scenario, config, seed)
    wall_clock_extra = getattr(agent, "wall_clock_extra", ())
    agent = with_tracking(agent, sim.sensor.spec, dict(sim.config.tracker))
    agent.stats = AgentStats()
    if not sim.unreachable:
        agent.reset(scenario.static_only(), np.random.default_rng(seed))
    while not sim.done:
        sim.step(agent.act(sim.observation()))
    res = sim.result(agent.name, seed, agent.stats, time.perf_counter() - wall0)
    if isinstance(agent, TrackingAgent):  # the tracker's settings, for reproducing the run
        res.extra["perception"]["tracker"] = agent.settings()
    res.wall_clock_fields += [f"extra.{k}" for k in wall_clock_extra if k in res.extra]
    return res
