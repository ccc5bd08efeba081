"""The st-bitstar agent: waits at a gap, passes behind crossing obstacles, stays deterministic."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.agents import AGENTS, make_agent
from anyplan.experiments.gaps import WALL_T, WALL_X, gap_world, issue_gap_scenario
from anyplan.planning.sequential import SequentialConfig
from anyplan.simulation import SimConfig, simulate
from anyplan.world.scenario import scenario_from_dict
from tests.conftest import DYNABARN_WORLDS as _DYNABARN
from tests.conftest import fast_at_a_wall_dict, head_on_corridor_dict, needs_dynabarn

P3DX = {"radius": 0.3, "v_max": 0.4, "omega_max": 0.4, "a_max": 0.4, "alpha_max": 1.0,
        "goal_tolerance": 0.2}


def _crossing_scenario():
    # The obstacle crosses the straight route at x = 6 m when a robot at full speed would.
    return scenario_from_dict({
        "name": "crossing", "time_limit": 60.0, "arena": {"width": 12.0, "height": 6.0},
        "robot": {"start": [1.0, 3.0, 0.0], "goal": [11.0, 3.0], **P3DX},
        "static_obstacles": [],
        "dynamic_obstacles": [{"name": "X", "start": [6.0, 0.5, math.pi / 2], "v": 0.3,
                               "radius": 0.3, "start_time": 13.0 - 2.5 / 0.3}]})


def _head_on_gap():
    # A 1.0 m gap; a walker comes through it towards the robot, then turns off to a corner.
    y = 4.0
    t_meet = 14.0
    walker = {"name": "W", "type": "waypoints", "radius": 0.3,
              "keyframes": [[0.0, 10.0, y], [t_meet - 4.0 / 0.4, 10.0, y], [t_meet, 6.0, y],
                            [t_meet + 2.0, 5.2, y], [t_meet + 10.0, 4.8, 7.6], [1000.0, 4.8, 7.6]]}
    return gap_world("head-on-gap", "test", np.array([1.5, 4.0]), np.array([10.5, 4.0]), y, 1.0,
                     [walker]), t_meet


def _fixed():
    # no wall-clock budget anywhere (improvement calls included): the same run under any load
    return {"planning_delay": 0.1, "search_budget_s": None, "improve_budget_s": None,
            "config": SequentialConfig(max_iterations=8, wait_delays_s=(), batches_per_plan=2,
                                       max_time_s=10.0)}


def test_registered():
    assert "st-bitstar" in AGENTS.names()
    assert make_agent("st-bitstar").name == "st-bitstar"


@pytest.mark.slow
def test_passes_behind_a_crossing_obstacle():
    sc = _crossing_scenario()
    r = simulate(sc, make_agent("st-bitstar", **_fixed()), seed=0)
    assert r.status == "reached" and not r.collision
    tr = r.trajectory_array
    k = int(np.argmax(tr[:, 1] >= 6.0))  # the robot crosses the obstacle's track
    ob = sc.moving_obstacles[0].motion.positions(np.array([tr[k, 0]]))[0]
    assert ob[1] > tr[k, 2] + 0.6  # the obstacle is already past: the robot went behind it
    assert r.min_clearance_m > 0.0


@pytest.mark.slow
def test_waits_at_a_gap_until_the_walker_has_passed():
    sc, t_meet = _head_on_gap()
    r = simulate(sc, make_agent("st-bitstar", **_fixed()), seed=0)
    assert r.status == "reached" and not r.collision
    tr = r.trajectory_array
    at = tr[np.argmin(np.abs(tr[:, 0] - t_meet))]
    assert at[1] < WALL_X - WALL_T / 2 - 0.3  # still in front of the wall when the walker is in the gap
    through = tr[int(np.argmax(tr[:, 1] >= WALL_X)), 0]
    assert through > t_meet  # it went through after the walker
    rest = tr[:, 4] < 0.01
    assert rest[(tr[:, 0] > 1.0) & (tr[:, 0] < t_meet)].sum() * r.dt_s >= 0.5  # it waited


@pytest.mark.slow
def test_issue_case_reaches_without_collision():
    r = simulate(issue_gap_scenario(), make_agent("st-bitstar", **_fixed()), seed=0)
    assert r.status == "reached" and not r.collision


@pytest.mark.slow
def test_deterministic_with_a_fixed_planning_delay():
    sc = _crossing_scenario()
    a = simulate(sc, make_agent("st-bitstar", **_fixed()), seed=3)
    b = simulate(sc, make_agent("st-bitstar", **_fixed()), seed=3)
    assert a.trajectory == b.trajectory
    assert [p["path"] for p in a.plans] == [p["path"] for p in b.plans]


@pytest.mark.slow
def test_result_fields():
    r = simulate(_crossing_scenario(), make_agent("st-bitstar", **_fixed()), seed=0)
    d = json.loads(json.dumps(r.to_dict()))
    ex = d["extra"]
    assert isinstance(ex["fallbacks"], list)
    assert all(set(f) >= {"t", "kind", "reason", "predicted_clearance_m"} for f in ex["fallbacks"])
    assert len(ex["st_waits_s"]) == len(d["plans"]) and all(w >= 0.0 for w in ex["st_waits_s"])
    assert 0 <= ex["st_timed"] <= len(d["plans"])
    assert len(ex["st_candidates"]) == len(d["planning_times_s"])
    assert isinstance(ex["st_pruned"], int) and ex["st_pruned"] >= 0
    assert isinstance(ex["st_trapped"], int) and 0 <= ex["st_trapped"] <= len(d["planning_times_s"])
    assert all(p["arrival_s"] >= p["t_start"] for p in d["plans"])
    # re-timed ("st+..."), or a plan_motion kind when the untimed motion was already free
    assert all(p["kind"].startswith("st+") or p["kind"] in ("smooth", "turn+smooth",
               "brake+turn+smooth", "polyline", "fallback-hold") for p in d["plans"])


def test_bad_options():
    with pytest.raises(ValueError, match="patience_s"):
        make_agent("st-bitstar", patience_s=0.0)
    for name in ("search_budget_s", "improve_budget_s"):
        for bad in (0.0, -1.0, "fast"):
            with pytest.raises(ValueError, match=name):
                make_agent("st-bitstar", **{name: bad})
        assert getattr(make_agent("st-bitstar", **{name: None}), name) is None
        assert AGENTS.get("st-bitstar").deterministic_settings[name] is None


@pytest.mark.slow
def test_holds_and_records_a_fallback_when_nothing_is_safe():
    # A 1.2 m corridor and an obstacle coming head-on along it: no motion avoids it.
    sc = scenario_from_dict(head_on_corridor_dict(20.0))
    r = simulate(sc, make_agent("st-bitstar", planning_delay=0.1), seed=0)
    fb = r.extra["fallbacks"]
    assert fb and all(f["kind"] in ("hold", "back_off", "evade", "turn_away") for f in fb)
    assert all(set(f) >= {"t", "kind", "reason", "predicted_clearance_m"} for f in fb)
    # The robot never drove towards the obstacle (+x); if it is hit, it did not cause it.
    tr = r.trajectory_array
    assert np.max(tr[:, 4] * np.cos(tr[:, 3])) < 0.05
    assert not r.collision or r.collision_robot_caused is False


def test_planning_predictions_of_uncertain_obstacles():
    # With predictions extrapolated from the twist (a horizon), st-bitstar plans against: none
    # out of reach before the horizon; a disc that already holds the robot shrunk to leave it
    # just outside (so leaving it is not a collision at t = 0). Announced motions: untouched.
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.world import UnicycleMotion

    agent = make_agent("st-bitstar")
    agent.reset(_crossing_scenario(), np.random.default_rng(0))
    p, t = np.array([1.0, 3.0]), 0.0
    growth = RadiusGrowth(0.0, np.array([0.0, 1.0, 3.0]), np.array([0.1, 0.4, 1.0]))
    near = PredictedObstacle("near", 0.25, UnicycleMotion(1.6, 3.0, 0.0, 0.5), growth, until=3.0)
    far = PredictedObstacle("far", 0.25, UnicycleMotion(11.0, 5.0, math.pi, 1.0), growth, until=3.0)
    kept = agent._planning_preds([near, far], p, t)
    assert [o.name for o in kept] == ["near"]
    gap = math.hypot(*(near.positions(np.array([t]))[0] - p)) - 0.3 - agent.config.margin
    assert gap - float(kept[0].radius_at(t)) == pytest.approx(0.02)
    assert kept[0].radius_at(2.0) > kept[0].radius_at(t)  # still grows with the horizon
    announced = [PredictedObstacle("near", 0.25, near.motion)]
    assert agent._planning_preds(announced, p, t) is announced


def test_evasion_beats_holding_before_a_fast_obstacle():
    # A robot at rest, an obstacle at 1.5 m/s coming straight at it: holding, braking, turning
    # away or backing off 0.6-1.2 m (the guard's fallbacks) are all struck within its horizon;
    # st-bitstar also drives 1.5 s at v_max sideways and takes what the guard's ranking prefers.
    from anyplan.prediction import PredictedObstacle
    from anyplan.world import RobotState, UnicycleMotion

    agent = make_agent("st-bitstar")
    agent.reset(_crossing_scenario(), np.random.default_rng(0))
    state = RobotState(4.0, 3.0, math.pi / 2, 0.0, 0.0)
    fast = [PredictedObstacle("F", 0.6, UnicycleMotion(10.0, 3.0, math.pi, 1.5), until=5.0)]
    dec = agent.guard.fallback(0.0, state, fast, "test")
    kind, tr, clear = agent._evasions(0.0, state, fast, None)
    assert dec.predicted_clearance_m < 0.0  # the guard alone: struck
    assert kind == "evade" and clear > dec.predicted_clearance_m
    assert agent.guard.clearance(tr, fast, 0.0, 5.0) == pytest.approx(clear)


def test_guard_option():
    assert make_agent("st-bitstar", guard="never").guard_mode == "never"
    assert make_agent("st-bitstar", passive_safety=True).passive_safety is True
    with pytest.raises(ValueError, match="passive_safety"):
        make_agent("st-bitstar", passive_safety="yes")
    with pytest.raises(ValueError, match="reach_extra_mps"):
        make_agent("st-bitstar", reach_extra_mps=-0.1)
    with pytest.raises(ValueError, match="reach_min_speed_mps"):
        make_agent("st-bitstar", reach_min_speed_mps=-1.0)
    with pytest.raises(ValueError, match="guard"):
        make_agent("st-bitstar", guard="sometimes")


def test_guard_of_a_safety_replanning_checks_the_full_discs():
    # When the motion in use can no longer stop before an uncertain disc, the replanning's guard
    # decides against the disc's full growth (1.0 m here), not the one capped at plan_extra_m
    # (0.3 m) that paths are planned and timed against.
    from anyplan.agents.base import Observation
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.world import RobotState, UnicycleMotion

    sc = scenario_from_dict({**_crossing_scenario().to_dict(), "dynamic_obstacles": []})
    agent = make_agent("st-bitstar", planning_delay=0.1)
    agent.reset(sc, np.random.default_rng(0))
    for t0 in (0.0, 0.1):  # the first plan, taken up after the planning delay
        agent.act(Observation(t0, RobotState(1.0, 3.0, 0.0, 0.0, 0.0)))
    t = 6.0
    assert agent.trajectory is not None and agent.trajectory.t_end > t + 2.0
    st = agent.trajectory.state(t)
    assert st.v > 0.3  # cruising towards the goal
    growth = RadiusGrowth(t, np.array([0.0, 1.0, 3.0]), np.array([0.1, 0.6, 1.0]))
    towards = UnicycleMotion(st.x + 1.2, st.y, math.pi, 0.3, 0.0, start_time=t)
    ahead = PredictedObstacle("A", 0.25, towards, growth, until=t + 3.0)
    seen = []
    decide = agent.guard.decide

    def spy(t_s, motion, current, state, preds, commit, reach=(), fallback=True):
        seen.append(list(preds))
        return decide(t_s, motion, current, state, preds, commit, reach, fallback)

    agent.guard.decide = spy
    agent._check(Observation(t, st), [ahead])
    assert agent.record.reasons[-1].startswith("safety")
    assert seen, "the guard decided nothing"
    assert max(o.growth.max_extra for o in seen[0]) == pytest.approx(1.0)


def test_a_contact_after_arrival_at_the_goal_does_not_replan_the_motion_in_use():
    # The motion in use ends at rest on the goal (11, 3). A parked obstacle 0.6 m beyond the
    # goal is touched (with the check's margin) only in the last 2.5 cm before the end, after
    # the robot is within half the goal tolerance, where the run is over: the check of the
    # motion in use stops at the arrival, as the guard's does, and does not replan for it.
    from anyplan.agents.base import Observation
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.world import RobotState, UnicycleMotion

    sc = scenario_from_dict({**_crossing_scenario().to_dict(), "dynamic_obstacles": []})
    agent = make_agent("st-bitstar", planning_delay=0.1)
    agent.reset(sc, np.random.default_rng(0))
    for t0 in (0.0, 0.1):
        agent.act(Observation(t0, RobotState(1.0, 3.0, 0.0, 0.0, 0.0)))
    traj = agent.trajectory
    assert traj is not None
    t = float(traj.t_end) - 6.0
    st = traj.state(t)
    parked = PredictedObstacle("P", 0.3, UnicycleMotion(11.6, 3.0, math.pi, 0.0))
    hit = first_collision(traj, [parked], agent.spec.radius, t_from=t,
                          margin=0.5 * agent.config.margin)
    t_arr = agent.guard.arrival(traj, t)
    assert hit is not None and t_arr < hit.t <= float(traj.t_end)  # only after arrival
    n = len(agent.record.reasons)
    agent._check(Observation(t, st), [parked])
    assert not any(r.startswith("collision with P") for r in agent.record.reasons[n:])


# The robot at 2 m/s before a wall (tests/conftest.py): plan_motion's best effort there starts
# at about 1 m/s, ``feasible=False`` (as in DynaBARN world 53 at t = 1.3 s, at 1.5 m/s).
def _fast_at_a_wall():
    return scenario_from_dict(fast_at_a_wall_dict())


def test_a_reference_the_robot_cannot_take_up_is_never_a_candidate():
    from anyplan.prediction import PredictedObstacle
    from anyplan.world import RobotState, UnicycleMotion

    agent = make_agent("st-bitstar")
    agent.reset(_fast_at_a_wall(), np.random.default_rng(0))
    state = RobotState(1.0, 1.0, 0.0, 2.0, 0.0)
    agent._preds = [PredictedObstacle("D", 0.3, UnicycleMotion(6.0, 7.0, math.pi, 0.0))]
    path = np.array([[1.0, 1.0], [1.4, 1.0], [1.4, 7.0]])
    out = agent._timed_fn(state, 0.0, 3.0)(path, [], 0.0)
    assert not out.feasible and out.state(0.0).v < 1.5  # the case: a best effort at ~1 m/s
    assert agent._cands == []


def test_the_motion_taken_up_starts_at_the_robots_speed():
    # The replanning at 0 s plans from the state at 0.1 s on the motion in use (2 m/s towards
    # the wall). Whatever it schedules (a new motion, or keeping the current one) must start at
    # the robot's speed then: a reference that starts slower leaves the tracker behind (0.5 m
    # in world 53, where Kanayama then reversed the robot into an obstacle).
    from anyplan.agents.base import Observation
    from anyplan.prediction import PredictedObstacle
    from anyplan.trajectory.trajectory import BrakeSegment, Trajectory
    from anyplan.world import UnicycleMotion

    sc = _fast_at_a_wall()
    agent = make_agent("st-bitstar", **AGENTS.get("st-bitstar").deterministic_settings)
    agent.reset(sc, np.random.default_rng(0))
    spec = sc.robot
    # Braking at a_max from 2.2 m/s: 2.0 m/s at (1.01, 1.0) at t = 0.1 s.
    agent.trajectory = Trajectory([BrakeSegment(0.8, 1.0, 0.0, 2.2, 0.0, spec.a_max,
                                                spec.alpha_max, 0.0)], kind="test")
    preds = [PredictedObstacle("D", 0.3, UnicycleMotion(6.0, 7.0, math.pi, 0.0))]
    before = agent.trajectory
    agent._replan(Observation(0.0, before.state(0.0)), preds, "test")
    t_switch, tr = agent.pending if agent.pending is not None else (0.1, agent.trajectory)
    robot = before.state(t_switch)
    assert robot.v == pytest.approx(2.0, abs=0.01)
    assert abs(tr.state(t_switch).v - robot.v) <= 0.05
    assert getattr(tr, "feasible", True)




@needs_dynabarn
def test_dynabarn_53_known_motion_no_robot_caused_collision():
    # World 53 with the obstacles' motions announced (oracle), deterministic settings: at 1.3 s
    # the robot (1.5 m/s, 3 cm from a static obstacle) took up a reference starting at 0.03 m/s,
    # overshot it by 0.5 m, and Kanayama reversed it into D20 at 4.05 s (-0.23 m/s).
    from anyplan.experiments.dynabarn import load_worlds, world_to_scenario
    from anyplan.simulation.perception import override_sensing

    world = next(w for w in load_worlds(_DYNABARN) if w["world"] == 53)
    sc = override_sensing(scenario_from_dict(world_to_scenario(world)), "oracle")
    agent = make_agent("st-bitstar", **AGENTS.get("st-bitstar").deterministic_settings)
    r = simulate(sc, agent, seed=0)
    assert not r.collision_robot_caused
    assert all(getattr(tr, "feasible", True) for _, tr in agent.executed)
    # Every reference taken up starts at the speed the robot had on the one before.
    for (_, prev), (ts, tr) in zip(agent.executed[:-1], agent.executed[1:], strict=True):
        assert abs(tr.state(ts).v - prev.state(ts).v) <= 0.05


def _agent_in_empty_room(**limits: float):
    """st-bitstar, reset in the crossing scenario's 12 m x 6 m room without its obstacle, for a
    robot with these limits (the fallback tests give it the predictions themselves)."""
    data = _crossing_scenario().to_dict()
    data["robot"].update(limits)
    data["dynamic_obstacles"] = []
    agent = make_agent("st-bitstar")
    agent.reset(scenario_from_dict(data), np.random.default_rng(0))
    return agent


def test_fallback_leaves_a_predicted_collision_rather_than_hold_in_it():
    # A robot at rest, an uncertain obstacle heading at it (1 m/s, 3 m away): holding is struck
    # by the disc planned against (capped at plan_extra_m); driving 1.5 m sideways touches only
    # the full uncertainty disc (1.5 m of growth) while moving, and the planned disc never. The
    # guard's own ranking holds (its moving part is trivially free); st-bitstar moves away.
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.prediction.collision import first_collision
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.0, a_max=1.0, alpha_max=2.0)
    state = RobotState(4.0, 2.0, math.pi / 2, 0.0, 0.0)
    growth = RadiusGrowth(0.0, np.array([0.0, 1.0, 3.0]), np.array([0.0, 0.5, 1.5]))
    obst = [PredictedObstacle("F", 0.25, UnicycleMotion(7.0, 2.0, math.pi, 1.0), growth, until=3.0)]
    dec = agent.guard.fallback(0.0, state, obst, "test")
    assert dec.kind == "hold"
    planned = agent._capped(obst)
    r = agent.spec.radius
    assert first_collision(dec.trajectory, planned, r, t_from=0.0, t_until=5.0) is not None
    kind, tr, _ = agent._evasions(0.0, state, obst, None)
    assert kind != "hold" and tr.t_end > 0.5
    # what it chose is free against the planned discs over the horizon ...
    assert first_collision(tr, planned, r, t_from=0.0, t_until=5.0,
                           margin=agent.guard.config.margin) is None
    # ... and moves away from the obstacle's line
    assert abs(tr.positions(np.array([tr.t_end]))[0][1] - 2.0) > 0.8


def test_evasion_from_a_moving_robot_keeps_its_speed():
    # A robot driving east at 1 m/s, an obstacle coming down across the point where it would
    # brake to rest: braking, holding and every evasion that brakes first are struck; a smooth
    # curve ahead from the robot's speed and heading passes in front of it.
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.0, a_max=1.0, alpha_max=2.0)
    state = RobotState(3.0, 3.0, 0.0, 1.0, 0.0)
    down = [PredictedObstacle("D", 0.25, UnicycleMotion(3.5, 4.6, -math.pi / 2, 1.0), until=5.0)]
    dec = agent.guard.fallback(0.0, state, down, "test")
    assert not dec.safe  # whatever the guard picks (brake, turn away, back off) is struck moving
    kind, tr, _ = agent._evasions(0.0, state, down, None)
    r, m = agent.spec.radius, agent.guard.config.margin
    assert kind == "evade"
    assert tr.state(0.2).v > 0.75  # it did not brake first
    assert first_collision(tr, down, r, t_from=0.0, t_until=5.0, margin=m) is None


def test_fallback_never_brakes_into_a_wall_when_a_curve_clears_it():
    # A robot at 0.8 m/s heading 30 degrees down at a wall 0.2 m beyond its disc: braking
    # straight ahead (0.64 m at 0.5 m/s^2) strikes the wall, so the guard's brake is not
    # certified free; the fallback chosen clears the static obstacles (a curve from the robot's
    # speed and heading).
    from anyplan.prediction import PredictedObstacle
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room(v_max=1.0, omega_max=2.0, a_max=0.5, alpha_max=4.0)
    state = RobotState(6.0, 0.5, -math.pi / 6, 0.8, 0.0)
    far = [PredictedObstacle("far", 0.25, UnicycleMotion(1.0, 5.0, 0.0, 0.2), until=5.0)]
    brake = agent.guard.candidates(0.0, state, far)[0]
    assert brake[0] == "brake" and not brake[1].certified_free
    kind, tr, _ = agent._evasions(0.0, state, far, None)
    assert tr.certified_free and kind != "brake"
    ts = np.linspace(0.0, float(tr.t_end), 200)
    p = tr.positions(ts)
    clear = np.array([agent.obstacles.clearance(tuple(q)) for q in p]) - agent.spec.radius
    assert clear.min() >= 0.0


def _struck_pair(agent, x_obstacle: float, x_drive: float):
    """A hold at (3, 3) and a drive east at 0.2 m/s from (x_drive, 3), an obstacle coming west at
    1 m/s from (x_obstacle, 3); their first predicted contacts."""
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.trajectory.motion import polyline_trajectory
    from anyplan.trajectory.reference import HoldSegment
    from anyplan.trajectory.trajectory import Trajectory
    from anyplan.world import RobotState, UnicycleMotion

    west = [PredictedObstacle("W", 0.25, UnicycleMotion(x_obstacle, 3.0, math.pi, 1.0))]
    hold = Trajectory([HoldSegment(3.0, 3.0, 0.0, 0.0, 12.0)], kind="hold")
    drive = polyline_trajectory(np.array([[x_drive, 3.0], [x_drive + 6.0, 3.0]]), agent.spec,
                                RobotState(x_drive, 3.0, 0.0, 0.0, 0.0), 0.0, agent.obstacles,
                                agent.spec.radius)
    r, m = agent.spec.radius, agent.guard.config.margin
    h_hold = first_collision(hold, west, r, t_from=0.0, t_until=12.0, margin=m)
    h_drive = first_collision(drive, west, r, t_from=0.0, t_until=drive.t_end, margin=m)
    assert h_hold is not None and h_drive is not None and h_drive.t > h_hold.t
    assert drive.state(h_drive.t).v > 0.15  # driving east, into the obstacle, at contact
    return west, hold, drive, h_hold, h_drive


def test_fallback_struck_at_rest_beats_one_struck_soon_after_driving_into_it():
    # Every candidate is predicted struck within the time the robot needs to decide again and
    # stop (react_s): a hold struck at rest ranks before a drive into the same obstacle struck a
    # little later (approach 0.2 m/s > 0.05: a robot-caused collision).
    agent = _agent_in_empty_room(v_max=0.2, omega_max=1.0, a_max=1.0, alpha_max=2.0)
    ranker = agent._ranker()
    gap = agent.spec.radius + 0.25 + agent.guard.config.margin
    west, hold, drive, _, h_drive = _struck_pair(agent, 3.0 + gap + 0.3, 2.9)
    assert h_drive.t < ranker.react_s  # both contacts are near
    k_hold, _ = agent._fallback_rank(hold, 0.0, west, west)
    k_drive, _ = agent._fallback_rank(drive, 0.0, west, west)
    assert k_hold > k_drive
    assert k_hold[:4] == k_drive[:4]  # tied on everything before the approach speed


def test_fallback_struck_later_than_the_reaction_time_beats_a_hold_struck_sooner():
    # The same obstacle, far away: both contacts lie beyond react_s, so at the next decision
    # the robot can still stop short of the drive's contact; the approach speed at so distant a
    # contact does not decide, the later contact does (a hold struck sooner is no safer).
    agent = _agent_in_empty_room(v_max=0.2, omega_max=1.0, a_max=1.0, alpha_max=2.0)
    ranker = agent._ranker()
    west, hold, drive, h_hold, _ = _struck_pair(agent, 12.0, 1.0)
    assert h_hold.t > ranker.react_s
    k_hold, _ = agent._fallback_rank(hold, 0.0, west, west)
    k_drive, _ = agent._fallback_rank(drive, 0.0, west, west)
    assert k_drive > k_hold
    assert k_hold[:5] == k_drive[:5]  # tied up to the contact time


def _corridor_ranker(agent, half_width: float):
    """The agent's fallback ranker in a corridor along x, |y - 3| <= half_width [m], walls 0.5 m
    thick."""
    from anyplan.agents.evasion import FallbackRanker
    from anyplan.geometry import ObstacleSet
    from anyplan.geometry.shapes import rectangle

    walls = ObstacleSet([rectangle((6.0, 3.0 - half_width - 0.25), (20.0, 0.5)),
                         rectangle((6.0, 3.0 + half_width + 0.25), (20.0, 0.5))])
    return FallbackRanker(agent.spec, walls, agent.guard, agent.check_period_s)


def test_evasions_stop_short_of_a_wall_instead_of_being_dropped():
    # A 2 m corridor: driving 1.5 m (v_max x 1.5 s) sideways would go through the wall, so the
    # sideways evasions end short of it, clear of it, at least MIN_EVADE_M from the start.
    from anyplan.agents.evasion import MIN_EVADE_M
    from anyplan.world import RobotState

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    ranker = _corridor_ranker(agent, 1.0)
    state = RobotState(5.0, 3.0, 0.0, 0.0, 0.0)
    ends = [tr.state(float(tr.t_end)) for kind, tr in ranker.candidates(0.0, state, [])
            if kind == "evade"]
    side = [e for e in ends if abs(e.x - 5.0) < 1e-6 and abs(e.y - 3.0) > 1e-6]
    assert len(side) == 2  # up and down the corridor's width, both kept
    for e in side:
        d = abs(e.y - 3.0)
        assert MIN_EVADE_M <= d < 1.5 * agent.spec.v_max
        assert ranker.obstacles.clearance((e.x, e.y)) >= agent.spec.radius


def test_evasions_start_from_a_robot_closer_to_the_wall_than_the_margin():
    # The robot hugs the wall (clearance between its radius and radius + margin): every straight
    # test with the margin fails at the start, yet the robot can still move away from the wall.
    from anyplan.world import RobotState

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    ranker = _corridor_ranker(agent, 1.0)
    r, m = agent.spec.radius, agent.guard.config.margin
    y = 3.0 - 1.0 + r + 0.5 * m  # half the margin from the lower wall
    state = RobotState(5.0, y, 0.0, 0.0, 0.0)
    assert not ranker.obstacles.segment_free((5.0, y), (5.0, y), r + m)
    evades = [tr for kind, tr in ranker.candidates(0.0, state, []) if kind == "evade"]
    assert evades
    ts = np.linspace(0.0, 1.0, 201)
    for tr in evades:  # none comes closer to the walls than the robot's bare radius
        p = tr.positions(ts * float(tr.t_end))
        assert min(ranker.obstacles.clearance(tuple(q)) for q in p) >= r - 1e-9


def test_a_stoppable_motion_struck_later_gives_way_to_a_free_evasion():
    # A hold at (3, 3) is "stoppable" (at rest already) but an obstacle coming west along
    # y = 3 strikes it within the guard's horizon; stepping aside is free of every disc, so
    # freer_evasion offers it. A motion that nothing strikes keeps its place (None).
    from anyplan.agents.evasion import freer_evasion
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.trajectory.reference import HoldSegment
    from anyplan.trajectory.trajectory import Trajectory
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    ranker = agent._ranker()
    state = RobotState(3.0, 3.0, 0.0, 0.0, 0.0)
    hold = Trajectory([HoldSegment(3.0, 3.0, 0.0, 0.0, 8.0)], kind="hold")
    west = [PredictedObstacle("W", 0.25, UnicycleMotion(8.0, 3.0, math.pi, 1.0))]
    h = agent.guard.config.horizon_s
    hit = first_collision(hold, west, agent.spec.radius, t_from=0.0, t_until=h,
                          margin=agent.guard.config.margin)
    assert hit is not None and hit.t > 1.0  # struck, after the robot could have moved
    better = freer_evasion(ranker, 0.0, state, west, west, hold)
    assert better is not None
    kind, tr, clear = better
    assert kind != "hold" and clear >= agent.guard.config.margin
    assert first_collision(tr, west, agent.spec.radius, t_from=0.0, t_until=h,
                           margin=agent.guard.config.margin) is None
    away = [PredictedObstacle("W", 0.25, UnicycleMotion(8.0, 3.0, 0.0, 1.0))]  # going east
    assert freer_evasion(ranker, 0.0, state, away, away, hold) is None


def test_a_motion_is_checked_until_it_arrives_at_the_goal():
    # The robot is 1.2 m short of its goal (11, 3); a person walks down x = 11 and reaches the
    # goal about 2 s after the robot is there. Checked to its end the motion to the goal is
    # struck at rest, at the goal, and a sideways evasion is free, so the freer-evasion rule
    # would leave the goal; but the run is over on arrival: the guard checks the motion until
    # then, finds it free to rest and starts it. A person there before the robot still counts.
    from anyplan.agents.base import Observation
    from anyplan.agents.evasion import freer_evasion
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.trajectory.motion import plan_motion
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    state = RobotState(9.8, 3.0, 0.0, 0.0, 0.0)
    motion = plan_motion(np.array([[9.8, 3.0], [11.0, 3.0]]), agent.spec, state,
                         agent.obstacles, 0.0)
    goal = np.asarray(agent.spec.goal)
    ts = np.linspace(0.0, float(motion.t_end), 2001)
    d = np.hypot(*(motion.positions(ts) - goal).T)
    t_arrive = agent.guard.arrival(motion, 0.0)
    first_in = float(ts[np.argmax(d <= agent.spec.arrival_radius)])
    assert first_in - 1e-9 <= t_arrive <= first_in + 0.02  # on 20 ms samples
    assert t_arrive < float(motion.t_end)
    away = plan_motion(np.array([[9.8, 3.0], [9.8, 5.0]]), agent.spec, state, agent.obstacles, 0.0)
    assert agent.guard.arrival(away, 0.0) == math.inf  # ends elsewhere
    m, commit = agent.guard.config.margin, agent._period()

    def walker(t_at_goal):
        y0 = 3.0 + 1.0 * t_at_goal  # 1 m/s southwards, at the goal at t_at_goal
        return [PredictedObstacle("P", 0.25, UnicycleMotion(11.0, y0, -math.pi / 2, 1.0))]

    late = walker(t_arrive + 2.0)
    hit = first_collision(motion, late, agent.spec.radius, t_from=0.0, t_until=8.0, margin=m)
    assert hit is not None and hit.t > t_arrive  # struck at the goal, after arrival
    assert freer_evasion(agent._ranker(), 0.0, state, late, late, motion) is not None
    assert agent.guard.check(motion, late, 0.0, commit)[0] == "free_to_rest"
    kind, tr = agent._guard(Observation(0.0, state), 0.0, motion, late, late, "test")
    assert kind == "motion" and tr is motion
    early = walker(t_arrive - 0.3)  # at the goal just before the robot
    hit = first_collision(motion, early, agent.spec.radius, t_from=0.0, t_until=8.0, margin=m)
    assert hit is not None and hit.t < t_arrive
    assert agent.guard.check(motion, early, 0.0, commit)[0] != "free_to_rest"
    kind, _ = agent._guard(Observation(0.0, state), 0.0, motion, early, early, "test")
    assert kind != "motion"


def test_the_prediction_horizon_covers_a_slow_robots_escape_time():
    # A robot that turns at 0.4 rad/s and drives at 0.4 m/s needs about 9 s to leave an
    # obstacle's way: predictions are extrapolated that long, not 3 s; a fast robot keeps 3 s.
    from anyplan.agents.evasion import escape_time_s

    slow = _agent_in_empty_room(v_max=0.4, omega_max=0.4, a_max=0.4, alpha_max=1.0)
    assert escape_time_s(slow.spec) > 8.0
    assert slow.prediction_horizon_s == pytest.approx(escape_time_s(slow.spec))
    fast = _agent_in_empty_room(v_max=2.0, omega_max=3.0, a_max=3.0, alpha_max=8.0)
    assert escape_time_s(fast.spec) < 3.0 and fast.prediction_horizon_s == 3.0


def test_when_no_fallback_is_passively_safe_the_one_at_rest_soonest_ranks_first():
    # A standing person 1.2 m ahead of a robot at 1 m/s, reachable at 1.6 m/s: no escape is at
    # rest before the person could reach it. Braking now (at rest in 1 s) outranks driving on
    # (its escape follows the motion one check period first, then brakes).
    from anyplan.agents.safety import reachable_discs
    from anyplan.prediction import PredictedObstacle
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.0, a_max=1.0, alpha_max=2.0)
    state = RobotState(3.0, 3.0, 0.0, 1.0, 0.0)
    person = [PredictedObstacle("P", 0.25, UnicycleMotion(4.2, 3.0, 0.0, 0.0))]
    reach = reachable_discs(person, 0.0, np.array([3.0, 3.0]), 0.0, 0.3, 5.0, min_speed=1.6)
    brake = next(tr for kind, tr, _ in agent.guard.candidates(0.0, state, person) if kind == "brake")
    from anyplan.trajectory.motion import plan_motion

    drive = plan_motion(np.array([[3.0, 3.0], [6.0, 3.0]]), agent.spec, state, agent.obstacles,
                        0.0, allow_turn=False)
    assert drive.state(0.5).v > 0.9
    k_brake, _ = agent._fallback_rank(brake, 0.0, person, person, reach)
    k_drive, _ = agent._fallback_rank(drive, 0.0, person, person, reach)
    assert k_brake[1][0] is False and k_drive[1][0] is False  # neither passively safe
    assert k_brake[1] > k_drive[1]


@needs_dynabarn
def test_branch_and_bound_prunes_paths_that_cannot_arrive_earlier(monkeypatch):
    # DynaBARN 40-47, motions announced, the first replanning only. With the bound, the shortest
    # path is timed with long waits first and a detour whose untimed motion arrives no earlier
    # than the best timed candidate ends the loop; each pruned path could only have been timed
    # later than the candidate chosen, and the choice arrives no later than the full search's.
    import anyplan.agents.spacetime as st
    from anyplan.experiments.dynabarn import load_worlds, world_to_scenario
    from anyplan.simulation.perception import override_sensing

    pruned: list[tuple[float, float]] = []  # (untimed arrival of the pruned path, best arrival)
    inner = st.SpaceTimeBITStarAgent._timed_fn

    def spy(self, state, t_start, max_wait_s, **kw):
        build = inner(self, state, t_start, max_wait_s, **kw)

        def wrapped(path, shapes, delay):
            n = self.record.st_pruned
            out = build(path, shapes, delay)
            if self.record.st_pruned > n:
                nominal = self._nominals[next(reversed(self._nominals))][0]
                pruned.append((nominal.t_end, min(c[0] for c in self._cands)))
                assert out is min(self._cands, key=lambda c: c[0])[1]
            return out
        return wrapped

    monkeypatch.setattr(st.SpaceTimeBITStarAgent, "_timed_fn", spy)
    worlds = {w["world"]: w for w in load_worlds(_DYNABARN)}
    cfg = SimConfig(time_limit=0.05)
    settings = AGENTS.get("st-bitstar").deterministic_settings
    for i in range(40, 48):
        sc = override_sensing(scenario_from_dict(world_to_scenario(worlds[i])), "oracle")
        first = []
        for bound in (True, False):
            agent = make_agent("st-bitstar", **settings)
            agent.branch_and_bound = bound
            simulate(sc, agent, seed=0, config=cfg)
            first.append(agent.stats.plans[0]["arrival_s"] if agent.stats.plans else math.inf)
        assert first[0] <= first[1] + 1e-9, i
    assert pruned, "no world pruned a path"
    assert all(nominal >= best - 1e-9 for nominal, best in pruned)


@needs_dynabarn
def test_search_budget_takes_the_best_candidate_once_one_is_timed():
    # DynaBARN 28 (motions announced): with no time left once a path is timed, the first
    # replanning stops at its first candidate, which it takes (verified free); the full search
    # times more paths (three there) and arrives no later.
    from anyplan.experiments.dynabarn import load_worlds, world_to_scenario
    from anyplan.simulation.perception import override_sensing

    world = next(w for w in load_worlds(_DYNABARN) if w["world"] == 28)
    sc = override_sensing(scenario_from_dict(world_to_scenario(world)), "oracle")
    cfg = SimConfig(time_limit=0.05)
    settings = dict(AGENTS.get("st-bitstar").deterministic_settings)
    full = make_agent("st-bitstar", **settings)
    simulate(sc, full, seed=0, config=cfg)
    settings["search_budget_s"] = 1e-9
    quick = make_agent("st-bitstar", **settings)
    simulate(sc, quick, seed=0, config=cfg)
    assert quick.record.st_pruned >= 1 and quick.record.st_candidates[0] == 1
    assert full.record.st_candidates[0] > quick.record.st_candidates[0]
    assert full.stats.plans[0]["arrival_s"] <= quick.stats.plans[0]["arrival_s"] + 1e-9
    assert quick.stats.plans[0]["kind"] != "fallback-hold"


def test_announced_motions_are_planned_on_a_receding_horizon():
    # Announced motions end at announced_horizon_s after the call (planned, timed and checked
    # that far ahead, no guard: they are certain); None keeps them whole. Predictions that end
    # as observed (twist, tracked) keep their own horizon.
    from anyplan.prediction import PredictedObstacle
    from anyplan.world import UnicycleMotion

    motion = UnicycleMotion(6.0, 0.5, math.pi / 2, 0.3)
    announced = [PredictedObstacle("X", 0.3, motion)]
    p = np.array([1.0, 3.0])
    for horizon in (30.0, 5.0, None):
        agent = make_agent("st-bitstar", announced_horizon_s=horizon)
        agent.reset(_crossing_scenario(), np.random.default_rng(0))
        planned, guarded = agent._split(announced, p, 2.0)
        assert guarded is None
        assert [o.until for o in planned] == [math.inf if horizon is None else 2.0 + horizon]
        assert planned[0].motion is motion and planned[0].radius == 0.3
    twist = [PredictedObstacle("X", 0.3, motion, until=10.0)]
    assert agent._split(twist, p, 2.0)[0][0].until == math.inf  # guard "growth": in full
    agent = make_agent("st-bitstar", announced_horizon_s=5.0, guard="horizon")
    agent.reset(_crossing_scenario(), np.random.default_rng(0))
    assert [o.until for o in agent._split(twist, np.array([5.0, 2.5]), 2.0)[0]] == [10.0]
    for bad in (0.0, -1.0, "far"):
        with pytest.raises(ValueError, match="announced_horizon_s"):
            make_agent("st-bitstar", announced_horizon_s=bad)


def test_a_crossing_beyond_the_announced_horizon_is_replanned_and_avoided():
    # The crossing (at about 13 s) is beyond a 5 s horizon at the start: the first motion
    # drives into it as far as it knows; as the crossing comes within the horizon, a check
    # predicts it and the robot replans, and passes without collision.
    r = simulate(_crossing_scenario(), make_agent("st-bitstar", announced_horizon_s=5.0,
                                                  **_fixed()), seed=0)
    assert r.status == "reached" and not r.collision
    assert any(x.startswith("collision with X predicted") for x in r.extra["reasons"])
    whole = simulate(_crossing_scenario(), make_agent("st-bitstar", announced_horizon_s=None,
                                                      **_fixed()), seed=0)
    assert not any(x.startswith("collision") for x in whole.extra["reasons"])


def test_a_planning_call_books_its_safety_decision_too(monkeypatch):
    # The guard and the fallbacks are part of the planning call: their time is booked in
    # planning_times_s (and so in the measured delay of the next calls), as seq-bitstar books
    # its guard. Here the guard is made 0.2 s slower; a call that ran it books at least that.
    import time as _time

    from anyplan.agents.spacetime import SpaceTimeBITStarAgent
    from anyplan.simulation.perception import override_sensing

    slow = 0.2
    original = SpaceTimeBITStarAgent._guard

    def slow_guard(self, *args, **kwargs):
        _time.sleep(slow)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(SpaceTimeBITStarAgent, "_guard", slow_guard)
    sc = override_sensing(scenario_from_dict(head_on_corridor_dict(2.0)), "twist")
    agent = make_agent("st-bitstar", guard="horizon", planning_delay=0.1)
    r = simulate(sc, agent, seed=0)
    guarded = r.extra["safety_time_s"]
    assert guarded and min(guarded) >= slow
    # every call ran the guard here (the obstacle's twist is uncertain under guard="horizon")
    assert len(r.planning_times_s) == len(guarded)
    assert all(p >= g for p, g in zip(r.planning_times_s, guarded, strict=True))


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 6), v0=st.floats(0.0, 0.4))
def test_lazy_fallback_ranking_picks_what_ranking_every_candidate_picks(seed, n, v0):
    # _best_ranked skips the clearance of candidates the planned discs strike within the margin
    # (the struck test of its staged key) and computes it only on a tie: the same candidate, key and
    # clearance as ranking every candidate by its whole key (FallbackRanker.rank).
    from anyplan.agents.evasion import _best_ranked
    from anyplan.prediction import PredictedObstacle
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.world import RobotState, UnicycleMotion

    agent = _agent_in_empty_room()
    rng = np.random.default_rng(seed)
    growth = RadiusGrowth(0.0, np.array([0.0, 1.0, 2.0, 4.0]), np.array([0.05, 0.3, 0.6, 1.0]))
    full = [PredictedObstacle(f"P{k}", 0.25,
                              UnicycleMotion(*rng.uniform([3.0, 1.5], [9.0, 4.5]),
                                             rng.uniform(-math.pi, math.pi), rng.uniform(0.2, 1.2)),
                              growth, until=5.0) for k in range(n)]
    planned = agent._capped(full)
    state = RobotState(6.0, 3.0, float(rng.uniform(-math.pi, math.pi)), v0, 0.0)
    ranker = agent._ranker()
    (key, clear), kind, tr = _best_ranked(ranker, 0.0, state, full, planned, None, None, ())
    ranked = [(ranker.rank(c, 0.0, full, planned), k, c)
              for k, c in ranker.candidates(0.0, state, full)]
    (k_all, clear_all), kind_all, tr_all = max(ranked, key=lambda c: c[0][0])
    assert (key, clear, kind) == (k_all, clear_all, kind_all)
    assert tr.t_end == tr_all.t_end and np.array_equal(tr.positions(np.array([0.5])),
                                                       tr_all.positions(np.array([0.5])))


def test_a_safety_decision_ready_after_its_switch_time_is_made_from_the_later_state(monkeypatch):
    # Measured planning delay, capped at 0.2 s (max_delay_s): a guard that takes 0.3 s cannot
    # hand over its decision at the switch time planned before it ran. The robot follows its
    # reference until the decision is ready, and the decision is made again from the state the
    # robot has then: every motion the guard lets start (or fallback) starts at its switch
    # time, no earlier than its call plus the guard's 0.3 s, and counts as a late plan.
    import time as _time

    from anyplan.agents.spacetime import SpaceTimeBITStarAgent
    from anyplan.simulation.perception import override_sensing

    slow = 0.3
    original = SpaceTimeBITStarAgent._guard
    decided: dict[int, float] = {}  # id(trajectory) -> time of the call that decided it

    def slow_guard(self, obs, t_switch, *args, **kwargs):
        _time.sleep(slow)
        kind, tr = original(self, obs, t_switch, *args, **kwargs)
        if kind != "keep":
            decided[id(tr)] = obs.t
        return kind, tr

    monkeypatch.setattr(SpaceTimeBITStarAgent, "_guard", slow_guard)
    sc = override_sensing(scenario_from_dict(head_on_corridor_dict(3.0)), "twist")
    agent = make_agent("st-bitstar", guard="horizon")  # measured delay
    agent.max_delay_s = 0.2  # (st-bitstar's cap is its loop's max_time_s, 0.3 s)
    r = simulate(sc, agent, seed=0)
    taken = [(t_sw, tr) for t_sw, tr in agent.executed if id(tr) in decided]
    assert len(taken) >= 2
    for t_sw, tr in taken:
        assert t_sw - decided[id(tr)] >= slow - 1e-9  # not before the guard could decide it
        assert float(tr.t_start) == pytest.approx(t_sw)  # from the state at its switch
    assert r.extra["late_plans"] >= len(taken)


def test_the_motion_is_checked_every_twist_check_period_among_exact_twists(monkeypatch):
    # With exact twists (no announced motion, no uncertain disc) each check is the robot's
    # next chance to react to a changed prediction: every twist_check_period_s (0.1 s); with
    # announced motions, tracked obstacles, and with the option off, every check_period_s
    # (0.2 s) as before.
    from anyplan.agents.spacetime import SpaceTimeBITStarAgent
    from anyplan.simulation.perception import override_sensing

    times: list[float] = []
    original = SpaceTimeBITStarAgent._check

    def spy(self, obs, preds):
        times.append(obs.t)
        return original(self, obs, preds)

    monkeypatch.setattr(SpaceTimeBITStarAgent, "_check", spy)
    base = scenario_from_dict(head_on_corridor_dict(2.0))

    def usual_interval(sc, **options):
        times.clear()
        simulate(sc, make_agent("st-bitstar", planning_delay=0.1, **options), seed=0)
        gaps, counts = np.unique(np.round(np.diff(times), 6), return_counts=True)
        assert len(times) > 5
        return float(gaps[np.argmax(counts)])

    assert usual_interval(override_sensing(base, "twist")) == pytest.approx(0.1)
    assert usual_interval(override_sensing(base, "twist"),
                          twist_check_period_s=0.15) == pytest.approx(0.15)
    for sc, options in ((base, {}), (override_sensing(base, "tracked"), {}),
                        (override_sensing(base, "twist"), {"twist_check_period_s": None})):
        assert usual_interval(sc, **options) == pytest.approx(0.2)
    for bad in (0.0, -0.1, "often"):
        with pytest.raises(ValueError, match="twist_check_period_s"):
            make_agent("st-bitstar", twist_check_period_s=bad)
