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
    if len(hit):
        assert tc is not None and tc <= t[hit[0]] + 1e-9
        # Never earlier than the true contact (within one 1e-4 s grid step of the first sampled
        # hit) by more than the search tolerance (1e-6 s).
        assert tc >= t[hit[0]] - 1e-4 - 1e-6 - 1e-9
    if tc is not None:
        dc = np.hypot(*(robot(np.array([tc])) - m.positions(np.array([tc])))[0])
        if dc > R + L * 1e-6 + 1e-9:
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
