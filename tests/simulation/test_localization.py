"""The robot's localization error (``SimConfig.localization_sigma_xy``, ``localization_sigma_theta``):
exact when zero, of the stated spread and correlation, seeded; what the robot senses is placed
from its believed pose while announced motions are not; the simulator moves and tests the true
robot; a run records the error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents.base import Agent, Observation
from anyplan.config import SettingError
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.actuation import ACTUATION_STREAM
from anyplan.simulation.localization import LOCALIZATION_STREAM, LOCALIZATION_TAU_S, LocalizationError
from anyplan.simulation.perception import NOISE_STREAM
from anyplan.simulation.simulator import Simulation
from anyplan.world import Command, RobotState, scenario_from_dict
from tests.conftest import small_scenario_dict


class Driver(Agent):
    """Drives a fixed command and records every observation (ignores them)."""

    name = "driver"
    handles_detections = True

    def __init__(self) -> None:
        self.cmd = Command(0.3, 0.1)

    def reset(self, scenario, rng):
        self.log = []

    def act(self, obs: Observation) -> Command:
        self.log.append(obs)
        return self.cmd


def _errors(loc: LocalizationError, n: int, dt: float = 0.05) -> np.ndarray:
    out = []
    for _ in range(n):
        out.append(loc.error.copy())
        loc.step(dt)
    return np.array(out)


def test_the_error_has_the_stated_spread_and_correlation():
    sxy, sth, dt = 0.05, 0.02, 0.05
    e = _errors(LocalizationError(sxy, sth, seed=5), 200_000, dt)
    assert e.std(axis=0) == pytest.approx([sxy, sxy, sth], rel=0.1)
    assert np.all(np.abs(e.mean(axis=0)) < 0.15 * np.array([sxy, sxy, sth]))
    rho = math.exp(-dt / LOCALIZATION_TAU_S)
    lag1 = [np.corrcoef(e[:-1, k], e[1:, k])[0, 1] for k in range(3)]
    assert lag1 == pytest.approx([rho] * 3, abs=0.005)
    # the axes are independent
    assert abs(np.corrcoef(e[:, 0], e[:, 1])[0, 1]) < 0.1


def test_the_error_is_seeded_on_a_stream_of_its_own():
    a, b, c = (_errors(LocalizationError(0.1, 0.1, seed=s), 50) for s in (3, 3, 4))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert LocalizationError(0.1, 0.1, seed=3).record()["seed"] == [3, LOCALIZATION_STREAM]
    assert len({LOCALIZATION_STREAM, ACTUATION_STREAM, NOISE_STREAM}) == 3


@pytest.mark.parametrize("args", [(-0.1, 0.0), (0.1, math.nan), (0.1, 0.1, 1, 0.0)])
def test_bad_spreads_raise(args):
    with pytest.raises(ValueError, match=r"sigma_xy|sigma_theta|tau_s"):
        LocalizationError(*args[:2], seed=0, **({"tau_s": args[3]} if len(args) > 3 else {}))


@pytest.mark.parametrize(("field", "value"), [("localization_sigma_xy", -0.1),
                                              ("localization_sigma_theta", math.inf)])
def test_bad_config_names_the_field(field, value):
    with pytest.raises(SettingError, match=field):
        SimConfig(**{field: value})


def test_sensed_points_move_with_the_believed_pose():
    rng = np.random.default_rng(2)
    for k in range(50):
        loc = LocalizationError(0.2, 0.3, seed=k)
        true = RobotState(*rng.uniform(-5, 5, 2), rng.uniform(-3, 3), 0.4, 0.1)
        est = loc.estimate(true)
        assert (est.v, est.omega) == (true.v, true.omega)
        pts = rng.uniform(-10, 10, (7, 2))
        mapped = loc.to_map(true, pts)
        # the same distances and bearings from the believed pose as from the true one
        d_true = pts - (true.x, true.y)
        d_est = mapped - (est.x, est.y)
        assert np.hypot(*d_est.T) == pytest.approx(np.hypot(*d_true.T), abs=1e-9)
        rel_true = np.arctan2(d_true[:, 1], d_true[:, 0]) - true.theta
        rel_est = np.arctan2(d_est[:, 1], d_est[:, 0]) - est.theta
        assert np.allclose(np.angle(np.exp(1j * (rel_est - rel_true))), 0.0, atol=1e-9)


def _twist_scenario(mode):
    d = small_scenario_dict(static_obstacles=[])
    d["dynamic_obstacles"] = [{"name": "D1", "start": [4.0, 1.0, 1.0], "v": 0.3, "omega": 0.0,
                               "radius": 0.3}]
    d["sensing"] = {"mode": mode}
    if mode == "tracked":  # only tracked reads these (the schema refuses them in other modes)
        d["sensing"].update(noise_m=0.0, rate_hz=20.0)
    return scenario_from_dict(d)


@pytest.mark.parametrize("mode", ["oracle", "twist", "tracked"])
def test_what_the_agent_sees_in_each_mode(mode):
    sc = _twist_scenario(mode)
    cfg = SimConfig(time_limit=3.0, localization_sigma_xy=0.1, localization_sigma_theta=0.05)
    sim = Simulation(sc, cfg, seed=1)
    o = sc.moving_obstacles[0]
    n = 0
    while not sim.done:
        loc, true = sim.localization, sim.state
        err = loc.error.copy()
        obs = sim.observation()
        assert (obs.robot.x - true.x, obs.robot.y - true.y) == pytest.approx(tuple(err[:2]))
        off = math.remainder(obs.robot.theta - true.theta - err[2], 2 * math.pi)
        assert off == pytest.approx(0.0, abs=1e-12)
        x, y, th, v, _ = o.motion.state(sim.t)
        seen = [(s.x, s.y, s.theta, s.v) for s in obs.obstacles] + [(d.x, d.y, None, None)
                                                                     for d in obs.detections]
        if mode == "oracle":  # announced by the world, not sensed: where it is
            assert seen == [pytest.approx((x, y, th, v))]
            n += 1
        elif seen:  # sensed: where the believed pose puts it
            (sx, sy, sth, sv), = seen
            q = loc.to_map(true, np.array([[x, y]]))[0]
            assert (sx, sy) == pytest.approx(tuple(q), abs=1e-9)
            if mode == "twist":
                turn = math.remainder(sth - th - err[2], 2 * math.pi)
                assert turn == pytest.approx(0.0, abs=1e-12)
                assert sv == pytest.approx(v)
            n += 1
        sim.step(Command(0.3, 0.0))
    assert n > 0


def test_the_simulator_moves_the_true_robot_and_records_the_error():
    sc = _twist_scenario("twist")
    runs = {}
    for name, cfg in (("exact", SimConfig(time_limit=4.0)),
                      ("loc", SimConfig(time_limit=4.0, localization_sigma_xy=0.05,
                                        localization_sigma_theta=0.02))):
        agent = Driver()
        runs[name] = (simulate(sc, agent, seed=3, config=cfg), agent.log)
    (exact, log0), (noisy, log1) = runs["exact"], runs["loc"]
    # an agent that ignores what it sees drives the same path: the error is in the belief only
    assert np.array_equal(exact.trajectory_array, noisy.trajectory_array)
    assert "localization" not in exact.extra
    rec = noisy.extra["localization"]
    assert rec["seed"] == [3, LOCALIZATION_STREAM] and rec["tau_s"] == LOCALIZATION_TAU_S
    assert (rec["sigma_xy_m"], rec["sigma_theta_rad"]) == (0.05, 0.02)
    off = [math.hypot(a.robot.x - b.robot.x, a.robot.y - b.robot.y) for a, b in zip(log0, log1, strict=True)]
    assert 0.0 < max(off) <= rec["max_position_error_m"] + 1e-12
    # exact: the truth, the robot's true state before each step (the run's recorded trajectory)
    seen = [[o.t, o.robot.x, o.robot.y, o.robot.theta, o.robot.v, o.robot.omega] for o in log0]
    assert np.array_equal(seen, exact.trajectory_array[:-1])
