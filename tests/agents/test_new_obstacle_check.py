"""A replanning agent checks the motion in use at the first step that shows it an obstacle it
has not seen close enough to meet it before the next periodic check and a brake could end: a
person who steps out 0.7 m ahead of a robot at 1 m/s leaves it no 0.2 s to lose (ETH hotel,
window 7, seed 2: the first check came 0.1 s after the person appeared, the robot stopped 2 mm
too late and was robot-caused). Obstacles first seen farther away wait for the period."""

from __future__ import annotations

import pytest

from anyplan.agents import AGENTS, make_agent
from anyplan.simulation import simulate
from anyplan.world.scenario import scenario_from_dict

#: When each person appears [s]: off the check periods' grid (0.1 s with exact twists).
APPEAR = (2.03, 2.58, 3.13, 3.68)
#: Where: the first three 0.7 m ahead of the robot (at 1 m/s, x = 2.45, 3.0 and 3.55 m when
#: they appear) and 0.85 m beside its lane (y = 2 m), a gap of 0.55 m to its disc, within the
#: 1.1 m it covers in 0.1 s of check period and 1 s of braking; the last one far from it.
PLACES = ((3.15, 2.85), (3.7, 1.15), (4.25, 2.85), (4.0, 10.5))


def _scenario():
    """A service robot crossing a 12 m hall along y = 2 m; four people step out, one after
    the other, and stand there."""
    people = [{"name": f"P{k}", "type": "track", "radius": 0.25,
               "samples": [[t, *PLACES[k]], [30.0, *PLACES[k]]]} for k, t in enumerate(APPEAR)]
    return scenario_from_dict({
        "name": "people-step-out", "time_limit": 30.0, "arena": {"width": 12.0, "height": 12.0},
        "robot": {"start": [1.0, 2.0, 0.0], "goal": [11.0, 2.0], "radius": 0.3, "v_max": 1.0,
                  "omega_max": 1.5, "a_max": 1.0, "alpha_max": 3.0, "goal_tolerance": 0.3},
        "dynamic_obstacles": people, "sensing": {"mode": "twist"}})


@pytest.mark.parametrize("planner", ["st-bitstar", "seq-bitstar"])
def test_an_obstacle_first_seen_is_checked_at_once(planner):
    agent = make_agent(planner, **AGENTS.get(planner).deterministic_settings)
    checks: list[float] = []
    first_seen: dict[str, float] = {}
    free: dict[float, bool] = {}  # per step: a motion in use and none pending
    check, act = agent._check, agent.act

    def recorded_check(obs, preds):
        checks.append(obs.t)
        return check(obs, preds)

    def recorded_act(obs):
        free[obs.t] = agent.trajectory is not None and agent.pending is None
        for o in obs.obstacles:
            first_seen.setdefault(o.name, obs.t)
        return act(obs)

    agent._check, agent.act = recorded_check, recorded_act
    res = simulate(_scenario(), agent, seed=0)
    assert res.status == "reached"
    assert sorted(first_seen) == ["P0", "P1", "P2", "P3"]
    # each appears after a step of the 0.05 s control loop, between two periodic checks
    assert all(first_seen[f"P{k}"] == pytest.approx(t, abs=0.05) for k, t in enumerate(APPEAR))
    # the release of a planned motion may be pending at that step (then the motion taken up
    # is checked at the next one); otherwise the check is at that very step for the near ones
    near = [first_seen[f"P{k}"] for k in range(3)]
    at_once = [t in checks for t in near if free.get(t)]
    assert at_once and all(at_once)
    # and not for the far one, first seen between two periodic checks
    t_far = first_seen["P3"]
    assert free.get(t_far) and t_far not in checks
    assert 0.0 < t_far - max(c for c in checks if c < t_far) < agent._period() - 1e-9
