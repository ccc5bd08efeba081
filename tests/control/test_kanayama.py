"""Kanayama tracking: the law itself, saturation, convergence and closed-loop accuracy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.control import KanayamaController, KanayamaGains, tracking_errors
from anyplan.geometry import Circle, ObstacleSet
from anyplan.trajectory import plan_motion
from anyplan.world import Command, RobotSpec, RobotState, clip_command, step

SPEC = RobotSpec(start=(1.0, 3.0, 0.0), goal=(9.0, 3.0), v_max=0.4, omega_max=0.4, a_max=0.4,
                 alpha_max=1.0)


def run(traj, state, spec=SPEC, dt=0.05, extra_time=3.0, controller=None):
    """Closed loop with the simulator's step(); returns times, states and position errors."""
    ctl = controller or KanayamaController(spec, dt=dt)
    t = traj.t_start
    states, errs, times = [state], [], []
    n = int(math.ceil((traj.t_end + extra_time - t) / dt))
    for i in range(n):
        t = traj.t_start + i * dt
        ref = traj.state(t)
        errs.append(math.hypot(ref.x - state.x, ref.y - state.y))
        times.append(t)
        state = step(spec, state, ctl.command(traj, state, t), dt)
        states.append(state)
    return np.array(times), states, np.array(errs)


def test_error_is_in_the_robot_frame():
    st = RobotState(1.0, 1.0, math.pi / 2)
    ex, ey, eth = tracking_errors(1.0, 2.0, math.pi / 2 + 0.3, st)
    assert ex == pytest.approx(1.0) and ey == pytest.approx(0.0, abs=1e-12) and eth == pytest.approx(0.3)
    ex, ey, _ = tracking_errors(0.0, 1.0, 0.0, st)  # reference to the robot's left
    assert ex == pytest.approx(0.0, abs=1e-12) and ey == pytest.approx(1.0)


def test_law_matches_formula_without_saturation():
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    tr = plan_motion(np.array([[1.0, 3.0], [9.0, 3.0]]), SPEC, RobotState(1.0, 3.0, 0.0), obs, 0.0)
    g = KanayamaGains(k_x=2.0, k_y=16.0, k_theta=8.0, k_turn=0.0)
    ctl = KanayamaController(SPEC, g, dt=0.05)
    t = 10.0  # cruising at v_max
    x, y, th, v_r, w_r = ctl.reference(tr, t)
    st = RobotState(x - 0.01, y + 0.005, th + 0.01, 0.4, 0.0)
    ex, ey, eth = tracking_errors(x, y, th, st)
    cmd = ctl.command(tr, st, t)
    v = v_r * math.cos(eth) + g.k_x * ex
    w = w_r + v_r * (g.k_y * ey + g.k_theta * math.sin(eth))
    # v is above v_max here only through the feedback term: check the law before clipping
    expect = clip_command(SPEC, st, Command(v, w), 0.05)
    assert (cmd.v, cmd.omega) == pytest.approx((expect.v, expect.omega), abs=1e-12)
    assert cmd.omega != 0.0


def test_on_reference_command_is_the_mean_feedforward():
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    path = np.array([[1.0, 3.0], [4.0, 4.0], [8.0, 2.5]])
    tr = plan_motion(path, SPEC, RobotState(1.0, 3.0, 0.3), obs, 0.0)
    ctl = KanayamaController(SPEC, dt=0.05)
    for t in (0.0, 3.0, 7.3, 12.0):
        st = tr.state(t)
        cmd = ctl.command(tr, st, t)
        # one step with the command lands on the reference (to integration accuracy)
        nxt = step(SPEC, st, cmd, 0.05)
        ref = tr.state(t + 0.05)
        assert math.hypot(nxt.x - ref.x, nxt.y - ref.y) < 1e-4


def test_output_is_saturated():
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    tr = plan_motion(np.array([[1.0, 3.0], [9.0, 3.0]]), SPEC, RobotState(1.0, 3.0, 0.0), obs, 0.0)
    ctl = KanayamaController(SPEC, KanayamaGains(k_x=50.0, k_y=500.0, k_theta=50.0), dt=0.05)
    st = RobotState(1.0, 4.0, 0.0, 0.0, 0.0)  # 1 m off to the right of the reference
    cmd = ctl.command(tr, st, 10.0)
    assert abs(cmd.v) <= 0.4 * 0.05 + 1e-12 and abs(cmd.omega) <= 1.0 * 0.05 + 1e-12
    st = RobotState(1.0, 4.0, 0.0, 0.4, 0.4)
    cmd = ctl.command(tr, st, 10.0)
    assert abs(cmd.v) <= 0.4 and abs(cmd.omega) <= 0.4


@pytest.mark.parametrize(("dx", "dy", "dth"), [(0.1, 0.0, 0.0), (0.0, 0.1, 0.0), (-0.05, -0.08, 0.2)])
def test_initial_error_converges(dx, dy, dth):
    # The reference runs at 0.3 m/s so that the robot (0.4 m/s) can catch up: a lag behind a
    # reference that runs at v_max cannot be recovered before it brakes.
    obs = ObstacleSet([], bounds=(0.0, 0.0, 12.0, 6.0))
    path = np.array([[1.0, 3.0], [11.0, 3.0]])
    slow = RobotSpec(start=SPEC.start, goal=SPEC.goal, v_max=0.3, omega_max=0.3, a_max=0.3, alpha_max=0.7)
    tr = plan_motion(path, slow, RobotState(1.0, 3.0, 0.0), obs, 0.0)
    t, _, e = run(tr, RobotState(1.0 + dx, 3.0 + dy, dth))
    assert e[0] > 0.05
    assert np.max(e[t > 15.0]) < 0.01


def test_turn_in_place_heading_feedback():
    # With v_r = 0 Kanayama's law has no heading term; k_turn removes an initial heading error.
    obs = ObstacleSet([], bounds=(0.0, 0.0, 10.0, 6.0))
    tr = plan_motion(np.array([[5.0, 3.0], [2.0, 3.0]]), SPEC, RobotState(5.0, 3.0, 0.0), obs, 0.0)
    assert tr.kind == "turn+smooth"
    _, states, e = run(tr, RobotState(5.0, 3.0, 0.15))
    assert e.max() < 0.05
    assert abs(abs(states[-1].theta) - math.pi) < 0.01


@pytest.mark.parametrize("seed", range(6))
def test_closed_loop_accuracy_random_paths(seed):
    rng = np.random.default_rng(seed)
    xs = np.linspace(1.0, 11.0, 6)
    path = np.column_stack([xs, rng.uniform(1.0, 5.0, 6)])
    obs = ObstacleSet([Circle((6.0, 8.0), 0.5)], bounds=(0.0, 0.0, 12.0, 10.0))
    th0 = float(rng.uniform(-np.pi, np.pi))
    tr = plan_motion(path, SPEC, RobotState(*path[0], th0), obs, 0.0, shortcut=False)
    _, states, e = run(tr, RobotState(*path[0], th0))
    assert math.sqrt(np.mean(e**2)) < 0.05 and e.max() < 0.15
    # in fact the mean-rate feedforward makes it far smaller
    assert e.max() < 1e-3
    end = states[-1]
    assert math.hypot(end.x - path[-1, 0], end.y - path[-1, 1]) < 0.01
