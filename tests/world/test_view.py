"""The sensor's field of view: range, line of sight past static obstacles, and discs in the
way, against brute force."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.geometry.shapes import rectangle
from anyplan.world.view import FieldOfView

EMPTY = ObstacleSet([])


def _hidden_brute(o, c, r, i):
    """Disc j hides centre i: nearer to o than c_i, and some point of the segment o -> c_i
    (dense) within r_j of c_j (the sampled distance is an upper bound of the exact one)."""
    s = np.linspace(0.0, 1.0, 20001)[:, None]
    seg = o + s * (c[i] - o)
    out = []
    for j in range(len(c)):
        if j == i or np.hypot(*(c[j] - o)) >= np.hypot(*(c[i] - o)):
            continue
        out.append(np.hypot(*(seg - c[j]).T).min() - r[j])
    return out


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(0.1, 0.6)),
                min_size=1, max_size=7))
def test_a_disc_in_the_way_hides_exactly_what_brute_force_says(discs):
    c = np.array([[x, y] for x, y, _ in discs])
    r = np.array([q for _, _, q in discs])
    o = np.array([0.3, -0.2])
    got = FieldOfView(None, EMPTY).expected(tuple(o), c, r)
    for i in range(len(c)):
        gaps = _hidden_brute(o, c, r, i)
        if any(g < -1e-6 for g in gaps):
            assert not got[i]          # clearly in the way
        elif all(g > 1e-3 for g in gaps):
            assert got[i]              # clearly clear (the dense segment is within 0.5 mm)


def test_range_and_walls():
    wall = ObstacleSet([rectangle((2.25, 0.0), (0.5, 2.0))])
    view = FieldOfView(6.0, wall)
    c = np.array([[1.0, 0.0], [3.0, 0.0], [3.0, 2.0], [7.0, 0.0], [0.0, -5.9]])
    assert view.visible((0.0, 0.0), c).tolist() == [True, False, True, False, True]
    # the same mask when nothing is in the way of one another
    assert view.expected((0.0, 0.0), c, np.full(5, 0.1)).tolist() == [True, False, True, False, True]
    # a disc hides what is behind it, not what is in front of it
    two = np.array([[1.0, 0.0], [1.8, 0.02]])
    assert FieldOfView(None, EMPTY).expected((0.0, 0.0), two, np.array([0.3, 0.3])).tolist() \
        == [True, False]
    assert FieldOfView(None, EMPTY).expected((0.0, 0.0), np.zeros((0, 2)), np.zeros(0)).shape == (0,)


def test_an_occupancy_maps_walls_occlude(tmp_path):
    from anyplan.world.scenario import load_scenario
    from anyplan.world.view import field_of_view
    from tests.world.test_occupancy import write_pgm, write_yaml

    px = np.full((10, 10), 255)
    px[2:8, 5] = 0  # a wall x in [2.5, 3] m, y in [1, 4] m (the image's top row is y = 4.5-5)
    write_pgm(tmp_path / "m.pgm", px)
    write_yaml(tmp_path / "m.yaml", "m.pgm", resolution=0.5)
    f = tmp_path / "s.yaml"
    f.write_text("name: s\nstatic_map: m.yaml\nrobot: {start: [1, 2.5, 0], goal: [4, 0.5], "
                 "radius: 0.2, v_max: 1, omega_max: 1, a_max: 1, alpha_max: 1}\n"
                 "sensing: {mode: tracked}\n")
    view = field_of_view(load_scenario(f))
    c = np.array([[4.0, 2.5], [2.0, 2.5], [3.2, 4.9], [4.0, 0.25]])
    # behind the wall, in front of it, past its top end (the line crosses x = 2.5 at y = 4.14),
    # behind its lower part
    assert view.visible((1.0, 2.5), c).tolist() == [False, True, True, False]
    assert FieldOfView(None, EMPTY).visible((1.0, 2.5), c).all()


def test_a_margin_keeps_centres_near_the_views_edges_out_of_what_is_expected():
    wall = ObstacleSet([rectangle((2.25, 0.0), (0.5, 2.0))])  # x in [2, 2.5], y in [-1, 1]
    view = FieldOfView(6.0, wall)
    o = (0.0, 0.0)
    # clear by far; 5.9 m away: in range, not by 0.2 m; a line of sight passing 0.09 m from the
    # wall's corner
    c = np.array([[3.0, 3.0], [0.0, 5.9], [4.0, 2.2]])
    assert view.visible(o, c).tolist() == [True, True, True]
    assert view.visible(o, c, 0.2).tolist() == [True, False, False]
    # a disc whose edge passes 0.1 m from the line of sight hides the other only with a margin
    two = np.array([[1.0, 0.4], [3.0, 0.0]])
    assert FieldOfView(None, EMPTY).expected(o, two, np.array([0.3, 0.3])).tolist() == [True, True]
    assert FieldOfView(None, EMPTY).expected(o, two, np.array([0.3, 0.3]), 0.2).tolist() \
        == [True, False]
