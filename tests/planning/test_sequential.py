"""The Sequential BIT* loop (the paper's Algorithm 1 and our extensions)."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.agents.sequential import SequentialBITStarAgent
from anyplan.geometry import ObstacleSet, rectangle
from anyplan.planning.sequential import SequentialBITStar, SequentialConfig, shrink_square
from anyplan.prediction import ConstantTwistPredictor, PredictedObstacle
from anyplan.simulation.simulator import observe
from anyplan.trajectory.motion import plan_motion
from anyplan.world import RobotSpec, RobotState, UnicycleMotion, load_scenario


def _loop(scenario, cfg=None, seed=0):
    spec = scenario.robot
    obstacles = scenario.obstacle_set()
    state = RobotState(*spec.start, 0.0, 0.0)

    def motion_fn(path, shapes, delay):
        obst = obstacles.with_shapes(shapes) if shapes else obstacles
        # The robot is at rest at the start: waiting is simply departing later.
        return plan_motion(path, spec, state, obst, delay, margin=0.015)

    loop = SequentialBITStar(obstacles, robot_radius=spec.radius, plan_radius=spec.radius + 0.03,
                             motion=motion_fn, config=cfg or SequentialConfig(),
                             rng=np.random.default_rng(seed))
    preds = ConstantTwistPredictor().predict(observe(scenario, 0.0, state))
    return loop, preds, state


def _dense_clearance(motion, scenario, t_step=0.01):
    t = np.arange(motion.t_start, motion.t_end + t_step, t_step)
    p = motion.positions(t)
    gaps = [np.hypot(*(p - o.motion.positions(t)).T) - o.radius - scenario.robot.radius
            for o in scenario.moving_obstacles]
    return min(float(g.min()) for g in gaps)


@pytest.mark.parametrize("name", ["paper-1", "paper-2", "paper-3"])
@pytest.mark.parametrize("warm", [True, False])
def test_loop_returns_a_motion_that_clears_every_moving_obstacle(name, warm):
    sc = load_scenario(name)
    loop, preds, _ = _loop(sc, SequentialConfig(warm_start=warm, prediction_dt=None))
    res = loop.replan(np.array(sc.robot.start[:2]), np.array(sc.robot.goal), preds, 0.0)
    assert res.collision_free and res.status == "collision_free"
    assert res.iterations == len(res.costs) >= 2  # the straight route collides first
    assert len(res.virtual_obstacles) == res.iterations - 1
    # Independent check on the true motions: the margin (0.05 m) is kept, up to the dense step.
    assert _dense_clearance(res.motion, sc) >= loop.config.margin - 0.4 * 0.01 - 1e-9
    # The path avoids the static obstacles and every virtual square exactly.
    obst = sc.obstacle_set().with_shapes([v.shape for v in res.virtual_obstacles])
    assert obst.path_free(res.path, sc.robot.radius)
    for v in res.virtual_obstacles:
        assert v.side == pytest.approx(2 * (0.3 + 0.3)) or v.shrunk


def test_squares_are_centred_on_the_robot_reference_at_the_collision():
    sc = load_scenario("paper-1")
    loop, preds, _ = _loop(sc, SequentialConfig(prediction_dt=None))
    res = loop.replan(np.array(sc.robot.start[:2]), np.array(sc.robot.goal), preds, 0.0)
    v = res.virtual_obstacles[0]
    assert v.obstacle == "D1"
    # The first plan is the straight line y = 5.5: the robot meets D1 there, before x = 5.
    assert v.center[1] == pytest.approx(5.5, abs=1e-6)
    assert 3.5 < v.center[0] < 5.0
    assert v.collision_time_s > 0.0


def _paper3_on_batches():
    """paper-3 with BIT* on batches (deterministic): the scenario, start, goal, loop settings and
    the loop's whole replanning from the start."""
    sc = load_scenario("paper-3")
    start, goal = np.array(sc.robot.start[:2]), np.array(sc.robot.goal)
    cfg = SequentialConfig(prediction_dt=None, batches_per_plan=2)
    loop, preds, _ = _loop(sc, cfg)
    return sc, start, goal, cfg, loop.replan(start, goal, preds, 0.0)


def test_a_chain_left_off_is_taken_up_where_it_stopped():
    # paper-3 (BIT* on batches: deterministic): the loop goes around three squares. Started
    # again from the first square of its chain, it plans around that square from its first
    # path on (the straight line is not tried again), counts it towards max_iterations, and
    # ends free as well.
    sc, start, goal, cfg, full = _paper3_on_batches()
    assert full.collision_free and len(full.virtual_obstacles) >= 2
    first = full.virtual_obstacles[:1]
    loop, preds, _ = _loop(sc, cfg)
    tried = []
    inner = loop.motion

    def spy(path, shapes, delay):
        tried.append(list(shapes))
        return inner(path, shapes, delay)

    res = loop.replan(start, goal, preds, 0.0, motion=spy, chain=first)
    assert res.collision_free
    assert all(first[0].shape in shapes for shapes in tried)
    assert res.virtual_obstacles[0] is first[0]
    assert res.iterations == len(res.virtual_obstacles) + 1
    # a chain that holds the start (the robot moved into a square) is dropped
    loop, preds, _ = _loop(sc, SequentialConfig(prediction_dt=None, batches_per_plan=2,
                                                max_iterations=1))
    on_start = [type(first[0])((float(start[0]), float(start[1])), 1.0, 0.0, 1.0, "D1", False)]
    res = loop.replan(start, goal, preds, 0.0, chain=on_start)
    assert res.status != "invalid_start" and on_start[0] not in res.virtual_obstacles
    assert len(res.costs) == 1  # max_iterations counted from an empty chain


def test_stop_ends_the_loop_before_a_search_with_the_squares_so_far():
    # paper-3 (batches: deterministic) needs at least three plans. A caller that stops before
    # the second search gets the first plan's best effort, and is asked once, with the first
    # square; one that never stops gets what no stop gives.
    sc, start, goal, cfg, full = _paper3_on_batches()
    asked = []

    def stop(squares):
        asked.append(list(squares))
        return True

    loop, preds, _ = _loop(sc, cfg)
    res = loop.replan(start, goal, preds, 0.0, stop=stop)
    assert res.status == "collision_predicted" and res.iterations == len(res.costs) == 1
    assert len(asked) == 1 and len(asked[0]) == 1
    assert asked[0][0].center == full.virtual_obstacles[0].center
    assert res.collision is not None and res.costs[0] == full.costs[0]  # the same first plan
    loop, preds, _ = _loop(sc, cfg)
    never = loop.replan(start, goal, preds, 0.0, stop=lambda squares: False)
    assert never.iterations == full.iterations and np.array_equal(never.path, full.path)


def test_shrink_square_keeps_the_robot_clear():
    rng = np.random.default_rng(1)
    for _ in range(500):
        c = rng.uniform(-2, 2, 2)
        pts = [rng.uniform(-2, 2, 2) for _ in range(2)]
        side = shrink_square(c, 1.2, pts, 0.33)
        assert 0.0 <= side <= 1.2
        if side > 0.0:
            box = ObstacleSet([rectangle(c, (side, side))])
            for p in pts:
                assert box.clearance(p) >= 0.33 - 1e-6
            # Maximal: a slightly larger square would touch one of the points (or side is 1.2).
            if side < 1.2 - 1e-9:
                bigger = ObstacleSet([rectangle(c, (side + 1e-4, side + 1e-4))])
                assert min(bigger.clearance(p) for p in pts) < 0.33


def test_unreachable_goal_is_a_clear_failure():
    sc = load_scenario("paper-1")
    wall = rectangle((10.0, 5.5), (0.4, 11.0))
    obst = sc.obstacle_set().with_shapes([wall])
    spec = sc.robot

    def motion_fn(path, shapes, delay):
        raise AssertionError("no path exists, so no motion is built")

    cfg = SequentialConfig(first_budget_s=0.05)
    loop = SequentialBITStar(obst, robot_radius=spec.radius, plan_radius=spec.radius + 0.03,
                             motion=motion_fn, config=cfg, rng=np.random.default_rng(0))
    res = loop.replan(np.array(spec.start[:2]), np.array(spec.goal), [], 0.0)
    assert res.status == "plan_failed" and res.motion is None and len(res.path) == 0


def test_a_batch_budget_gives_up_on_an_unreachable_goal_by_work_not_time():
    # With batches_per_plan, a search that finds no solution stops after 20 x the batches (not
    # after a wall-clock cap, which made --deterministic runs differ run to run).
    sc = load_scenario("paper-1")
    obst = sc.obstacle_set().with_shapes([rectangle((10.0, 5.5), (0.4, 11.0))])
    spec = sc.robot

    def motion_fn(path, shapes, delay):
        raise AssertionError("no path exists, so no motion is built")

    cfg = SequentialConfig(batches_per_plan=2)
    out = []
    for _ in range(2):
        loop = SequentialBITStar(obst, robot_radius=spec.radius, plan_radius=spec.radius + 0.03,
                                 motion=motion_fn, config=cfg, rng=np.random.default_rng(0))
        res = loop.replan(np.array(spec.start[:2]), np.array(spec.goal), [], 0.0)
        assert res.status == "plan_failed"
        out.append((loop.rng.bit_generator.state["state"], res.plan_time_s))
    assert out[0][0] == out[1][0]  # the same samples drawn: the same amount of work
    assert max(t for _, t in out) < 10.0


@pytest.mark.parametrize("gap", ["none", "open", "narrow"])
def test_prove_blocked_ends_a_detour_search_that_cannot_succeed(gap):
    # A wall across paper-1: whole, with a 0.8 m gap, or with a gap 1 cm narrower than the
    # planning disc (finer than any cell of the cover, so only the visibility graph proves it
    # closed). A detour search (not the first plan) with prove_blocked stops after its
    # ordinary budget (2 batches) when the cell cover proves the wall separates start and
    # goal, after five budgets when only the visibility graph does, where it otherwise
    # searches 20 x longer; with the open gap it finds the path all the same.
    from anyplan.planning.bitstar import BITStar
    from anyplan.planning.problem import Problem

    sc = load_scenario("paper-1")
    spec = sc.robot
    r = spec.radius + 0.03
    width = {"none": 0.0, "open": 0.8, "narrow": 2.0 * r - 0.01}[gap]
    lo, hi = 6.0 - width / 2.0, 6.0 + width / 2.0
    wall = [rectangle((10.0, lo / 2.0), (0.4, lo)), rectangle((10.0, (hi + 11.0) / 2.0),
                                                              (0.4, 11.0 - hi))]
    obst = sc.obstacle_set().with_shapes(wall)
    batches = {}
    for prove in (False, True):
        cfg = SequentialConfig(batches_per_plan=2, prove_blocked=prove)
        loop = SequentialBITStar(obst, robot_radius=spec.radius, plan_radius=r,
                                 config=cfg, rng=np.random.default_rng(0))
        problem = Problem.create(obst, spec.start[:2], spec.goal, r)
        planner = BITStar(problem, cfg.bitstar, rng=loop.rng)
        loop._solve(planner, first=False)
        res = planner.result()
        assert res.solved == (gap == "open")
        if gap == "open":
            assert problem.path_valid(res.path)
        batches[prove] = planner.n_batches
    if gap == "none":
        assert batches[True] <= 3 < 2 * 20 <= batches[False]
    if gap == "narrow":
        assert 3 < batches[True] <= 2 + 4 * 2 + 2 < 2 * 20 <= batches[False]


def test_a_motion_the_model_verified_is_not_checked_again(monkeypatch):
    # The loop takes a motion its model reports as verified without its own check; any
    # other motion is checked as before (and a predicted collision places a square).
    import anyplan.planning.sequential as seq

    sc = load_scenario("paper-1")
    loop, preds, _ = _loop(sc, SequentialConfig(batches_per_plan=2))
    calls = []
    real = seq.first_collision

    def counting(motion, *args, **kwargs):
        calls.append(motion)
        return real(motion, *args, **kwargs)

    monkeypatch.setattr(seq, "first_collision", counting)
    trusted = []

    def verified(motion):
        trusted.append(motion)
        return True

    res = loop.replan(np.array(sc.robot.start[:2]), np.array(sc.robot.goal), preds, 0.0,
                      verified=verified)
    assert res.collision_free and res.iterations == 1 and not calls and trusted == [res.motion]
    res = loop.replan(np.array(sc.robot.start[:2]), np.array(sc.robot.goal), preds, 0.0,
                      verified=lambda m: False)
    assert calls and calls[0] is not trusted[0]


def _corridor_crossing(wait_delays_s):
    """A corridor 1.3 m wide (the arena itself: y in [0, 1.3]) from (1, 0.65) to (4, 0.65),
    and a disc of radius 0.3 crossing it at x = 2.5 at 0.5 m/s (y = -1.75 + 0.5 t). With the
    margin its contact distance to the robot's centre line is 0.3 + 0.3 + 0.05 = 0.65, so it
    blocks the corridor from t = 3.5 s (y = 0) to t = 6.1 s (y = 1.3). The robot (0.4 m/s,
    0.4 m/s^2) departing at once reaches x = 2.5 at t = 1 + 1.3 / 0.4 = 4.25 s: in the middle
    of it. No detour exists: a square (side 2 (0.3 + 0.3) = 1.2 m) at the collision leaves
    0.05 m on each side of the corridor, less than the robot. Only a later departure helps."""
    spec = RobotSpec(start=(1.0, 0.65, 0.0), goal=(4.0, 0.65), radius=0.3, v_max=0.4,
                     omega_max=0.4, a_max=0.4, alpha_max=1.0)
    corridor = ObstacleSet([], bounds=(0.0, 0.0, 5.0, 1.3))
    state = RobotState(*spec.start, 0.0, 0.0)

    def motion_fn(path, shapes, delay):
        obst = corridor.with_shapes(shapes) if shapes else corridor
        return plan_motion(path, spec, state, obst, delay, margin=0.015)

    cfg = SequentialConfig(prediction_dt=None, batches_per_plan=2, prove_blocked=True,
                           wait_delays_s=wait_delays_s)
    loop = SequentialBITStar(corridor, robot_radius=0.3, plan_radius=0.33, motion=motion_fn,
                             config=cfg, rng=np.random.default_rng(0))
    crossing = PredictedObstacle("X", 0.3, UnicycleMotion(2.5, -1.75, np.pi / 2, 0.5))
    res = loop.replan(np.array(spec.start[:2]), np.array(spec.goal), [crossing], 0.0)

    def gap(motion):  # dense, independent of the loop's own prediction check
        t = np.arange(motion.t_start, motion.t_end + 0.01, 0.01)
        return float((np.hypot(*(motion.positions(t) - crossing.positions(t)).T) - 0.6).min())

    return res, motion_fn, gap


def test_a_corridor_blocked_for_a_while_makes_the_robot_depart_later():
    delays = (0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 12.0)
    res, motion_fn, gap = _corridor_crossing(delays)
    straight = np.array([[1.0, 0.65], [4.0, 0.65]])
    # Departing d s late, the robot is at x = 2.5 at 4.25 + d s, and the disc is off the
    # centre line by 0.65 m (y >= 1.3) only from 6.1 s: any d < 1.85 s collides; d = 2 s still
    # clips the disc on the approach, 3 s passes behind it (the dense check decides).
    assert gap(motion_fn(straight, [], 0.0)) < 0.0
    first_clear = next(d for d in delays if gap(motion_fn(straight, [], d)) >= 0.05)
    assert first_clear == 3.0
    assert res.status == "waiting" and res.collision_free and res.collision is None
    assert res.delay_s == first_clear > 0.0
    np.testing.assert_allclose(res.path, straight)  # the only way; no square is kept
    assert res.iterations == 1 and res.virtual_obstacles == []
    assert res.motion.t_start == pytest.approx(first_clear)  # at rest until then
    assert gap(res.motion) >= 0.05 - 0.004  # the margin, up to the dense step at 0.4 m/s


def test_a_corridor_blocked_longer_than_any_delay_reports_the_predicted_collision():
    delays = (0.5, 1.0, 2.0)  # all too short (see the test above)
    res, motion_fn, gap = _corridor_crossing(delays)
    assert all(gap(motion_fn(res.path, [], d)) < 0.0 for d in (0.0, *delays))
    assert res.status == "collision_predicted" and not res.collision_free
    # the best effort: the straight departure at once, with its first predicted collision
    assert res.delay_s == 0.0 and res.motion.t_start == 0.0
    np.testing.assert_allclose(res.path, [[1.0, 0.65], [4.0, 0.65]])
    assert res.collision is not None and res.collision.obstacle == "X"
    assert 3.5 <= res.collision.t <= 4.25  # after the disc enters, before the robot is at x = 2.5


def test_config_validation_names_the_field():
    with pytest.raises(ValueError, match="max_iterations"):
        SequentialConfig(max_iterations=0)
    with pytest.raises(ValueError, match="anchor"):
        SequentialConfig(anchor="centre")
    with pytest.raises(ValueError, match="planning_delay"):
        SequentialBITStarAgent(planning_delay="soon")


def _waiting_search(obstacles, hide_departure, delays=(0.5, 1.0, 16.0, 20.0, 25.0)):
    """The loop in a corridor 1.3 m wide (no detour: a square closes it) with a model whose
    late departures say when they leave (``departs_s``), or hide it; returns the result and the
    delays the model was asked for."""
    from anyplan.trajectory.reference import ReferenceBuilder

    spec = RobotSpec(start=(1.0, 0.65, 0.0), goal=(9.0, 0.65), radius=0.3, v_max=0.4,
                     omega_max=0.4, a_max=0.4, alpha_max=1.0)
    corridor = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 1.3))
    model = ReferenceBuilder(spec=spec, obstacles=corridor).departing(
        RobotState(*spec.start, 0.0, 0.0), 0.0)
    asked = []

    def motion_fn(path, shapes, delay):
        tr = model(path, shapes, delay)
        if delay > 0.0:
            asked.append(delay)
            assert tr.departs_s == tr.t_start + delay  # at rest: no braking first
            if hide_departure:
                tr.departs_s = None
        return tr

    cfg = SequentialConfig(prediction_dt=0.02, batches_per_plan=2, wait_delays_s=delays)
    loop = SequentialBITStar(corridor, robot_radius=0.3, plan_radius=0.33, motion=motion_fn,
                             config=cfg, rng=np.random.default_rng(0))
    res = loop.replan(np.array(spec.start[:2]), np.array(spec.goal), obstacles, 0.0)
    return res, asked


def test_the_waiting_search_skips_later_departures_where_the_robot_is_struck_waiting():
    """A corridor 1.3 m wide and a disc coming head-on down its centre line at 0.5 m/s: no
    detour, and a robot waiting at the start is struck when the disc arrives (about 14.7 s).
    A departure 16 s late is struck while it waits (before it leaves, ``departs_s``), so the
    search tries no later one along that path; with ``departs_s`` hidden it tries them all,
    and both searches give the same answer."""
    head_on = PredictedObstacle("H", 0.3, UnicycleMotion(9.0, 0.65, np.pi, 0.5))
    skipped, tried = _waiting_search([head_on], False)
    full, tried_all = _waiting_search([head_on], True)
    assert tried_all == [0.5, 1.0, 16.0, 20.0, 25.0]
    assert tried == [0.5, 1.0, 16.0]
    assert skipped.status == full.status == "collision_predicted"
    assert skipped.delay_s == full.delay_s
    np.testing.assert_allclose(skipped.motion.positions(np.array([5.0])),
                               full.motion.positions(np.array([5.0])))


def _crossing(x, t_centre, speed=0.5):
    """A disc crossing the corridor upwards at ``x`` [m], on its centre line at ``t_centre`` [s]."""
    return PredictedObstacle(f"X{x}", 0.3, UnicycleMotion(x, 0.65 - speed * t_centre, np.pi / 2,
                                                          speed))


@pytest.mark.parametrize("obstacles", [
    [PredictedObstacle("H", 0.3, UnicycleMotion(9.0, 0.65, np.pi, 0.5))],  # head-on
    [PredictedObstacle("H", 0.3, UnicycleMotion(9.0, 0.65, np.pi, 1.2))],  # head-on, fast
    [_crossing(2.5, 4.8)],                      # blocks the way ahead for a while: wait 3 s
    [_crossing(2.5, 4.8), _crossing(1.0, 2.5)],  # ... and crosses where the robot waits
    [_crossing(2.5, 4.8), _crossing(1.0, 9.0)],  # ... there too, after the robot has left
    [_crossing(2.5, 4.8), _crossing(4.0, 9.0, 0.3), _crossing(1.0, 14.0)],
], ids=["head-on", "head-on-fast", "ahead", "ahead-and-here", "ahead-then-here", "three"])
def test_the_waiting_search_decides_as_if_it_tried_every_delay(obstacles):
    delays = (0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 16.0, 20.0)
    skipped, tried = _waiting_search(obstacles, False, delays)
    full, tried_all = _waiting_search(obstacles, True, delays)
    assert tried == tried_all[:len(tried)]  # the same order, fewer at most
    assert (skipped.status, skipped.delay_s) == (full.status, full.delay_s)
    np.testing.assert_array_equal(skipped.path, full.path)
    assert (skipped.collision is None) == (full.collision is None)
    if skipped.collision is not None:
        assert skipped.collision.t == full.collision.t
