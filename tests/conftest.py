"""Shared fixtures: headless plotting, small scenarios."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

# CI replays the same examples on every run (derandomised); locally each run explores new ones.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

os.environ.setdefault("MPLBACKEND", "Agg")


def shared_benchmark(*parts: str) -> Path:
    """A file of the benchmark data beside the checkout (``../shared/benchmarks/...``, which the
    package does not ship), found above the tests or the working directory; where it is absent,
    the path it would have (tests that need it skip)."""
    rel = Path("shared", "benchmarks", *parts)
    bases = [*Path(__file__).resolve().parents, *Path.cwd().resolve().parents]
    return next((b / rel for b in bases if (b / rel).exists()), bases[1] / rel)


DYNABARN_WORLDS = shared_benchmark("dynabarn", "worlds.json")
BARN_WORLDS = shared_benchmark("barn", "worlds.json")
CROWDS = shared_benchmark("crowds")
needs_dynabarn = pytest.mark.skipif(not DYNABARN_WORLDS.is_file(),
                                    reason="shared DynaBARN worlds.json not present")


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(0)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import sys

    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


def small_scenario_dict(**overrides):
    """A small valid scenario dictionary (8 m x 6 m, one box, one crossing obstacle)."""
    d = {
        "name": "small",
        "arena": {"width": 8.0, "height": 6.0},
        "robot": {"start": [1.0, 3.0, 0.0], "goal": [7.0, 3.0], "radius": 0.3, "v_max": 0.5,
                  "omega_max": 0.8, "a_max": 0.5, "alpha_max": 1.0},
        "static_obstacles": [{"name": "S1", "type": "rectangle", "center": [4.0, 5.0],
                              "size": [1.0, 1.0], "angle": 0.0}],
        "dynamic_obstacles": [{"name": "D1", "start": [4.0, 0.5, 1.5708], "v": 0.3,
                               "omega": 0.0, "radius": 0.3}],
    }
    for k, v in overrides.items():
        d[k] = v
    return d


def fast_at_a_wall_dict():
    """A robot at (1, 1) heading +x with 2 m/s limits, a wall at x >= 2.2 m, goal (1.5, 7).

    Driving +x at 2 m/s from (1, 1), the robot cannot brake to rest clear of the wall (1 m of
    braking for a 0.34 m disc), and a spline turning off before it starts at about 1 m/s:
    ``plan_motion`` returns that spline as its best effort, ``feasible=False``."""
    return {
        "name": "fast-at-a-wall", "time_limit": 30.0, "arena": {"width": 8.0, "height": 8.0},
        "robot": {"start": [1.0, 1.0, 0.0], "goal": [1.5, 7.0], "radius": 0.34, "v_max": 2.0,
                  "omega_max": 2.0, "a_max": 2.0, "alpha_max": 4.0, "goal_tolerance": 0.5},
        "static_obstacles": [{"name": "W", "type": "rectangle", "center": [2.7, 4.0],
                              "size": [1.0, 8.0], "angle": 0.0}],
        "dynamic_obstacles": [{"name": "D", "start": [6.0, 7.0, 3.14159], "v": 0.0,
                               "radius": 0.3}],
    }


def head_on_corridor_dict(time_limit: float = 20.0):
    """A 1.2 m corridor, 8 m long, and an obstacle (r 0.3 m, 0.3 m/s) coming head-on along it
    from x = 6 m towards a P3DX-like robot (r 0.3 m, 0.4 m/s) at x = 1 m: no motion avoids it."""
    return {
        "name": "corridor", "time_limit": time_limit, "arena": {"width": 8.0, "height": 1.2},
        "robot": {"start": [1.0, 0.6, 0.0], "goal": [7.0, 0.6], "radius": 0.3, "v_max": 0.4,
                  "omega_max": 0.4, "a_max": 0.4, "alpha_max": 1.0, "goal_tolerance": 0.2},
        "static_obstacles": [],
        "dynamic_obstacles": [{"name": "H", "start": [6.0, 0.6, 3.141592653589793], "v": 0.3,
                               "radius": 0.3}],
    }
