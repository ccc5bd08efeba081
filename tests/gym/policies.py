"""Policies on the observation vector of anyplan/Nav-v0 (importable by benchmark workers)."""

from __future__ import annotations

import math

import numpy as np


def go_to_goal(obs: np.ndarray) -> tuple[float, float]:
    """Turn toward the goal and drive at it (ignores the obstacles): a policy a learner could find."""
    dx, dy, c, s = (float(v) for v in obs[:4])
    err = math.atan2(dy, dx) - math.atan2(s, c)
    err = math.atan2(math.sin(err), math.cos(err))
    v = 0.0 if abs(err) > 0.3 else min(0.4, 0.5 * math.hypot(dx, dy))
    return v, max(-0.4, min(0.4, 1.5 * err))
