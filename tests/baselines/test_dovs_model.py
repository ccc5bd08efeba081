"""The DOVS model is conservative: brute-force simulation finds no collision it misses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.baselines.dovs import (
    DOVSConfig,
    DOVSModel,
    ModelObstacle,
    StaticMap,
    arc_points,
    model_obstacles,
    to_robot_frame,
    to_world_frame,
    vs_grid,
)
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Circle, rectangle
from anyplan.prediction.base import ObstacleObservation
from anyplan.world.robot import RobotLimits

CFG = DOVSConfig()
TS = np.linspace(0.0, CFG.time_horizon_s, 2401)


def _obstacle_path(ob: ModelObstacle, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if ob.kind == "static":
        return np.full_like(t, ob.x), np.full_like(t, ob.y)
    if ob.kind == "linear":
        return ob.x + ob.v * t * math.cos(ob.theta), ob.y + ob.v * t * math.sin(ob.theta)
    r = ob.v / ob.omega
    th = ob.theta + ob.omega * t
    return ob.x + r * (np.sin(th) - math.sin(ob.theta)), ob.y - r * (np.cos(th) - math.cos(ob.theta))


def _robot_paths(v: np.ndarray, w: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Robot-frame positions (n_cmd, n_t) of constant commands."""
    moving = v > 1e-12
    kappa = np.where(moving, w / np.where(moving, v, 1.0), 0.0)
    s = v[:, None] * t[None, :]
    return arc_points(kappa[:, None], s)


def _brute_force_collides(ob: ModelObstacle, paths: tuple[np.ndarray, np.ndarray], t: np.ndarray,
                          shrink: float = 1e-6) -> np.ndarray:
    """Whether each robot path (n_cmd, n_t) comes within the inflated radius of the obstacle."""
    px, py = paths
    ox, oy = _obstacle_path(ob, t)
    d2 = (px - ox[None, :]) ** 2 + (py - oy[None, :]) ** 2
    return np.any(d2 < (ob.radius - shrink) ** 2, axis=1)


def _random_obstacle(rng: np.random.Generator, kind: str) -> ModelObstacle:
    x, y = rng.uniform(-4.0, 4.0, 2)
    th = rng.uniform(-math.pi, math.pi)
    v = rng.uniform(0.1, 0.6)
    R = rng.uniform(0.3, 0.9)
    w = 0.0
    if kind == "circular":
        w = rng.uniform(-0.6, 0.6)
        if abs(v / w) <= R + 0.05:
            w = math.copysign(v / (R + rng.uniform(0.05, 3.0)), w if w != 0.0 else 1.0)
    return ModelObstacle("o", kind, float(x), float(y), float(th), float(v), float(w), float(R))


@pytest.mark.parametrize("kind", ["linear", "circular"])
@pytest.mark.parametrize("merge", ["hull", "union"])
def test_no_collision_missed_against_brute_force(kind: str, merge: str) -> None:
    rng = np.random.default_rng(11 if kind == "linear" else 12)
    cfg = DOVSConfig(merge=merge)
    gv, gw = vs_grid(cfg, 24)
    paths = _robot_paths(gv, gw, TS)
    pairs = colliding = missed = 0
    for _ in range(120):
        ob = _random_obstacle(rng, kind)
        forb = DOVSModel([ob], cfg).forbidden(gv, gw)
        hit = _brute_force_collides(ob, paths, TS)
        pairs += len(gv)
        colliding += int(hit.sum())
        missed += int(np.sum(hit & ~forb))
    assert pairs > 20000 and colliding > 1000  # the sample exercises many conflicts
    assert missed == 0


def test_no_collision_missed_for_curved_rays_near_obstacles() -> None:
    """Tight arcs that re-enter a band (the authors' first-crossing rule misses these)."""
    rng = np.random.default_rng(5)
    cfg = DOVSConfig(limits=RobotLimits(v_max=0.7, omega_max=3.14), time_horizon_s=10.0,
                     velocity_space="rectangle")
    gv, gw = vs_grid(cfg, 24)
    ts = np.linspace(0.0, cfg.time_horizon_s, 4001)
    paths = _robot_paths(gv, gw, ts)
    missed = colliding = 0
    for _ in range(80):
        ob = _random_obstacle(rng, "linear" if rng.random() < 0.5 else "circular")
        ob = ModelObstacle(ob.name, ob.kind, ob.x * 0.5, ob.y * 0.5, ob.theta, ob.v, ob.omega, ob.radius)
        forb = DOVSModel([ob], cfg).forbidden(gv, gw)
        hit = _brute_force_collides(ob, paths, ts)
        colliding += int(hit.sum())
        missed += int(np.sum(hit & ~forb))
    assert colliding > 500
    assert missed == 0


def test_several_obstacles_forbidden_set_is_union_superset() -> None:
    rng = np.random.default_rng(3)
    gv, gw = vs_grid(CFG, 20)
    for _ in range(30):
        obs = [_random_obstacle(rng, k) for k in ("linear", "circular", "linear")]
        hull = DOVSModel(obs, CFG).forbidden(gv, gw)
        union = DOVSModel(obs, DOVSConfig(merge="union")).forbidden(gv, gw)
        each = np.any([DOVSModel([o], CFG).forbidden(gv, gw) for o in obs], axis=0)
        assert np.array_equal(union, each)
        assert np.all(hull >= union)


def test_static_disc_braking_rule_matches_first_contact() -> None:
    """A static disc forbids exactly the speeds above sqrt(2 a (s_hit - d_safe)) on each ray."""
    rng = np.random.default_rng(8)
    cfg = DOVSConfig(brake_along_ray=False)
    for _ in range(20):
        x, y = rng.uniform(-1.0, 1.0, 2)
        ob = ModelObstacle("s", "static", float(x), float(y), 0.0, 0.0, 0.0, float(rng.uniform(0.3, 0.6)))
        w = rng.uniform(-0.4, 0.4, 50)
        v = rng.uniform(0.01, 1.0, 50) * (cfg.v_max * (1 - np.abs(w) / cfg.omega_max))
        forb = DOVSModel([ob], cfg).forbidden(v, w)
        # Brute force first contact along each arc, fine arc-length sampling.
        s = np.linspace(0.0, 1.0, 20001)
        px, py = arc_points((w / v)[:, None], s[None, :])
        inside = np.hypot(px - ob.x, py - ob.y) < ob.radius
        s_hit = np.where(inside.any(axis=1), s[np.argmax(inside, axis=1)], np.inf)
        v_stop = np.sqrt(2.0 * cfg.a_v * np.maximum(s_hit - cfg.d_safe, 0.0))
        clear = np.abs(v - v_stop) > 2e-3  # away from the boundary (sampling resolution)
        assert np.array_equal(forb[clear], (v > v_stop)[clear])


def test_static_map_sphere_tracing_is_a_lower_bound_on_contact() -> None:
    shapes = [rectangle((2.0, 0.4), (0.6, 0.6), 0.3), Circle((0.9, -0.8), 0.3)]
    cfg = DOVSConfig(static_range=5.0)
    smap = StaticMap(shapes, (-3.0, -3.0, 3.0, 3.0), cfg)
    exact = ObstacleSet(shapes, bounds=(-3.0, -3.0, 3.0, 3.0))
    rng = np.random.default_rng(2)
    pose = (0.1, 0.05, 0.2)
    kappa = rng.uniform(-2.0, 2.0, 300)
    s_hit = smap.first_contact(pose, kappa, np.full(300, 4.0))
    s = np.linspace(0.0, 4.0, 8001)
    px, py = arc_points(kappa[:, None], s[None, :])
    wx, wy, _ = to_world_frame(pose, px, py)
    clear = exact.clearances(np.column_stack([wx.ravel(), wy.ravel()])).reshape(wx.shape)
    touching = clear < cfg.static_clearance
    true_hit = np.where(touching.any(axis=1), s[np.argmax(touching, axis=1)], np.inf)
    assert np.all(s_hit <= true_hit + 1e-3)           # never later than the real contact
    fin = np.isfinite(true_hit)
    assert np.all(np.abs(s_hit[fin] - true_hit[fin]) < 5e-3)  # and converged where it matters
    assert fin.sum() > 100


def test_robot_frame_round_trip_and_classification() -> None:
    pose = (2.0, -1.0, 0.7)
    x, y, th = to_robot_frame(pose, 3.0, 0.5, 1.0)
    X, Y, TH = to_world_frame(pose, x, y, th)
    assert np.allclose([X, Y, TH], [3.0, 0.5, 1.0])
    obs = [
        ObstacleObservation("lin", 0.0, 3.0, 0.5, 1.0, 0.2, 0.0, 0.3),
        ObstacleObservation("circ", 0.0, 3.0, 0.5, 1.0, 0.2, 0.1, 0.3),
        ObstacleObservation("slow", 0.0, 3.0, 0.5, 1.0, 0.05, 0.0, 0.3),
        ObstacleObservation("spin", 0.0, 3.0, 0.5, 1.0, 0.2, 1.0, 0.3),
        ObstacleObservation("back", 0.0, 3.0, 0.5, 1.0, -0.2, 0.0, 0.3),
    ]
    m = {o.name: o for o in model_obstacles(pose, obs, CFG)}
    assert m["lin"].kind == "linear" and m["circ"].kind == "circular"
    assert m["slow"].kind == "static" and m["spin"].kind == "static"
    assert m["spin"].radius == pytest.approx(0.2 + CFG.inflated_radius(0.3))
    assert m["lin"].radius == pytest.approx(0.3 + 1.1 * 0.3)
    assert m["back"].v == pytest.approx(0.2) and math.isclose(
        (m["back"].theta - m["lin"].theta) % (2 * math.pi), math.pi)


def test_standing_robot_in_the_way_is_forbidden_to_stop() -> None:
    # An obstacle 2 m ahead driving at the robot: staying still collides; so does creeping.
    ob = ModelObstacle("o", "linear", 2.0, 0.0, math.pi, 0.4, 0.0, 0.63)
    model = DOVSModel([ob], CFG)
    assert model.origin_threat
    assert model.forbidden(np.array([0.0, 0.05]), np.array([0.3, 0.0])).all()
    # The same obstacle driving away is no threat.
    away = ModelObstacle("o", "linear", 2.0, 0.0, 0.0, 0.4, 0.0, 0.63)
    assert not DOVSModel([away], CFG).origin_threat
