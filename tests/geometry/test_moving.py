"""Moving-disc contact: closed forms and certified search against dense sampling."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import (
    closest_approach,
    closest_approach_straight,
    first_contact,
    first_contact_straight,
)
from anyplan.geometry.moving import MAX_EVALUATIONS
from anyplan.world.motion import UnicycleMotion

f = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(px=f, py=f, ux=f, uy=f, qx=f, qy=f, wx=f, wy=f, R=st.floats(0.1, 1.5))
def test_straight_first_contact_matches_sampling(px, py, ux, uy, qx, qy, wx, wy, R):
    p, u, q, w = map(np.array, ([px, py], [ux, uy], [qx, qy], [wx, wy]))
    t = np.linspace(0.0, 5.0, 50001)
    d = np.hypot(*((p + np.outer(t, u)) - (q + np.outer(t, w))).T)
    hit = np.nonzero(d <= R)[0]
    tc = first_contact_straight(p, u, q, w, R, 0.0, 5.0)
    _tm, dm = closest_approach_straight(p, u, q, w, 0.0, 5.0)
    assert dm <= d.min() + 1e-9
    assert abs(dm - d.min()) <= np.hypot(*(u - w)) * 1e-4 + 1e-9
    if len(hit):
        assert tc is not None
        assert tc <= t[hit[0]] + 1e-9
        assert tc >= t[hit[0]] - 1e-4 - 1e-9
    elif tc is not None:
        # Sampling may step over a graze; the exact contact must then be real.
        pc = p + u * tc - (q + w * tc)
        assert np.hypot(*pc) <= R + 1e-6


@settings(max_examples=60, deadline=None)
@given(x0=f, y0=f, th=st.floats(-3.2, 3.2), v=st.floats(0.05, 0.5), om=st.floats(-0.8, 0.8),
       px=f, py=f, ux=st.floats(-0.5, 0.5), uy=st.floats(-0.5, 0.5), R=st.floats(0.2, 1.0))
def test_certified_first_contact_circular_never_late(x0, y0, th, v, om, px, py, ux, uy, R):
    m = UnicycleMotion(x0, y0, th, v, om)
    p, u = np.array([px, py]), np.array([ux, uy])

    def robot(t):
        return p + np.outer(t, u)

    L = v + float(np.hypot(ux, uy))
    tc = first_contact(robot, m.positions, L, R, 0.0, 20.0, tol=1e-6)
    t = np.linspace(0.0, 20.0, 200001)
    d = np.hypot(*(robot(t) - m.positions(t)).T)
    hit = np.nonzero(d <= R)[0]
    dc = (None if tc is None else
          float(np.hypot(*(robot(np.array([tc])) - m.positions(np.array([tc])))[0])))
    if len(hit):
        assert tc is not None and dc is not None and tc <= t[hit[0]] + 1e-9
        # Never earlier than the true contact (within one 1e-4 s grid step of the first sampled
        # hit) by more than the search tolerance (1e-6 s), unless the distance there is already
        # within L x tol of the contact distance: a graze the search cannot tell from a contact,
        # reported as one (conservative, as documented; a tangent contact at t = 2 s is reported
        # 0.5 ms early, where the distance is 4e-8 m above R).
        assert tc >= t[hit[0]] - 1e-4 - 1e-6 - 1e-9 or dc <= R + L * 1e-6 + 1e-9
    if tc is not None and dc is not None and dc > R + L * 1e-6 + 1e-9:
        # A conservative early answer: only when the distance grazes the contact distance
        # for long (the evaluation budget of a near-plateau ran out).
        assert d[t >= tc].min() - R < 20.0 * L * 8 / MAX_EVALUATIONS + 1e-3
    _tm, dm = closest_approach(robot, m.positions, L, 0.0, 20.0, tol=1e-6)
    # Certified to within L * tol of the true minimum, which sampling can only overestimate.
    assert dm <= d.min() + L * 1e-6 + 1e-9
    assert dm >= d.min() - L * 1e-4 - 1e-9


def test_plateau_terminates_and_stays_conservative():
    """An obstacle circling a parked robot keeps a constant distance: the searches must end."""
    m = UnicycleMotion(1.0, 0.0, np.pi / 2, 0.5, 0.5)  # circle of radius 1 around the origin

    def robot(t):
        return np.zeros((len(t), 2))

    # Contact distance a hair below the constant distance: a true answer is "no contact", which
    # takes ~T L / gap evaluations to certify; past the budget a contact is reported early.
    tc = first_contact(robot, m.positions, 0.5, 1.0 - 1e-7, 0.0, 20.0, tol=1e-6)
    assert tc is None or 0.0 <= tc <= 20.0
    assert first_contact(robot, m.positions, 0.5, 0.9, 0.0, 20.0) is None
    assert first_contact(robot, m.positions, 0.5, 1.0 + 1e-9, 0.0, 20.0) == 0.0
    _, d = closest_approach(robot, m.positions, 0.5, 0.0, 20.0, tol=1e-6)
    assert abs(d - 1.0) < 1e-9


def _closest_one_by_one(pos_a, pos_b, rel_speed_bound, t0, t1, tol=1e-6):
    """closest_approach evaluating interval by interval (its former loop): the reference."""
    L = max(rel_speed_bound, 1e-12)

    def dist(t):
        d = pos_a(t) - pos_b(t)
        return np.hypot(d[:, 0], d[:, 1])

    ts = np.linspace(t0, t1, 129)
    fs = dist(ts)
    i = int(np.argmin(fs))
    best_t, best = float(ts[i]), float(fs[i])
    intervals = [(ts[j], ts[j + 1], fs[j], fs[j + 1]) for j in range(128)]
    evals = 129
    while intervals and evals < MAX_EVALUATIONS:
        nxt = []
        for a, b, fa, fb in intervals:
            if 0.5 * (fa + fb - L * (b - a)) >= best - L * tol or b - a <= tol:
                continue
            mids = np.linspace(a, b, 5)
            fm = dist(mids[1:-1])
            evals += 3
            j = int(np.argmin(fm))
            if fm[j] < best:
                best, best_t = float(fm[j]), float(mids[1 + j])
            vals = np.concatenate([[fa], fm, [fb]])
            nxt.extend((mids[m], mids[m + 1], vals[m], vals[m + 1]) for m in range(4))
        intervals = nxt
    return best_t, best


@settings(max_examples=60, deadline=None)
@given(x0=f, y0=f, th=st.floats(-3.2, 3.2), v=st.floats(0.05, 1.5), om=st.floats(-0.8, 0.8),
       mid=st.floats(3.0, 7.0), t0=st.floats(0.0, 5.0), span=st.floats(0.5, 12.0))
def test_closest_approach_batched_levels_answer_as_one_by_one(x0, y0, th, v, om, mid, t0, span):
    # Each refinement level is evaluated in one call: the same time and distance, bit for bit,
    # as evaluating every interval on its own, along a planned (spline) motion.
    from anyplan.geometry import ObstacleSet
    from anyplan.trajectory.motion import plan_motion
    from anyplan.world import RobotSpec, RobotState

    spec = RobotSpec(start=(1.0, 5.0, 0.0), goal=(14.0, 5.0))
    robot = plan_motion(np.array([[1.0, 5.0], [7.5, mid], [14.0, 5.0]]), spec,
                        RobotState(1.0, 5.0, 0.0), ObstacleSet([], bounds=(0.0, 0.0, 15.0, 11.0)),
                        0.0)
    m = UnicycleMotion(x0 + 7.0, y0 + 5.0, th, v, om)
    L = float(robot.max_speed) + v
    assert closest_approach(robot.positions, m.positions, L, t0, t0 + span) == \
        _closest_one_by_one(robot.positions, m.positions, L, t0, t0 + span)
