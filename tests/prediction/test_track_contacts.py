"""First contacts with looping tracks (``WaypointMotion``) in closed form on the robot's samples,
against brute force on a fine grid; the jumps of open tracks included."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.geometry import ObstacleSet
from anyplan.prediction import PredictedObstacle, collision
from anyplan.prediction.collision import SampledMotion, first_collision, predict_collisions
from anyplan.trajectory.motion import plan_motion
from anyplan.world import RobotSpec, RobotState, WaypointMotion

SPEC = RobotSpec(start=(1.0, 5.0, 0.0), goal=(14.0, 5.0), v_max=1.0, omega_max=1.0, a_max=0.8)
ARENA = ObstacleSet([], bounds=(0.0, 0.0, 15.0, 11.0))
MOTION = plan_motion(np.array([[1.0, 5.0], [7.5, 6.0], [14.0, 5.0]]), SPEC,
                     RobotState(1.0, 5.0, 0.0), ARENA, 0.0)
DT = 0.02
REACH0 = 0.35  # robot radius 0.3 + margin 0.05


def _brute(obstacle: PredictedObstacle, step: float = 1e-4) -> tuple[float | None, float]:
    """The first grid time at which the robot's samples (linear in between) come within the
    contact distance of the obstacle's true position (its jumps included), and the smallest
    gap [m] on the grid."""
    sm = SampledMotion(MOTION, MOTION.t_start, MOTION.t_end, DT)
    t = np.arange(MOTION.t_start, sm.t_end, step)
    gap = np.hypot(*(sm.positions(t) - obstacle.positions(t)).T) - (
        REACH0 + sm.error_bound + obstacle.radius)
    hit = np.flatnonzero(gap <= 0.0)
    return (float(t[hit[0]]) if len(hit) else None), float(gap.min())


def _track(rng: np.random.Generator, closed: bool) -> WaypointMotion:
    nk = int(rng.integers(2, 7))
    t = np.cumsum(np.r_[0.0, rng.uniform(0.3, 3.0, nk - 1)])
    pts = rng.uniform((0.0, 0.0), (15.0, 11.0), (nk, 2))
    if closed:
        pts[-1] = pts[0]
    return WaypointMotion(np.column_stack([t, pts]))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), closed=st.booleans())
def test_track_contacts_are_the_first_contacts_on_the_samples(seed, closed):
    rng = np.random.default_rng(seed)
    obs = [PredictedObstacle(f"o{i}", float(rng.uniform(0.2, 0.5)), _track(rng, closed))
           for i in range(6)]
    collision._MEMO.clear()
    got = {c.obstacle: c for c in predict_collisions(MOTION, obs, 0.3, margin=0.05,
                                                     sample_dt=DT)}
    for o in obs:
        t_ref, gap = _brute(o)
        hit = got.get(o.name)
        if t_ref is None:
            # no grid time in contact: at most a graze between grid times (gap below L step)
            assert hit is None or gap <= (MOTION.max_speed + o.max_speed) * 1e-4
        else:
            assert hit is not None
            # exact: never after the grid's first contact, and not before the previous grid time
            assert t_ref - 1e-4 - 1e-9 <= hit.t <= t_ref + 1e-9
            np.testing.assert_allclose(hit.robot_position,
                                       MOTION.positions(np.array([hit.t]))[0], atol=1e-12)


def test_an_open_track_that_jumps_onto_the_robot_is_a_contact_at_the_jump():
    # The track starts on the robot's path at (4, 5), leaves it at 5 m/s and walks on at
    # y = 10, then at its period's end jumps back to (4, 5): just ahead of the robot, which is
    # then at x = 3.8. A bound on the track's speed alone does not see the jump.
    ts = np.linspace(MOTION.t_start, MOTION.t_end, 4001)
    x = MOTION.positions(ts)[:, 0]
    period = float(ts[np.argmax(x >= 3.8)])
    track = WaypointMotion(np.array([[0.0, 4.0, 5.0], [1.0, 4.0, 10.0], [period, 6.0, 10.0]]))
    assert track.is_open
    ob = PredictedObstacle("J", 0.3, track)
    for sample_dt in (DT, None):  # closed form on the samples; the certified search
        collision._MEMO.clear()
        hit = first_collision(MOTION, [ob], 0.3, margin=0.05, sample_dt=sample_dt)
        # (the certified search starts 1 ns after a jump: the positions' wrap may lag it)
        assert hit is not None and period - 1e-12 <= hit.t <= period + 2e-9
        np.testing.assert_allclose(hit.obstacle_position, [4.0, 5.0], atol=1e-9)
    t_ref, _ = _brute(ob)
    assert t_ref is not None and period - 1e-4 - 1e-9 <= t_ref <= period + 1e-4


def test_a_first_contact_only_is_the_earliest_of_all():
    rng = np.random.default_rng(7)
    obs = [PredictedObstacle(f"o{i}", 0.3, _track(rng, i % 2 == 0)) for i in range(40)]
    collision._MEMO.clear()
    every = predict_collisions(MOTION, obs, 0.3, margin=0.05, sample_dt=DT)
    collision._MEMO.clear()
    first = first_collision(MOTION, obs, 0.3, margin=0.05, sample_dt=DT)
    assert len(every) > 3 and first is not None
    assert (first.obstacle, first.t) == (every[0].obstacle, every[0].t)
