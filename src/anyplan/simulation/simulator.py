"""The simulator: one loop that serves every agent alike.

Each step of ``dt`` seconds:

1. the agent gets an :class:`~anyplan.agents.base.Observation` (its pose and twist, and the
   moving obstacles it can see) and returns a command;
2. the command is clipped to the robot's dynamic limits and the unicycle is integrated exactly;
3. the moving obstacles follow their true motions;
4. collisions are tested over the whole step, not only at its end: the robot's chord against
   the static shapes and walls exactly, and the closest approach of the robot's and each
   obstacle's chords in relative motion. (Over dt = 0.05 s the chord of a 0.4 rad/s arc departs
   from the arc by less than 0.1 mm.)

The run ends at the goal (within ``goal_tolerance``), at the first collision (unless
``stop_on_collision`` is off) or at the time limit. Before the first step, when the visibility
graph proves the goal out of reach among the static obstacles
(:func:`~anyplan.simulation.feasibility.goal_unreachable`), the run ends at once with status
``unreachable``.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from anyplan import __version__
from anyplan.agents.base import Agent, AgentStats, Observation
from anyplan.geometry.collision import COLLISION_EPS
from anyplan.geometry.moving import closest_approach_straight
from anyplan.planning.time_bound import scenario_time_lower_bound
from anyplan.prediction.base import ObstacleObservation
from anyplan.simulation.contact import (
    approach_speed,
    disc_contact,
    nearest_obstacle_point,
    robot_caused,
    static_contact,
)
from anyplan.simulation.feasibility import goal_unreachable
from anyplan.simulation.metrics import moving_obstacle_metrics
from anyplan.simulation.perception import Sensor, effective_sensing, observe_exact, with_tracking
from anyplan.world.limits import MAX_SIM_STEPS, MAX_TIME_LIMIT_S, MIN_DT_S
from anyplan.world.robot import RobotState, step
from anyplan.world.scenario import Scenario

__all__ = ["SimConfig", "RunResult", "simulate"]


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
    """

    dt: float = 0.05
    time_limit: float | None = None
    stop_on_collision: bool = True
    announce_motions: bool = True
    check_feasibility: bool = True

    def __post_init__(self) -> None:
        if not MIN_DT_S <= self.dt <= 0.05:
            raise ValueError(f"dt must be in [{MIN_DT_S:g}, 0.05] s, got {self.dt}")
        if self.time_limit is not None and not 0.0 < self.time_limit <= MAX_TIME_LIMIT_S:
            raise ValueError(f"time_limit must be in (0, {MAX_TIME_LIMIT_S:g}] s, "
                             f"got {self.time_limit}")

    def steps(self, scenario_time_limit: float) -> int:
        """Number of simulation steps of a run (``ValueError`` beyond ``MAX_SIM_STEPS``)."""
        limit = self.time_limit if self.time_limit is not None else scenario_time_limit
        n = int(math.ceil(limit / self.dt - 1e-9))
        if n > MAX_SIM_STEPS:
            raise ValueError(f"time limit {limit:g} s / dt {self.dt:g} s = {n} steps, more than "
                             f"the limit of {MAX_SIM_STEPS}")
        return n


@dataclass
class RunResult:
    """The outcome of one simulated run (the ``result.json`` contract).

    Lengths in m, times in s, angles in rad. ``trajectory`` rows are
    ``[t, x, y, theta, v, omega]``, one per simulation step (the first at t = 0).

    ``collision_robot_caused`` (None without a collision) tells whether, at the first contact,
    the robot's velocity had a component of more than 0.05 m/s towards what it hit
    (:mod:`anyplan.simulation.contact`); ``collision_approach_speed_mps`` is that component.
    ``time_lower_bound_s`` is the least time from rest to the edge of the goal tolerance along
    the static shortest path (:func:`anyplan.planning.time_bound.scenario_time_lower_bound`;
    None without a path) and ``time_over_lower_bound`` the time to goal over it.
    """

    scenario: str
    planner: str
    seed: int
    reached_goal: bool
    collision: bool
    path_length_m: float
    time_to_goal_s: float | None
    planning_times_s: list[float]
    replans: int
    min_clearance_m: float
    trajectory: list[list[float]]
    status: str = "timeout"
    collision_with: str | None = None
    collision_time_s: float | None = None
    virtual_obstacles: list[dict[str, Any]] = field(default_factory=list)
    plans: list[dict[str, Any]] = field(default_factory=list)
    scenario_hash: str = ""
    dt_s: float = 0.05
    wall_time_s: float = 0.0
    anyplan_version: str = __version__
    extra: dict[str, Any] = field(default_factory=dict)
    collision_robot_caused: bool | None = None
    collision_approach_speed_mps: float | None = None
    time_lower_bound_s: float | None = None
    time_over_lower_bound: float | None = None
    #: Smallest robot-to-moving-obstacle surface distance [m] (None without moving obstacles)
    #: and time [s] within 0.2 m of one (:mod:`anyplan.simulation.metrics`).
    min_distance_to_moving_m: float | None = None
    discomfort_time_s: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable dictionary."""
        return _jsonable(asdict(self))

    @property
    def trajectory_array(self) -> np.ndarray:
        """The trajectory as an array, shape (N, 6)."""
        return np.asarray(self.trajectory, dtype=float).reshape(-1, 6)


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.floating | float):
        x = float(obj)
        return x if math.isfinite(x) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def observe(scenario: Scenario, t: float, robot: RobotState,
            announce: bool = True) -> tuple[ObstacleObservation, ...]:
    """The moving obstacles visible at time ``t`` [s] (within the sensing range, if any); with
    ``announce`` each observation carries the obstacle's motion model
    (:func:`anyplan.simulation.perception.observe_exact`)."""
    return observe_exact(scenario, t, robot, announce)


def simulate(scenario: Scenario, agent: Agent, seed: int = 0,
             config: SimConfig | None = None) -> RunResult:
    """Run ``agent`` on ``scenario`` until the goal, a collision or the time limit.

    Args:
        scenario: The full scenario (the agent only gets its static part).
        agent: A fresh agent; it is reset here.
        seed: Seed of the agent's random generator (recorded in the result).
        config: Simulation settings.
    """
    cfg = config or SimConfig()
    dt = cfg.dt
    n_max = cfg.steps(scenario.time_limit)
    spec = scenario.robot
    r = spec.radius
    obstacles = scenario.obstacle_set()
    movers = scenario.moving_obstacles
    wall0 = time.perf_counter()
    sensor = Sensor(scenario, effective_sensing(scenario, cfg.announce_motions), seed)
    agent = with_tracking(agent, sensor.spec)
    unreachable = cfg.check_feasibility and goal_unreachable(scenario)
    if unreachable:
        n_max = 0  # nothing to simulate
    else:
        agent.reset(scenario.static_only(), np.random.default_rng(seed))

    state = RobotState(*spec.start, 0.0, 0.0)
    t = 0.0
    traj = [[0.0, state.x, state.y, state.theta, 0.0, 0.0]]
    length = 0.0
    min_clear = math.inf
    collision_with: str | None = None
    collision_time: float | None = None
    caused: bool | None = None
    approach: float | None = None
    reached = False
    time_to_goal: float | None = None
    start_clear = obstacles.clearance((state.x, state.y)) - r
    min_clear = min(min_clear, start_clear)
    if movers:
        p_obs = np.array([o.position(0.0) for o in movers])
        radii = np.array([o.radius for o in movers])
        d0 = np.hypot(p_obs[:, 0] - state.x, p_obs[:, 1] - state.y) - radii - r
        alive0 = [o.motion.exists(0.0) for o in movers]
        if any(alive0):
            min_clear = min(min_clear, float(d0[alive0].min()))
    else:
        p_obs = np.zeros((0, 2))
        radii = np.zeros(0)

    for i in range(n_max):
        if math.hypot(state.x - spec.goal[0], state.y - spec.goal[1]) <= spec.goal_tolerance:
            reached = True
            time_to_goal = t
            break
        seen, detections = sensor.observe(t, state)
        obs = Observation(t, state, seen, detections)
        cmd = agent.act(obs)
        new = step(spec, state, cmd, dt)
        t_new = (i + 1) * dt
        a = np.array([state.x, state.y])
        b = np.array([new.x, new.y])
        length += float(np.hypot(*(b - a)))
        # Static obstacles and walls: exact clearance of the step's chord.
        c_static = obstacles.segment_clearance(a, b) - r
        step_clear = c_static
        hit = None
        u = (b - a) / dt  # the robot's velocity over the step's chord [m/s]
        if c_static < -COLLISION_EPS:
            hit = scenario.nearest_static(a, b)
            if collision_with is None:
                pc = a + static_contact(obstacles, a, b, r) * (b - a)
                q = nearest_obstacle_point(obstacles, pc)
                approach, caused = approach_speed(u, pc, q), robot_caused(u, pc, q)
        if movers:
            p_new = np.array([o.position(t_new) for o in movers])
            for j, o in enumerate(movers):
                lo, hi = o.motion.span  # a recorded track exists only within its span
                s0, s1 = max(t, lo) - t, min(t_new, hi) - t
                if s1 < s0:
                    continue
                w = (p_new[j] - p_obs[j]) / dt
                _, d = closest_approach_straight(a, u, p_obs[j], w, s0, s1)
                c = d - r - radii[j]
                if c < step_clear:
                    step_clear = c
                if c < -COLLISION_EPS and hit is None:
                    hit = o.name
                    if collision_with is None:
                        tc = disc_contact(a, u, p_obs[j], w, r + radii[j], s0, s1)
                        pc, q = a + u * tc, p_obs[j] + w * tc
                        approach, caused = approach_speed(u, pc, q), robot_caused(u, pc, q)
            p_obs = p_new
        min_clear = min(min_clear, step_clear)
        state, t = new, t_new
        traj.append([t, state.x, state.y, state.theta, state.v, state.omega])
        if hit is not None and collision_with is None:
            collision_with, collision_time = hit, t
            if cfg.stop_on_collision:
                break
    else:
        if math.hypot(state.x - spec.goal[0], state.y - spec.goal[1]) <= spec.goal_tolerance:
            reached, time_to_goal = True, t

    collided = collision_with is not None
    status = "collision" if collided else ("reached" if reached else "timeout")
    if unreachable:
        status = "unreachable"
    bound = scenario_time_lower_bound(scenario)
    ttg = time_to_goal if reached else None
    st = AgentStats() if unreachable else agent.stats
    return RunResult(
        scenario=scenario.name,
        planner=agent.name,
        seed=int(seed),
        reached_goal=reached and not (collided and cfg.stop_on_collision),
        collision=collided,
        path_length_m=length,
        time_to_goal_s=time_to_goal if reached else None,
        planning_times_s=list(st.planning_times_s),
        replans=int(st.replans),
        min_clearance_m=float(min_clear),
        trajectory=traj,
        status=status,
        collision_with=collision_with,
        collision_time_s=collision_time,
        virtual_obstacles=list(st.virtual_obstacles),
        plans=list(st.plans),
        scenario_hash=scenario.content_hash(),
        dt_s=dt,
        wall_time_s=time.perf_counter() - wall0,
        extra={**st.extra, "perception": sensor.record()},
        collision_robot_caused=caused if collided else None,
        collision_approach_speed_mps=approach if collided else None,
        time_lower_bound_s=bound,
        time_over_lower_bound=(ttg / bound if ttg is not None and bound is not None and bound > 0.0
                               else None),
        **moving_obstacle_metrics(scenario, np.asarray(traj)),
    )
