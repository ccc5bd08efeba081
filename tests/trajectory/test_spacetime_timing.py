"""s-t maps, re-timing along a path and the certified check (growing radii included)."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.geometry.collision import ObstacleSet
from anyplan.prediction.base import PredictedObstacle
from anyplan.prediction.collision import first_collision
from anyplan.trajectory.motion import plan_motion
from anyplan.trajectory.spacetime import RowCache, build_stmap, retime, verify
from anyplan.world.motion import UnicycleMotion
from anyplan.world.robot import RobotSpec, RobotState

SPEC = RobotSpec(start=(1.0, 2.0, 0.0), goal=(9.0, 2.0), radius=0.3, v_max=0.4, omega_max=0.4,
                 a_max=0.4, alpha_max=1.0)
ARENA = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 4.0))


class Growing:
    """A prediction whose radius grows linearly with time (as an uncertain prediction does)."""

    def __init__(self, name, motion, r0, rate, t0=0.0):
        self.name, self.motion, self.r0, self.rate, self.t0 = name, motion, r0, rate, t0

    def positions(self, t):
        return self.motion.positions(t)

    @property
    def max_speed(self):
        return self.motion.max_speed

    @property
    def radius(self):
        return self.r0

    def radius_at(self, t):
        return self.r0 + self.rate * np.maximum(np.asarray(t, dtype=float) - self.t0, 0.0)


def _straight():
    path = np.array([[1.0, 2.0], [9.0, 2.0]])
    return plan_motion(path, SPEC, RobotState(1.0, 2.0, 0.0), ARENA, 0.0)


def _crossing(t_cross=11.0, v=0.3):
    # Crosses the route at x = 5 going up, at the middle of its disc at t_cross.
    return PredictedObstacle("X", 0.3, UnicycleMotion(5.0, 2.0 - v * t_cross, np.pi / 2, v))


@pytest.mark.parametrize("seed", range(4))
def test_stmap_is_conservative(seed):
    """Free cells: no contact anywhere in the cell over the whole row (dense samples)."""
    rng = np.random.default_rng(seed)
    ob = PredictedObstacle("O", 0.3, UnicycleMotion(rng.uniform(3, 7), rng.uniform(0, 1),
                                                    rng.uniform(0.5, 2.6), rng.uniform(0.1, 0.6),
                                                    rng.uniform(-0.2, 0.2)))
    length, ds, h, margin = 8.0, 0.05, 0.05, 0.05

    def pts(s):
        s = np.asarray(s, dtype=float)
        return np.column_stack([1.0 + s, np.full(s.shape, 2.0)])

    m = build_stmap(pts, length, [ob], SPEC.radius, 0.0, 20.0, margin=margin, ds=ds, h=h)
    reach = SPEC.radius + 0.3 + margin
    free_rows, free_cells = np.nonzero(~m.forbidden)
    pick = rng.choice(len(free_rows), size=min(3000, len(free_rows)), replace=False)
    for j, c in zip(free_rows[pick], free_cells[pick], strict=True):
        ts = np.linspace(j * h, (j + 1) * h, 6)
        ss = np.linspace(c * ds, min((c + 1) * ds, length), 6)
        p = pts(ss)
        q = ob.positions(ts)
        d = np.hypot(p[:, None, 0] - q[None, :, 0], p[:, None, 1] - q[None, :, 1])
        assert d.min() > reach
    assert m.forbidden.any()


def _pts(s):
    s = np.asarray(s, dtype=float)
    return np.column_stack([1.0 + s, np.full(s.shape, 2.0)])


@pytest.mark.parametrize("period", [3.0, 3.013, 3.04, 2.999999999, 1.01])
@pytest.mark.parametrize("shared", [False, True])
def test_stmap_is_conservative_where_an_open_track_jumps(period, shared):
    """An open track starts on the route, leaves it, and at each period's end jumps back onto
    it: free cells have no contact over the whole row, the rows where it jumps included (the
    jump times n p and the positions' wrap, t mod p, differ by rounding for some periods)."""
    from anyplan.world.motion import WaypointMotion

    track = WaypointMotion(np.array([[0.0, 5.0, 2.0], [0.4, 5.0, 3.9], [period, 8.0, 3.9]]))
    ob = PredictedObstacle("O", 0.3, track)
    length, ds, h, margin = 8.0, 0.05, 0.05, 0.05
    m = build_stmap(_pts, length, [ob], SPEC.radius, 0.0, 20.0, margin=margin, ds=ds, h=h,
                    rows=RowCache(0.0, h) if shared else None)
    reach = SPEC.radius + 0.3 + margin
    g = m.grid()
    ts = (np.arange(g.shape[0])[:, None] + np.linspace(0.0, 1.0, 11)[None, :]) * h  # rows x 11
    q = ob.positions(ts.ravel()).reshape(g.shape[0], 11, 2)
    ss = (np.arange(g.shape[1])[:, None] + np.linspace(0.0, 1.0, 6)[None, :]) * ds
    p = _pts(np.minimum(ss.ravel(), length)).reshape(g.shape[1], 6, 2)
    # the gap of every (row, cell) at 11 x 6 sample pairs, rows in chunks
    for j0 in range(0, g.shape[0], 50):
        qq = q[j0:j0 + 50]
        d = np.hypot(qq[:, None, :, None, 0] - p[None, :, None, :, 0],
                     qq[:, None, :, None, 1] - p[None, :, None, :, 1]).min(axis=(2, 3))
        assert not np.any((d <= reach) & ~g[j0:j0 + 50])
    assert m.blockers == ["O"]


def test_shared_rows_give_the_same_map_on_their_grid_and_a_conservative_one_off_it():
    # Maps of several paths built with one RowCache: a map starting on the cache's grid is
    # the map built without it; one starting between rows starts at the row
    # before (rows of the grid) and is conservative over its whole span (dense samples).
    ob = PredictedObstacle("X", 0.3, UnicycleMotion(5.0, -1.3, np.pi / 2, 0.3))
    grow = Growing("G", UnicycleMotion(3.0, 5.0, -np.pi / 2, 0.2), 0.3, 0.02)
    rows = RowCache(1.0, 0.05)
    for length in (6.0, 8.0, 3.5):  # the cache grows to the longest horizon asked for
        plain = build_stmap(_pts, length, [ob, grow], SPEC.radius, 1.25, 25.0, margin=0.05)
        shared = build_stmap(_pts, length, [ob, grow], SPEC.radius, 1.25, 25.0, margin=0.05,
                             rows=rows)
        assert shared.t_map == plain.t_map
        assert np.array_equal(shared.forbidden, plain.forbidden) and plain.forbidden.any()
    off = build_stmap(_pts, 8.0, [ob, grow], SPEC.radius, 1.27, 25.0, margin=0.05, rows=rows)
    assert off.t_map == pytest.approx(1.25) and off.t_map + off.horizon_s >= 1.27 + 25.0 - 1e-9
    reach = SPEC.radius + 0.05
    rng = np.random.default_rng(0)
    free_rows, free_cells = np.nonzero(~off.forbidden)
    pick = rng.choice(len(free_rows), size=3000, replace=False)
    for j, c in zip(free_rows[pick], free_cells[pick], strict=True):
        ts = off.t_map + np.linspace(j * off.h, (j + 1) * off.h, 6)
        p = _pts(np.linspace(c * off.ds, min((c + 1) * off.ds, 8.0), 6))
        for o in (ob, grow):
            q = o.positions(ts)
            d = np.hypot(p[:, None, 0] - q[None, :, 0], p[:, None, 1] - q[None, :, 1])
            r = np.broadcast_to(np.asarray(o.radius_at(ts), dtype=float), ts.shape)
            assert (d - r[None, :]).min() > reach


def test_stacked_rows_are_each_obstacles_rows_and_name_the_blockers():
    # RowCache.rows_all (every obstacle's rows at once, what build_stmap asks for) holds each
    # obstacle's own rows, over a growing horizon; the map names the obstacles that mark it
    # (not the one that stays away), with and without the cache, in the order given.
    ob = PredictedObstacle("X", 0.3, UnicycleMotion(5.0, -1.3, np.pi / 2, 0.3))
    grow = Growing("G", UnicycleMotion(3.0, 5.0, -np.pi / 2, 0.2), 0.3, 0.02)
    far = PredictedObstacle("F", 0.3, UnicycleMotion(5.0, 40.0, 0.0, 0.3))
    rows = RowCache(1.0, 0.05)
    for j0, j1 in ((0, 300), (10, 700), (0, 120), (5, 1500)):
        qx, qy, r = rows.rows_all([grow, far, ob], j0, j1)
        for k, o in enumerate((grow, far, ob)):
            q1, r1 = RowCache(1.0, 0.05).rows(o, j0, j1)
            assert np.array_equal(qx[k], q1[:, 0]) and np.array_equal(qy[k], q1[:, 1])
            assert np.array_equal(r[k], r1)
    for cache in (None, rows):
        m = build_stmap(_pts, 8.0, [grow, far, ob], SPEC.radius, 1.25, 25.0, margin=0.05,
                        rows=cache)
        assert m.blockers == ["G", "X"]


def _cached_crossing():
    """A crossing motion that logs the length of every sampling, and a RowCache that has
    sampled it once (rows 20-399 of its first replanning, at 1 s): (log, motion, cache, rows)."""
    calls: list[int] = []

    class Counted(UnicycleMotion):
        def positions(self, t):
            calls.append(len(t))
            return super().positions(t)

    motion = Counted(5.0, -1.3, np.pi / 2, 0.3)
    rows = RowCache(0.0, 0.05)
    rows.begin(1.0)
    return calls, motion, rows, rows.rows_all([PredictedObstacle("X", 0.3, motion)], 20, 400)


def test_rows_are_shared_by_later_replannings_of_the_same_motions_only():
    # A RowCache kept across replannings (begin() at each): a new prediction of the same motion
    # and radius reuses its rows without sampling the motion again, and the rows are the same;
    # another radius, or a growing disc made anew, gets rows of its own; entries the last
    # replanning did not use are dropped (predictions made anew each time never come back).
    calls, motion, rows, first = _cached_crossing()
    n = len(calls)
    rows.begin(1.2)
    again = rows.rows_all([PredictedObstacle("X", 0.3, motion)], 24, 300)
    assert len(calls) == n  # not sampled again
    for a, b in zip(first, again, strict=True):
        assert np.array_equal(a[:, 4:280], b)
    wider = rows.rows_all([PredictedObstacle("X", 0.5, motion)], 24, 300)
    assert len(calls) == n + 1 and np.all(wider[2] > again[2])
    grow = Growing("G", motion, 0.3, 0.02)
    rows.rows_all([grow], 24, 300)
    assert len(calls) == n + 2
    rows.begin(1.4)
    rows.rows_all([PredictedObstacle("X", 0.5, motion)], 28, 300)
    rows.begin(1.6)
    assert len(rows._rows) == 1  # the growing disc's entry is gone, the motion's stays


def test_retimed_motion_passes_behind_and_is_certified_free():
    tr = _straight()
    ob = _crossing()
    assert first_collision(tr, [ob], SPEC.radius, margin=0.05) is not None  # the race fails
    res = retime(tr, [ob], SPEC, margin=0.05)
    new = res.trajectory
    assert new is not None
    assert first_collision(new, [ob], SPEC.radius, margin=0.05) is None  # exact, no sampling
    # Behind: when the robot reaches x = 5 the obstacle is already past the route.
    t = np.arange(new.t_start, new.t_end, 1e-3)
    p = new.positions(t)
    t5 = t[np.argmax(p[:, 0] >= 5.0)]
    assert ob.positions(np.array([t5]))[0, 1] > 2.0 + 0.6
    # Limits every 1 ms.
    x, y, _, v, w = new.sample(t)
    assert p.tobytes() == np.column_stack([x, y]).tobytes()  # positions alone: the same x, y
    assert np.all(v <= SPEC.v_max + 1e-9) and np.all(v >= -1e-9)
    assert np.all(np.abs(np.diff(v)) <= SPEC.a_max * 1e-3 * (1 + 1e-6) + 1e-12)
    assert np.all(np.abs(w) <= SPEC.omega_max + 1e-9)
    assert res.delay_s > 0.0


def test_growing_radius_is_respected():
    tr = _straight()
    # Passes the route well before the robot: harmless with a constant radius ...
    motion = UnicycleMotion(5.0, 0.2, np.pi / 2, 0.3)
    const = PredictedObstacle("G", 0.3, motion)
    grow = Growing("G", motion, 0.3, 0.08)
    assert verify(tr, [const], SPEC.radius, margin=0.05) is None
    # ... but a radius growing by 8 cm/s covers the route when the robot gets there.
    assert verify(tr, [grow], SPEC.radius, margin=0.05) is not None
    res = retime(tr, [grow], SPEC, margin=0.05, max_wait_s=40.0)
    assert res.trajectory is None or verify(res.trajectory, [grow], SPEC.radius, margin=0.05) is None
    m_c = build_stmap(lambda s: np.column_stack([1 + s, 2 + 0 * s]), 8.0, [const], 0.3, 0.0, 30.0)
    m_g = build_stmap(lambda s: np.column_stack([1 + s, 2 + 0 * s]), 8.0, [grow], 0.3, 0.0, 30.0)
    assert m_g.forbidden.sum() > m_c.forbidden.sum()
    assert not (m_c.forbidden & ~m_g.forbidden).any()


def test_retime_rejects_polyline_motions():
    tr = _straight()
    from anyplan.trajectory.trajectory import Trajectory

    two = Trajectory(tr.segments + tr.segments, kind="polyline")
    assert retime(two, [_crossing()], SPEC).trajectory is None


@pytest.mark.parametrize("cached", [False, True])
def test_a_prediction_that_ends_marks_nothing_after_its_end(cached):
    # A receding-horizon prediction (``until``) has no disc after its end: its map is the map of
    # the unending prediction before the end, and free after it. Before, a row after the end
    # (radius -inf) passed the exact test with an infinite squared reach and marked every cell
    # of the path's chunks near the obstacle. With a cache kept across replannings, a prediction
    # of the same motion that ends elsewhere gets rows of its own.
    motion = UnicycleMotion(4.0, 2.2, 0.0, 0.0)  # standing on the route
    rows = RowCache(0.0, 0.05) if cached else None
    endless = build_stmap(_pts, 8.0, [PredictedObstacle("S", 0.3, motion)], SPEC.radius, 0.0,
                          20.0, margin=0.05, rows=rows)
    for until in (5.0, 12.5):
        ends = build_stmap(_pts, 8.0, [PredictedObstacle("S", 0.3, motion, until=until)],
                           SPEC.radius, 0.0, 20.0, margin=0.05, rows=rows)
        j_end = int(until / ends.h)  # the row that contains the end still has the disc
        g_ends, g_endless = ends.grid(), endless.grid()
        assert ends.rows == endless.rows == g_ends.shape[0]
        assert np.array_equal(g_ends[:j_end + 1], g_endless[:j_end + 1])
        assert g_endless[:j_end + 1].any(axis=1).all()
        assert not g_ends[j_end + 1:].any()
        assert g_endless[j_end + 1:].any(axis=1).all()
        # the rows after the end are not stored: the map holds the end's row and the next
        assert ends.forbidden.shape[0] == j_end + 2 < ends.rows


def test_rows_of_one_motion_are_shared_whatever_its_predictions_end():
    # A receding horizon makes each replanning's predictions end at another time: the rows of
    # the same motion and radius are still sampled once, and each end is applied on reading.
    calls, motion, rows, full = _cached_crossing()
    n = len(calls)
    for until in (4.0, 9.97, 15.0):
        rows.begin(1.0)
        q_x, _, r = rows.rows_all([PredictedObstacle("X", 0.3, motion, until=until)], 20, 400)
        one = rows.rows(PredictedObstacle("X", 0.3, motion, until=until), 20, 400)
        assert len(calls) == n  # not sampled again
        assert np.array_equal(q_x, full[0]) and np.array_equal(r[0], one[1])
        starts = 0.05 * np.arange(20, 400)
        assert np.array_equal(r[0], np.where(starts <= until, full[2][0], -np.inf))
        # a row has the disc as radius_at says at its start, middle or end
        ends = 0.05 * np.arange(20, 401)
        at = PredictedObstacle("X", 0.3, motion, until=until).radius_at
        r_ref = np.maximum(at(starts + 0.025), np.maximum(at(ends[:-1]), at(ends[1:])))
        assert np.array_equal(r[0], r_ref)


def test_cached_rows_are_bit_for_bit_the_rows_sampled_one_obstacle_at_a_time():
    # RowCache samples the row times once for all the new entries of a stack (and radii_at
    # copies a radius array of the right shape without broadcasting): each obstacle's rows are
    # still its centres at the rows' middles and its largest radius at their edges and middles,
    # bit for bit, for fixed, growing and ending discs over growing ranges.
    from anyplan.prediction.base import RadiusGrowth
    from anyplan.trajectory.spacetime import radii_at

    growth = RadiusGrowth(1.0, np.array([0.0, 2.0, 5.0]), np.array([0.0, 0.4, 1.0]))
    obs = [PredictedObstacle("A", 0.3, UnicycleMotion(5.0, -1.3, np.pi / 2, 0.3)),
           PredictedObstacle("B", 0.25, UnicycleMotion(3.0, 5.0, -1.0, 0.7), growth, until=6.0),
           PredictedObstacle("C", 0.2, UnicycleMotion(1.0, 1.0, 0.3, 1.1, 0.4), growth),
           Growing("G", UnicycleMotion(3.0, 5.0, -np.pi / 2, 0.2), 0.3, 0.02)]
    rows = RowCache(1.0, 0.05)
    for j0, j1 in ((0, 300), (10, 700), (0, 120), (5, 1500)):
        qx, qy, r = rows.rows_all(obs, j0, j1)
        j = np.arange(j0, j1)
        t_mid = 1.0 + 0.05 * (j + 0.5)
        t_edges = 1.0 + 0.05 * np.arange(j0, j1 + 1)
        for k, o in enumerate(obs):
            q = o.positions(t_mid)
            re = np.broadcast_to(np.asarray(o.radius_at(t_edges), dtype=float), t_edges.shape)
            rm = np.broadcast_to(np.asarray(o.radius_at(t_mid), dtype=float), t_mid.shape)
            want = np.maximum(rm, np.maximum(re[:-1], re[1:]))
            if isinstance(o, PredictedObstacle) and o.growth is None:  # fixed size, then its end
                want = np.where(1.0 + 0.05 * j <= o.until, o.radius, -np.inf)
            assert qx[k].tobytes() == q[:, 0].tobytes() and qy[k].tobytes() == q[:, 1].tobytes()
            assert r[k].tobytes() == want.tobytes()
            assert radii_at(o, t_mid).tobytes() == rm.tobytes()


def test_rows_after_every_predictions_end_are_free_and_the_rest_as_computed_in_full():
    # Predictions with horizons (until): the map computes its rows up to the last end only.
    # A far obstacle that never ends makes it compute every row: the same map, bit for bit.
    rng = np.random.default_rng(3)
    obs = [PredictedObstacle(f"o{i}", 0.3, UnicycleMotion(float(rng.uniform(3, 7)), -1.0,
                                                          np.pi / 2, float(rng.uniform(0.2, 0.6))),
                             until=float(rng.uniform(2.0, 12.0))) for i in range(6)]
    far = PredictedObstacle("F", 0.3, UnicycleMotion(5.0, 40.0, 0.0, 0.3))
    last = max(o.until for o in obs)
    for rows in (None, RowCache(1.0, 0.05)):
        cut = build_stmap(_pts, 8.0, obs, SPEC.radius, 1.25, 25.0, margin=0.05, rows=rows)
        full = build_stmap(_pts, 8.0, [*obs, far], SPEC.radius, 1.25, 25.0, margin=0.05,
                           rows=None if rows is None else RowCache(1.0, 0.05))
        assert np.array_equal(cut.grid(), full.grid()) and cut.forbidden.any()
        starts = cut.t_map + cut.h * np.arange(cut.rows)
        assert not cut.grid()[starts > last].any() and (starts > last).sum() > 100
        # and only the rows up to the last end are stored
        assert cut.forbidden.shape[0] <= (starts <= last).sum() + 1 < full.forbidden.shape[0]


def test_a_map_beyond_its_bound_gets_wider_cells_and_the_timing_stays_free(monkeypatch):
    # A 1 km path (an arena of the schema's 1000 m) made a map of 10^9 cells: 13 GB and five
    # minutes for one re-timing. Here the bound is made small to show what happens beyond it.
    import anyplan.trajectory.spacetime.timing as timing

    monkeypatch.setattr(timing, "MAX_MAP_CELLS", 20_000)
    tr = _straight()
    ob = _crossing()
    res = retime(tr, [ob], SPEC, margin=0.05)
    assert res.stmap is not None and res.stmap.forbidden.size <= 20_000
    assert res.stmap.ds > 0.05
    assert res.trajectory is not None
    assert first_collision(res.trajectory, [ob], SPEC.radius, margin=0.05) is None
    assert timing.map_ds(0.05, 8.0, 60.0, 0.05) > 0.05
    monkeypatch.undo()
    assert timing.map_ds(0.05, 30.0, 105.0, 0.05) == 0.05  # the paper's robot on 30 m
