"""The robot's execution error (``SimConfig.actuation_sigma_v``, ``actuation_sigma_omega``):
exact when zero, within the limits, of the stated spread and correlation, seeded, recorded."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents import make_agent
from anyplan.agents.settings import deterministic_settings
from anyplan.config import SettingError
from anyplan.geometry.se2 import unicycle_arc
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.actuation import ACTUATION_STREAM, ACTUATION_TAU_S, ActuationNoise
from anyplan.simulation.perception import NOISE_STREAM
from anyplan.world.robot import Command, RobotSpec, RobotState, step
from anyplan.world.scenario import load_scenario

_SPEC = RobotSpec((0.0, 0.0, 0.0), (10.0, 0.0), radius=0.3, v_max=1.0, omega_max=1.5, a_max=1.0,
                  alpha_max=3.0)


def _drive(noise: ActuationNoise, cmd: Command, n: int, dt: float = 0.05) -> np.ndarray:
    """The twist (v, omega) the robot moved by in each of ``n`` steps under the constant
    command ``cmd`` (reached at once)."""
    s, out = RobotState(0.0, 0.0, 0.0, cmd.v, cmd.omega), []
    for _ in range(n):
        s1 = noise.step(_SPEC, s, cmd, dt)
        assert (s1.v, s1.omega) == (cmd.v, cmd.omega)  # the state reports the drive's twist
        # the pose moved by the ground twist
        x, y, _ = unicycle_arc(s.x, s.y, s.theta, noise.ground.v, noise.ground.omega, dt)
        assert (x, y) == pytest.approx((s1.x, s1.y), abs=1e-12)
        out.append((noise.ground.v, noise.ground.omega))
        s = s1
    return np.array(out)


def test_zero_spread_is_the_exact_step():
    rng = np.random.default_rng(1)
    for _ in range(100):
        s = RobotState(*rng.uniform(-5, 5, 2), rng.uniform(-3, 3), rng.uniform(-1, 1), rng.uniform(-1.5, 1.5))
        cmd = Command(*rng.uniform(-2, 2, 2))
        assert ActuationNoise(0.0, 0.0, seed=0).step(_SPEC, s, cmd, 0.05) == step(_SPEC, s, cmd, 0.05)
    # and a chain of steps (the drive's own twist carried from step to step)
    noise, a = ActuationNoise(0.0, 0.0, seed=0), RobotState(0.0, 0.0, 0.0)
    b = a
    for cmd in rng.uniform(-2, 2, (100, 2)):
        a, b = noise.step(_SPEC, a, Command(*cmd), 0.05), step(_SPEC, b, Command(*cmd), 0.05)
        assert a == b


def test_the_error_has_the_stated_spread_and_correlation_and_keeps_the_limits():
    sv, sw, dt = 0.05, 0.1, 0.05
    # half the top speed and half the top turn rate: full motion, the full spreads
    cmd = Command(0.5 * _SPEC.v_max, 0.5 * _SPEC.omega_max)
    tw = _drive(ActuationNoise(sv, sw, seed=7), cmd, 40_000, dt)
    err = tw - np.array([cmd.v, cmd.omega])
    assert err.std(axis=0) == pytest.approx([sv, sw], rel=0.1)
    assert abs(err.mean(axis=0)[0]) < 0.1 * sv
    # a quarter of the top speed alone: a quarter of the spreads
    slow = _drive(ActuationNoise(sv, sw, seed=7), Command(0.25 * _SPEC.v_max, 0.0), 40_000, dt)
    assert (slow - np.array([0.25 * _SPEC.v_max, 0.0])).std(axis=0) == pytest.approx(
        [0.25 * sv, 0.25 * sw], rel=0.1)
    rho = math.exp(-dt / ACTUATION_TAU_S)
    lag1 = [np.corrcoef(err[:-1, k], err[1:, k])[0, 1] for k in range(2)]
    assert lag1 == pytest.approx([rho, rho], abs=0.02)
    # at full speed and turn rate the error can only slow the robot down
    top = _drive(ActuationNoise(0.2, 0.2, seed=7), Command(_SPEC.v_max, _SPEC.omega_max), 2_000)
    assert top[:, 0].max() <= _SPEC.v_max and top[:, 1].max() <= _SPEC.omega_max
    assert top[:, 0].mean() < _SPEC.v_max - 0.05


def test_a_robot_at_rest_does_not_drift():
    noise, s = ActuationNoise(0.5, 0.5, seed=1), RobotState(1.0, 2.0, 0.3)
    for _ in range(200):
        s = noise.step(_SPEC, s, Command(0.0, 0.0), 0.05)
    assert (s.x, s.y, s.v, s.omega) == (1.0, 2.0, 0.0, 0.0)
    assert s.theta == pytest.approx(0.3, abs=1e-12)  # (wrapped to [-pi, pi) at each step)


def test_the_error_is_seeded_on_a_stream_of_its_own():
    a = _drive(ActuationNoise(0.1, 0.1, seed=3), Command(0.5, 0.2), 50)
    b = _drive(ActuationNoise(0.1, 0.1, seed=3), Command(0.5, 0.2), 50)
    c = _drive(ActuationNoise(0.1, 0.1, seed=4), Command(0.5, 0.2), 50)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert ActuationNoise(0.1, 0.1, seed=3).record()["seed"] == [3, ACTUATION_STREAM]
    assert ACTUATION_STREAM != NOISE_STREAM


@pytest.mark.parametrize(("field", "value"), [("actuation_sigma_v", -0.1),
                                              ("actuation_sigma_omega", math.nan)])
def test_bad_spreads_name_the_field(field, value):
    with pytest.raises(SettingError, match=field):
        SimConfig(**{field: value})


def test_a_run_records_its_execution_error():
    sc = load_scenario("paper-1")
    agent = make_agent("st-bitstar", **deterministic_settings(type(make_agent("st-bitstar")), "st-bitstar"))
    exact = simulate(sc, agent, seed=2, config=SimConfig(time_limit=5.0))
    assert "actuation" not in exact.extra
    cfg = SimConfig(time_limit=5.0, actuation_sigma_v=0.02, actuation_sigma_omega=0.02)
    noisy = simulate(sc, agent, seed=2, config=cfg)
    again = simulate(sc, agent, seed=2, config=cfg)
    assert noisy.extra["actuation"] == {"sigma_v_mps": 0.02, "sigma_omega_radps": 0.02,
                                        "tau_s": ACTUATION_TAU_S, "seed": [2, ACTUATION_STREAM]}
    assert np.array_equal(noisy.trajectory_array, again.trajectory_array)
    assert not np.array_equal(noisy.trajectory_array, exact.trajectory_array)
