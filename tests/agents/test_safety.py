"""The safety invariant: hand-made decisions, the property on random runs, the gap case."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from anyplan.agents import make_agent
from anyplan.agents.safety import FALLBACK_KINDS, SafetyConfig, SafetyGuard
from anyplan.experiments.generate import random_scenario
from anyplan.geometry.collision import ObstacleSet
from anyplan.prediction.base import PredictedObstacle
from anyplan.prediction.collision import first_collision
from anyplan.simulation import SimConfig, simulate
from anyplan.trajectory.brake import SwerveSegment
from anyplan.trajectory.motion import brake_to_rest, plan_motion, swerve_trajectory
from anyplan.trajectory.trajectory import Trajectory
from anyplan.world import RobotSpec, RobotState, load_scenario
from anyplan.world.motion import UnicycleMotion

SPEC = RobotSpec(start=(1.0, 4.0, 0.0), goal=(11.0, 4.0), radius=0.3, v_max=0.4, omega_max=0.4,
                 a_max=0.4, alpha_max=1.0)
ROOM = ObstacleSet([], bounds=(0.0, 0.0, 12.0, 8.0))


def _cruising(t0=0.0):
    """The robot at (1, 4) driving +x at v_max, on a straight 10 m motion."""
    state = RobotState(1.0, 4.0, 0.0, 0.4, 0.0)
    return state, plan_motion(np.array([[1.0, 4.0], [11.0, 4.0]]), SPEC, state, ROOM, t0)


def _parked_disc(name, x, y):
    return PredictedObstacle(name, 0.3, UnicycleMotion(x, y, 0.0, 0.0, 0.0))


def test_free_motion_is_started():
    guard = SafetyGuard(SPEC, ROOM)
    state, motion = _cruising()
    d = guard.decide(0.0, motion, None, state, [], 0.3)
    assert (d.kind, d.rule, d.safe) == ("motion", "free_to_rest", True)
    assert guard.fallbacks == []


def test_a_motion_to_the_goal_is_checked_until_it_arrives():
    # The run is over within half the goal tolerance: an obstacle that crosses the goal 2 s
    # after the robot's arrival strikes the motion only at rest there, after arrival, so the
    # motion is free to rest; the same obstacle 2 s earlier is not.
    from anyplan.trajectory.reference import HoldSegment
    from anyplan.trajectory.trajectory import Trajectory

    guard = SafetyGuard(SPEC, ROOM)
    _, motion = _cruising()
    goal, reach = np.asarray(SPEC.goal), SPEC.arrival_radius
    ts = np.linspace(0.0, float(motion.t_end), 20001)
    inside = np.hypot(*(motion.positions(ts) - goal).T) <= reach
    first = float(ts[np.argmax(inside)])
    t_arr = guard.arrival(motion, 0.0)
    assert first - 1e-9 <= t_arr <= first + 0.02 + 1e-9  # never before the true arrival
    assert t_arr < float(motion.t_end)

    def crossing(t_at_goal):  # down x = 11 at 0.4 m/s, over the goal at t_at_goal
        return [PredictedObstacle("C", 0.3, UnicycleMotion(11.0, 4.0 + 0.4 * t_at_goal,
                                                           -math.pi / 2, 0.4))]

    late = crossing(t_arr + 2.0)
    hit = first_collision(motion, late, SPEC.radius, margin=guard.config.margin)
    assert hit is not None and hit.t > t_arr
    assert guard.check(motion, late, 0.0, 0.2)[0] == "free_to_rest"
    assert guard.check(motion, crossing(t_arr - 2.0), 0.0, 0.2)[0] != "free_to_rest"
    # standing at the goal: arrived already, however long the hold; elsewhere: never
    assert guard.arrival(Trajectory([HoldSegment(11.0, 4.0, 0.0, 0.0, 1e4)]), 5.0) == 5.0
    assert guard.arrival(Trajectory([HoldSegment(5.0, 4.0, 0.0, 0.0, 1e4)]), 5.0) == math.inf


def test_far_collision_is_stoppable_near_one_is_not():
    guard = SafetyGuard(SPEC, ROOM)
    state, motion = _cruising()
    # A parked disc 4 m ahead: contact in about 8.5 s, the robot can stop long before.
    d = guard.decide(0.0, motion, None, state, [_parked_disc("far", 5.0, 4.0)], 0.3)
    assert (d.kind, d.rule) == ("motion", "stoppable") and d.first_collision_s > d.t_rest
    # 0.9 m ahead: contact at x = 0.25 m further on; committing 0.3 s (0.12 m) and braking
    # (0.2 m) takes the robot 0.32 m: it cannot stop. The guard brakes at once instead, which
    # stops it 0.2 m further, clear of the disc: never "the latest collision".
    guard2 = SafetyGuard(SPEC, ROOM)
    d2 = guard2.decide(0.0, motion, None, state, [_parked_disc("near", 1.9, 4.0)], 0.3)
    assert d2.kind == "brake" and d2.safe and d2.rule == "fallback"
    assert guard2.fallbacks == [{"t": 0.0, "kind": "brake",
                                 "predicted_clearance_m": pytest.approx(d2.predicted_clearance_m)}]
    # Its trajectory stops the robot 0.2 m on: 1.9 - 1.2 - 0.6 = 0.1 m of clearance remains.
    assert d2.predicted_clearance_m == pytest.approx(0.1, abs=2e-3)


def test_a_motion_whose_brake_would_strike_a_wall_is_not_stoppable():
    # The robot drives straight down at the room's bottom wall (y = 0) at 1 m/s, its centre
    # 2.1 m above it; braking at a_max = 0.3 m/s^2 takes 1 / 0.6 = 1.67 m, so braking now stops
    # it at y = 0.43, clear of the wall. The proposed motion drives on for 0.5 s and then swerves
    # away (a 0.5 m turning radius), its centre never below y = 0.85, to rest next to a
    # parked disc P that it strikes about 4 s on. The robot acts again only after committing
    # 0.4 s (a check period and a planning delay): by then it is at y = 1.7, still heading
    # straight down, and braking would stop its centre at y = 0.03, 0.27 m into the wall. So the
    # motion is neither free to rest (P) nor stoppable (the wall): the guard must refuse it.
    spec = RobotSpec(start=(3.0, 2.1, -math.pi / 2), goal=(11.0, 3.0), radius=0.3, v_max=1.0,
                     omega_max=2.0, a_max=0.3, alpha_max=4.0)
    room = ObstacleSet([], bounds=(0.0, 0.0, 12.0, 6.0))
    state = RobotState(3.0, 2.1, -math.pi / 2, 1.0, 0.0)
    down = SwerveSegment(3.0, 2.1, -math.pi / 2, 1.0, 0.0, 1.0, 0.0, spec.a_max, spec.alpha_max,
                         0.0, 0.5)  # the twist held: straight down at 1 m/s
    away = swerve_trajectory(RobotState(3.0, 1.6, -math.pi / 2, 1.0, 0.0), spec, room,
                             spec.radius, 0.5, 1.0, 2.0, 1.0)
    motion = Trajectory([down, *away.segments], kind="down+swerve")
    p = motion.positions(np.linspace(0.0, motion.t_end, 2001))
    assert p[:, 1].min() > spec.radius + 0.5 and p[:, 0].min() > 2.9  # clear of every wall
    park = [_parked_disc("P", 5.6, 1.5)]
    hit = first_collision(motion, park, spec.radius, margin=0.05)
    assert hit is not None and hit.t > 3.5 and hit.robot_position[0] > 4.5
    commit_s = 0.4
    at = motion.state(commit_s)
    assert (at.x, at.y, at.theta, at.v, at.omega) == pytest.approx((3.0, 1.7, -math.pi / 2, 1.0, 0.0))
    stop_y = at.y - at.v**2 / (2.0 * spec.a_max)  # straight down, no turn left to make
    assert stop_y == pytest.approx(0.0333, abs=1e-3) and stop_y < spec.radius - 0.25
    assert state.y - state.v**2 / (2.0 * spec.a_max) > spec.radius + 0.1  # braking now: clear
    # The escape's brake runs along x = 3, 2 m clear of P: the wall alone forbids it. With the
    # wall 5 m lower the same motion is stoppable.
    guard = SafetyGuard(spec, room)
    assert guard.check(motion, park, 0.0, commit_s)[0] == "unsafe"
    deep = SafetyGuard(spec, ObstacleSet([], bounds=(0.0, -5.0, 12.0, 6.0)))
    assert deep.check(motion, park, 0.0, commit_s)[0] == "stoppable"
    d = guard.decide(0.0, motion, None, state, park, commit_s)
    assert d.kind in FALLBACK_KINDS and d.rule == "fallback" and "cannot stop" in d.reason
    assert all(x.kind != "motion" for x in guard.decisions)


def test_current_motion_is_kept_when_the_new_one_is_unsafe():
    guard = SafetyGuard(SPEC, ROOM)
    _state, motion = _cruising()
    # The proposed motion drives into a disc 0.9 m ahead; the current one is parked in place.
    hold = guard.fallback(0.0, RobotState(1.0, 4.0, 0.0, 0.0, 0.0), [])
    d = guard.decide(0.0, motion, hold.trajectory, RobotState(1.0, 4.0, 0.0, 0.0, 0.0),
                     [_parked_disc("near", 1.9, 4.0)], 0.3)
    assert d.kind == "keep" and d.trajectory is hold.trajectory


def test_fallback_is_the_safest_by_clearance():
    # Parked robot, a walker coming straight at it at 0.3 m/s from 5 m: holding is hit within the
    # 15 s horizon (negative clearance); turning away (about 4.3 s to turn a quarter, then 1.2 m
    # sideways) keeps more distance. The guard takes the candidate with the largest predicted
    # clearance among those whose moving part is collision-free.
    guard = SafetyGuard(SPEC, ROOM, SafetyConfig(horizon_s=15.0))
    walker = PredictedObstacle("w", 0.3, UnicycleMotion(6.0, 4.0, math.pi, 0.3, 0.0))
    rest = RobotState(1.0, 4.0, 0.0, 0.0, 0.0)
    d = guard.decide(0.0, None, None, rest, [walker], 0.3)
    assert d.kind in FALLBACK_KINDS and d.rule == "fallback"
    kinds = {c[0] for c in d.candidates}
    assert {"hold", "turn_away", "back_off"} <= kinds
    free = [c for c in d.candidates if c[1]]
    assert free and d.safe
    assert d.predicted_clearance_m == pytest.approx(max(c[2] for c in free))
    hold_clear = next(c[2] for c in d.candidates if c[0] == "hold")
    assert hold_clear < 0.0 < d.predicted_clearance_m
    assert d.kind in ("turn_away", "back_off")
    assert guard.fallbacks[-1]["kind"] == d.kind


# --- the property on random runs ----------------------------------------------------------------
def _truth(scenario):
    return [PredictedObstacle(o.name, o.radius, o.motion) for o in scenario.moving_obstacles]


def _escape_free(traj, t, t_commit, spec, obstacles, preds):
    """Independent re-prediction: follow traj to t_commit, brake at a_max; exact predictor."""
    t_commit = min(max(t_commit, traj.t_start), traj.t_end)
    st_c = traj.state(t_commit)
    segs, t_rest, _, static_ok = brake_to_rest(st_c, spec, obstacles, spec.radius, t_commit)
    brake = segs[0] if segs else None

    class Esc:
        t_start, t_end = traj.t_start, t_rest
        max_speed = traj.max_speed

        @staticmethod
        def positions(ts):
            ts = np.atleast_1d(ts)
            p = traj.positions(np.minimum(ts, t_commit))
            if brake is not None:
                m = ts > t_commit
                if m.any():
                    x, y, _, _, _ = brake.sample(np.minimum(ts[m], brake.t1))
                    p[m, 0], p[m, 1] = x, y
            return p

    if t_rest <= t:
        return static_ok
    return static_ok and first_collision(Esc, preds, spec.radius, t_from=t, t_until=t_rest) is None


def _commit_times(agent):
    """For each logged decision, the earliest time [s] the robot can act again, from the
    agent's own timing, not from the guard's log: it follows what was chosen at ``d.t`` until
    its next check (one ``check_period_s``) and then through a replanning's delay. Each
    replanning (``record.replan_times_s``) makes one decision; its delay is the time from
    the replanning to the switch, at least a fixed ``planning_delay``."""
    decisions, t_plans = agent.guard.decisions, agent.record.replan_times_s
    assert len(decisions) == len(t_plans)
    out = []
    for d, t_plan in zip(decisions, t_plans, strict=True):
        delay = d.t - t_plan
        if agent.planning_delay != "measured":
            assert delay >= float(agent.planning_delay) - 1e-9, (d, t_plan)
        out.append(d.t + agent.check_period_s + delay)
    return out


def check_invariant(scenario, agent, result):
    """Every executed motion was predicted free over its stopping horizon when chosen, or was
    the best fallback and is recorded as such. A stoppable motion's escape brakes no earlier
    than the robot can act again (:func:`_commit_times`), and is re-predicted from then."""
    spec, obst, preds = scenario.robot, scenario.obstacle_set(), _truth(scenario)
    decisions = agent.guard.decisions
    fallbacks = result.extra["fallbacks"]
    commits = _commit_times(agent)
    # Every switch of the executed trajectory is a logged decision.
    for t, traj in agent.executed:
        assert any(d.trajectory is traj and abs(d.t - t) < 1e-9 and d.kind != "keep"
                   for d in decisions), t
    n_fb = 0
    for d, t_act in zip(decisions, commits, strict=True):
        tr = d.trajectory
        if d.kind in ("motion", "keep"):
            if d.rule == "free_to_rest":
                assert first_collision(tr, preds, spec.radius, t_from=d.t,
                                       t_until=max(tr.t_end, d.t)) is None, d
            else:
                assert d.rule == "stoppable"
                # (an escape brakes at the end of its motion at the latest)
                assert d.t_commit >= min(t_act, tr.t_end) - 1e-9, (d, t_act)
                assert _escape_free(tr, d.t, t_act, spec, obst, preds), d
        elif d.rule == "give_way":  # a stoppable motion gave way (seq-bitstar's give_way)
            assert fallbacks[n_fb]["t"] == d.t and fallbacks[n_fb]["kind"] == d.kind
            n_fb += 1
            assert d.first_collision_s is not None and d.first_collision_s - d.t <= 5.0 + 1e-9
            if d.safe:
                assert first_collision(tr, preds, spec.radius, t_from=d.t,
                                       t_until=max(tr.t_end, d.t + 5.0)) is None, d
        else:
            assert d.kind in FALLBACK_KINDS
            assert fallbacks[n_fb]["t"] == d.t and fallbacks[n_fb]["kind"] == d.kind
            n_fb += 1
            free = [c for c in d.candidates if c[1]]
            if free:  # a safe option existed: the chosen one is safe and the clearest of them
                assert d.safe and d.predicted_clearance_m >= max(c[2] for c in free) - 1e-12
                assert first_collision(tr, preds, spec.radius, t_from=d.t,
                                       t_until=max(d.t_rest, d.t)) is None, d
            else:
                assert d.predicted_clearance_m >= max(c[2] for c in d.candidates) - 1e-12
    assert n_fb == len(fallbacks)


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), n_moving=st.integers(2, 6))
def test_invariant_on_random_crossing_scenarios(seed, n_moving):
    sc = random_scenario(np.random.default_rng(seed), n_moving=n_moving)
    agent = make_agent("seq-bitstar", planning_delay=0.1)
    res = simulate(sc, agent, seed=seed, config=SimConfig(time_limit=40.0))
    check_invariant(sc, agent, res)
    assert not (res.collision and res.collision_robot_caused), (seed, res.collision_with)


@pytest.mark.slow
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), n_moving=st.integers(2, 6))
def test_invariant_on_random_crossing_scenarios_many_slow(seed, n_moving):
    test_invariant_on_random_crossing_scenarios.hypothesis.inner_test(seed, n_moving)


# --- the gap case ------------------------------------------------------------------------
def test_gap_walker_without_waiting_collides_unless_the_invariant_holds():
    """Algorithm 1 alone (no waiting extension) takes the latest-collision motion and drives into
    the walker; with the invariant the robot brakes or backs off instead."""
    sc = load_scenario("gap-walker")
    bad = simulate(sc, make_agent("seq-bitstar", wait_delays_s=(), safety=False, planning_delay=0.1),
                   seed=0)
    assert bad.collision and bad.collision_with == "walker" and bad.collision_robot_caused
    agent = make_agent("seq-bitstar", wait_delays_s=(), planning_delay=0.1)
    good = simulate(sc, agent, seed=0)
    assert not (good.collision and good.collision_robot_caused)
    assert good.extra["fallbacks"]
    # the run takes stoppable motions, so check_invariant checks their commit times
    assert any(d.rule == "stoppable" for d in agent.guard.decisions)
    check_invariant(sc, agent, good)


@pytest.mark.slow
@pytest.mark.parametrize("waiting", [True, False])
def test_gap_walker_no_robot_caused_collision_in_6_seeds(waiting):
    sc = load_scenario("gap-walker")
    kw = {} if waiting else {"wait_delays_s": ()}
    for seed in range(6):
        agent = make_agent("seq-bitstar", **kw)
        res = simulate(sc, agent, seed=seed)
        assert not (res.collision and res.collision_robot_caused), (seed, res.status)
        check_invariant(sc, agent, res)


def test_a_motion_the_robot_cannot_take_up_is_not_started():
    # plan_motion's best effort for a robot at 2 m/s before a wall starts at about 1 m/s
    # (feasible=False): free of every prediction, but not where the robot would go. The guard
    # falls back instead, to a motion that starts at the robot's speed.
    from anyplan.world.scenario import scenario_from_dict
    from tests.conftest import fast_at_a_wall_dict

    sc = scenario_from_dict(fast_at_a_wall_dict())
    obst = sc.obstacle_set()
    state = RobotState(1.0, 1.0, 0.0, 2.0, 0.0)
    motion = plan_motion(np.array([[1.0, 1.0], [1.4, 1.0], [1.4, 7.0]]), sc.robot, state, obst,
                         0.0, margin=0.015, grid_step=0.05)
    assert not motion.feasible and motion.state(0.0).v < 1.5
    guard = SafetyGuard(sc.robot, obst)
    d = guard.decide(0.0, motion, None, state, [_parked_disc("far", 6.0, 7.0)], 0.3)
    assert d.kind in FALLBACK_KINDS and "infeasible" in d.reason
    assert d.trajectory.state(0.0).v == pytest.approx(2.0)


def test_reachable_discs_contain_every_bounded_speed_future():
    # Whatever an obstacle does at up to its predicted speed + extra, it stays in its disc;
    # an obstacle behind the robot is left out.
    from anyplan.agents.safety import reachable_discs

    rng = np.random.default_rng(3)
    ahead = PredictedObstacle("A", 0.3, UnicycleMotion(4.0, 4.0, math.pi, 0.8, 0.0))
    behind = PredictedObstacle("B", 0.3, UnicycleMotion(0.0, 4.0, 0.0, 0.8, 0.0))
    discs = reachable_discs([ahead, behind], 1.0, np.array([1.0, 4.0]), 0.0, 0.2, 5.0)
    assert [d.name for d in discs] == ["A"]
    d = discs[0]
    q0 = ahead.positions(np.array([1.0]))[0]
    for _ in range(200):  # random piecewise-constant velocities of norm <= 1.0 m/s
        q, t = q0.copy(), 1.0
        for _ in range(5):
            dt = rng.uniform(0.0, 0.8)
            ang, sp = rng.uniform(-math.pi, math.pi), rng.uniform(0.0, 1.0)
            q = q + sp * dt * np.array([math.cos(ang), math.sin(ang)])
            t += dt
            centre = d.positions(np.array([t]))[0]
            assert math.hypot(*(q - centre)) + 0.3 <= float(d.radius_at(t)) + 1e-9


def test_passive_safety_refuses_speed_an_obstacle_could_cut_into():
    # An obstacle 1.5 m ahead of a robot cruising at 0.4 m/s drives away at 0.5 m/s: the
    # prediction is free, but if it turned back it could meet the robot still braking (commit
    # 0.3 s + 1 s of braking against 1.5 - 0.6 = 0.9 m at 0.7 m/s closing). Without the
    # reachable discs the motion starts; with them it does not, and the guard brakes.
    from anyplan.agents.safety import reachable_discs

    guard = SafetyGuard(SPEC, ROOM)
    state, motion = _cruising()
    away = [PredictedObstacle("W", 0.3, UnicycleMotion(2.5, 4.0, 0.0, 0.5, 0.0))]
    assert guard.check(motion, away, 0.0, 0.3)[0] == "free_to_rest"
    reach = reachable_discs(away, 0.0, np.array([1.0, 4.0]), 0.0, 0.2, 5.0)
    assert guard.check(motion, away, 0.0, 0.3, reach=reach)[0] == "unsafe"
    d = guard.decide(0.0, motion, None, state, away, 0.3, reach)
    assert d.kind == "brake"
    # Far away (6 m ahead) the same motion is passively safe, and a robot at rest always is.
    far = [PredictedObstacle("W", 0.3, UnicycleMotion(7.0, 4.0, 0.0, 0.5, 0.0))]
    reach_far = reachable_discs(far, 0.0, np.array([1.0, 4.0]), 0.0, 0.2, 5.0)
    assert guard.check(motion, far, 0.0, 0.3, reach=reach_far)[0] != "unsafe"
    hold = guard.fallback(0.0, RobotState(1.0, 4.0, 0.0, 0.0, 0.0), []).trajectory
    assert guard.check(hold, away, 0.0, 0.0, reach=reach)[0] != "unsafe"


def test_reachable_disc_of_a_standing_obstacle_grows_at_the_floor_speed():
    from anyplan.agents.safety import reachable_discs

    standing = [PredictedObstacle("S", 0.25, UnicycleMotion(3.0, 4.0, 0.0, 0.0, 0.0))]
    p, h = np.array([1.0, 4.0]), 5.0
    (d,) = reachable_discs(standing, 0.0, p, 0.0, 0.3, h)
    assert float(d.radius_at(1.0)) == pytest.approx(0.25 + 0.3)
    (d,) = reachable_discs(standing, 0.0, p, 0.0, 0.3, h, min_speed=1.6)
    assert float(d.radius_at(1.0)) == pytest.approx(0.25 + 1.6)
    assert float(d.radius_at(10.0)) == pytest.approx(0.25 + 1.6 * h)  # held after the horizon


def test_decide_without_fallback_says_unsafe_and_logs_nothing():
    # The same near disc as above: the guard would brake; asked for no fallback, it returns
    # "unsafe" without a trajectory and logs no fallback.
    guard = SafetyGuard(SPEC, ROOM)
    state, motion = _cruising()
    d = guard.decide(0.0, motion, None, state, [_parked_disc("near", 1.9, 4.0)], 0.3,
                     fallback=False)
    assert (d.kind, d.trajectory, d.safe) == ("unsafe", None, False)
    assert d.reason.startswith("proposed motion: collision predicted")
    assert guard.fallbacks == [] and guard.decisions == []


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 12), nan=st.booleans())
def test_threat_found_for_all_obstacles_at_once_is_the_one_found_one_at_a_time(seed, n, nan):
    # SafetyGuard.candidates' threat (the obstacle nearest to the robot braking in place) is
    # searched for every obstacle at once: bit for bit the direction of the search one obstacle
    # at a time that keeps the first strictly nearer one, horizons, growth and NaN included.
    from anyplan.agents.safety import _threat
    from anyplan.prediction.base import RadiusGrowth

    rng = np.random.default_rng(seed)
    growth = RadiusGrowth(0.0, np.array([0.0, 2.0]), np.array([0.0, 0.5]))
    preds = [PredictedObstacle(f"P{k}", float(rng.choice([0.2, 0.3])),
                               UnicycleMotion(*rng.uniform(0.0, 8.0, 2), rng.uniform(-3.0, 3.0),
                                              float(rng.choice([0.0, 0.5, 1.0]))),
                               growth if rng.random() < 0.5 else None,
                               until=float(rng.choice([math.inf, rng.uniform(-1.0, 6.0)])))
             for k in range(n)]
    ts = np.linspace(0.0, 5.0, 41)
    pr = np.column_stack([np.linspace(4.0, 4.5, 41), np.full(41, 4.0)])
    if nan:
        pr[int(rng.integers(41)), 0] = math.nan
    p_rest = pr[-1]
    best, want = math.inf, None
    for o in preds:
        d = np.hypot(*(pr - o.positions(ts)).T) - float(getattr(o, "max_radius", o.radius))
        d[ts > o.until] = math.inf
        k = int(np.argmin(d))
        if d[k] < best:
            best, want = float(d[k]), o.positions(ts[k:k + 1])[0] - p_rest
    got = _threat(preds, ts, pr, p_rest)
    assert (got is None) == (want is None)
    assert got is None or got.tobytes() == want.tobytes()


def test_clearance_is_searched_between_the_jumps_of_an_open_track():
    # The robot holds at (0, 0) over [38, 43] s. A stands 0.7 m away (clearance 0.1 m). B, an
    # open track at 2 m/s, jumps back to its first keyframe 0.522 m from the robot (overlap) at
    # t = 39.901 s, just after a point of the 0.1 s pre-filter grid, and leaves at once: no speed
    # bound holds across the jump, so B must be searched piece by piece, not dropped behind A.
    from anyplan.trajectory.reference import HoldSegment
    from anyplan.world.motion import WaypointMotion

    spec = RobotSpec((0.0, 0.0, 0.0), (30.0, 0.0), radius=0.3, v_max=2.0, omega_max=2.0,
                     a_max=2.0, alpha_max=4.0)
    guard = SafetyGuard(spec, ObstacleSet([]))
    a = PredictedObstacle("A", 0.3, UnicycleMotion(0.0, 0.7, 0.0, 0.0))
    b = PredictedObstacle("B", 0.3, WaypointMotion(np.array(
        [[0.0, 0.522, 0.0], [1.0, 2.522, 0.0], [39.901, 20.0, 0.0]])))
    t0, t1 = 38.0, 43.0
    assert b.motion.jump_times(t0, t1) == [39.901]
    hold = Trajectory([HoldSegment(0.0, 0.0, 0.0, t0, t1)], kind="hold")

    def brute(o):  # dense samples on each piece between the jumps
        ts = np.concatenate([np.linspace(u, w, 200001) for u, w in o.motion.continuous_pieces(t0, t1)])
        return float(np.min(np.hypot(*(hold.positions(ts) - o.positions(ts)).T))) - 0.3 - o.radius

    truth = min(brute(a), brute(b))
    assert truth == pytest.approx(-0.078, abs=1e-6)
    for preds in ([a, b], [b, a], [b]):
        clear = guard.clearance(hold, preds, t0, t1)
        assert clear <= truth  # a lower bound (here the minimum, at the jump, exactly)
        assert clear == pytest.approx(truth, abs=1e-6)
        assert clear < guard.config.margin  # not clear by the margin


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_clearance_of_open_tracks_is_a_lower_bound_on_random_cases(seed):
    # open tracks whose jumps fall anywhere in the horizon, beside a parked disc
    from anyplan.world.motion import WaypointMotion

    rng = np.random.default_rng(seed)
    guard = SafetyGuard(SPEC, ROOM)
    t0 = float(rng.uniform(0.0, 20.0))
    rest = RobotState(*rng.uniform([3.0, 3.0], [9.0, 5.0]), 0.0, 0.0, 0.0)
    preds = [_parked_disc("A", rest.x + 1.2, rest.y)]
    for k in range(3):
        n = int(rng.integers(2, 4))
        kt = np.concatenate([[0.0], np.cumsum(rng.uniform(0.3, 2.0, n - 1))])
        pts = np.array([rest.x, rest.y]) + rng.uniform(-2.0, 2.0, (n, 2))
        preds.append(PredictedObstacle(f"B{k}", 0.3, WaypointMotion(np.column_stack([kt, pts]))))
    assert all(o.motion.may_jump for o in preds[1:])
    (_, hold, t_rest), *_ = guard.candidates(t0, rest, preds)
    t1 = max(t0 + guard.config.horizon_s, t_rest)
    clear = guard.clearance(hold, preds, t0, t1)
    truth = math.inf
    for o in preds:
        ts = np.concatenate([np.linspace(u, w, 50001) for u, w in o.motion.continuous_pieces(t0, t1)])
        d = np.hypot(*(hold.positions(ts) - o.positions(ts)).T) - SPEC.radius - o.radius
        truth = min(truth, float(d.min()))
    # each piece's minimum is certified within L tol (closest_approach), the samples within
    # L * 1e-4 (L the fastest obstacle's speed: the robot is at rest)
    speed = max(o.max_speed for o in preds)
    assert truth - speed * 1e-4 - 1e-9 <= clear <= truth + speed * guard.config.tol + 1e-9
