"""Our own cubic-spline solver and evaluator against scipy's (the curves must be the same)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline, make_interp_spline

from anyplan.geometry import Circle, ObstacleSet
from anyplan.geometry.collision import COLLISION_EPS
from anyplan.trajectory.spline import START_KNOT, SmoothCurve, clean_path, shortcut_path
from anyplan.trajectory.spline._clearance import CAP_DELTA
from anyplan.trajectory.spline._fit import cubic_spline
from anyplan.trajectory.spline._pp import pp_eval
from anyplan.trajectory.spline.clearance import failing_pieces, worst_failures, worst_per_group


def _points(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    y = np.cumsum(rng.uniform(-1.0, 2.0, (n, 2)), axis=0)
    x = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 3.0, n - 1))])
    return x, y


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("n", [2, 3, 4, 9])
def test_cubic_spline_matches_scipy(seed, n):
    x, y = _points(seed, n)
    th = float(np.random.default_rng(seed + 100).uniform(-math.pi, math.pi))
    tan = np.array([math.cos(th), math.sin(th)])
    kap = float(np.random.default_rng(seed + 200).uniform(-3.0, 3.0))
    nrm = np.array([-tan[1], tan[0]]) * kap
    extra = x[0] + min(0.5 * (x[1] - x[0]), START_KNOT)
    t_knots = np.concatenate([[x[0]] * 4, [extra], x[1:-1], [x[-1]] * 4])
    refs = {
        0: CubicSpline(x, y, axis=0, bc_type="natural"),
        1: CubicSpline(x, y, axis=0, bc_type=((1, tan), (2, np.zeros(2)))),
        2: make_interp_spline(x, y, k=3, t=t_knots, bc_type=([(1, tan), (2, nrm)], [(2, np.zeros(2))]),
                              axis=0),
    }
    u = np.concatenate([np.linspace(x[0] - 0.5, x[-1] + 0.5, 501), x])
    scale = 1.0 + np.abs(y).max()
    for mode, ref in refs.items():
        bx, bc = cubic_spline(x, y, mode, tan, nrm, extra)
        assert len(bx) == len(x) + (mode == 2)
        for nu in range(4):
            got = pp_eval(bx, bc, u, nu)
            want = ref(u, nu)
            # the third derivative jumps at the breakpoints: compare away from them only
            sel = np.min(np.abs(u[:, None] - bx[None, :]), axis=1) > 1e-9 if nu == 3 else slice(None)
            np.testing.assert_allclose(got[sel], want[sel], rtol=0, atol=1e-9 * scale * 10 ** nu)


def test_curve_queries_keep_shapes():
    c = SmoothCurve(np.array([[0.0, 0.0], [2.0, 1.0], [4.0, -1.0]]), start_heading=0.3,
                    start_curvature=0.5)
    assert c.position(1.0).shape == (2,)
    assert c.position(np.zeros((3, 4))).shape == (3, 4, 2)
    assert c.heading(np.zeros((3, 4))).shape == (3, 4)
    k0, _ = c.curvature(np.array([0.0]))
    assert k0[0] == pytest.approx(0.5, abs=1e-9)
    assert c.u_of_s(np.zeros((2, 5))).shape == (2, 5)


@pytest.mark.parametrize("seed", range(10))
def test_shortcut_takes_the_farthest_free_vertex(seed):
    # Greedy farthest-in-sight: each kept vertex jumps to the farthest later vertex whose straight
    # segment keeps the clearance (or to the next vertex if none does), checked exhaustively.
    rng = np.random.default_rng(seed)
    shapes = [Circle(rng.uniform(1.0, 9.0, 2), float(rng.uniform(0.2, 0.8))) for _ in range(6)]
    obs = ObstacleSet(shapes, bounds=(0.0, 0.0, 10.0, 10.0))
    path = np.column_stack([np.linspace(0.5, 9.5, 25), 5.0 + np.cumsum(rng.normal(0.0, 0.3, 25))])
    path[:, 1] = np.clip(path[:, 1], 0.5, 9.5)
    r = 0.2
    out = shortcut_path(path, obs, r)
    idx = [int(np.flatnonzero(np.all(path == q, axis=1))[0]) for q in out]
    assert idx[0] == 0 and idx[-1] == len(path) - 1 and idx == sorted(idx)
    for i, j in zip(idx[:-1], idx[1:], strict=True):
        free = [k for k in range(i + 2, len(path)) if obs.segment_free(path[i], path[k], r)]
        assert j == (max(free) if free else i + 1)


def test_clean_path_keeps_turns_and_last_point():
    p = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [2.0, 1.0 + 1e-12]])
    out = clean_path(p)
    np.testing.assert_array_equal(out, [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0 + 1e-12]])
    np.testing.assert_array_equal(clean_path(np.zeros((3, 2))), [[0.0, 0.0]])
    with pytest.raises(ValueError, match="at least one point"):
        clean_path(np.zeros((0, 2)))


def _reduce(kk: np.ndarray, fu: np.ndarray, fc: np.ndarray) -> tuple[list, list, list]:
    """Per interval, the first failing piece of least clearance (what the repair uses)."""
    ks, idx = worst_per_group(kk.astype(np.int64), fc)
    return ks.tolist(), fu[idx].tolist(), fc[idx].tolist()


@pytest.mark.parametrize("seed", range(30))
def test_branch_and_bound_finds_the_same_worst_pieces(seed):
    # The repair's reduced certification (branch and bound) against the full one: same intervals,
    # same worst piece and clearance in each (exactly), and the same margin when the curve is free.
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform(-1.0, 2.0, (6, 2)), axis=0)
    c = SmoothCurve(pts, start_heading=float(rng.uniform(-np.pi, np.pi)) if seed % 2 else None,
                    grid_step=0.05)
    shapes = [Circle(rng.uniform(pts.min(0), pts.max(0)), float(rng.uniform(0.1, 0.6))) for _ in range(4)]
    # every third world has walls that the curve leaves (zero-clearance stretches)
    lo, hi = pts.min(0) + 0.3, pts.max(0) - 0.3
    obs = ObstacleSet(shapes, bounds=(lo[0], lo[1], hi[0], hi[1]) if seed % 3 == 0 else None)
    true_min = float(obs.clearances(c.position(np.linspace(0.0, c.knots[-1], 20_000))).min())
    for radius in (0.05, 0.3, true_min - 1e-3, true_min + 1e-3, true_min + 0.3):
        if radius <= 0.0:
            continue
        kk, fu, fc, margin = failing_pieces(c, obs, radius, 4)
        ks, bu, bc, bmargin = worst_failures(c, obs, radius, 4)
        assert _reduce(kk, fu, fc) == (ks.tolist(), bu.tolist(), bc.tolist())
        if len(kk) == 0:
            assert bmargin == margin


@pytest.mark.parametrize("seed", range(6))
def test_branch_and_bound_on_a_long_curve_out_of_its_arena_finds_the_same_worst_pieces(seed):
    # A long path's first spline swings metres out of a narrow arena: thousands of buried
    # pieces, whose leaves the bound made for distances (its slack grows with the coordinates)
    # could not prune, 4^4 leaves each; the bound for buried pieces prunes them. Same answers.
    rng = np.random.default_rng(40 + seed)
    xs = np.concatenate([[0.0, rng.uniform(2.0, 4.0)], np.sort(rng.uniform(20.0, 140.0, 2)), [150.0]])
    ys = np.array([0.0, rng.choice([-1.0, 1.0]) * rng.uniform(1.0, 2.0), 0.0, rng.uniform(-0.5, 0.5), 0.0])
    pts = np.column_stack([xs + 400.0 * (seed % 2), ys])  # far from the origin: a large slack
    # a sharp first turn, then long segments: the spline swings up to 17 m off the line
    c = SmoothCurve(pts, start_heading=float(-np.sign(ys[1]) * rng.uniform(0.5, 1.2)), grid_step=0.05)
    obs = ObstacleSet([Circle((pts[2, 0], 1.5), 0.5)], bounds=(pts[0, 0] - 1.0, -2.5,
                                                             pts[-1, 0] + 1.0, 2.5))
    off = np.abs(c.position(np.linspace(0.0, c.knots[-1], 5000))[:, 1]) > 2.5 + 0.3
    assert off.mean() > 0.2  # a quarter to a half of the curve is out of the arena
    for radius in (0.1, 0.3):
        kk, fu, fc, margin = failing_pieces(c, obs, radius, 4)
        ks, bu, bc, bmargin = worst_failures(c, obs, radius, 4)
        assert _reduce(kk, fu, fc) == (ks.tolist(), bu.tolist(), bc.tolist())
        if len(kk) == 0:
            assert bmargin == margin


@pytest.mark.parametrize("seed", range(16))
def test_branch_and_bound_on_maps_finds_the_same_worst_pieces(seed):
    # The same on a map: curves through walls (buried pieces: no clearance queries below them),
    # past them (capped queries, deferred pieces) and out of the arena; a repeated question
    # gets the same answer.
    from anyplan.geometry.cells import cell_boxes, merge_cells

    rng = np.random.default_rng(seed)
    occ = np.zeros((60, 80), dtype=bool)
    for _ in range(6):  # walls and blocks of cells
        j, i = int(rng.integers(0, 55)), int(rng.integers(0, 75))
        occ[j:j + int(rng.integers(1, 5)), i:i + int(rng.integers(1, 25))] = True
    occ |= rng.random(occ.shape) < 0.01
    boxes = cell_boxes(merge_cells(occ), (0.0, 0.0), 0.05)
    obs = ObstacleSet([Circle((2.0, 1.5), 0.2)], bounds=(0.1, 0.1, 3.9, 2.9) if seed % 2 else None,
                      boxes=boxes, index=True)
    assert obs.indexed
    pts = rng.uniform([0.0, 0.0], [4.0, 3.0], (5, 2))
    c = SmoothCurve(pts, start_heading=float(rng.uniform(-np.pi, np.pi)), grid_step=0.02)
    for radius in (0.02, 0.1, 0.3):
        kk, fu, fc, margin = failing_pieces(c, obs, radius, 4)
        ks, bu, bc, bmargin = worst_failures(c, obs, radius, 4)
        assert _reduce(kk, fu, fc) == (ks.tolist(), bu.tolist(), bc.tolist())
        if len(kk) == 0:
            assert bmargin == margin
        again = worst_failures(c, obs, radius, 4)
        assert [a.tolist() for a in again[:3]] == [ks.tolist(), bu.tolist(), bc.tolist()]
        assert again[3] == bmargin or (math.isinf(bmargin) and math.isinf(again[3]))
        # without the tight margin: the same failures, and the margin capped at CAP_DELTA
        # (the deferred pieces, never measured, clear it)
        loose = worst_failures(c, obs, radius, 4, tight=False)
        assert [a.tolist() for a in loose[:3]] == [ks.tolist(), bu.tolist(), bc.tolist()]
        assert loose[3] == min(bmargin, (radius - COLLISION_EPS) + CAP_DELTA - radius)


def test_smoothing_memo_answers_as_a_fresh_smoothing():
    # A repeated smooth_path (same path, obstacles, settings) is answered from the memo: the same
    # curve and counts as a fresh computation; other obstacles or settings are not mixed up.
    from anyplan.geometry import square
    from anyplan.trajectory.spline import smooth as sm

    path = np.array([[0.5, 0.5], [2.0, 2.5], [4.0, 2.0], [5.5, 4.0]])
    base = ObstacleSet([Circle((2.6, 1.6), 0.3)], bounds=(0.0, 0.0, 6.0, 5.0))
    cases = [(base, 0.2, 0.3), (base.with_shapes([square((3.0, 3.2), 0.4)]), 0.2, 0.3),
             (base, 0.25, 0.3), (base, 0.2, None)]
    got = [sm.smooth_path(path, o, r, start_heading=h) for o, r, h in cases]
    again = [sm.smooth_path(path, o, r, start_heading=h) for o, r, h in cases]
    sm._MEMO.clear()
    fresh = [sm.smooth_path(path, o, r, start_heading=h) for o, r, h in cases]
    for a, b, c in zip(got, again, fresh, strict=True):
        assert b.curve is a.curve  # from the memo
        assert (a.rounds, a.points_added, a.margin) == (c.rounds, c.points_added, c.margin)
        assert np.array_equal(a.curve.arrays.c, c.curve.arrays.c)
    assert len({r.curve.arrays.c.tobytes() for r in got}) > 1  # the cases differ
