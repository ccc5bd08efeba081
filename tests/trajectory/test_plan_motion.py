"""plan_motion and Trajectory: the whole chain on hand-made paths and random static worlds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.geometry import Circle, ObstacleSet, rectangle
from anyplan.trajectory import SmoothCurve, Trajectory, plan_motion, polyline_trajectory
from anyplan.world import RobotState, load_scenario

PAPER_PATH = np.array([[1.5, 5.5], [5.5, 5.5], [6.0, 5.0], [8.0, 5.2], [13.5, 5.5]])


def dense_clearance(traj: Trajectory, obstacles: ObstacleSet, dt: float = 2e-3) -> float:
    t = np.arange(traj.t_start, traj.t_end + dt, dt)
    return float(obstacles.clearances(traj.positions(t)).min())


def test_sample_contract_and_hold_after_end():
    sc = load_scenario("paper-1").static_only()
    tr = plan_motion(PAPER_PATH, sc.robot, RobotState(1.5, 5.5, 0.0), sc.obstacle_set(), 2.0)
    assert tr.t_start == 2.0 and tr.t_end > tr.t_start
    t = np.linspace(0.0, tr.t_end + 3.0, 77).reshape(7, 11)
    vals = tr.sample(t)
    assert all(v.shape == (7, 11) for v in vals)
    assert tr.positions(t.ravel()).shape == (77, 2)
    np.testing.assert_allclose(tr.positions(np.array([2.0])), [[1.5, 5.5]], atol=1e-12)
    # before the start: held at the start pose
    x, y, th, _, _ = tr.sample(np.array([0.0, 2.0]))
    assert x[0] == x[1] and y[0] == y[1] and th[0] == th[1]
    xe, ye, _, ve, we = tr.sample(np.array([tr.t_end, tr.t_end + 100.0]))
    np.testing.assert_allclose([xe[0], ye[0]], [13.5, 5.5], atol=1e-9)
    assert ve[1] == 0.0 and we[1] == 0.0 and xe[1] == xe[0]
    assert tr.path.shape[1] == 2
    assert np.allclose(tr.path[0], [1.5, 5.5]) and np.allclose(tr.path[-1], [13.5, 5.5])
    assert tr.length == pytest.approx(float(np.sum(np.hypot(*np.diff(tr.path, axis=0).T))), rel=1e-3)
    st = tr.state(5.0)
    assert isinstance(st, RobotState)
    xs, ys, ths, vs, ws = tr.sample(np.array([5.0]))
    assert (st.x, st.y, st.theta, st.v, st.omega) == (xs[0], ys[0], ths[0], vs[0], ws[0])


@pytest.mark.parametrize("shortcut", [True, False])
def test_paper_path_limits_clearance_and_bound(shortcut, limits_checker):
    sc = load_scenario("paper-1").static_only()
    obs, spec = sc.obstacle_set(), sc.robot
    tr = plan_motion(PAPER_PATH, spec, RobotState(1.5, 5.5, 0.0), obs, 0.0, shortcut=shortcut)
    limits_checker(tr, spec)
    assert dense_clearance(tr, obs) >= spec.radius - 1e-9
    assert tr.lower_bound_s - 1e-9 <= tr.duration <= 1.10 * tr.lower_bound_s
    if shortcut:  # the hand-made detour is not needed: a straight line is free
        assert tr.info["vertices"] == 2 and tr.length == pytest.approx(12.0)


@pytest.mark.parametrize("seed", range(10))
def test_random_worlds_chain(seed, world_factory, limits_checker):
    obs, path, spec = world_factory(seed)
    st = RobotState(spec.start[0], path[0, 1], spec.start[2] + (0.8 if seed % 2 else 0.0))
    tr = plan_motion(path, spec, st, obs, 1.0, shortcut=seed % 3 != 0)
    assert tr.kind in ("smooth", "turn+smooth", "polyline")
    limits_checker(tr, spec)
    assert dense_clearance(tr, obs) >= spec.radius - 1e-9
    np.testing.assert_allclose(tr.positions(np.array([tr.t_end])), path[-1:], atol=1e-9)
    assert tr.duration >= tr.lower_bound_s - 1e-9


@pytest.mark.parametrize("theta", [0.0, 0.6, -1.2, 2.5])
def test_start_while_moving(theta, limits_checker):
    # Replanning on the move: v0 = 0.3 m/s, omega0 = 0.1 rad/s, heading theta.
    obs = ObstacleSet([Circle((5.0, 3.0), 0.7)], bounds=(0.0, 0.0, 10.0, 6.0))
    spec = load_scenario("paper-1").robot
    path = np.array([[2.0, 3.0], [4.0, 4.3], [6.5, 4.3], [8.5, 3.0]])
    st = RobotState(2.0, 3.0, theta, 0.3, 0.1)
    tr = plan_motion(path, spec, st, obs, 10.0)
    _, _, th, v, _ = tr.sample(np.array([10.0]))
    assert v[0] == pytest.approx(0.3)
    assert th[0] == pytest.approx(theta)
    assert tr.feasible
    limits_checker(tr, spec)
    assert dense_clearance(tr, obs) >= spec.radius - 1e-9
    c = tr.info["candidates"]
    assert tr.duration == pytest.approx(min(c.values()))
    if abs(theta) > 0.01:
        # braking and turning in place was considered: built, or not built because its lower
        # bound is later than the motion taken
        pruned = tr.info.get("pruned", {})
        assert "turn+smooth" in c or pruned["turn+smooth"] > tr.duration


def test_zero_slack_path_falls_back_to_polyline(limits_checker):
    # The polyline runs at exactly the robot radius along a wall into a corner: no spline through
    # its corner can stay on the free side, so the chain falls back to turning in place.
    r = 0.3
    path = np.array([[1.0, 4.0], [5.0, 2.0], [9.0, 4.0]])
    d = (path[1] - path[0]) / np.hypot(*(path[1] - path[0]))
    n = np.array([d[1], -d[0]])
    box = rectangle((3.0, 3.0) + n * (r + 0.25), (3.0, 0.5), math.atan2(d[1], d[0]))
    obs = ObstacleSet([box], bounds=(0.0, 0.0, 10.0, 6.0))
    spec = load_scenario("paper-1").robot
    st = RobotState(1.0, 4.0, math.atan2(d[1], d[0]))
    tr = plan_motion(path, spec, st, obs, 0.0, max_repair_rounds=4, shortcut=False)
    assert tr.kind == "polyline"
    limits_checker(tr, spec)
    assert dense_clearance(tr, obs) >= r - 1e-9
    # straight legs: the path is exactly the polyline
    rel = tr.path[:10] - path[0]
    assert np.max(np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0])) < 1e-9


def test_polyline_trajectory_direct(limits_checker):
    spec = load_scenario("paper-1").robot
    tr = polyline_trajectory(PAPER_PATH, spec, RobotState(1.5, 5.5, 1.0), 0.0)
    limits_checker(tr, spec)
    assert [s.kind for s in tr.segments][:2] == ["turn", "curve"]
    assert tr.length == pytest.approx(float(np.sum(np.hypot(*np.diff(PAPER_PATH, axis=0).T))))


def test_max_speed_bounds_position_rate():
    sc = load_scenario("paper-1").static_only()
    tr = plan_motion(PAPER_PATH, sc.robot, RobotState(1.5, 5.5, 0.0), sc.obstacle_set(), 0.0)
    assert sc.robot.v_max <= tr.max_speed <= 1.02 * sc.robot.v_max
    t = np.arange(0.0, tr.t_end, 1e-3)
    p = tr.positions(t)
    assert np.max(np.hypot(*np.diff(p, axis=0).T) / 1e-3) <= tr.max_speed


def test_already_at_goal_holds():
    spec = load_scenario("paper-1").robot
    tr = plan_motion(np.array([[3.0, 3.0]]), spec, RobotState(3.0, 3.0, 0.0), ObstacleSet(), 0.0)
    assert tr.kind == "hold" and tr.length == 0.0


@pytest.mark.parametrize(("v0", "w0"), [(0.0, 0.3), (0.0, -0.4), (0.3, 0.2)])
def test_already_at_goal_comes_to_rest_without_turning_back(v0, w0, limits_checker):
    # A robot on its goal, still driving or spinning: it brakes and stops its turn where the
    # deceleration leaves it (come_to_rest), not back at the heading it had.
    spec = load_scenario("paper-1").robot
    st = RobotState(3.0, 3.0, 0.5, v0, w0)
    tr = plan_motion(np.array([[3.0, 3.0]]), spec, st, ObstacleSet(), 0.0)
    assert tr.kind == "hold"
    limits_checker(tr, spec)
    _, _, th, v, w = tr.sample(np.linspace(0.0, tr.t_end, 200))
    assert v[-1] == 0.0 and w[-1] == 0.0
    # the heading moves one way only: the spin decelerates, it never reverses
    dth = np.diff(th)
    assert np.all(dth * np.sign(w0) >= -1e-12)
    if v0 == 0.0:
        assert th[-1] - 0.5 == pytest.approx(w0 * abs(w0) / (2.0 * spec.alpha_max), abs=1e-9)


@pytest.mark.parametrize("v0", [0.0, 0.2, 0.4])
def test_facing_a_wall_brakes_and_turns(v0, limits_checker):
    # Heading into a wall 0.6 m away: a smooth start would have to loop through the wall.
    spec = load_scenario("paper-1").robot
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    tr = plan_motion(np.array([[0.9, 3.0], [9.0, 3.0]]), spec, RobotState(0.9, 3.0, math.pi, v0, 0.0),
                     obs, 0.0)
    assert tr.kind == ("turn+smooth" if v0 == 0.0 else "brake+turn+smooth")
    assert "smooth" not in tr.info["candidates"]
    limits_checker(tr, spec)
    assert dense_clearance(tr, obs) >= spec.radius - 1e-9
    assert tr.certified_free and tr.feasible


def test_colliding_input_is_reported():
    spec = load_scenario("paper-1").robot
    obs = ObstacleSet([Circle((5.0, 3.0), 0.5)], bounds=(0.0, 0.0, 10.0, 6.0))
    tr = plan_motion(np.array([[1.0, 3.0], [9.0, 3.0]]), spec, RobotState(1.0, 3.0, 0.0), obs, 0.0,
                     max_repair_rounds=2)
    assert tr.kind == "polyline" and not tr.certified_free


def test_certified_first_contact_with_a_moving_obstacle():
    # How Sequential BIT* uses a Trajectory: certified first contact with a predicted disc.
    from anyplan.geometry import first_contact
    from anyplan.world import UnicycleMotion

    sc = load_scenario("paper-1").static_only()
    tr = plan_motion(PAPER_PATH, sc.robot, RobotState(1.5, 5.5, 0.0), sc.obstacle_set(), 0.0,
                     shortcut=False)
    mover = UnicycleMotion(7.0, 1.0, math.pi / 2, 0.25)
    contact = 0.3 + 0.3
    t_hit = first_contact(tr.positions, mover.positions, tr.max_speed + mover.max_speed, contact,
                          tr.t_start, tr.t_end + 5.0, tol=1e-4)
    t = np.arange(0.0, tr.t_end + 5.0, 1e-3)
    d = np.hypot(*(tr.positions(t) - mover.positions(t)).T)
    brute = t[np.argmax(d <= contact)] if np.any(d <= contact) else None
    assert brute is not None and t_hit is not None
    assert t_hit <= brute + 1e-9 and t_hit >= brute - 2e-3


@pytest.mark.parametrize(("w0", "target"), [(0.4, 0.0), (-0.4, 0.5), (0.2, -0.8), (0.0, 0.5)])
def test_smooth_start_matches_the_current_turn_rate(w0, target, limits_checker):
    # Replanning while driving on a curve: the reference starts at the robot's own (v, omega).
    spec = load_scenario("paper-1").robot
    obs = ObstacleSet([], bounds=(0.0, 0.0, 20.0, 20.0))
    st = RobotState(5.0, 10.0, 0.0, 0.4, w0)
    path = np.array([[5.0, 10.0], [5.0 + 8.0 * math.cos(target), 10.0 + 8.0 * math.sin(target)]])
    tr = plan_motion(path, spec, st, obs, 0.0)
    assert tr.kind == "smooth"
    _, _, th, v, w = tr.sample(np.array([0.0]))
    assert th[0] == pytest.approx(0.0, abs=1e-12)
    assert 0.4 - 0.01 <= v[0] <= 0.4 + 1e-12
    assert w[0] == pytest.approx(w0 * v[0] / 0.4, abs=1e-9)
    limits_checker(tr, spec)
    # it beats stopping and turning toward the path: its duration, or a lower bound of it when
    # it was not built for that reason (``pruned``)
    turn = {**tr.info.get("pruned", {}), **tr.info["candidates"]}["turn+smooth"]
    assert tr.duration < turn


def test_curvature_matched_curve_keeps_points_and_conditions():
    pts = np.array([[0.0, 0.0], [1.0, 0.2], [2.4, 0.8], [3.9, 0.6], [6.0, 0.0]])
    for k0 in (-1.0, 0.0, 0.5, 2.0):
        c = SmoothCurve(pts, start_heading=0.3, start_curvature=k0)
        np.testing.assert_allclose(c.position(c.point_u), pts, atol=1e-12)
        k, _ = c.curvature(np.array([0.0, c.knots[-1]]))
        assert k[0] == pytest.approx(k0, abs=1e-9) and abs(k[1]) < 1e-9
        assert c.heading(np.array([0.0]))[0] == pytest.approx(0.3, abs=1e-12)


def test_spinning_in_place_continues_with_the_turn():
    # At v = 0 while turning at 0.4 rad/s, a smooth start would need omega to jump to 0.
    spec = load_scenario("paper-1").robot
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    tr = plan_motion(np.array([[2.0, 3.0], [8.0, 3.5]]), spec, RobotState(2.0, 3.0, 0.0, 0.0, 0.4), obs, 0.0)
    assert tr.kind == "turn+smooth"
    _, _, _, v, w = tr.sample(np.array([0.0]))
    assert v[0] == 0.0 and w[0] == pytest.approx(0.4)
    assert tr.info["candidates"]["smooth"] == math.inf


def test_polyline_fallback_from_a_moving_state(limits_checker):
    spec = load_scenario("paper-1").robot
    st = RobotState(1.5, 5.5, 0.3, 0.3, 0.2)
    tr = polyline_trajectory(PAPER_PATH, spec, st, 4.0)
    assert [s.kind for s in tr.segments][:3] == ["brake", "turn", "curve"]
    _, _, _, v, w = tr.sample(np.array([4.0]))
    assert v[0] == pytest.approx(0.3) and w[0] == pytest.approx(0.2)
    limits_checker(tr, spec)


def test_margin_is_reduced_to_the_start_clearance():
    # The robot starts 5 mm from a wall's inflated boundary; a 2 cm margin cannot be kept there.
    spec = load_scenario("paper-1").robot
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    st = RobotState(1.0, spec.radius + 0.005, 0.0)
    tr = plan_motion(np.array([[1.0, 0.305], [9.0, 0.305]]), spec, st, obs, 0.0, margin=0.02)
    assert tr.certified_free and tr.kind == "smooth"
    assert dense_clearance(tr, obs) >= spec.radius - 1e-9


def test_turn_candidate_pruned_by_its_bound_changes_no_motion(monkeypatch):
    """The turn-in-place candidate is not built when its lower bound (turn, then a straight line
    as long as the polyline its curve passes through, under v_max and a_max) is later than the
    smooth start: on random paths
    and states (at rest and moving, aligned or not) the same motion, bit for bit, as building
    it always; it is pruned in some cases and wins in others; and where it is built its
    duration is never below the bound."""
    from anyplan.trajectory import motion as motion_mod
    from anyplan.trajectory.path import clean_path, polyline_length
    from anyplan.trajectory.profile import time_lower_bound

    rng = np.random.default_rng(7)
    obs = ObstacleSet([Circle((5.0, 3.0), 0.7), Circle((3.0, 1.5), 0.4)], bounds=(0.0, 0.0, 10.0, 6.0))
    spec = load_scenario("paper-1").robot
    pruned = won = 0
    for _ in range(40):
        p0 = rng.uniform((0.5, 0.5), (2.0, 5.5))
        mid = rng.uniform((2.0, 0.5), (8.0, 5.5), (int(rng.integers(0, 3)), 2))
        path = np.vstack([p0, mid, rng.uniform((8.0, 0.5), (9.5, 5.5))])
        if not obs.path_free(path, spec.radius):
            continue
        v = float(rng.choice([0.0, 0.3, 1.0]))
        st = RobotState(*p0, float(rng.uniform(-np.pi, np.pi)), v, float(rng.choice([0.0, 0.1])) * (v > 0))
        got = plan_motion(path, spec, st, obs, 3.0)
        with monkeypatch.context() as mp:
            mp.setattr(motion_mod, "_PRUNE_SLACK_S", math.inf)  # never pruned
            want = plan_motion(path, spec, st, obs, 3.0)
        assert got.kind == want.kind and got.t_end == want.t_end
        t = np.linspace(got.t_start, got.t_end, 301)
        assert np.array_equal(np.column_stack(got.sample(t)), np.column_stack(want.sample(t)))
        pruned += "pruned" in got.info
        won += want.kind.endswith("turn+smooth")
        if "turn+smooth" in want.info["candidates"] and want.kind.endswith("turn+smooth"):
            curve_seg = want.segments[-1]
            length = polyline_length(clean_path(want.polyline))
            assert curve_seg.curve.length >= length * (1.0 - 1e-6)
            assert want.t_end >= curve_seg.t0 + time_lower_bound(length * (1.0 - 1e-6), spec, 0.0)
        if "pruned" in got.info:
            assert got.info["pruned"]["turn+smooth"] > got.duration
    assert pruned > 0 and won > 0


def test_braking_memo_answers_as_a_fresh_braking():
    # brake_to_rest reuses a braking segment built from the same inputs (bit for bit) and its
    # certification per obstacle set and radius: the same segment and answer as a fresh one,
    # never another obstacle set's or radius's answer, and -0.0 is not taken for 0.0.
    from anyplan.trajectory import motion as mo
    from anyplan.trajectory.trajectory import BrakeSegment

    spec = load_scenario("paper-1").robot
    free = ObstacleSet([Circle((3.0, 0.0), 0.2)])
    wall = ObstacleSet([Circle((1.2, 0.0), 0.2)])  # the braking path ends 0.25 m short of it
    t = np.linspace(0.5, 2.0, 31)
    built = []
    for theta in (0.0, -0.0):
        st = RobotState(0.5, 0.0, theta, 0.5, 0.0)
        fresh = BrakeSegment(0.5, 0.0, theta, 0.5, 0.0, spec.a_max, spec.alpha_max, 0.5)
        answers = []
        for obst, radius in ((free, 0.3), (wall, 0.3), (free, 0.3), (wall, 0.1)):
            segs, t_rest, rest, ok = mo.brake_to_rest(st, spec, obst, radius, 0.5)
            assert all(np.array_equal(a, b) for a, b in zip(segs[0].sample(t), fresh.sample(t),
                                                           strict=True))
            assert t_rest == fresh.t1 and rest.v == 0.0
            answers.append(ok)
        assert answers == [True, False, True, True]
        built.append(segs[0])
        assert mo.brake_to_rest(st, spec, free, 0.3, 0.5)[0][0] is segs[0]  # from the memo
    assert built[0] is not built[1]
