"""The coverage of the uncertainty radius on synthetic pedestrians: no recorded data needed.

``test_uncertain.py`` checks the stated rate (docs/perception.md, "Prediction accuracy on
ETH/UCY": the disc holds the truth >= 90 % of the time up to 2 s and >= 80 % over 4.8 s) on the
recorded crowds under ``../shared/benchmarks/crowds``, and skips where they are absent (a fresh
CI machine). Here the same protocol runs on walkers generated with a seeded Generator, so the
claim is checked everywhere. The recorded crowds remain the stronger check.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.prediction.base import ConstantTwistPredictor
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import Tracker, TrackerConfig, TrackEstimate
from anyplan.prediction.uncertain import UncertaintyModel
from anyplan.world.motion import UnicycleMotion

H = 0.01  # [s] integration step of the true paths
FRAME = 0.1  # [s] 10 Hz detections
N_OBS = 32  # 3.2 s observed, as in the ETH/UCY protocol
HORIZONS = 0.4 * np.arange(1, 13)  # its 12 predicted frames, 0.4 s apart, up to 4.8 s
NOISE_M = 0.05  # [m] detection noise per axis
V_MIN, V_MAX = 0.5, 1.9  # [m/s] walking speeds


def _walkers(rng: np.random.Generator, n: int, duration: float = 8.0) -> np.ndarray:
    """True positions (n, steps + 1, 2) every H [s] of n walkers.

    Each walks straight at a constant speed (N(1.3, 0.2) m/s, within [0.7, V_MAX]) for legs
    of mean 4 s (exponential), between which it manoeuvres for 1-3 s: a constant turn rate in
    [-0.3, 0.3] rad/s and a constant acceleration in [-0.2, 0.2] m/s^2 (speed kept in
    [V_MIN, V_MAX]). The paths have no noise of their own. The rates are those of the recorded
    pedestrians: on UCY zara01, 90 % of the 0.4 s annotation steps of people walking (faster
    than 0.3 m/s) turn slower than 0.33 rad/s and change speed slower than 0.26 m/s^2. The
    walkers stray from a straight line nearly as far as the recorded crowds do (see
    ``test_uncertainty_radius_covers_synthetic_pedestrians_at_the_stated_rate``).
    """
    steps = round(duration / H)
    w = np.zeros((n, steps))
    a = np.zeros((n, steps))
    for i in range(n):
        k = int(rng.exponential(4.0) / H)
        while k < steps:
            m = int(rng.uniform(1.0, 3.0) / H)
            w[i, k:k + m] = rng.uniform(-0.3, 0.3)
            a[i, k:k + m] = rng.uniform(-0.2, 0.2)
            k += m + int(rng.exponential(4.0) / H)
    th = rng.uniform(-math.pi, math.pi, n)
    v = np.clip(rng.normal(1.3, 0.2, n), 0.7, V_MAX)
    p = np.zeros((n, steps + 1, 2))
    for k in range(steps):  # midpoint rule: the error (< 1e-5 m) is far below the noise
        vn = np.clip(v + a[:, k] * H, V_MIN, V_MAX)
        vm, thm = 0.5 * (v + vn), th + 0.5 * w[:, k] * H
        p[:, k + 1] = p[:, k] + (vm * H)[:, None] * np.column_stack([np.cos(thm), np.sin(thm)])
        v, th = vn, th + w[:, k] * H
    return p


def _inside(truth: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Whether each walker's true position is within the disc's extra radius of the predicted
    centre at each horizon (n, 12): tracker fed N_OBS noisy detections at 10 Hz, then the
    uncertainty model and the predictor, as ``evaluate_prediction`` does at 2.5 Hz. One
    tracker holds every walker (named tracks are independent: each is its own filter)."""
    n = len(truth)
    names = [f"w{i}" for i in range(n)]
    tracker = Tracker(TrackerConfig(sigma_m=NOISE_M))
    every = round(FRAME / H)
    for k in range(N_OBS):
        t = FRAME * k
        z = truth[:, k * every] + rng.normal(0.0, NOISE_M, (n, 2))
        tracker.update(t, [Detection(nm, t, float(x), float(y), 0.25)
                           for nm, (x, y) in zip(names, z, strict=True)])
    t_last = FRAME * (N_OBS - 1)
    by_name = {e.name: e for e in tracker.estimates(t_last)}
    obs = UncertaintyModel().observations([by_name[nm] for nm in names])
    preds = ConstantTwistPredictor(use_announced=False).predict(obs)
    ft = t_last + HORIZONS
    idx = np.rint(ft / H).astype(int)
    err = np.array([np.hypot(*(p.positions(ft) - truth[i, idx]).T) for i, p in enumerate(preds)])
    extra = np.array([p.growth.at(ft) for p in preds])
    return err <= extra


def _straying(truth: np.ndarray) -> np.ndarray:
    """Distance [m] (n, 12) of the truth from the straight line through its last two observed
    frames of the 2.5 Hz protocol (0.4 s apart), at each horizon: how far the walkers stray."""
    step = round(0.4 / H)
    last = round(FRAME * (N_OBS - 1) / H)
    p1, p0 = truth[:, last], truth[:, last - step]
    line = p1[:, None, :] + ((p1 - p0) / 0.4)[:, None, :] * HORIZONS[None, :, None]
    fut = truth[:, last + np.rint(HORIZONS / H).astype(int)]
    return np.hypot(*(line - fut).transpose(2, 0, 1))


def test_uncertainty_radius_covers_synthetic_pedestrians_at_the_stated_rate():
    n = 2000
    rng = np.random.default_rng(20260101)
    truth = _walkers(rng, n)
    # Not too easy: the walkers stray from a straight line nearly as far as the recorded
    # crowds. 90th percentiles at 2 s and 4.8 s: 0.61 m and 1.92 m on ETH hotel, 0.68 m and
    # 2.11 m on UCY zara01, 0.51-0.55 m and 1.98-2.11 m here (seeds 0-7); required: 0.45 m
    # and 1.7 m, about 3/4 and 9/10 of ETH hotel's.
    q90 = np.percentile(_straying(truth), 90, axis=0)
    assert q90[4] >= 0.45 and q90[11] >= 1.7
    inside = _inside(truth, rng)
    # The walkers are independent; one walker's frames are not (a turn puts several out), but
    # a mean of frames in [0, 1] has a variance of at most p (1 - p). So at a true rate p the
    # fraction over n walkers has a standard error of at most sqrt(p (1 - p) / n): 0.0067 for
    # p = 0.9 and 0.0089 for p = 0.8 with n = 2000. Three of them are allowed below the
    # stated rate (a true rate that meets it fails with probability ~0.1 %).
    def floor(p):
        return p - 3.0 * math.sqrt(p * (1.0 - p) / n)

    up_to_2s, overall = inside[:, :5].mean(), inside.mean()
    assert up_to_2s >= floor(0.90), up_to_2s  # 0.973 today (0.978-0.983 on seeds 0-7)
    assert overall >= floor(0.80), overall  # 0.837 today (0.841-0.857 on seeds 0-7)


@pytest.mark.parametrize("change", ["veer", "slow"])
def test_a_pedestrian_who_changes_her_mind_within_the_allowance_stays_in_the_disc(change):
    # The coverage above hardly depends on the manoeuvre allowance (without it about 0.96 and
    # 0.83): on those walkers the covariance disc alone meets the stated rate, so the
    # allowance itself is checked here.
    # A track known exactly (zero covariance, going straight at 1.3 m/s): the disc is the
    # manoeuvre allowance alone, a_m tau^2 / 2 with a_m = 0.1 m/s^2 (docs/perception.md,
    # "Tracker settings"), 0.2 m at 2 s. A walker who then changes her mind at 0.1 m/s^2
    # strays at most that far from the straight extrapolation (|dv| <= a_m tau), so she stays
    # in the disc up to the last knot (4 s, 0.8 m; beyond it the disc stays constant). She
    # veers (a circle at v omega = 0.1 m/s^2) or slows down at 0.1 m/s^2 (on the disc's edge).
    t0, v, a_m = 2.0, 1.3, 0.1
    est = TrackEstimate("p", t0, np.array([1.0, 2.0, v, 0.0, 0.0]), np.zeros((5, 5)),
                        np.array([1.0, 0.0]), 0.25, t0, 40)
    pred = ConstantTwistPredictor(use_announced=False).predict(UncertaintyModel().observations([est]))[0]
    ts = t0 + np.linspace(0.0, 4.0, 401)
    tau = ts - t0
    if change == "veer":
        truth = UnicycleMotion(1.0, 2.0, 0.0, v, a_m / v, start_time=t0).positions(ts)
    else:
        truth = np.column_stack([1.0 + v * tau - 0.5 * a_m * tau**2, np.full_like(tau, 2.0)])
    gap = np.hypot(*(truth - pred.positions(ts)).T)
    assert np.all(gap <= 0.5 * a_m * tau**2 + 1e-9)  # the claim on the walker itself
    assert gap[-1] > 0.7  # she does leave the straight line
    extra = pred.growth.at(ts)
    out = gap > extra + 1e-9
    assert not out.any(), (f"outside the disc from {tau[out][0]:.2f} s on, "
                           f"by up to {np.max(gap - extra):.3f} m")
