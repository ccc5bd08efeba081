"""Crowd-navigation metrics of a run, computed exactly from the executed motion.

Between two simulation steps the robot's and each obstacle's centres move on straight chords
(the simulator's collision test uses the same chords), so their separation is
``|d0 + dv s|`` on each step, a quadratic under the root, and both metrics are closed form:

* ``min_distance_to_moving_m``: the smallest surface-to-surface distance [m] between the robot's
  disc and any moving obstacle's disc while it exists (negative: overlap); None without moving
  obstacles;
* ``discomfort_time_s``: the time [s] during which the robot is within ``discomfort_m``
  (0.2 m, CrowdNav's discomfort distance) of at least one moving obstacle's disc. Intervals of
  several obstacles on one step are merged, not added.
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.world.scenario import Scenario

__all__ = ["DISCOMFORT_M", "moving_obstacle_metrics"]

#: CrowdNav's discomfort distance [m] between the robot's and a person's discs.
DISCOMFORT_M = 0.2


def moving_obstacle_metrics(scenario: Scenario, trajectory: np.ndarray,
                            discomfort_m: float = DISCOMFORT_M) -> dict[str, float | None]:
    """``min_distance_to_moving_m`` and ``discomfort_time_s`` of a run.

    Args:
        scenario: The full scenario (true motions).
        trajectory: Rows ``[t, x, y, ...]``, one per step.
        discomfort_m: Discomfort distance [m].
    """
    tr = np.asarray(trajectory, dtype=float)
    movers = scenario.moving_obstacles
    if not movers or len(tr) < 2:
        return {"min_distance_to_moving_m": None, "discomfort_time_s": 0.0}
    t = tr[:, 0]
    t0, t1 = t[:-1], t[1:]
    h = t1 - t0
    r = scenario.robot.radius
    best = math.inf
    lo_all, hi_all = [], []
    for o in movers:
        p = o.motion.positions(t)
        d0 = tr[:-1, 1:3] - p[:-1]
        dv = (tr[1:, 1:3] - p[1:]) - d0            # change of the separation over the step
        a_lo, a_hi = o.motion.span
        s0 = np.clip((a_lo - t0) / h, 0.0, 1.0)     # the part of each step where it exists
        s1 = np.clip((a_hi - t0) / h, 0.0, 1.0)
        ok = (t1 >= a_lo) & (t0 <= a_hi)  # the step meets the span (touching counts)
        if not ok.any():
            continue
        A = np.einsum("ij,ij->i", dv, dv)
        B = 2.0 * np.einsum("ij,ij->i", d0, dv)
        C = np.einsum("ij,ij->i", d0, d0)
        s_min = np.where(A > 0.0, np.clip(-B / (2.0 * np.where(A > 0.0, A, 1.0)), s0, s1), s0)
        dmin = np.sqrt(np.maximum(A * s_min ** 2 + B * s_min + C, 0.0))
        best = min(best, float(dmin[ok].min()) - r - o.radius)
        # separation < R: A s^2 + B s + C - R^2 < 0 on [s0, s1]
        R = r + o.radius + discomfort_m
        Cq = C - R * R
        disc = B * B - 4.0 * A * Cq
        with np.errstate(invalid="ignore", divide="ignore"):
            sq = np.sqrt(np.maximum(disc, 0.0))
            ra = np.where(A > 0.0, (-B - sq) / (2.0 * A), np.where(Cq < 0.0, -np.inf, np.inf))
            rb = np.where(A > 0.0, (-B + sq) / (2.0 * A), np.where(Cq < 0.0, np.inf, -np.inf))
        inside = ok & ((A > 0.0) & (disc > 0.0) | (A <= 0.0) & (Cq < 0.0))
        lo = np.maximum(ra, s0)
        hi = np.minimum(rb, s1)
        inside &= hi > lo
        idx = np.flatnonzero(inside)
        lo_all.append(np.column_stack([idx, t0[idx] + lo[idx] * h[idx]]))
        hi_all.append(t0[idx] + hi[idx] * h[idx])
    total = 0.0
    if lo_all:
        lo = np.vstack(lo_all)
        hi = np.concatenate(hi_all)
        order = np.lexsort((lo[:, 1], lo[:, 0]))
        cur_step, cur_lo, cur_hi = -1, 0.0, 0.0
        for k in order:
            step, a, b = int(lo[k, 0]), lo[k, 1], hi[k]
            if step != cur_step or a > cur_hi:
                total += cur_hi - cur_lo
                cur_step, cur_lo, cur_hi = step, a, b
            else:
                cur_hi = max(cur_hi, b)
        total += cur_hi - cur_lo
    return {"min_distance_to_moving_m": None if best == math.inf else best,
            "discomfort_time_s": float(total)}
