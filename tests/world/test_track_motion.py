"""The ``track`` motion: exact at every sample, linear in between, present only within its span."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.errors import ScenarioError
from anyplan.world import scenario_from_dict
from anyplan.world.motion import TrackMotion
from tests.conftest import small_scenario_dict


def test_positions_exact_at_samples_and_linear_between():
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.1, 1.0, 30)) + 2.0
    xy = rng.uniform(0, 10, (30, 2))
    m = TrackMotion(np.column_stack([t, xy]))
    assert np.array_equal(m.positions(t), xy)
    for i in range(29):
        for f in (0.25, 0.5, 0.9):
            tt = t[i] + f * (t[i + 1] - t[i])
            np.testing.assert_allclose(m.position(tt), xy[i] + f * (xy[i + 1] - xy[i]), atol=1e-12)
    assert m.span == (t[0], t[-1])
    assert m.exists(t[0]) and m.exists(t[-1]) and not m.exists(t[0] - 1e-6)
    assert not m.exists(t[-1] + 1e-6)
    seg = np.hypot(*np.diff(xy, axis=0).T) / np.diff(t)
    assert m.max_speed == pytest.approx(seg.max())
    *_, v, w = m.state(0.5 * (t[3] + t[4]))
    assert v == pytest.approx(seg[3]) and w == 0.0
    assert m.state(t[-1] + 1.0)[3] == 0.0


def test_no_loop_unlike_waypoints():
    m = TrackMotion(np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]]))
    assert np.array_equal(m.position(5.0), [1.0, 0.0])  # stays at its last sample (and is gone)


def test_track_in_a_scenario_round_trips():
    d = small_scenario_dict(dynamic_obstacles=[
        {"name": "P", "type": "track", "radius": 0.25, "samples": [[1, 2, 2], [2, 3, 2.5]]}])
    sc = scenario_from_dict(d)
    again = scenario_from_dict(sc.to_dict())
    assert again.content_hash() == sc.content_hash()
    assert isinstance(again.moving_obstacles[0].motion, TrackMotion)


@pytest.mark.parametrize(("samples", "msg"), [
    ([[0, 1, 1]], "at least 2"),
    ([[0, 1, 1], [0, 2, 2]], "increase strictly"),
    ([[0, 1, 1], [1, 2]], r"samples\[1\]"),
])
def test_bad_track_names_the_field(samples, msg):
    d = small_scenario_dict(dynamic_obstacles=[{"type": "track", "radius": 0.25, "samples": samples}])
    with pytest.raises(ScenarioError, match=msg) as ei:
        scenario_from_dict(d, "x.yaml")
    assert ei.value.field.startswith("dynamic_obstacles[0].samples")
