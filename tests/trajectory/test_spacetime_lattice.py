"""The s-t velocity planner (lattice A*) against hand cases and brute force."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from anyplan.trajectory.spacetime import edge_ok, lattice_dt, plan_velocity
from anyplan.trajectory.spacetime.lattice import MAX_LATTICE_CELLS, bounded_lattice, lattice_cells

DS, H = 0.05, 0.05
A, V = 0.4, 0.4


def _assert_same_plan(a, b) -> None:
    """Both plans None, or equal bit for bit (times, arc lengths, speeds, accelerations)."""
    assert (a is None) == (b is None)
    if a is not None and b is not None:
        for f in ("t", "s", "v", "a"):
            assert np.array_equal(getattr(a, f), getattr(b, f))


def _caps(length: float, cap: float = V * V) -> tuple[np.ndarray, np.ndarray]:
    n = int(math.ceil(length / DS))
    return np.full(n, cap), np.full(n, cap)


def _check_limits(plan, forbidden, x0, x1, length):
    """Sample the plan every 1 ms: speed, acceleration, map and end conditions."""
    t = np.arange(plan.t[0], plan.t[-1], 1e-3)
    s, v, a = plan.at_time(t)
    assert np.all(v >= -1e-9)
    assert np.all(np.abs(a) <= A + 1e-9)
    dv = np.diff(v) / 1e-3
    assert np.all(np.abs(dv) <= A * (1 + 1e-6) + 1e-6)
    cell = np.clip((s / DS).astype(int), 0, forbidden.shape[1] - 1)
    cap = np.where(np.abs(a) > 0, x1[cell], x0[cell])
    assert np.all(v * v <= cap * (1 + 1e-9) + 1e-12)
    row = np.clip(((t - 0.0) / H).astype(int), 0, forbidden.shape[0] - 1)
    assert not forbidden[row, cell].any()
    assert plan.v[-1] == 0.0
    dt, _ = lattice_dt(V, A)
    assert length - A * dt * dt - 1e-9 <= plan.s[-1] <= length + 1e-9


def test_free_path_arrives_at_the_closed_form_optimum():
    # 10 m from rest to rest: 1 s up to 0.4 m/s, 23.5 s cruise... = L / v + v / a = 26 s.
    length = 10.0
    x0, x1 = _caps(length)
    forbidden = np.zeros((1000, len(x0)), dtype=bool)
    plan = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, A, V)
    assert plan is not None
    assert plan.arrival_s == pytest.approx(length / V + V / A, abs=1e-9)
    assert plan.wait_s == 0.0
    _check_limits(plan, forbidden, x0, x1, length)


def test_waits_for_a_blocked_stretch_then_goes():
    length = 6.0
    x0, x1 = _caps(length)
    forbidden = np.zeros((1000, len(x0)), dtype=bool)
    forbidden[:200, 40:60] = True  # s in [2, 3] m blocked during the first 10 s
    plan = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, A, V, key_cells=0)
    assert plan is not None
    _check_limits(plan, forbidden, x0, x1, length)
    # It cannot be at s >= 2 m before t = 10 s; from there 4 m remain (>= 4 / 0.4 s).
    assert plan.arrival_s >= 10.0 + 4.0 / V - 1e-9
    assert plan.arrival_s <= 10.0 + 4.0 / V + V / A + 2 * lattice_dt(V, A)[0]


def test_speed_cap_of_a_curve_is_kept():
    length = 4.0
    x0, x1 = _caps(length)
    x0[30:50] = x1[30:50] = 0.2 ** 2  # a tight bend: v <= 0.2 m/s on s in [1.5, 2.5]
    forbidden = np.zeros((600, len(x0)), dtype=bool)
    plan = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, A, V)
    assert plan is not None
    _check_limits(plan, forbidden, x0, x1, length)


def test_start_speed_off_the_lattice():
    length = 3.0
    x0, x1 = _caps(length)
    forbidden = np.zeros((600, len(x0)), dtype=bool)
    plan = plan_velocity(forbidden, 2.0, H, DS, x0, x1, length, 2.0, 0.13, A, V)
    assert plan is not None
    assert plan.t[0] == 2.0 and plan.v[0] == pytest.approx(0.13)
    t = np.arange(plan.t[0], plan.t[-1], 1e-3)
    _, v, _ = plan.at_time(t)
    assert np.all(np.abs(np.diff(v)) <= A * 1e-3 * (1 + 1e-6))


def test_no_plan_when_the_end_is_blocked_for_ever():
    length = 2.0
    x0, x1 = _caps(length)
    forbidden = np.zeros((400, len(x0)), dtype=bool)
    forbidden[:, 20:25] = True
    assert plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, A, V) is None


def _brute_force(forbidden, x0, x1, length, n_max):
    """Earliest rest at the goal over every acceleration sequence (3^n), same lattice."""
    dt, kmax = lattice_dt(V, A)
    delta = 0.5 * A * dt * dt
    m_goal = int(math.floor(length / delta + 1e-9))
    m_goal -= m_goal % 2
    frontier = {(0, 0)}
    for n in range(n_max + 1):
        if (m_goal, 0) in frontier:
            return n * dt
        nxt = set()
        for m, k in frontier:
            for u in (1, 0, -1):
                k2, m2 = k + u, m + 2 * k + u
                if 0 <= k2 <= kmax and m2 <= m_goal and edge_ok(
                        forbidden, 0.0, H, DS, x0, x1, n * dt, m * delta, k * A * dt, u * A, dt):
                    nxt.add((m2, k2))
        frontier = nxt
    return None


@pytest.mark.parametrize("seed", range(6))
def test_astar_matches_brute_force_on_small_maps(seed):
    rng = np.random.default_rng(seed)
    length = 1.5
    x0, x1 = _caps(length)
    forbidden = np.zeros((240, len(x0)), dtype=bool)
    for _ in range(3):  # random blocks in (s, t)
        c, j = rng.integers(0, len(x0) - 3), rng.integers(0, 150)
        forbidden[j:j + rng.integers(10, 60), c:c + rng.integers(1, 5)] = True
    forbidden[:, :2] = False  # the start is free
    best = _brute_force(forbidden, x0, x1, length, 46)
    plan = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, A, V, key_cells=0,
                         horizon_s=11.9)
    if best is None:
        assert plan is None
        return
    assert plan is not None
    assert plan.arrival_s == pytest.approx(best, abs=1e-9)
    _check_limits(plan, forbidden, x0, x1, length)
    coarse = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, A, V, key_cells=2,
                           horizon_s=11.9)
    if coarse is not None:  # coarser keys: still valid, never earlier than the optimum
        assert coarse.arrival_s >= best - 1e-9
        _check_limits(coarse, forbidden, x0, x1, length)


def test_lattice_dt_hits_v_max_exactly():
    for v, a in ((0.4, 0.4), (2.0, 2.0), (0.5, 0.3)):
        dt, k = lattice_dt(v, a)
        assert k * a * dt == pytest.approx(v)
        assert k >= 2


@pytest.mark.parametrize("seed", range(12))
def test_capped_search_gives_the_exhaustive_answer(seed):
    # The search ends once no queued node can arrive within the horizon (plan_velocity's cap):
    # on random maps, blocked for ever or not, with and without start speeds off the lattice and
    # coarse keys, the answer is the exhaustive search's, bit for bit.
    rng = np.random.default_rng(100 + seed)
    length = float(rng.uniform(1.0, 4.0))
    x0, x1 = _caps(length)
    i = int(rng.integers(0, len(x0)))
    x0[i:i + 10] = x1[i:i + 10] = 0.2 ** 2  # a slow stretch
    forbidden = np.zeros((int(rng.integers(150, 400)), len(x0)), dtype=bool)
    for _ in range(int(rng.integers(2, 8))):
        c, j = rng.integers(0, len(x0) - 3), rng.integers(0, forbidden.shape[0] - 10)
        forbidden[j:j + rng.integers(10, 120), c:c + rng.integers(1, 8)] = True
    if seed % 3 == 0:
        forbidden[:, len(x0) // 2] = True  # never passable: no motion
    forbidden[:4, :3] = False
    horizon = float(rng.uniform(3.0, forbidden.shape[0] * H))
    v0 = 0.0 if seed % 2 else float(rng.uniform(0.0, V))
    for key in (0, 4):
        a, b = (plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, v0, A, V,
                              horizon_s=horizon, key_cells=key, cap=cap) for cap in (True, False))
        _assert_same_plan(a, b)


@pytest.mark.parametrize("seed", range(12))
def test_goal_bounds_on_the_reachable_cells_only_give_the_same_answer(seed):
    # goal_times computed only on the cells a motion from the start can be in (frontier=True):
    # on random maps, with start speeds off the lattice, a map starting before t0 and coarse
    # keys, the plan is the one with every cell computed, bit for bit.
    rng = np.random.default_rng(300 + seed)
    length = float(rng.uniform(1.0, 5.0))
    vm, am = 1.0, 0.8  # a cell a row at top speed: the frontier matters
    x0, x1 = _caps(length, vm * vm)
    forbidden = np.zeros((int(rng.integers(150, 400)), len(x0)), dtype=bool)
    for _ in range(int(rng.integers(2, 10))):
        c, j = rng.integers(0, len(x0) - 3), rng.integers(0, forbidden.shape[0] - 10)
        forbidden[j:j + rng.integers(5, 120), c:c + rng.integers(1, 8)] = True
    forbidden[:4, :3] = False
    t_map = -float(rng.uniform(0.0, H)) if seed % 2 else 0.0
    v0 = 0.0 if seed % 3 == 0 else float(rng.uniform(0.0, vm))
    for key in (0, 4):
        a, b = (plan_velocity(forbidden, t_map, H, DS, x0, x1, length, 0.0, v0, am, vm,
                              horizon_s=forbidden.shape[0] * H + t_map, key_cells=key,
                              frontier=f) for f in (True, False))
        _assert_same_plan(a, b)


def _goal_times_by_definition(forbidden, t_map, h, c_goal, reach, ds, v_max, c_first):
    """The relaxation of ``goal_times``' docstring, written from its definition: from a free
    cell the robot reaches, within a row, the free cells up to ``reach`` ahead (stopping at
    the first forbidden one), and the goal at once if one of them is a goal cell."""
    nrow, ncell = forbidden.shape
    g = np.full((nrow + 1, ncell), np.inf)
    g[nrow, c_goal:] = t_map + nrow * h
    for j in reversed(range(nrow)):
        tj = t_map + j * h
        computed = ncell if c_first < 0 else min(ncell, c_first + j * reach + 1)
        for c in range(computed):
            if c >= c_goal:
                g[j, c] = tj
                continue
            if forbidden[j, c]:
                continue
            window = range(c, min(c + reach, ncell - 1) + 1)
            cells = list(itertools.takewhile(lambda k, j=j: not forbidden[j, k], window))
            best = tj if any(k >= c_goal for k in cells) else min(g[j + 1, k] for k in cells)
            g[j, c] = max(best, tj + (c_goal - c - 1) * ds / v_max)
    return g


@pytest.mark.parametrize("seed", range(8))
def test_goal_bounds_equal_their_recurrence_bit_for_bit(seed):
    # goal_times reads the free rows at the map's end (after the predictions) in one step per
    # cell; on random maps, forbidden cells early and late, with and without a free suffix and
    # a frontier, every bound is the recurrence's, bit for bit.
    from anyplan.trajectory.spacetime._lattice_kernels import goal_times

    rng = np.random.default_rng(500 + seed)
    nrow, ncell = int(rng.integers(40, 160)), int(rng.integers(20, 90))
    forbidden = np.zeros((nrow, ncell), dtype=bool)
    last = int(rng.integers(1, nrow)) if seed % 4 else nrow  # rows after it stay free
    for _ in range(int(rng.integers(1, 12))):
        c, j = int(rng.integers(0, ncell - 2)), int(rng.integers(0, last))
        forbidden[j:min(j + int(rng.integers(1, 30)), last), c:c + int(rng.integers(1, 6))] = True
    if seed == 5:
        forbidden[nrow - 1, ncell // 2] = True  # no free suffix at all
    c_goal = int(rng.integers(ncell // 2, ncell))
    reach = int(rng.integers(1, 4))
    t_map, h, ds, v_max = float(rng.uniform(-0.05, 2.0)), 0.05, 0.05, float(rng.uniform(0.5, 2.0))
    for c_first in (-1, int(rng.integers(0, 4))):
        got = goal_times(forbidden, t_map, h, c_goal, reach, ds, v_max, c_first)
        want = _goal_times_by_definition(forbidden, t_map, h, c_goal, reach, ds, v_max, c_first)
        assert np.array_equal(got, want)


@pytest.mark.parametrize("seed", range(10))
def test_a_map_without_its_free_rows_gives_the_same_bounds_and_plans_bit_for_bit(seed):
    # A long path's map is mostly rows after every prediction's end: they are not stored, and
    # their goal-time bounds are computed in closed form (free_goal_time). On random maps, with
    # reach both larger and smaller than a row's time allows (the closed form's two branches),
    # every bound and every plan is the one the whole map gives.
    from anyplan.trajectory.spacetime._lattice_kernels import free_goal_time, goal_times

    rng = np.random.default_rng(700 + seed)
    nrow, ncell = int(rng.integers(60, 200)), int(rng.integers(20, 90))
    r_dense = int(rng.integers(0, nrow // 2))  # rows after it are free
    forbidden = np.zeros((nrow, ncell), dtype=bool)
    for _ in range(int(rng.integers(0, 10)) if r_dense else 0):
        c, j = int(rng.integers(0, ncell - 2)), int(rng.integers(0, r_dense))
        forbidden[j:min(j + int(rng.integers(1, 30)), r_dense), c:c + int(rng.integers(1, 6))] = True
    c_goal = int(rng.integers(ncell // 2, ncell))
    reach = int(rng.integers(1, 5))
    t_map, h, ds, v_max = float(rng.uniform(-0.05, 2.0)), 0.05, 0.05, float(rng.uniform(0.5, 4.0))
    for c_first in (-1, int(rng.integers(0, 4))):
        full = goal_times(forbidden, t_map, h, c_goal, reach, ds, v_max, c_first)
        cut = goal_times(forbidden[:r_dense], t_map, h, c_goal, reach, ds, v_max, c_first, nrow)
        assert cut.shape == (r_dense + 1, ncell)
        assert np.array_equal(cut, full[:r_dense + 1])
        for j in range(r_dense, nrow + 1):
            computed = ncell if c_first < 0 else min(ncell, c_first + j * reach + 1)
            for c in range(computed if j < nrow else ncell):
                got = free_goal_time(j, c, t_map, h, c_goal, reach, ds, v_max, nrow)
                assert got == full[j, c], (j, c)
    # the planner on the map without its free rows: the same plan
    length = float(rng.uniform(1.0, 4.0))
    x0, x1 = _caps(length)
    forbidden = np.zeros((nrow, len(x0)), dtype=bool)
    for _ in range(int(rng.integers(1, 6)) if r_dense else 0):
        c, j = int(rng.integers(3, len(x0) - 3)), int(rng.integers(0, r_dense))
        forbidden[j:min(j + int(rng.integers(5, 40)), r_dense), c:c + int(rng.integers(1, 6))] = True
    v0 = 0.0 if seed % 3 == 0 else float(rng.uniform(0.0, V))
    for key in (0, 4):
        a = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, v0, A, V, key_cells=key,
                          horizon_s=nrow * H)
        b = plan_velocity(forbidden[:r_dense], 0.0, H, DS, x0, x1, length, 0.0, v0, A, V,
                          key_cells=key, horizon_s=nrow * H, rows=nrow)
        _assert_same_plan(a, b)


@pytest.mark.parametrize("seed", range(12))
def test_the_search_kept_in_hash_tables_finds_the_same_plans(seed):
    # A large lattice keeps its search's marks in hash tables, not dense arrays (a long path's
    # arrays were hundreds of MB, zeroed each search): on random maps, with coarse keys and
    # without, from speeds off the lattice, the plans are the dense arrays' bit for bit.
    rng = np.random.default_rng(900 + seed)
    length = float(rng.uniform(1.0, 5.0))
    x0, x1 = _caps(length)
    forbidden = np.zeros((int(rng.integers(150, 400)), len(x0)), dtype=bool)
    for _ in range(int(rng.integers(0, 10))):
        c, j = rng.integers(3, len(x0) - 3), rng.integers(0, forbidden.shape[0] - 10)
        forbidden[j:j + rng.integers(5, 120), c:c + rng.integers(1, 8)] = True
    v0 = 0.0 if seed % 3 == 0 else float(rng.uniform(0.0, V))
    for key in (0, 4):
        a, b = (plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, v0, A, V, key_cells=key,
                              horizon_s=forbidden.shape[0] * H, dense_cells=d) for d in (None, 0))
        _assert_same_plan(a, b)


def test_a_map_cannot_claim_fewer_rows_than_it_holds():
    x0, x1 = _caps(2.0)
    with pytest.raises(ValueError, match="rows: 10 is fewer than the map's 20"):
        plan_velocity(np.zeros((20, len(x0)), dtype=bool), 0.0, H, DS, x0, x1, 2.0, 0.0, 0.0, A, V,
                      rows=10)


@pytest.mark.parametrize("a_max", [0.001, 1000.0])
def test_a_robot_at_the_schemas_acceleration_limits_gets_a_bounded_lattice(a_max):
    # a_max = 0.001 made 1600 speed levels and a_max = 1000 a step of 0.2 ms: the search's
    # dense arrays asked for 10^11 bytes (MemoryError in st-bitstar's first re-timing).
    length = 4.0
    x0, x1 = _caps(length)
    forbidden = np.zeros((4000, len(x0)), dtype=bool)
    forbidden[:100, 40:60] = True  # s in [2, 3] m blocked during the first 5 s
    dt, kmax, a = bounded_lattice(V, a_max, 0.25, 200.0, length, len(x0))
    assert lattice_cells(dt, kmax, a, 200.0, length, len(x0)) <= MAX_LATTICE_CELLS
    assert a <= a_max and kmax * a * dt == pytest.approx(V)
    plan = plan_velocity(forbidden, 0.0, H, DS, x0, x1, length, 0.0, 0.0, a_max, V,
                         horizon_s=200.0)
    assert plan is not None
    assert np.all(np.abs(plan.a) <= a_max * (1 + 1e-9)) and np.all(plan.v <= V + 1e-9)
    t = np.arange(plan.t[0], plan.t[-1], 1e-2)
    s, _, _ = plan.at_time(t)
    row = np.clip((t / H).astype(int), 0, forbidden.shape[0] - 1)
    cell = np.clip((s / DS).astype(int), 0, forbidden.shape[1] - 1)
    assert not forbidden[row, cell].any()
    assert plan.v[-1] == 0.0 and plan.s[-1] <= length + 1e-9


def test_the_usual_robots_keep_their_lattice():
    # The bound changes nothing below it: the paper's robot on a 30 m path, a Jackal.
    for v, a, length, horizon in ((0.4, 0.4, 30.0, 105.0), (2.0, 20.0, 10.0, 35.0),
                                  (1.0, 1.0, 30.0, 60.0)):
        ncell = int(math.ceil(length / DS))
        assert bounded_lattice(v, a, 0.25, horizon, length, ncell) == (*lattice_dt(v, a), a)
