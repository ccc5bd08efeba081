"""Crowd-navigation metrics of a run, computed exactly from the executed motion.

Between two simulation steps the robot's and each obstacle's centres move on straight chords
(the simulator's collision test uses the same chords; across a jump of an open track, a chord
to it and one from it: :func:`~anyplan.simulation.contact.step_pieces`), so their separation is
``|d0 + dv s|`` on each chord, a quadratic under the root, and both metrics are closed form:

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

from anyplan.simulation.contact import step_pieces
from anyplan.world.motion import Motion
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
        jumped = None
        if o.motion.may_jump:  # the steps across a jump: their chords before and after it
            p = np.array(p, dtype=float)  # (step_pieces sets a jump's end at the step's end)
            jumped = _jump_chords(o.motion, tr, p)
        d0 = tr[:-1, 1:3] - p[:-1]
        dv = (tr[1:, 1:3] - p[1:]) - d0            # change of the separation over the step
        a_lo, a_hi = o.motion.span
        s0 = np.clip((a_lo - t0) / h, 0.0, 1.0)     # the part of each step where it exists
        s1 = np.clip((a_hi - t0) / h, 0.0, 1.0)
        ok = (t1 >= a_lo) & (t0 <= a_hi)  # the step meets the span (touching counts)
        of_step = np.arange(len(t0))  # the step of each chord
        if jumped is not None and len(jumped[0]):
            steps, rows, jd0, jdv, js0, js1 = jumped
            ok[steps] = False  # the straight chord across a jump is not the motion: its pieces
            of_step = np.concatenate([of_step, rows])
            d0, dv = np.vstack([d0, jd0]), np.vstack([dv, jdv])
            s0, s1 = np.concatenate([s0, js0]), np.concatenate([s1, js1])
            ok = np.concatenate([ok, np.ones(len(rows), dtype=bool)])
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
        st = of_step[idx]
        lo_all.append(np.column_stack([st, t0[st] + lo[idx] * h[st]]))
        hi_all.append(t0[st] + hi[idx] * h[st])
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


def _jump_chords(motion: Motion, tr: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, ...]:
    """The steps of ``tr`` across which ``motion`` jumps, and the chords of its motion on them
    as the simulator tests them (:func:`step_pieces`, which also sets ``p`` [m] at a step's end
    to the position after a jump there): (steps, the step of each chord, d0, dv, s0, s1), the
    separation ``d0 + dv s`` [m] for s in [s0, s1] (fractions of the step)."""
    t = tr[:, 0]
    n = len(t) - 1
    cand: set[int] = set()
    for jt in motion.jump_times(float(t[0]) - 1e-6, float(t[-1]) + 1e-6):
        # the steps that may report this jump (Motion.jumps: each end moved 1 ns later)
        cand.update(range(int(np.searchsorted(t[1:], jt - 1e-6)),
                          min(int(np.searchsorted(t[:-1], jt + 1e-6, side="right")), n)))
    steps, rows, d0, dv, s0, s1 = [], [], [], [], [], []
    lo, hi = motion.span
    for i in sorted(cand):
        ta, tb = float(t[i]), float(t[i + 1])
        jumps = motion.jumps(ta, tb)
        if not jumps:
            continue
        steps.append(i)
        e0, e1 = max(ta, lo) - ta, min(tb, hi) - ta
        if e1 < e0:
            continue
        h = tb - ta
        a, b = tr[i, 1:3], tr[i + 1, 1:3]
        for q0, w, ps0, ps1 in step_pieces(jumps, p[i], p, i + 1, ta, h, e0, e1):
            # the robot at a + (b - a) s / h, the obstacle at q0 + w s (s [s] into the step)
            rows.append(i)
            d0.append(a - q0)
            dv.append((b - a) - w * h)
            s0.append(ps0 / h)
            s1.append(ps1 / h)
    return (np.asarray(steps, dtype=np.int64), np.asarray(rows, dtype=np.int64),
            np.reshape(d0, (-1, 2)), np.reshape(dv, (-1, 2)), np.asarray(s0, dtype=float),
            np.asarray(s1, dtype=float))
