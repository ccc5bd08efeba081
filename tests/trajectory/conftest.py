"""Helpers for the trajectory tests: random static worlds with a known free polyline."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.geometry import Circle, ObstacleSet, rectangle
from anyplan.world import RobotSpec


def make_world(seed: int, radius: float = 0.3, tight: bool = True):
    """A 12 m x 8 m arena, a random polyline path, and obstacles that keep it free.

    Obstacles are accepted when the polyline keeps a clearance of at least ``radius + gap``
    from them; with ``tight`` some gaps are only 2 cm, so the spline must be repaired.

    Returns:
        (obstacles, path (N, 2), spec)
    """
    rng = np.random.default_rng(seed)
    w, h = 12.0, 8.0
    n = int(rng.integers(3, 7))
    xs = np.sort(rng.uniform(1.0, w - 1.0, n))
    xs[0], xs[-1] = 1.0, w - 1.0
    ys = rng.uniform(1.0, h - 1.0, n)
    path = np.column_stack([xs, ys])
    shapes = []
    walls = ObstacleSet([], bounds=(0.0, 0.0, w, h))
    assert walls.path_free(path, radius + 0.05)
    tries = 0
    while len(shapes) < 10 and tries < 2000:
        tries += 1
        c = rng.uniform([0.0, 0.0], [w, h])
        if rng.random() < 0.5:
            s = Circle(c, float(rng.uniform(0.2, 0.9)))
        else:
            s = rectangle(c, tuple(rng.uniform(0.3, 1.6, 2)), float(rng.uniform(0, np.pi)))
        gap = 0.02 if (tight and rng.random() < 0.5) else 0.15
        one = ObstacleSet([s])
        clr = one.segments_clearance(path[:-1], path[1:]).min()
        if clr >= radius + gap:
            # pull tight obstacles toward the path until the gap is exactly `gap`
            if tight and gap < 0.1:
                d = clr - radius - gap
                p = path[np.argmin(np.hypot(*(path - c).T))]
                u = (p - c) / max(np.hypot(*(p - c)), 1e-9)
                moved = Circle(c + u * d, s.radius) if isinstance(s, Circle) else None
                if moved is not None and ObstacleSet([moved]).segments_clearance(
                        path[:-1], path[1:]).min() >= radius + 0.005:
                    s = moved
            shapes.append(s)
    obs = ObstacleSet(shapes, bounds=(0.0, 0.0, w, h))
    heading = float(np.arctan2(*(path[1] - path[0])[::-1]))
    spec = RobotSpec(start=(1.0, float(ys[0]), heading), goal=(w - 1.0, float(ys[-1])), radius=radius,
                     v_max=0.4, omega_max=0.4, a_max=0.4, alpha_max=1.0)
    return obs, path, spec


@pytest.fixture
def world_factory():
    return make_world


def check_limits(traj, spec, dt: float = 1e-3) -> dict:
    """Assert every limit of ``spec`` on a dense time grid of ``traj`` (1 ms by default).

    Finite differences over dt bound the mean derivative over each step, so a violation of
    |dv/dt| <= a_max or |d omega/dt| <= alpha_max anywhere inside a step of 1 ms shows up unless
    it is shorter than the step and compensated inside it.

    Returns:
        The observed maxima.
    """
    t = np.arange(traj.t_start, traj.t_end + 1.0, dt)
    x, y, th, v, w = traj.sample(t)
    acc = np.diff(v) / dt
    alpha = np.diff(w) / dt
    tol = 1e-6
    out = {"v": float(v.max()), "omega": float(np.abs(w).max()), "a": float(np.abs(acc).max()),
           "alpha": float(np.abs(alpha).max())}
    assert v.min() >= -1e-12
    assert out["v"] <= spec.v_max * (1 + tol), out
    assert out["omega"] <= spec.omega_max * (1 + tol), out
    assert out["a"] <= spec.a_max * (1 + tol), out
    assert out["alpha"] <= spec.alpha_max * (1 + tol), out
    # kinematic consistency: the pose moves as the unicycle with (v, omega)
    dp = np.hypot(np.diff(x), np.diff(y)) / dt
    vm = 0.5 * (v[1:] + v[:-1])
    assert np.max(np.abs(dp - vm)) < 1e-3 * spec.v_max + 1e-6
    dth = np.angle(np.exp(1j * np.diff(th))) / dt
    wm = 0.5 * (w[1:] + w[:-1])
    assert np.max(np.abs(dth - wm)) < 2e-3 * spec.omega_max + 1e-6
    assert np.max(dp) <= traj.max_speed + 1e-9
    # at rest and held after the end
    xe, ye, the, ve, we = traj.sample(np.array([traj.t_end, traj.t_end + 5.0]))
    assert ve.max() == 0.0 and np.abs(we).max() == 0.0
    assert xe[0] == xe[1] and ye[0] == ye[1] and the[0] == the[1]
    return out


@pytest.fixture
def limits_checker():
    return check_limits
