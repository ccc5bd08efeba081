"""anyplan/Nav-v0: the Gymnasium checker, the documented reward and termination, seeding, the same
physics as simulate(), and a policy benchmarked beside seq-bitstar on the same scenarios."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

import anyplan.gym  # noqa: E402, F401 - registers the environment
from anyplan.agents import make_agent  # noqa: E402
from anyplan.agents.policy import ObservationEncoder, PolicyAgent  # noqa: E402
from anyplan.experiments.runner import PlannerSpec, run_bench  # noqa: E402
from anyplan.simulation import simulate  # noqa: E402
from anyplan.world import load_scenario, scenario_from_dict  # noqa: E402
from tests.conftest import small_scenario_dict  # noqa: E402
from tests.gym.policies import go_to_goal  # noqa: E402


@pytest.mark.parametrize("scenario", ["paper-3", ["paper-1", "paper-2"], "random"])
def test_passes_the_gymnasium_checker(scenario):
    env = gymnasium.make("anyplan/Nav-v0", scenario=scenario, max_obstacles=4)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped, skip_render_check=True)
    assert not [str(w.message) for w in caught]  # not even a warning
    obs, _ = env.reset(seed=1)
    assert obs.shape == (8 + 7 * 4,) and obs.dtype == np.float32


def test_observation_is_padded_and_nearest_first():
    env = gymnasium.make("anyplan/Nav-v0", scenario="paper-3", max_obstacles=5).unwrapped
    obs, _ = env.reset(seed=0)
    sc = load_scenario("paper-3")
    r = sc.robot
    assert obs[:2] == pytest.approx([r.goal[0] - r.start[0], r.goal[1] - r.start[1]])
    slots = obs[8:].reshape(5, 7)
    assert list(slots[:, 0]) == [1, 1, 1, 0, 0] and not slots[3:].any()  # 3 obstacles, 2 padding slots
    d = np.hypot(slots[:3, 1], slots[:3, 2])
    assert np.all(np.diff(d) >= 0)
    assert sorted(slots[:3, 6]) == pytest.approx(sorted(o.radius for o in sc.moving_obstacles))


def test_stepping_the_env_is_simulate_with_the_policy_agent():
    sc = load_scenario("paper-1")
    env = gymnasium.make("anyplan/Nav-v0", scenario=sc, max_obstacles=3).unwrapped
    obs, _ = env.reset(seed=0)
    done, rewards = False, []
    while not done:
        obs, rew, term, trunc, info = env.step(go_to_goal(obs))
        rewards.append(rew)
        done = term or trunc
    ref = simulate(sc, PolicyAgent(go_to_goal, max_obstacles=3), seed=0)
    got = info["result"]
    assert got.trajectory == ref.trajectory and got.status == ref.status == info["status"]
    # The go-to-goal policy hits paper-1's crossing obstacle: a collision ends the episode (terminated).
    assert ref.collision and term and not trunc
    assert rewards[-1] < -9.0  # the collision penalty
    # Progress reward: the sum telescopes to the distance gained, less the time penalty.
    tr = np.asarray(ref.trajectory)
    g = np.asarray(sc.robot.goal)
    gained = np.hypot(*(tr[0, 1:3] - g)) - np.hypot(*(tr[-1, 1:3] - g))
    assert sum(rewards) == pytest.approx(gained - 0.01 * len(rewards) - 10.0, abs=1e-9)


def test_goal_terminates_with_the_goal_reward_and_the_time_limit_truncates(tmp_path):
    free = scenario_from_dict(small_scenario_dict(static_obstacles=[], dynamic_obstacles=[]))
    env = gymnasium.make("anyplan/Nav-v0", scenario=free).unwrapped
    obs, _ = env.reset(seed=0)
    while True:
        obs, rew, term, trunc, info = env.step(go_to_goal(obs))
        if term or trunc:
            break
    assert term and not trunc and info["status"] == "reached" and rew > 9.0
    env = gymnasium.make("anyplan/Nav-v0", scenario=free, time_limit=1.0).unwrapped
    env.reset(seed=0)
    n = 0
    while True:
        _, _, term, trunc, info = env.step(np.zeros(2, dtype=np.float32))
        n += 1
        if term or trunc:
            break
    assert trunc and not term and info["status"] == "timeout" and n == 20
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(2))


def test_seeded_resets_pick_the_same_worlds():
    a = gymnasium.make("anyplan/Nav-v0", scenario="random").unwrapped
    b = gymnasium.make("anyplan/Nav-v0", scenario="random").unwrapped
    oa, _ = a.reset(seed=5)
    ob, _ = b.reset(seed=5)
    assert np.array_equal(oa, ob) and a.scenario.content_hash() == b.scenario.content_hash()
    b.reset(seed=6)
    assert b.scenario.content_hash() != a.scenario.content_hash()


def test_a_policy_is_benchmarked_beside_seq_bitstar(tmp_path):
    scenarios = [load_scenario("paper-1"), load_scenario("paper-2")]
    planners = [PlannerSpec("policy", {"policy": "tests.gym.policies:go_to_goal"}),
                PlannerSpec("seq-bitstar", make_agent("seq-bitstar").deterministic_settings)]
    s = run_bench(scenarios, planners, 1, tmp_path / "b.db", jobs=1, progress=False)
    assert s.finished == 4 and s.errors == 0
    import sqlite3

    con = sqlite3.connect(tmp_path / "b.db")
    rows = con.execute("SELECT p.name, r.outcome FROM runs r "
                       "JOIN plannerConfigs p ON r.plannerid = p.id").fetchall()
    con.close()
    assert sorted(n for n, _ in rows) == ["policy", "policy", "seq-bitstar", "seq-bitstar"]
    assert all(oc == "reached" for n, oc in rows if n == "seq-bitstar")
    assert all(oc in ("reached", "collision", "timeout") for n, oc in rows if n == "policy")


def test_policy_agent_refuses_a_bad_policy():
    with pytest.raises(ValueError, match="module:function"):
        make_agent("policy", policy="nocolon")
    with pytest.raises(ValueError, match="cannot load"):
        make_agent("policy", policy="tests.gym.policies:nothing")
    assert ObservationEncoder((0, 0), 0).size == 8


def test_an_execution_error_is_seeded_with_the_episode():
    def positions(noise: tuple[float, float], seed: int) -> np.ndarray:
        env = gymnasium.make("anyplan/Nav-v0", scenario="paper-1", actuation_noise=noise).unwrapped
        env.reset(seed=seed)
        action = np.array([0.4, 0.1], dtype=np.float32)  # full speed (the P3-DX), turning
        for _ in range(40):
            env.step(action)
        return np.array([env.sim.state.x, env.sim.state.y])

    exact = positions((0.0, 0.0), 3)
    noisy = positions((0.05, 0.05), 3)
    assert np.array_equal(noisy, positions((0.05, 0.05), 3))  # the same seed, the same error
    assert not np.array_equal(noisy, positions((0.05, 0.05), 4))
    assert 0.0 < np.hypot(*(noisy - exact)) < 0.5


def test_a_localization_error_moves_the_observed_pose_not_the_robot():
    def episode(noise: tuple[float, float], seed: int) -> tuple[np.ndarray, np.ndarray]:
        env = gymnasium.make("anyplan/Nav-v0", scenario="paper-1", localization_noise=noise).unwrapped
        obs, _ = env.reset(seed=seed)
        action = np.array([0.4, 0.1], dtype=np.float32)
        for _ in range(20):
            obs, *_ = env.step(action)
        return obs[6:8].astype(float), np.array([env.sim.state.x, env.sim.state.y])

    (seen0, at0), (seen1, at1) = episode((0.0, 0.0), 3), episode((0.05, 0.02), 3)
    assert np.array_equal(at0, at1)  # open loop: the robot drives the same way
    assert np.allclose(seen0, at0, atol=1e-6)  # exact: the vector holds the true position
    assert 1e-3 < np.hypot(*(seen1 - at1)) < 0.3  # off by the error (float32 rounding aside)
    assert np.array_equal(seen1, episode((0.05, 0.02), 3)[0])  # seeded with the episode
