"""Greedy selection, dynamic window, velocity space, goal velocities and configuration."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.baselines.dovs import (
    DOVSConfig,
    DOVSConfigError,
    DOVSModel,
    DOVSPlanner,
    DynamicWindow,
    ModelObstacle,
    goal_velocities,
    in_velocity_space,
    ray_v_max,
    select_greedy,
    vs_v_max,
)
from anyplan.prediction.base import ObstacleObservation
from anyplan.world.robot import RobotLimits

CFG = DOVSConfig()


def _random_scene(rng: np.random.Generator, n: int) -> list[ModelObstacle]:
    out = []
    for i in range(n):
        kind = "circular" if rng.random() < 0.4 else "linear"
        x, y = rng.uniform(-3.0, 3.0, 2)
        v = rng.uniform(0.1, 0.5)
        w = 0.0
        if kind == "circular":
            w = math.copysign(v / rng.uniform(0.8, 3.0), rng.uniform(-1, 1))
        out.append(ModelObstacle(f"o{i}", kind, float(x), float(y), float(rng.uniform(-math.pi, math.pi)),
                                 float(v), float(w), float(rng.uniform(0.4, 0.8))))
    return out


def _random_velocity(rng: np.random.Generator, cfg: DOVSConfig) -> tuple[float, float]:
    w = float(rng.uniform(-cfg.omega_max, cfg.omega_max))
    return float(rng.uniform(0.0, 1.0) * vs_v_max(w, cfg)), w


def test_table1_defaults() -> None:
    assert (CFG.v_max, CFG.omega_max, CFG.a_v, CFG.a_omega) == (0.4, 0.4, 0.4, 1.0)
    assert CFG.d_safe == 0.1 and CFG.safety_factor == 1.1 and CFG.control_period_s == 0.2
    assert CFG.effective_static_range == pytest.approx(0.1 + 0.4 ** 2 / (2 * 0.4))


@pytest.mark.parametrize(("field", "value"), [
    ("v_max", 0.0), ("a_v", -1.0), ("time_horizon_s", math.inf), ("d_safe", -0.1),
    ("merge", "max"), ("velocity_space", "circle"), ("dw_samples", 20), ("dw_samples", 2.5),
    ("safety_factor", 0.9), ("static_range", 0.0), ("brake_along_ray", 1),
])
def test_config_rejects_bad_values_naming_the_field(field: str, value: object) -> None:
    # The robot's limits are one record; DOVS names them v_max, a_v (= a_max), ...
    limit = {"v_max": "v_max", "a_v": "a_max"}.get(field)
    kw = {"limits": RobotLimits(**{limit: value})} if limit else {field: value}
    with pytest.raises(DOVSConfigError, match=f"DOVSConfig.{field}"):
        DOVSConfig(**kw)


def test_chosen_command_is_free_whenever_a_free_window_sample_exists() -> None:
    rng = np.random.default_rng(21)
    n_greedy = n_fallback = 0
    for _ in range(150):
        model = DOVSModel(_random_scene(rng, int(rng.integers(1, 5))), CFG)
        v0, w0 = _random_velocity(rng, CFG)
        win = DynamicWindow.around(v0, w0, CFG)
        target = _random_velocity(rng, CFG)
        sel = select_greedy(win, target, model.forbidden, CFG)
        cv, cw = win.candidates(CFG)
        free = ~model.forbidden(cv, cw)
        if free.any():
            n_greedy += 1
            assert sel.mode == "greedy" and sel.free
            assert not model.forbidden(np.array([sel.v]), np.array([sel.omega]))[0]
            # ... and it is the free sample nearest to the target.
            d = np.hypot(cv - target[0], cw - target[1])
            assert math.hypot(sel.v - target[0], sel.omega - target[1]) == pytest.approx(d[free].min())
        else:
            n_fallback += 1
            assert sel.mode in ("escape", "stop") and not sel.free
    assert n_greedy > 60 and n_fallback > 0


@pytest.mark.parametrize("shape", ["diamond", "box"])
@pytest.mark.parametrize("vs", ["triangle", "rectangle"])
def test_dynamic_window_and_velocity_space_limits_are_respected(shape: str, vs: str) -> None:
    cfg = DOVSConfig(window_shape=shape, velocity_space=vs, vs_samples=30)
    rng = np.random.default_rng(4)
    dv, dw = cfg.a_v * cfg.control_period_s, cfg.a_omega * cfg.control_period_s
    for _ in range(80):
        v0, w0 = _random_velocity(rng, cfg)
        win = DynamicWindow.around(v0, w0, cfg)
        model = DOVSModel(_random_scene(rng, 3), cfg)
        sel = select_greedy(win, _random_velocity(rng, cfg), model.forbidden, cfg)
        a, b = abs(sel.v - v0) / dv, abs(sel.omega - w0) / dw
        if shape == "diamond":
            assert a + b <= 1.0 + 1e-9
        else:
            assert a <= 1.0 + 1e-9 and b <= 1.0 + 1e-9
        assert in_velocity_space(sel.v, sel.omega, cfg)
        assert sel.v >= 0.0 and abs(sel.omega) <= cfg.omega_max + 1e-12


def test_ray_speed_bound_is_on_the_triangle_border() -> None:
    kappa = np.array([-5.0, -1.0, -0.1, 0.0, 0.3, 2.0])
    v = ray_v_max(kappa, CFG)
    assert np.allclose(v, vs_v_max(kappa * v, CFG))
    assert v[3] == CFG.v_max


def test_goal_velocities() -> None:
    ahead = goal_velocities((10.0, 0.0), CFG)
    assert ahead.mode == "dir_goal" and ahead.target == pytest.approx((CFG.v_max, 0.0))
    near = goal_velocities((1.0, 0.5), CFG)
    assert near.mode == "command_goal"
    v, w = near.target
    assert w / v == pytest.approx(2 * 0.5 / (1.0 ** 2 + 0.5 ** 2))   # on the goal arc
    assert v == pytest.approx(float(vs_v_max(w, CFG)))                 # on the VS border
    behind = goal_velocities((-3.0, -0.1), CFG)
    assert behind.mode == "rotate" and behind.target == (0.0, -CFG.omega_max)
    close = goal_velocities((0.05, 0.0), CFG)
    assert close.mode == "vel_goal" and close.target[0] == pytest.approx(0.05 / CFG.control_period_s)


def test_mirrored_scene_mirrors_the_decision() -> None:
    obs = [ObstacleObservation("a", 0.0, 3.0, 1.0, -1.2, 0.2, 0.0, 0.3),
           ObstacleObservation("b", 0.0, 4.0, -1.5, 2.0, 0.15, -0.1, 0.3)]
    mirrored = [ObstacleObservation(o.name, 0.0, o.x, -o.y, -o.theta, o.v, -o.omega, o.radius) for o in obs]
    p = DOVSPlanner(CFG, (8.0, 0.7))
    q = DOVSPlanner(CFG, (8.0, -0.7))
    d1 = p.decide((0.0, 0.0, 0.0), (0.2, 0.05), obs)
    d2 = q.decide((0.0, 0.0, 0.0), (0.2, -0.05), mirrored)
    assert d1.selection.v == pytest.approx(d2.selection.v)
    assert d1.selection.omega == pytest.approx(-d2.selection.omega)


def test_no_obstacles_heads_for_the_goal() -> None:
    p = DOVSPlanner(CFG, (5.0, 0.0))
    d = p.decide((0.0, 0.0, 0.0), (0.2, 0.0), [])
    assert d.selection.mode == "greedy"
    assert d.selection.v == pytest.approx(0.2 + CFG.a_v * CFG.control_period_s)
    assert d.selection.omega == pytest.approx(0.0)
