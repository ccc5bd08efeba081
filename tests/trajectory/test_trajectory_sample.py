"""Trajectory.sample finds the segment that serves all times from their earliest and latest,
and the segments' slices of times in order: bit for bit the answer of finding every time's
segment (searchsorted), on random trajectories of several segments and random times (sorted or
not, on segment starts, after the end, NaN)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.trajectory import Trajectory, plan_motion
from anyplan.trajectory.motion import swerve_trajectory
from anyplan.world import RobotSpec, RobotState

SPEC = RobotSpec(start=(0.0, 0.0, 0.0), goal=(9.0, 0.0), radius=0.3, v_max=1.0, omega_max=1.5,
                 a_max=1.0, alpha_max=3.0)


def _reference(tr: Trajectory, t: np.ndarray) -> list[np.ndarray]:
    """Every time's segment by searchsorted, each segment sampled at its own times."""
    flat = np.asarray(t, dtype=float).ravel()
    segs = tr.segments
    idx = np.clip(np.searchsorted(np.array([s.t0 for s in segs]), flat, side="right") - 1, 0,
                  len(segs) - 1)
    out = [np.empty(flat.shape) for _ in range(5)]
    for k in np.unique(idx):
        m = idx == k
        for o, val in zip(out, segs[k].sample(flat[m]), strict=True):
            o[m] = val
    after = flat >= segs[-1].t1
    out[3][after] = 0.0
    out[4][after] = 0.0
    return out


@settings(max_examples=40, deadline=None)
@given(kind=st.sampled_from(["turn+curve", "swerve"]), seed=st.integers(0, 10_000),
       n=st.integers(0, 40), order=st.sampled_from(["sorted", "random", "starts", "starts sorted"]),
       nan=st.booleans())
def test_sample_equals_the_time_by_time_segment_lookup(kind, seed, n, order, nan):
    rng = np.random.default_rng(seed)
    free = ObstacleSet([])
    if kind == "swerve":
        state = RobotState(0.0, 0.0, 0.0, float(rng.uniform(0.0, 1.0)), float(rng.uniform(-1, 1)))
        tr = swerve_trajectory(state, SPEC, free, SPEC.radius, 1.0, float(rng.uniform(0.2, 1.0)),
                               float(rng.uniform(-1.5, 1.5)), 1.0)
    else:
        a = float(rng.uniform(-math.pi, math.pi))
        state = RobotState(0.0, 0.0, a, 0.0, 0.0)
        tr = plan_motion(np.array([[0.0, 0.0], [4.0, float(rng.uniform(-3.0, 3.0))]]), SPEC, state,
                         free, 1.0)
    lo, hi = tr.t_start - 0.5, tr.t_end + 0.5
    if order.startswith("starts"):  # on the segments' starts and ends, and between
        t = np.concatenate([[s.t0 for s in tr.segments], [tr.t_end], rng.uniform(lo, hi, n)])
        if order == "starts sorted":
            t = np.sort(t)
    else:
        t = rng.uniform(lo, hi, n)
        if order == "sorted":
            t = np.sort(t)
    if nan and len(t):
        t[int(rng.integers(len(t)))] = math.nan
    got = tr.sample(t)
    want = _reference(tr, t)
    assert len(tr.segments) >= 2 or kind == "turn+curve"
    for g, w in zip(got, want, strict=True):
        assert g.shape == t.shape and g.tobytes() == w.tobytes()
    p = tr.positions(t)
    assert p.shape == (len(t), 2) and p[:, 0].tobytes() == want[0].tobytes()
    assert p[:, 1].tobytes() == want[1].tobytes()


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 60),
       order=st.sampled_from(["sorted", "random", "reversed"]))
def test_curve_sampling_from_the_last_interval_is_each_time_alone(seed, n, order):
    """The curve's sampling starts each lookup from the previous time's interval: bit for bit
    what each time sampled alone gives (a lookup from scratch), whatever the order; x and y
    alone are the full sample's."""
    from anyplan.trajectory.trajectory import CurveSegment

    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform((0.5, -2.0), (3.0, 2.0), (int(rng.integers(2, 6)), 2)), axis=0)
    tr = plan_motion(np.vstack([[0.0, 0.0], pts]), SPEC, RobotState(0.0, 0.0, 0.3, 0.5, 0.0),
                     ObstacleSet([]), 0.0)
    seg = next(s for s in tr.segments if isinstance(s, CurveSegment))
    tau = rng.uniform(-0.5, seg.t1 - seg.t0 + 0.5, n)
    tau = {"sorted": np.sort(tau), "reversed": np.sort(tau)[::-1], "random": tau}[order]
    got = seg.curve.sample_profile(seg._prof, tau)
    alone = np.column_stack([seg.curve.sample_profile(seg._prof, tau[j:j + 1]) for j in range(n)])
    assert got.tobytes() == alone.tobytes()
    assert seg.curve.sample_profile(seg._prof, tau, False).tobytes() == got[:2].tobytes()
