"""st-bitstar's fallback ranking: the approach speed counts every obstacle met within the
reaction time, not only the first; the staged ranking picks what ranking every candidate by
its whole key picks."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from anyplan.prediction import PredictedObstacle
from anyplan.prediction.base import RadiusGrowth
from anyplan.prediction.collision import predict_collisions
from anyplan.trajectory import plan_motion
from anyplan.world import RobotState, UnicycleMotion
from tests.agents.test_spacetime_agent import _agent_in_empty_room


def _grazed_then_blocked(agent):
    """A robot driving east at 1 m/s, a drive straight on and a brake; A crosses its path from
    the north and meets every candidate first, beside the robot (no approach); B stands on the
    drive's line, 1.2 m ahead, where braking stops short of it."""
    spec, m = agent.spec, agent.guard.config.margin
    state = RobotState(2.0, 3.0, 0.0, 1.0, 0.0)
    drive = plan_motion(np.array([[2.0, 3.0], [6.0, 3.0]]), spec, state, agent.obstacles, 0.0,
                        allow_turn=False)
    brake = next(tr for kind, tr in agent._ranker().candidates(0.0, state, [])
                 if kind == "brake")
    reach = spec.radius + 0.25 + m
    a = PredictedObstacle("A", 0.25, UnicycleMotion(2.1, 3.0 + reach + 0.5, -math.pi / 2, 2.5))
    b = PredictedObstacle("B", 0.25, UnicycleMotion(3.2, 3.0, 0.0, 0.0))
    return spec, drive, brake, a, b


def test_a_drive_grazed_first_then_into_a_standing_obstacle_ranks_as_driving_into_it():
    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    spec, drive, brake, a, b = _grazed_then_blocked(agent)
    ranker = agent._ranker()
    hits = predict_collisions(drive, [a, b], spec.radius, t_from=0.0, t_until=ranker.react_s,
                              margin=agent.guard.config.margin, sample_dt=0.02)
    assert [h.obstacle for h in hits] == ["A", "B"]  # A first, then B, both within react_s
    assert drive.state(hits[1].t).v > 0.5  # driving into B
    # A alone: met beside the robot, no approach; with B the drive's approach is B's
    k_alone, _ = agent._fallback_rank(drive, 0.0, [a], [a])
    k_drive, _ = agent._fallback_rank(drive, 0.0, [a, b], [a, b])
    assert k_alone[4] == 0.0
    assert k_drive[4] <= -0.5
    # braking, struck by A only (at rest or slowing beside it), now ranks before driving on
    assert predict_collisions(brake, [b], spec.radius, t_from=0.0, t_until=5.0,
                              margin=agent.guard.config.margin, sample_dt=0.02) == []
    k_brake, _ = agent._fallback_rank(brake, 0.0, [a, b], [a, b])
    assert k_brake[:4] == k_drive[:4]
    assert k_brake > k_drive


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 8), v0=st.floats(0.0, 0.8),
       grow=st.booleans(), passive=st.booleans())
def test_staged_ranking_picks_what_ranking_every_candidate_by_its_whole_key_picks(seed, n, v0,
                                                                                 grow, passive):
    # best_fallback and freer_evasion compute each part of a candidate's key only when it can
    # still decide (the lead parts, the first four, then the approach, then the clearance):
    # the same choice, key and clearance as FallbackRanker.rank on every candidate, and the
    # same answer of freer_evasion as comparing its motion's whole key with the best one.
    from anyplan.agents.evasion import _best_ranked, freer_evasion
    from anyplan.agents.safety import reachable_discs

    agent = _agent_in_empty_room(v_max=1.0, omega_max=1.5, a_max=1.0, alpha_max=3.0)
    rng = np.random.default_rng(seed)
    growth = (RadiusGrowth(0.0, np.array([0.0, 1.0, 2.0, 4.0]), np.array([0.05, 0.3, 0.6, 1.0]))
              if grow else None)
    full = [PredictedObstacle(f"P{k}", 0.25,
                              UnicycleMotion(*rng.uniform([2.0, 0.8], [10.0, 5.2]),
                                             rng.uniform(-math.pi, math.pi), rng.uniform(0.0, 1.2)),
                              growth, until=5.0 if grow else math.inf) for k in range(n)]
    planned = agent._capped(full)
    state = RobotState(6.0, 3.0, float(rng.uniform(-math.pi, math.pi)), v0, 0.0)
    reach = (reachable_discs(full, 0.0, np.array([state.x, state.y]), state.theta, 0.2, 5.0)
             if passive else [])
    ranker = agent._ranker()
    (key, clear), kind, tr = _best_ranked(ranker, 0.0, state, full, planned, None, None, reach)
    cands = ranker.candidates(0.0, state, full)
    ranked = [(ranker.rank(c, 0.0, full, planned, reach), k, c) for k, c in cands]
    (k_all, clear_all), kind_all, tr_all = max(ranked, key=lambda c: c[0][0])
    assert (key, clear, kind) == (k_all, clear_all, kind_all)
    assert tr.t_end == tr_all.t_end and np.array_equal(tr.positions(np.array([0.5])),
                                                       tr_all.positions(np.array([0.5])))
    # freer_evasion, for a motion driving straight on (or the first candidate at rest)
    motion = (plan_motion(np.array([[6.0, 3.0], [6.0 + 3.0 * math.cos(state.theta),
                                                 3.0 + 3.0 * math.sin(state.theta)]]),
                          agent.spec, state, agent.obstacles, 0.0, allow_turn=False)
              if v0 > 0.1 else cands[0][1])
    k_motion, _ = ranker.rank(motion, 0.0, full, planned, reach)
    better = freer_evasion(ranker, 0.0, state, full, planned, motion, reach)
    if k_all[:4] <= k_motion[:4]:
        assert better is None
    else:
        assert better is not None and (better[0], better[2]) == (kind_all, clear_all)
        assert better[1].t_end == tr_all.t_end


def test_the_guard_caps_the_predictions_into_the_planning_s_own_objects():
    # _capped keeps its last answer: the guard, capping the predictions the planning capped,
    # gets the same objects (the contact searches' caches of prediction sets serve both),
    # each equal to one capped anew; other predictions are capped anew.
    agent = _agent_in_empty_room()
    growth = RadiusGrowth(0.0, np.array([0.0, 2.0, 4.0]), np.array([0.0, 1.0, 2.0]))
    full = [PredictedObstacle(f"P{k}", 0.25, UnicycleMotion(2.0 + k, 3.0, 0.5 * k, 0.8),
                              growth if k % 2 else None, until=5.0) for k in range(5)]
    planned = agent._capped(full)
    again = agent._capped(list(full))
    assert again is not planned and all(a is b for a, b in zip(again, planned, strict=True))
    c = agent.plan_extra_m
    for o, p in zip(full, planned, strict=True):
        assert (p is o) == (o.growth is None or o.growth.max_extra <= c)
        if p is not o:
            assert p.growth.values.tobytes() == o.growth.capped(c).values.tobytes()
            assert (p.name, p.radius, p.motion, p.until) == (o.name, o.radius, o.motion, o.until)
    other = [PredictedObstacle("P1", 0.25, full[1].motion, growth, until=5.0)]
    assert agent._capped(other)[0] is not planned[1]
