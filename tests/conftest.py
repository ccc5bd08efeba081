"""Shared fixtures: headless plotting, small scenarios."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import settings

# CI replays the same examples on every run (derandomised); locally each run explores new ones.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

os.environ.setdefault("MPLBACKEND", "Agg")


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
