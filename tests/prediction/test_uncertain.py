"""Uncertain predictions: growing discs, the certified check that honours them, and the coverage
of the uncertainty radius on recorded pedestrians."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.experiments.crowds import read_obsmat
from anyplan.experiments.prediction_eval import evaluate_prediction, trajectory_samples
from anyplan.prediction.base import ConstantTwistPredictor, PredictedObstacle, RadiusGrowth
from anyplan.prediction.collision import first_collision, min_separation
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import Tracker, TrackerConfig
from anyplan.prediction.uncertain import UncertaintyModel
from anyplan.world.motion import UnicycleMotion
from tests.conftest import CROWDS


def test_radius_growth_is_monotone_capped_and_its_rate_bounds_the_slope():
    g = RadiusGrowth(2.0, np.array([0.0, 0.5, 1.0, 2.0]), np.array([0.1, 0.3, 0.2, 0.9]))
    assert np.array_equal(g.values, [0.1, 0.3, 0.3, 0.9])  # made nondecreasing
    t = np.linspace(0.0, 6.0, 6001)
    e = g.at(t)
    assert np.all(np.diff(e) >= 0.0) and e[0] == 0.1 and e[-1] == 0.9 == g.max_extra
    assert np.max(np.diff(e) / np.diff(t)) <= g.rate + 1e-9
    assert g.rate == pytest.approx(0.6)


def test_growths_built_row_by_row_at_once_equal_the_growths_built_one_by_one():
    rng = np.random.default_rng(3)
    taus = np.array([0.0, 0.5, 1.0, 2.0, 4.0])
    values = rng.normal(0.3, 0.4, (6, len(taus)))  # negative and decreasing entries too
    t0 = list(rng.uniform(0.0, 10.0, 6))
    for g, t, row in zip(RadiusGrowth.rows(t0, taus, values), t0, values, strict=True):
        one = RadiusGrowth(t, taus, row)
        assert g.t0 == one.t0 and g.rate == one.rate and g.max_extra == one.max_extra
        assert np.array_equal(g.taus, one.taus) and np.array_equal(g.values, one.values)
    assert RadiusGrowth.rows([], taus, np.zeros((0, len(taus)))) == []
    with pytest.raises(ValueError, match="increasing"):
        RadiusGrowth.rows([0.0], taus[::-1], values[:1])
    with pytest.raises(ValueError, match="as long as"):
        RadiusGrowth.rows([0.0, 1.0], taus, values[:1])


def test_a_capped_growth_equals_the_growth_built_from_the_capped_values():
    rng = np.random.default_rng(4)
    taus = np.array([0.0, 0.5, 1.0, 2.0, 4.0])
    for row in rng.normal(0.3, 0.4, (8, len(taus))):
        g = RadiusGrowth(1.5, taus, row)
        for cap in (0.0, 0.1, 0.3, float(g.max_extra), 2.0):
            c = g.capped(cap)
            ref = RadiusGrowth(1.5, taus, np.minimum(g.values, cap))
            assert c.t0 == ref.t0 and c.rate == ref.rate and c.max_extra == ref.max_extra
            assert np.array_equal(c.taus, ref.taus) and np.array_equal(c.values, ref.values)
            assert c.max_extra <= cap
    with pytest.raises(ValueError, match="cap"):
        RadiusGrowth(0.0, taus, taus).capped(-0.1)


def test_uncertainty_grows_with_the_horizon_and_with_occlusion():
    tr = Tracker(TrackerConfig(sigma_m=0.05))
    rng = np.random.default_rng(0)
    for k in range(30):
        t = 0.1 * k
        z = np.array([t, 0.0]) + rng.normal(0, 0.05, 2)
        tr.update(t, [Detection("a", t, *z, 0.3)])
    unc = UncertaintyModel()
    fresh = unc.extras(tr.estimates(2.9))[0]
    coasted = unc.extras(tr.estimates(3.9))[0]
    assert np.all(np.diff(fresh) >= 0.0) and fresh[-1] > fresh[0]
    assert np.all(coasted >= fresh - 1e-12) and coasted[0] > fresh[0]
    assert np.all(fresh <= unc.cap_m)


def _brute_first(traj_pos, obst: PredictedObstacle, r, t0, t1):
    t = np.linspace(t0, t1, 400001)
    d = np.hypot(*(traj_pos(t) - obst.positions(t)).T) - r - obst.radius_at(t)
    hit = np.flatnonzero(d <= 0.0)
    return None if len(hit) == 0 else t[hit[0]]


class _Line:
    def __init__(self, p, v, t0=0.0, t1=10.0):
        self.p, self.v, self.t_start, self.t_end = np.asarray(p, float), np.asarray(v, float), t0, t1
        self.max_speed = float(np.hypot(*v))

    def positions(self, t):
        t = np.clip(np.asarray(t, float), self.t_start, self.t_end) - self.t_start
        return self.p + t[:, None] * self.v


def test_certified_check_honours_the_growing_radius():
    rng = np.random.default_rng(3)
    for _ in range(40):
        robot = _Line(rng.uniform(0, 2, 2), rng.uniform(-1, 1, 2))
        mo = UnicycleMotion(*rng.uniform(2, 6, 2), rng.uniform(-3, 3), rng.uniform(0.2, 1.5),
                            rng.uniform(-0.5, 0.5))
        g = RadiusGrowth(0.0, np.array([0.0, 1.0, 2.0, 4.0]), np.sort(rng.uniform(0, 1.2, 4)))
        ob = PredictedObstacle("o", 0.3, mo, g)
        hit = first_collision(robot, [ob], 0.3, t_from=0.0, t_until=10.0, tol=1e-4)
        truth = _brute_first(robot.positions, ob, 0.3, 0.0, 10.0)
        if truth is None:
            # not missed; a grazing approach may be reported (conservative), never a far miss
            assert hit is None or min_separation(robot, [ob], 0.3, 0.0, 10.0, 0.001) < 1e-2
        else:
            assert hit is not None and hit.t <= truth + 1e-4 and hit.t >= truth - 1e-3
            assert hit.obstacle_radius == pytest.approx(0.3 + g.at(hit.t))
        # without growth, the fixed disc is met later or not at all
        plain = first_collision(robot, [PredictedObstacle("o", 0.3, mo)], 0.3, t_from=0.0,
                                t_until=10.0)
        if plain is not None:
            assert hit is not None and hit.t <= plain.t + 1e-9


def test_predictor_carries_the_growth_to_the_planners():
    tr = Tracker()
    for k in range(10):
        tr.update(0.1 * k, [Detection("a", 0.1 * k, 0.1 * k, 0.0, 0.3)])
    obs = UncertaintyModel().observations(tr.estimates(0.9))
    p = ConstantTwistPredictor().predict(obs)[0]
    assert p.growth is obs[0].growth and p.radius == 0.3
    assert p.max_radius > p.radius and float(p.radius_at(0.9)) < p.max_radius


@pytest.mark.skipif(not CROWDS.is_dir(), reason="shared crowd recordings not present")
@pytest.mark.parametrize("scene", ["eth_hotel", "ucy_zara01"])
def test_uncertainty_radius_covers_recorded_pedestrians_at_the_stated_rate(scene):
    # ETH/UCY protocol: 8 frames observed, 12 predicted (2.5 Hz); 5 cm detection noise.
    samples = trajectory_samples(read_obsmat(CROWDS / f"{scene}_obsmat.txt"), stride=8)
    r = evaluate_prediction(samples, noise_m=0.05, seed=1)
    cov = np.array(r.coverage_by_horizon)
    # stated in docs/perception.md: >= 90 % up to 2 s (5 frames), >= 80 % over the 4.8 s
    assert cov[:5].mean() >= 0.90 and r.coverage >= 0.80
    # the tracker is at least as accurate as the constant-velocity baseline on noisy positions
    assert r.ade_imm <= r.ade_cv and r.fde_imm <= r.fde_cv


def test_manoeuvre_allowance_covers_an_obstacle_that_turns_within_it():
    # An exact pose and twist (perception 'twist'); the obstacle really turns at a lateral
    # acceleration v * omega = 1.2 m/s^2 <= the allowance 1.5 m/s^2: the grown disc around the
    # straight extrapolation contains its true centre at every time until the cap (1 m).
    from anyplan.prediction.base import ObstacleObservation, manoeuvre_growth

    t0, v, w = 3.0, 1.5, 0.8
    truth = UnicycleMotion(2.0, 1.0, 0.3, v, w, start_time=t0)
    seen = ObstacleObservation("a", t0, 2.0, 1.0, 0.3, v, 0.0, 0.25)  # seen going straight
    p = ConstantTwistPredictor(manoeuvre_accel=1.5, manoeuvre_cap_m=1.0).predict([seen])[0]
    assert p.growth is not None and p.growth.max_extra == pytest.approx(1.0)
    ts = np.linspace(t0, t0 + 4.0, 401)
    gap = np.hypot(*(truth.positions(ts) - p.positions(ts)).T)
    extra = p.growth.at(ts)
    inside = gap <= extra + 1e-12
    t_cap = t0 + math.sqrt(2.0 * 1.0 / 1.5)
    assert inside[ts <= t_cap].all()
    assert not inside.all()  # beyond the cap it may leave: the cap is a real limit
    # without the allowance: no growth; an announced motion is never grown; nor a tracked disc
    assert ConstantTwistPredictor().predict([seen])[0].growth is None
    announced = ObstacleObservation("b", t0, 2.0, 1.0, 0.3, v, 0.0, 0.25, truth)
    assert ConstantTwistPredictor(manoeuvre_accel=1.5).predict([announced])[0].growth is None
    g = manoeuvre_growth(t0, 1.0, 0.5)
    tracked = ObstacleObservation("c", t0, 2.0, 1.0, 0.3, v, 0.0, 0.25, None, g)
    assert ConstantTwistPredictor(manoeuvre_accel=1.5).predict([tracked])[0].growth is g
    with pytest.raises(ValueError, match="manoeuvre_accel"):
        ConstantTwistPredictor(manoeuvre_accel=-1.0)
