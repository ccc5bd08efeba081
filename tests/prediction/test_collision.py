"""Predicted collisions of a timed reference motion against brute-force dense sampling."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.prediction import PredictedObstacle
from anyplan.prediction.collision import SampledMotion, first_collision, predict_collisions
from anyplan.trajectory.motion import plan_motion
from anyplan.world import RobotSpec, RobotState, UnicycleMotion

SPEC = RobotSpec(start=(1.0, 5.0, 0.0), goal=(14.0, 5.0))
ARENA = ObstacleSet([], bounds=(0.0, 0.0, 15.0, 11.0))


def _motion(mid_y: float):
    path = np.array([[1.0, 5.0], [7.5, mid_y], [14.0, 5.0]])
    return plan_motion(path, SPEC, RobotState(1.0, 5.0, 0.0), ARENA, 0.0)


def _dense_first(motion, obstacle, reach, t1, dt=1e-3):
    t = np.arange(0.0, t1, dt)
    d = np.hypot(*(motion.positions(t) - obstacle.positions(t)).T)
    hit = np.nonzero(d <= reach)[0]
    return (t[hit[0]] if len(hit) else None), d


MOTIONS = {y: _motion(y) for y in (3.5, 5.0, 6.5)}


@settings(max_examples=40, deadline=None)
@given(mid=st.sampled_from([3.5, 5.0, 6.5]), x0=st.floats(3.0, 12.0), y0=st.floats(1.0, 9.0),
       th=st.floats(-3.2, 3.2), v=st.floats(0.05, 0.3), om=st.sampled_from([0.0, -0.14, 0.2]),
       sample_dt=st.sampled_from([None, 0.02, 0.05]))
def test_first_collision_is_never_late_and_tight(mid, x0, y0, th, v, om, sample_dt):
    motion = MOTIONS[mid]
    ob = PredictedObstacle("D", 0.3, UnicycleMotion(x0, y0, th, v, om))
    reach = 0.6
    hit = first_collision(motion, [ob], 0.3, sample_dt=sample_dt, t_until=motion.t_end)
    t_ref, d = _dense_first(motion, ob, reach, motion.t_end)
    if t_ref is not None:
        assert hit is not None and hit.t <= t_ref + 1e-9
        if sample_dt is None:
            # Tight: no contact before hit.t was missed (above), and at hit.t the distance is
            # within the search's allowance, L * tol (L the relative speed bound, tol 1e-4 s),
            # of the contact distance. A grazing approach may be reported up to that allowance
            # early in distance, which can be milliseconds early in time.
            lip = motion.max_speed + ob.max_speed
            at = np.array([hit.t])
            d_hit = np.hypot(*(motion.positions(at)[0] - ob.positions(at)[0]))
            assert d_hit <= reach + lip * 1e-4 + 1e-9
    if hit is not None:
        # The reported place is where the robot's reference is at that time.
        np.testing.assert_allclose(hit.robot_position, motion.positions(np.array([hit.t]))[0], atol=1e-9)
    else:
        assert d.min() > reach


def test_resampled_motion_error_bound_holds():
    motion = MOTIONS[6.5]
    sm = SampledMotion(motion, 0.0, motion.t_end, 0.05)
    t = np.linspace(0.0, motion.t_end, 20001)
    err = np.hypot(*(sm.positions(t) - motion.positions(t)).T)
    assert err.max() <= sm.error_bound + 1e-12


def test_collisions_are_sorted_and_per_obstacle():
    motion = MOTIONS[5.0]
    obs = [PredictedObstacle("late", 0.3, UnicycleMotion(11.0, 10.1, -np.pi / 2, 0.2)),
           PredictedObstacle("early", 0.3, UnicycleMotion(4.0, 4.04, np.pi / 2, 0.12)),
           PredictedObstacle("never", 0.3, UnicycleMotion(1.0, 10.0, 0.0, 0.1))]
    hits = predict_collisions(motion, obs, 0.3)
    assert [h.obstacle for h in hits] == ["early", "late"]
    assert hits[0].t < hits[1].t


def _same(a, b):
    if a is None or b is None:
        return a is b
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return (a.obstacle, a.t, a.obstacle_radius) == (b.obstacle, b.t, b.obstacle_radius) and \
        np.array_equal(a.robot_position, b.robot_position) and \
        np.array_equal(a.obstacle_position, b.obstacle_position)


def test_repeated_checks_give_the_direct_answers():
    # Answers are remembered for the last few (motion, obstacles, settings): a repeated check
    # equals a fresh computation, and other settings or other obstacle objects are not mixed up.
    from anyplan.prediction import collision

    motion = MOTIONS[5.0]
    obs = [PredictedObstacle("early", 0.3, UnicycleMotion(4.0, 4.04, np.pi / 2, 0.12)),
           PredictedObstacle("late", 0.3, UnicycleMotion(11.0, 10.1, -np.pi / 2, 0.2))]
    calls = [{"margin": 0.0}, {"margin": 0.2}, {"margin": 0.0, "t_until": 10.0},
             {"margin": 0.0, "sample_dt": 0.02}, {"margin": 0.0, "t_from": 30.0}]
    fresh = []
    for kw in calls:
        collision._MEMO.clear()
        fresh.append((first_collision(motion, obs, 0.3, **kw), predict_collisions(motion, obs, 0.3, **kw)))
    collision._MEMO.clear()
    for _ in range(2):
        for kw, (first, every) in zip(calls, fresh, strict=True):
            assert _same(first_collision(motion, obs, 0.3, **kw), first)
            assert _same(predict_collisions(motion, obs, 0.3, **kw), every)
    moved = [PredictedObstacle("early", 0.3, UnicycleMotion(4.0, 1.0, np.pi / 2, 0.12)), obs[1]]
    collision._MEMO.clear()
    direct = first_collision(motion, moved, 0.3)
    first_collision(motion, obs, 0.3)
    again = first_collision(motion, moved, 0.3)
    assert _same(again, direct) and not _same(again, first_collision(motion, obs, 0.3))


def test_unicycle_positions_are_the_chord_formula_bit_for_bit():
    # Predictions evaluate UnicycleMotion.positions in every check; its straight fast path and
    # inlined sinc must give exactly the contract's chord form with numpy's sinc.
    rng = np.random.default_rng(7)
    for i in range(400):
        om = 0.0 if i % 2 else float(rng.uniform(-1.0, 1.0)) * 10.0 ** -float(rng.integers(0, 10))
        m = UnicycleMotion(*rng.uniform(-10.0, 10.0, 2), float(rng.uniform(-7.0, 7.0)),
                           float(rng.uniform(-2.0, 2.0)), om, float(rng.uniform(-5.0, 5.0)))
        t = rng.uniform(-10.0, 60.0, int(rng.integers(1, 300)))
        tau = np.maximum(t - m.start_time, 0.0)
        half = 0.5 * m.omega * tau
        chord = m.v * tau * np.sinc(half / np.pi)
        ref = np.column_stack([m.x0 + chord * np.cos(m.theta0 + half),
                               m.y0 + chord * np.sin(m.theta0 + half)])
        assert np.array_equal(m.positions(t), ref)
        assert np.array_equal(m.positions(float(t[0])), ref[:1])


def test_a_prediction_with_a_horizon_is_checked_up_to_it_only():
    # A walker crossing the robot's line where the robot passes (x = 7.5 m); the same prediction
    # ending (until) before the contact predicts none, one ending after it the same contact.
    motion = _motion(5.0)
    t = np.linspace(motion.t_start, motion.t_end, 2001)
    t_pass = float(t[np.argmin(np.abs(motion.positions(t)[:, 0] - 7.5))])
    walker = UnicycleMotion(7.5, 5.0 + 0.6 * t_pass, -np.pi / 2, 0.6)
    full = PredictedObstacle("w", 0.3, walker)
    hit = first_collision(motion, [full], SPEC.radius)
    assert hit is not None
    early = PredictedObstacle("w", 0.3, walker, until=hit.t - 0.5)
    late = PredictedObstacle("w", 0.3, walker, until=hit.t + 0.5)
    assert first_collision(motion, [early], SPEC.radius) is None
    assert first_collision(motion, [late], SPEC.radius).t == pytest.approx(hit.t, abs=1e-3)
    assert early.radius_at(hit.t) == -np.inf and early.radius_at(hit.t - 1.0) == 0.3
    assert np.all(early.radius_at(np.array([0.0, hit.t])) == np.array([0.3, -np.inf]))


def test_horizon_only_for_extrapolated_predictions():
    from anyplan.prediction import ConstantTwistPredictor, ObstacleObservation

    walker = UnicycleMotion(7.5, 9.0, -np.pi / 2, 0.6)
    seen = ObstacleObservation("a", 2.0, 7.5, 9.0, -np.pi / 2, 0.6, 0.0, 0.3)
    announced = ObstacleObservation("b", 2.0, 7.5, 9.0, -np.pi / 2, 0.6, 0.0, 0.3, walker)
    a, b = ConstantTwistPredictor(horizon_s=3.0).predict([seen, announced])
    assert a.until == pytest.approx(5.0) and b.until == np.inf
    assert ConstantTwistPredictor().predict([seen])[0].until == np.inf
    with pytest.raises(ValueError, match="horizon_s"):
        ConstantTwistPredictor(horizon_s=0.0)


@pytest.mark.parametrize("seed", range(3))
def test_coarse_certificate_changes_no_answer(seed, monkeypatch):
    # The coarse pass (every 16th grid point) only skips obstacles it certifies clear: every
    # contact, time and position is that of the fine grid alone, growing discs included.
    from anyplan.prediction import collision
    from anyplan.prediction.base import RadiusGrowth

    rng = np.random.default_rng(seed)
    lo, hi = (0, 0, -np.pi, 0.0, -0.2), (15, 11, np.pi, 0.8, 0.2)
    obs = [PredictedObstacle(f"o{i}", float(rng.uniform(0.2, 0.5)),
                             UnicycleMotion(*rng.uniform(lo, hi)),
                             RadiusGrowth(0.0, np.array([0.0, 5.0]), np.array([0.0, 0.5])) if i % 3 == 0
                             else None)
           for i in range(20)]
    for mid in MOTIONS:
        answers = []
        for coarse in (16, 10**9):  # 10**9: the coarse pass is skipped
            monkeypatch.setattr(collision, "_COARSE", coarse)
            collision._MEMO.clear()
            answers.append([predict_collisions(MOTIONS[mid], obs, 0.3, margin=0.05, sample_dt=sd)
                            for sd in (None, 0.02)])
        assert _same(answers[0], answers[1])
    assert any(answers[0])


@pytest.mark.parametrize("seed", range(4))
def test_track_box_broad_phase_changes_no_answer(seed, monkeypatch):
    # The broad phase over all obstacles at once (each obstacle's track box against the robot's
    # coarse samples) only skips obstacles that the coarse certificate would skip: every
    # contact, time and position is that of the loop alone; pacing (waypoints), circling,
    # straight and growing discs, near the robot's route and far from it.
    from anyplan.prediction import collision
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.world.motion import WaypointMotion

    rng = np.random.default_rng(seed)
    obs = []
    for i in range(40):
        a, b = rng.uniform((0, 0), (15, 11)), rng.uniform((0, 0), (15, 11))
        if i % 4 == 0:
            m = UnicycleMotion(*rng.uniform((0, 0, -np.pi, 0.0, 0.1), (15, 11, np.pi, 0.8, 0.4)))
        elif i % 4 == 1:
            m = UnicycleMotion(*rng.uniform((0, 0, -np.pi, 0.0, 0.0), (15, 11, np.pi, 0.8, 0.0)))
        else:
            t1 = float(np.hypot(*(b - a))) / float(rng.uniform(0.3, 1.0)) + 0.1
            m = WaypointMotion(np.array([[0.0, *a], [t1, *b], [2 * t1, *a]]))
        g = RadiusGrowth(0.0, np.array([0.0, 5.0]), np.array([0.0, 0.5])) if i % 5 == 0 else None
        obs.append(PredictedObstacle(f"o{i}", float(rng.uniform(0.2, 0.5)), m, g))
    skipped = 0
    for mid in MOTIONS:
        answers = []
        for broad in (True, False):
            if not broad:
                monkeypatch.setattr(collision, "_far_from_tracks",
                                    lambda o, *a: np.zeros(len(o), dtype=bool))
            collision._MEMO.clear()
            answers.append([predict_collisions(MOTIONS[mid], obs, 0.3, margin=0.05, sample_dt=sd)
                            for sd in (None, 0.02)])
        monkeypatch.undo()
        m = MOTIONS[mid]
        grid = np.linspace(m.t_start, m.t_end, 200)
        skipped += int(collision._far_from_tracks(obs, grid, m.positions(grid), m.max_speed,
                                                  0.35).sum())
        assert _same(answers[0], answers[1])
        assert any(answers[0])
        # the first contact, with starts computed lazily from the interpolated lower bounds,
        # is the earliest of all contacts, and what computing every start first gives
        for sd in (None, 0.02):
            collision._MEMO.clear()
            lazy = first_collision(m, obs, 0.3, margin=0.05, sample_dt=sd)
            assert _same(lazy, (predict_collisions(m, obs, 0.3, margin=0.05, sample_dt=sd)
                                or [None])[0])
            monkeypatch.setattr(collision, "_start_bounds",
                                lambda o, far, *a: np.where(far, np.inf, -np.inf))
            collision._MEMO.clear()
            assert _same(lazy, first_collision(m, obs, 0.3, margin=0.05, sample_dt=sd))
            monkeypatch.undo()
            bounds = collision._start_bounds(obs, np.zeros(len(obs), dtype=bool), grid, grid,
                                             m.positions(grid), m.max_speed, 0.35)
            assert np.isfinite(bounds).any()
    assert skipped > 0  # the broad phase did skip some


def _start_bounds_per_length(obstacles, far, grid, gc, pc, vr, reach0):
    """The former _start_bounds: one interpolation per group of tracks of one keyframe count."""
    import math

    from anyplan.prediction import collision
    from anyplan.world.motion import WaypointMotion

    n = len(obstacles)
    out = np.full(n, -math.inf)
    out[far] = math.inf
    if len(gc) < 2:
        return out
    dt = np.diff(gc)
    half_fine = 0.5 * float(np.diff(grid).max())
    groups: dict[int, list[int]] = {}
    for k, o in enumerate(obstacles):
        if not far[k] and o.growth is None and isinstance(o.motion, WaypointMotion):
            groups.setdefault(len(o.motion.keyframes), []).append(k)
    for ks in groups.values():
        kf = np.stack([obstacles[k].motion.keyframes for k in ks])
        tm = np.mod(gc[None, :], kf[:, -1, 0][:, None])
        i = np.clip((kf[:, None, :, 0] <= tm[:, :, None]).sum(axis=2) - 1, 0, kf.shape[1] - 2)
        a = np.take_along_axis(kf, i[:, :, None].repeat(3, axis=2), axis=1)
        b = np.take_along_axis(kf, (i + 1)[:, :, None].repeat(3, axis=2), axis=1)
        w = np.clip((tm - a[:, :, 0]) / (b[:, :, 0] - a[:, :, 0]), 0.0, 1.0)
        d = np.hypot(pc[None, :, 0] - (a[:, :, 1] + w * (b[:, :, 1] - a[:, :, 1])),
                     pc[None, :, 1] - (a[:, :, 2] + w * (b[:, :, 2] - a[:, :, 2])))
        lip = np.array([vr + collision._track(obstacles[k])[1] for k in ks])
        need = (reach0 + np.array([obstacles[k].radius for k in ks]) + lip * half_fine
                + 1e-9 * (1.0 + reach0 + lip))
        low = 0.5 * (d[:, :-1] + d[:, 1:] - lip[:, None] * dt[None, :]) <= need[:, None]
        first = np.argmax(low, axis=1)
        out[np.array(ks)] = np.where(low.any(axis=1), gc[first], math.inf)
    return out


@pytest.mark.parametrize("seed", range(4))
def test_start_bounds_of_tracks_of_every_length_at_once_are_the_per_length_ones(seed):
    """Tracks of 2-9 keyframes in one padded stack, each scanned by the compiled kernel until
    its first uncertified interval: for closed tracks bit for bit the bounds of one numpy
    interpolation per keyframe count, with far, growing and other obstacles mixed in; for open
    ones (they jump back at each period's start) those bounds or the start of the first coarse
    interval that holds a jump, whichever is earlier. The padded stack cached for the same
    tracks is rebuilt for other ones."""
    from anyplan.prediction import collision
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.world.motion import WaypointMotion

    rng = np.random.default_rng(seed)
    obs = []
    for i in range(30):
        if i % 7 == 3:
            m = UnicycleMotion(*rng.uniform((0, 0, -np.pi, 0.0, 0.0), (15, 11, np.pi, 0.8, 0.3)))
        else:
            nk = int(rng.integers(2, 10))
            t = np.cumsum(np.r_[0.0, rng.uniform(0.5, 4.0, nk - 1)])
            pts = rng.uniform((0, 0), (15, 11), (nk, 2))
            if i % 2:
                pts[-1] = pts[0]  # closed
            m = WaypointMotion(np.column_stack([t, pts]))
        g = RadiusGrowth(0.0, np.array([0.0, 5.0]), np.array([0.0, 0.5])) if i % 9 == 4 else None
        obs.append(PredictedObstacle(f"o{i}", float(rng.uniform(0.2, 0.5)), m, g))
    for mid in MOTIONS:
        m = MOTIONS[mid]
        grid = np.linspace(m.t_start, m.t_end + 40.0, 401)
        gc = grid[::16]
        pc = m.positions(gc)
        far = rng.random(len(obs)) < 0.2
        for sub in (obs, obs[::2], obs[5:]):  # other sets of tracks: the cache must miss
            fa = far[: len(sub)]
            got = collision._start_bounds(sub, fa, grid, gc, pc, m.max_speed, 0.35)
            want = _start_bounds_per_length(sub, fa, grid, gc, pc, m.max_speed, 0.35)
            for k, o in enumerate(sub):
                jump = np.inf
                if isinstance(o.motion, WaypointMotion) and o.motion.is_open and not fa[k] \
                        and o.growth is None:
                    cross = np.flatnonzero(np.diff(np.floor(gc / o.motion.period)) > 0)
                    jump = gc[cross[0]] if len(cross) else np.inf
                assert got[k] == min(want[k], jump), o.name
            assert np.isfinite(got).any() and (got == -np.inf).any()
            want = got
            assert np.array_equal(collision._start_bounds(sub, fa, grid, gc, pc, m.max_speed, 0.35),
                                  want)  # from the cache


@pytest.mark.parametrize("seed", range(4))
def test_straight_start_bounds_are_lower_bounds_and_change_no_answer(seed, monkeypatch):
    # Twist and tracked predictions (straight lines, growing discs, a horizon): the bounds of
    # _start_bounds never pass an uncertified fine interval, and the first contact found with
    # them is the one found with no bounds at all.
    from anyplan.prediction import collision
    from anyplan.prediction.base import RadiusGrowth

    rng = np.random.default_rng(100 + seed)
    obs = []
    for i in range(60):
        x0, y0, th, v = rng.uniform((0, 0, -np.pi, 0.0), (15, 11, np.pi, 1.5))
        if i % 4 == 0:  # crossing the robot's route, met or just missed
            x0, y0, th = rng.uniform(2.0, 13.0), 5.0 - 3.0 * np.sign(i % 8 - 3.5), np.pi / 2
            th *= np.sign(5.0 - y0)
        t0 = float(rng.uniform(0.0, 2.0))
        g = (RadiusGrowth(t0, np.array([0.0, 3.0]), np.array([0.05, 0.05 + 0.4 * rng.uniform()]))
             if i % 2 else None)
        until = float(rng.uniform(3.0, 8.0)) if i % 3 == 0 else np.inf
        obs.append(PredictedObstacle(f"p{i}", 0.25, UnicycleMotion(x0, y0, th, v, 0.0, t0), g,
                                     until))
    found = 0
    for m in MOTIONS.values():
        for sd in (None, 0.02):
            collision._MEMO.clear()
            lazy = first_collision(m, obs, 0.3, margin=0.05, sample_dt=sd)
            monkeypatch.setattr(collision, "_straight_bounds", lambda *a: None)
            collision._MEMO.clear()
            plain = first_collision(m, obs, 0.3, margin=0.05, sample_dt=sd)
            monkeypatch.undo()
            assert _same(lazy, plain)
            found += lazy is not None
        grid = np.linspace(m.t_start, m.t_end, 401)
        gc = grid[::16]
        p = m.positions(grid)
        reach0 = 0.35
        bounds = collision._start_bounds(obs, np.zeros(len(obs), dtype=bool), grid, gc,
                                         m.positions(gc), m.max_speed, reach0)
        assert np.isfinite(bounds).any() and np.isposinf(bounds).any()
        for o, b in zip(obs, bounds, strict=True):
            # the fine certificate of _predict_uncached, brute force on every fine interval
            d = np.hypot(*(p - o.positions(grid)).T)
            rate = 0.0
            if o.growth is not None:
                d = d - o.growth.at(grid)
                rate = o.growth.rate
            low = 0.5 * (d[:-1] + d[1:] - (m.max_speed + o.max_speed + rate) * np.diff(grid))
            bad = np.flatnonzero(low <= reach0 + o.radius)
            if len(bad):
                assert b <= grid[bad[0]], o.name
    assert found > 0


def test_growth_of_many_discs_at_once_matches_each_disc():
    # The broad phase interpolates the growth of every disc in one pass (_growth_rows): the
    # values of RadiusGrowth.at, disc by disc, up to rounding; before the first knot, between
    # knots, beyond the cap, without growth, and with knots that differ between discs.
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.prediction.collision import _growth_rows, _stack
    from anyplan.world import UnicycleMotion

    taus = np.array([0.0, 0.5, 1.0, 2.0, 4.0])
    t = np.linspace(-1.0, 6.0, 57)
    for other in (taus, np.array([0.0, 1.0, 3.0, 5.0, 6.0])):
        obs = [PredictedObstacle(f"P{k}", 0.25, UnicycleMotion(k, 0.0, 0.1 * k, 0.5),
                                 None if k == 2 else RadiusGrowth(
                                     0.3 * k, other if k == 4 else taus,
                                     np.cumsum(np.full(5, 0.1 + 0.05 * k))))
               for k in range(6)]
        rows = np.arange(6)
        got = _growth_rows(_stack(obs), rows, t)
        want = np.array([np.zeros_like(t) if o.growth is None else o.growth.at(t) for o in obs])
        assert np.allclose(got, want, rtol=0.0, atol=1e-12)
        assert np.all(got[2] == 0.0)


class _AtRest:
    """A robot reference standing at ``p`` [m] over [0, t_end] [s]."""

    def __init__(self, p, t_end):
        self.p, self.t_start, self.t_end, self.max_speed = np.asarray(p, float), 0.0, t_end, 0.0

    def positions(self, t):
        return np.tile(self.p, (len(np.atleast_1d(t)), 1))


@pytest.mark.parametrize("sd", [0.02, 0.05])
def test_straight_discs_meet_a_robot_at_rest_at_the_closed_form_time(sd):
    # An obstacle 6 m away comes straight at the robot at 0.5 m/s, its disc growing at
    # 0.25 m/s for 4 s then capped; a second one waits 2 s, then comes at 1 m/s; a third passes
    # 1.5 m wide; a fourth would come but its prediction ends first.
    from anyplan.prediction.base import RadiusGrowth

    robot = _AtRest((0.0, 0.0), 12.0)
    grow = RadiusGrowth(0.0, np.array([0.0, 4.0]), np.array([0.0, 1.0]))
    obs = [PredictedObstacle("a", 0.3, UnicycleMotion(6.0, 0.0, np.pi, 0.5), grow),
           PredictedObstacle("b", 0.3, UnicycleMotion(0.0, 5.0, -np.pi / 2, 1.0, 0.0, 2.0), grow),
           PredictedObstacle("c", 0.3, UnicycleMotion(-5.0, 1.5, 0.0, 1.0)),
           PredictedObstacle("d", 0.3, UnicycleMotion(0.0, -3.0, np.pi / 2, 1.0), until=1.0)]
    hits = {h.obstacle: h for h in predict_collisions(robot, obs, 0.3, sample_dt=sd)}
    assert set(hits) == {"a", "b"}
    # a: 6 - 0.5 t = 0.6 + 0.25 t before the cap -> t = 7.2 (> 4: capped) -> 6 - 0.5 t = 1.6
    assert hits["a"].t == pytest.approx(8.8, abs=1e-9)
    # b: at rest until 2 s; then 5 - (t - 2) = 0.6 + 0.25 t -> t = 5.12 (> 4) -> 7 - t = 1.6
    assert hits["b"].t == pytest.approx(5.4, abs=1e-9)
    assert hits["b"].obstacle_radius == pytest.approx(1.3, abs=1e-9)
    # the same with the growth's cap 2 s later: the contact before it, on the slope
    late = RadiusGrowth(0.0, np.array([0.0, 6.0]), np.array([0.0, 1.5]))
    hit = first_collision(robot, [PredictedObstacle("b", 0.3, obs[1].motion, late)], 0.3, sample_dt=sd)
    assert hit.t == pytest.approx(6.4 / 1.25, abs=1e-9)
    first = first_collision(robot, obs, 0.3, sample_dt=sd)
    assert first.obstacle == "b" and first.t == hits["b"].t


@pytest.mark.parametrize("seed", range(3))
def test_straight_discs_in_closed_form_agree_with_the_certified_search(seed):
    # Straight discs, with and without growth, with horizons, some starting later: the closed
    # form on the robot's samples finds the contacts the certified search on the same samples
    # finds, never earlier than it (it reports the start of the first interval it cannot
    # certify free), at a time where the gap is zero and before which it is nowhere negative.
    from anyplan.prediction import collision
    from anyplan.prediction.base import RadiusGrowth

    rng = np.random.default_rng(seed)
    grows = [None, RadiusGrowth(0.3, np.array([0.0, 1.0, 3.0]), np.array([0.05, 0.4, 0.9]))]
    obs = []
    for i in range(40):
        x0, y0, th, v = rng.uniform((0, 0, -np.pi, 0.0), (15, 11, np.pi, 1.5))
        m = UnicycleMotion(x0, y0, th, v, 0.0, float(rng.choice([0.0, rng.uniform(0, 5)])))
        until = float(rng.choice([np.inf, rng.uniform(1, 8)]))
        obs.append(PredictedObstacle(f"o{i}", float(rng.uniform(0.2, 0.5)), m, grows[i % 2], until))
    tol, found = 1e-4, 0
    for m in MOTIONS.values():
        for sd in (0.02, 0.05):
            collision._MEMO.clear()
            new = {h.obstacle: h for h in predict_collisions(m, obs, 0.3, margin=0.05, sample_dt=sd)}
            old = {h.obstacle: h for h in collision._certified_hits(
                m, obs, 0.3, m.t_start, m.t_end, 0.05, tol, sd, False)}
            assert set(new) == set(old)
            sm = SampledMotion(m, m.t_start, m.t_end, sd)
            for name, h in new.items():
                assert old[name].t - 1e-9 <= h.t
                np.testing.assert_allclose(h.robot_position, m.positions(np.array([h.t]))[0])
                o = next(o for o in obs if o.name == name)
                reach = 0.3 + 0.05 + sm.error_bound + o.radius

                def gap(t, o=o, reach=reach, sm=sm):
                    d = np.hypot(*(sm.positions(t) - o.positions(t)).T)
                    return d - reach - (0.0 if o.growth is None else o.growth.at(t))

                assert gap(np.array([h.t]))[0] <= 1e-9
                assert h.t == m.t_start or gap(np.array([h.t]))[0] >= -1e-9
                before = np.arange(m.t_start, h.t, 1e-3)
                assert np.all(gap(before) > -1e-9)
            found += len(new)
            first = first_collision(m, obs, 0.3, margin=0.05, sample_dt=sd)
            assert first is not None and first.t == min(h.t for h in new.values())
    assert found >= 10


@pytest.mark.parametrize("seed", range(3))
def test_robot_not_sampled_after_every_prediction_has_ended(seed):
    # Every prediction straight with a horizon: the robot's samples stop at the first at or
    # after the last horizon, the same times and positions as the whole motion's first ones,
    # and the contacts are those on the whole motion's samples, bit for bit.
    from anyplan.prediction import collision
    from anyplan.prediction._contact_kernels import StraightDiscs

    rng = np.random.default_rng(seed)
    obs = []
    for i in range(30):
        x0, y0, th, v = rng.uniform((0, 2, -np.pi, 0.0), (9, 8, np.pi, 1.5))  # near its start
        m = UnicycleMotion(x0, y0, th, v, 0.0, float(rng.uniform(0, 3)))
        obs.append(PredictedObstacle(f"o{i}", 0.3, m, until=float(rng.uniform(1.0, 6.0))))
    last = max(o.until for o in obs)
    lines = StraightDiscs.of(obs)
    found = 0
    for m in MOTIONS.values():
        assert m.t_end > last + 1.0  # the stop leaves samples out
        for sd in (0.02, 0.05):
            whole = SampledMotion(m, m.t_start, m.t_end, sd)
            cut = SampledMotion(m, m.t_start, m.t_end, sd, stop=last)
            k = len(cut._t)
            assert k < len(whole._t) and cut._t[-1] >= last > cut._t[-2]
            assert np.array_equal(cut._t, whole._t[:k]) and np.array_equal(cut._x, whole._x[:k])
            ref = lines.first_contacts(whole._t, whole._x, whole._y, 0.35 + whole.error_bound,
                                       m.t_start, m.t_end, False)
            collision._MEMO.clear()
            hits = {h.obstacle: h.t for h in predict_collisions(m, obs, 0.3, margin=0.05, sample_dt=sd)}
            assert hits == {obs[int(j)].name: float(ref[j]) for j in np.flatnonzero(ref < np.inf)}
            found += len(hits)
    assert found >= 5
