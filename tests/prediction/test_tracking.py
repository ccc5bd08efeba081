"""The IMM tracker: convergence on straight and turning motion, consistency, appearing,
coasting through occlusions, dropping, and the coordinated-turn Jacobian."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import Tracker, TrackerConfig, ct_transition


def _circle(t, v, w):
    if w == 0.0:
        return np.array([1.0 + v * t, 2.0 + 0.5 * v * t]), np.array([v, 0.5 * v])
    return (np.array([v / w * np.sin(w * t), v / w * (1 - np.cos(w * t))]),
            np.array([v * np.cos(w * t), v * np.sin(w * t)]))


def _run(v, w, seed, secs=8.0, sigma=0.05, rate=10.0):
    rng = np.random.default_rng(seed)
    tr = Tracker(TrackerConfig(sigma_m=sigma))
    t = 0.0
    for k in range(int(secs * rate) + 1):
        t = k / rate
        p, _ = _circle(t, v, w)
        z = p + rng.normal(0.0, sigma, 2)
        tr.update(t, [Detection("a", t, float(z[0]), float(z[1]), 0.3)])
    return tr, t


def test_converges_on_straight_motion_with_a_covariance_that_does_not_understate_the_error():
    errs, nees = [], []
    for seed in range(30):
        tr, t = _run(1.2, 0.0, seed)
        e = tr.estimates(t)[0]
        p, vel = _circle(t, 1.2, 0.0)
        d = np.concatenate([e.state[:2] - p, e.state[2:4] - vel])
        errs.append(np.linalg.norm(e.state[2:4] - vel))
        nees.append(d @ np.linalg.solve(e.cov[:4, :4], d))
        assert abs(e.state[4]) < 0.2
    assert np.median(errs) < 0.1  # m/s
    # not overconfident: the mean NEES of the 4-D error stays below 4 (its value for an exact
    # covariance); the process noise makes it conservative on a perfectly straight motion
    assert np.mean(nees) < 4.0


def test_converges_on_turning_motion_and_detects_the_turn():
    ws, probs = [], []
    for seed in range(10):
        tr, t = _run(1.2, 0.5, seed)
        e = tr.estimates(t)[0]
        p, vel = _circle(t, 1.2, 0.5)
        assert np.linalg.norm(e.state[:2] - p) < 0.1
        assert np.linalg.norm(e.state[2:4] - vel) < 0.2
        ws.append(e.turn_rate)
        probs.append(e.mode_probs[1])
    assert abs(np.median(ws) - 0.5) < 0.08
    assert np.median(probs) > 0.7  # the CT model dominates (UncertaintyModel.turn_confidence)
    # and on the straight motion it does not
    tr, t = _run(1.2, 0.0, 0)
    assert tr.estimates(t)[0].mode_probs[1] < 0.7


def test_appearing_coasting_and_leaving():
    cfg = TrackerConfig(sigma_m=0.05, drop_after_s=1.5)
    tr = Tracker(cfg)
    tr.update(0.0, [Detection("a", 0.0, 0.0, 0.0, 0.3)])
    assert len(tr) == 1
    for k in range(1, 21):
        t = 0.1 * k
        tr.update(t, [Detection("a", t, t, 0.0, 0.3), Detection("b", t, 5.0, t, 0.4)] if k >= 10
                  else [Detection("a", t, t, 0.0, 0.3)])
    assert len(tr) == 2  # b appeared
    est = {e.name: e for e in tr.estimates(2.0)}
    assert est["b"].radius == 0.4 and est["b"].n_updates == 11
    # a is occluded from t = 2.0 on: it coasts, its position covariance grows, its mean moves on
    traces, xs = [], []
    for k in range(21, 36):
        t = 0.1 * k
        tr.update(t, [Detection("b", t, 5.0, t, 0.4)])
        a = {e.name: e for e in tr.estimates(t)}.get("a")
        if a is None:
            break
        traces.append(np.trace(a.cov[:2, :2]))
        xs.append(a.state[0])
    assert len(traces) == 15 and np.all(np.diff(traces) > 0.0)
    assert xs[-1] == pytest.approx(3.5, abs=0.2)  # extrapolated at 1 m/s
    # 1.5 s after its last detection (t = 2.0) it is dropped
    tr.update(3.55, [Detection("b", 3.55, 5.0, 3.55, 0.4)])
    assert [e.name for e in tr.estimates(3.55)] == ["b"] and tr.dropped == 1
    # when it comes back it is a new track
    tr.update(3.6, [Detection("a", 3.6, 3.6, 0.0, 0.3)])
    assert {e.name: e.n_updates for e in tr.estimates(3.6)}["a"] == 1


def test_estimates_do_not_change_the_filter():
    tr, t = _run(1.0, 0.0, 0, secs=2.0)
    before = tr.x.copy(), tr.P.copy()
    tr.estimates(t + 1.0)
    assert np.array_equal(before[0], tr.x) and np.array_equal(before[1], tr.P)


@pytest.mark.parametrize("w", [0.7, -1.3, 1e-7, 0.0])
def test_ct_jacobian_matches_finite_differences(w):
    x = np.array([[1.0, 2.0, 0.7, -0.3, w]])
    T = np.array([0.4])
    f, F = ct_transition(x, T)
    J = np.zeros((5, 5))
    h = 1e-6
    for k in range(5):
        e = np.zeros(5)
        e[k] = h
        J[:, k] = (ct_transition(x + e, T)[0][0] - ct_transition(x - e, T)[0][0]) / (2 * h)
    np.testing.assert_allclose(F[0], J, atol=1e-7)
    # the transition is the exact unicycle motion
    v, th = np.hypot(0.7, -0.3), np.arctan2(-0.3, 0.7)
    if abs(w) > 1e-3:
        exp = [1.0 + v / w * (np.sin(th + w * 0.4) - np.sin(th)),
               2.0 - v / w * (np.cos(th + w * 0.4) - np.cos(th))]
    else:
        exp = [1.0 + 0.7 * 0.4, 2.0 - 0.3 * 0.4]
    np.testing.assert_allclose(f[0, :2], exp, atol=1e-6)


def test_a_jump_restarts_the_track_instead_of_a_fast_motion():
    # An obstacle walking at 1 m/s along x teleports 6 m back (a looping track's jump): the
    # track restarts at the new place (at rest, counted) instead of estimating a dash of
    # -60 m/s; an ordinary walk never triggers it.
    from anyplan.prediction.detection import Detection
    from anyplan.prediction.tracking import Tracker

    tr = Tracker()
    rng = np.random.default_rng(0)
    for k in range(30):
        t = 0.1 * k
        x = 0.1 * k if k < 20 else 0.1 * k - 6.0
        tr.update(t, [Detection("a", t, x + 0.05 * rng.standard_normal(),
                                0.05 * rng.standard_normal(), 0.3)])
        if k == 19:
            assert tr.restarted == 0
            assert tr.estimates(t)[0].speed == pytest.approx(1.0, abs=0.2)
    assert tr.restarted == 1
    est = tr.estimates(2.9)[0]
    assert abs(est.state[0] - (2.9 - 6.0)) < 0.2 and est.speed < 2.0


def _reversal_errors(cfg_kw, seeds=range(20)):
    """Mean speed error [m/s] of the estimate 0.1 .. 1.0 s after an obstacle moving at 1.7 m/s
    reverses (DynaBARN's tracks turn back at their corners), 5 cm noise at 10 Hz, and the
    mean error over the 1 s before the reversal."""
    after, before = np.zeros(10), []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        tr = Tracker(TrackerConfig(sigma_m=0.05, **cfg_kw))
        for k in range(61):
            t = 0.1 * k
            x = 1.7 * t if k <= 50 else 1.7 * 5.0 - 1.7 * (t - 5.0)
            z = np.array([x, 0.0]) + rng.normal(0.0, 0.05, 2)
            tr.update(t, [Detection("a", t, float(z[0]), float(z[1]), 0.5)])
            v_true = 1.7 if k <= 50 else -1.7
            err = abs(tr.estimates(t)[0].state[2] - v_true)
            if 40 < k <= 50:
                before.append(err)
            elif k > 50:
                after[k - 51] += err / len(seeds)
    return after, float(np.mean(before))


def test_a_manoeuvre_is_followed_within_a_few_frames_without_noisier_steady_state():
    # With the manoeuvre noise the speed error 0.3 s after a reversal (3.4 m/s of change) is
    # under 0.5 m/s; without it (q_manoeuvre = 0) it is still over 1 m/s. Before the
    # reversal both filters are as quiet (the noise is added only at a manoeuvre).
    with_m, quiet_m = _reversal_errors({})
    without, quiet = _reversal_errors({"q_manoeuvre": 0.0})
    assert with_m[2] < 0.5 < 1.0 < without[2]
    assert with_m[:6].mean() < 0.5 * without[:6].mean()
    assert quiet_m < 0.1 and quiet < 0.1 and abs(quiet_m - quiet) < 0.02


def _walker_frames(tr, t0, t1, expected, present_until):
    """Frames every 0.1 s of a walker at 1 m/s along x, detected (named) until present_until."""
    for k in range(int(round(t0 * 10)), int(round(t1 * 10)) + 1):
        t = k / 10
        dets = [Detection("a", t, t, 0.0, 0.3)] if t <= present_until + 1e-9 else []
        tr.update(t, dets, expected)


@pytest.mark.parametrize("misses", [1, 3, 5])
def test_a_track_missed_in_plain_view_is_dropped_after_visible_misses_frames(misses):
    tr = Tracker(TrackerConfig(sigma_m=0.05, visible_misses=misses))
    always = lambda c, r: np.ones(len(c), dtype=bool)  # noqa: E731
    _walker_frames(tr, 0.0, 1.0, always, present_until=1.0)
    assert len(tr) == 1
    # gone at 1.0 s: missed at 1.1, 1.2, ...; dropped at the frame of its misses-th miss
    for k in range(1, misses + 1):
        t = 1.0 + 0.1 * k
        tr.update(t, [], always)
        assert len(tr) == (0 if k == misses else 1)
    assert tr.vanished == 1 and tr.dropped == 1


def test_a_hidden_track_coasts_and_frames_out_of_view_do_not_reset_the_count():
    cfg = TrackerConfig(sigma_m=0.05, visible_misses=3, drop_after_s=1.5)
    tr = Tracker(cfg)
    never = lambda c, r: np.zeros(len(c), dtype=bool)  # noqa: E731
    _walker_frames(tr, 0.0, 1.0, never, present_until=1.0)
    # hidden (not expected): coasts until drop_after_s, as without negative information
    _walker_frames(tr, 1.1, 2.5, never, present_until=1.0)
    assert len(tr) == 1
    tr.update(2.6, [], never)
    assert len(tr) == 0 and tr.vanished == 0
    # expected, hidden, expected, hidden, expected: the third expected miss drops it
    tr = Tracker(cfg)
    _walker_frames(tr, 0.0, 1.0, never, present_until=1.0)
    flags = [True, False, True, False, True]
    for k, f in enumerate(flags, 1):
        tr.update(1.0 + 0.1 * k, [], lambda c, r, f=f: np.full(len(c), f))
        assert len(tr) == (0 if k == 5 else 1)
    # a detection resets the count; without ``expected`` (no sensor frame) nothing is counted
    tr = Tracker(cfg)
    always = lambda c, r: np.ones(len(c), dtype=bool)  # noqa: E731
    _walker_frames(tr, 0.0, 1.0, always, present_until=1.0)
    tr.update(1.1, [], always)
    tr.update(1.2, [], always)
    tr.update(1.3, [Detection("a", 1.3, 1.3, 0.0, 0.3)], always)
    tr.update(1.4, [], always)
    tr.update(1.5, [], always)
    for t in (1.55, 1.6, 1.65):
        tr.update(t, [])
    assert len(tr) == 1
    tr.update(1.7, [], always)
    assert len(tr) == 0


def test_expected_sees_the_predicted_centres_and_radii():
    tr = Tracker(TrackerConfig(sigma_m=0.05))
    seen = []

    def expected(c, r):
        seen.append((c.copy(), r.copy()))
        return np.zeros(len(c), dtype=bool)

    _walker_frames(tr, 0.0, 1.0, expected, present_until=1.0)
    tr.update(1.5, [], expected)
    c, r = seen[-1]
    assert c.shape == (1, 2) and r.tolist() == [0.3]
    assert c[0] == pytest.approx([1.5, 0.0], abs=0.1)  # predicted at 1 m/s to 1.5 s
    assert TrackerConfig().visible_misses == 3
    with pytest.raises(ValueError, match="visible_misses"):
        TrackerConfig(visible_misses=-1)
