"""Late departures (``ReferenceBuilder.departing``): the drive from rest is planned once per path
and squares and moved in time for other delays; the motions are those planned afresh."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.geometry import ObstacleSet, rectangle
from anyplan.trajectory.kinds import SegmentKind
from anyplan.trajectory.motion import plan_motion as _plan_motion
from anyplan.trajectory.reference import ReferenceBuilder
from anyplan.world import RobotSpec, RobotState

SPEC = RobotSpec(start=(1.0, 1.0, 0.0), goal=(8.5, 5.0), radius=0.3, v_max=1.0, omega_max=1.5,
                 a_max=1.0, alpha_max=3.0)
ROOM = ObstacleSet([rectangle((4.0, 2.0), (1.0, 1.0))], bounds=(0.0, 0.0, 10.0, 6.0))
STATES = {
    "at rest": RobotState(1.0, 1.0, 0.0),
    "driving": RobotState(1.0, 1.0, 0.4, 0.8, 0.2),
    "spinning": RobotState(1.0, 1.0, 2.5, 0.0, -1.2),
}
PATHS = {
    "ahead": np.array([[1.0, 1.0], [8.0, 1.0], [8.0, 4.5]]),
    "behind": np.array([[1.0, 1.0], [1.0, 5.0], [8.5, 5.0]]),  # a turn in place first
}


def _same_motion(a, b) -> None:
    assert [type(s) for s in a.segments] == [type(s) for s in b.segments]
    assert [(s.t0, s.t1) for s in a.segments] == [(s.t0, s.t1) for s in b.segments]
    assert (a.kind, a.feasible, a.certified_free, a.departs_s, a.max_speed) == \
        (b.kind, b.feasible, b.certified_free, b.departs_s, b.max_speed)
    assert a.lower_bound_s == b.lower_bound_s
    t = np.linspace(a.t_start - 0.5, a.t_end + 0.5, 1501)
    for u, v in zip(a.sample(t), b.sample(t), strict=True):
        assert np.array_equal(u, v)
    # positions alone (each segment's xy) are the samples' x and y, bit for bit
    x, y = a.sample(t)[:2]
    assert a.positions(t).tobytes() == np.column_stack([x, y]).tobytes()


@pytest.mark.parametrize("state", STATES)
@pytest.mark.parametrize("path", PATHS)
@pytest.mark.parametrize("squares", [0, 1])
def test_later_departures_are_the_motions_planned_afresh(state, path, squares, monkeypatch):
    from anyplan.trajectory import reference

    builder = ReferenceBuilder(spec=SPEC, obstacles=ROOM)
    shapes = [rectangle((6.0, 3.2), (0.6, 0.6))][:squares]
    t0 = 12.345
    pts = PATHS[path]
    delays = (0.5, 3.0, 0.25, 17.75)
    fresh = [builder.departing(STATES[state], t0)(pts, shapes, d) for d in delays]
    planned = []
    monkeypatch.setattr(reference, "plan_motion",
                        lambda *a, **k: planned.append(a[4]) or _plan_motion(*a, **k))
    model = builder.departing(STATES[state], t0)
    for d, want in zip(delays, fresh, strict=True):
        m = model(pts, shapes, d)
        _same_motion(m, want)
        hold = [s for s in m.segments if s.kind == SegmentKind.HOLD]
        assert len(hold) == 1 and hold[0].t1 - hold[0].t0 == pytest.approx(d)
        assert m.departs_s == hold[0].t1
    assert len(planned) == 1  # the drive from rest was planned once, for the first delay
    # another path (a new array), other squares or departing at once plan again
    model(pts.copy(), shapes, 0.5)
    model(pts, [*shapes, rectangle((2.0, 5.0), (0.4, 0.4))], 0.5)
    model(pts, shapes, 0.0)
    assert len(planned) == 4
