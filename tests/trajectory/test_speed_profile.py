"""Speed profiles: every limit between grid points, optimality against the time lower bound."""

from __future__ import annotations

import numpy as np
import pytest

from anyplan.trajectory import SmoothCurve, time_lower_bound, time_parameterize
from anyplan.world import RobotSpec

SPEC = RobotSpec(start=(0.0, 0.0, 0.0), goal=(1.0, 0.0), v_max=0.4, omega_max=0.4, a_max=0.4,
                 alpha_max=1.0)


def dense_check(curve, prof, spec, sub=50):
    """Evaluate v, omega, a and alpha analytically at ``sub`` points inside each grid interval."""
    n = len(prof.t) - 1
    fr = (np.arange(sub) + 0.5) / sub
    tau = (prof.t[:-1, None] + np.diff(prof.t)[:, None] * fr[None, :]).ravel()
    s, v, a = prof.at_time(tau)
    u = curve.u_of_s(s)
    k, dk = curve.curvature(u)
    omega = k * v
    alpha = dk * v * v + k * a
    tol = 1e-9
    assert np.all(v <= spec.v_max + tol)
    assert np.all(np.abs(omega) <= spec.omega_max + tol), np.abs(omega).max()
    assert np.all(np.abs(a) <= spec.a_max + tol)
    assert np.all(np.abs(alpha) <= spec.alpha_max + tol), np.abs(alpha).max()
    assert n == len(prof.s) - 1
    return np.abs(omega).max(), np.abs(alpha).max()


def test_straight_line_meets_the_lower_bound():
    c = SmoothCurve(np.array([[0.0, 0.0], [12.0, 0.0]]))
    p = time_parameterize(c, SPEC, 0.0)
    lb = time_lower_bound(12.0, SPEC)
    assert lb == pytest.approx(12.0 / 0.4 + 0.4 / 0.4)
    assert p.duration >= lb - 1e-9
    # switching points fall inside grid intervals: at most one interval's worth of time lost
    assert p.duration <= lb + 2 * 0.02 / 0.4
    assert p.v[0] == 0.0 and p.v[-1] == 0.0
    dense_check(c, p, SPEC)


@pytest.mark.parametrize("length", [0.05, 0.3, 0.8])
def test_short_lines_triangle_profile(length):
    c = SmoothCurve(np.array([[0.0, 0.0], [length, 0.0]]))
    p = time_parameterize(c, SPEC, 0.0)
    lb = time_lower_bound(length, SPEC)
    assert lb - 1e-9 <= p.duration <= lb * 1.05 + 0.05
    assert p.v.max() <= np.sqrt(SPEC.a_max * length) + 1e-9


def test_start_speed_is_kept_and_bound_accounts_for_it():
    c = SmoothCurve(np.array([[0.0, 0.0], [5.0, 0.0]]))
    p = time_parameterize(c, SPEC, 0.3)
    assert p.feasible and p.v[0] == pytest.approx(0.3)
    lb = time_lower_bound(5.0, SPEC, 0.3)
    assert lb - 1e-9 <= p.duration <= lb + 0.1


@pytest.mark.parametrize("seed", range(12))
def test_limits_hold_between_grid_points_on_random_curves(seed):
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform(0.3, 2.0, (6, 2)) * rng.choice([-1.0, 1.0], (6, 2)), axis=0)
    spec = RobotSpec(start=(0.0, 0.0, 0.0), goal=(1.0, 0.0), v_max=float(rng.uniform(0.3, 1.0)),
                     omega_max=float(rng.uniform(0.2, 1.5)), a_max=float(rng.uniform(0.2, 1.0)),
                     alpha_max=float(rng.uniform(0.3, 2.0)))
    c = SmoothCurve(pts, start_heading=float(rng.uniform(-3, 3)) if seed % 3 == 0 else None)
    p = time_parameterize(c, spec, 0.0)
    dense_check(c, p, spec)
    assert p.duration >= time_lower_bound(c.length, spec) - 1e-9
    assert np.all(np.isfinite(p.t))


def test_alpha_constraint_binds_and_holds():
    # Wiggly curve, low alpha_max: the angular-acceleration limit must be the active one.
    x = np.linspace(0.0, 8.0, 17)
    pts = np.column_stack([x, 0.4 * np.sin(2.0 * x)])
    spec = RobotSpec(start=(0.0, 0.0, 0.0), goal=(1.0, 0.0), v_max=1.0, omega_max=3.0, a_max=2.0,
                     alpha_max=0.3)
    c = SmoothCurve(pts)
    p = time_parameterize(c, spec, 0.0)
    _, amax = dense_check(c, p, spec)
    assert amax > 0.5 * spec.alpha_max  # close to the limit somewhere


def test_converges_with_grid_refinement():
    pts = np.array([[0.0, 0.0], [2.0, 1.5], [4.0, -1.0], [6.0, 0.5]])
    coarse = time_parameterize(SmoothCurve(pts, grid_step=0.04), SPEC)
    fine = time_parameterize(SmoothCurve(pts, grid_step=0.005), SPEC)
    # the interval bounds are conservative: a finer grid can only be (slightly) faster
    assert fine.duration <= coarse.duration + 1e-6
    assert coarse.duration <= fine.duration * 1.02


def test_too_fast_start_into_a_tight_curve_is_flagged():
    # Full speed straight into a 0.3 m radius turn 5 cm ahead: cannot be followed.
    th = np.linspace(0.0, np.pi / 2, 10)
    pts = np.vstack([[[-0.05, -0.3]], np.column_stack([0.3 * np.sin(th), -0.3 * np.cos(th)])])
    c = SmoothCurve(pts, start_heading=0.0)
    p = time_parameterize(c, SPEC, 0.4)
    assert not p.feasible
    assert p.v[0] < 0.4


def test_time_lower_bound_cases():
    assert time_lower_bound(0.0, SPEC) == 0.0
    assert time_lower_bound(0.4, SPEC) == pytest.approx(2.0 * np.sqrt(0.4 / 0.4))
    # cannot stop within the length: braking time
    assert time_lower_bound(0.01, SPEC, 0.4) == pytest.approx(1.0)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
def test_against_toppra_oracle(seed):
    """Optional oracle (toppra is not a dependency): same v, omega and a limits, alpha off.

    toppra enforces its limits at its grid points only, so it may be a little faster; ours must
    stay within 2 % of it and must not be faster by more than toppra's own grid error.
    """
    ta = pytest.importorskip("toppra")
    import dataclasses

    import toppra.algorithm as algo
    import toppra.constraint as constraint

    rng = np.random.default_rng(seed)
    pts = np.column_stack([np.linspace(0.0, 12.0, 7), rng.uniform(-2.0, 2.0, 7)])
    c = SmoothCurve(pts)
    spec = dataclasses.replace(SPEC, alpha_max=1e9)
    ours = time_parameterize(c, spec).duration

    def vlim(s):
        k, _ = c.curvature(c.u_of_s(np.atleast_1d(s)))
        v = min(spec.v_max, spec.omega_max / max(abs(float(k[0])), 1e-12))
        return np.array([[-v, v]])

    path = ta.SplineInterpolator([0.0, c.length], [[0.0], [c.length]])
    cons = [constraint.JointVelocityConstraintVarying(vlim),
            constraint.JointAccelerationConstraint(np.array([[-spec.a_max, spec.a_max]]))]
    inst = algo.TOPPRA(cons, path, gridpoints=np.linspace(0.0, c.length, 2001),
                       parametrizer="ParametrizeConstAccel")
    ref = float(inst.compute_trajectory(0, 0).duration)
    assert ref * 0.999 <= ours <= ref * 1.02
