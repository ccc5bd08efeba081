"""Benchmark of the path-to-motion chain (issue 4).

Part A, time optimality of the speed profile: on smoothed curves from random static worlds, our
forward/backward-pass profile (v, omega = kappa v and a limits; alpha disabled so that both solve
the same problem) against toppra 0.6.10 (optional oracle, ``pip install toppra``; not a
dependency). toppra enforces the limits at its grid points only, so it may come out slightly
faster; ours enforces them everywhere. Reported: duration ratio ours / toppra and solve-time
ratio ours / toppra, both measured in this process.

Part B, closed loop: the ``bitstar`` agent in the simulator on the paper scenarios without their
moving obstacles and on random static worlds: time to goal against the smoothed path's time
lower bound (length / v_max + v_max / a_max), reference duration against the same bound, and the
tracking error (RMS and max, against the reference at every control step).

Usage::

    python benchmarks/bench_motion.py [--worlds 10] [--statics 12] [--no-toppra]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

from anyplan.agents import make_agent
from anyplan.experiments.generate import random_scenario
from anyplan.planning import plan
from anyplan.simulation import simulate
from anyplan.trajectory import shortcut_path, smooth_path, time_parameterize
from anyplan.world import load_scenario


def toppra_duration(curve, spec, n: int = 1000) -> float:
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    ta.setup_logging("WARNING") if hasattr(ta, "setup_logging") else None
    L = curve.length

    def vlim(s):
        k, _ = curve.curvature(curve.u_of_s(np.atleast_1d(s)))
        v = min(spec.v_max, spec.omega_max / max(abs(float(k[0])), 1e-12))
        return np.array([[-v, v]])

    path = ta.SplineInterpolator([0.0, L], [[0.0], [L]])
    cons = [constraint.JointVelocityConstraintVarying(vlim),
            constraint.JointAccelerationConstraint(np.array([[-spec.a_max, spec.a_max]]))]
    inst = algo.TOPPRA(cons, path, gridpoints=np.linspace(0.0, L, n + 1),
                       parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0, 0)
    return float(traj.duration)


def part_a(n_worlds: int, statics: int) -> None:
    print("A. speed profile vs toppra (alpha limit off in both)")
    print(f"{'world':>6} {'L [m]':>7} {'ours [s]':>9} {'toppra [s]':>10} {'ratio':>6} "
          f"{'t_ours [ms]':>11} {'t_toppra [ms]':>13}")
    ratios, tr = [], []
    for seed in range(n_worlds):
        sc = random_scenario(seed, n_moving=1, n_static=statics).static_only()
        obs, spec = sc.obstacle_set(), sc.robot
        res = plan(obs, spec.start[:2], spec.goal, spec.radius + 0.03, time_budget_s=0.3, rng=seed)
        pts = shortcut_path(res.path, obs, spec.radius + 0.025)
        curve = smooth_path(pts, obs, spec.radius + 0.015, start_heading=spec.start[2]).curve
        if curve is None:
            continue
        spec_na = dataclasses.replace(spec, alpha_max=1e9)
        t0 = time.perf_counter()
        ours = time_parameterize(curve, spec_na, 0.0).duration
        t1 = time.perf_counter()
        ref = toppra_duration(curve, spec_na)
        t2 = time.perf_counter()
        ratios.append(ours / ref)
        tr.append((t1 - t0) / (t2 - t1))
        print(f"{seed:>6} {curve.length:7.3f} {ours:9.3f} {ref:10.3f} {ours / ref:6.4f} "
              f"{1e3 * (t1 - t0):11.2f} {1e3 * (t2 - t1):13.2f}")
    if ratios:
        print(f"duration ours/toppra: min {min(ratios):.4f} median {np.median(ratios):.4f} "
              f"max {max(ratios):.4f}; solve time ours/toppra median {np.median(tr):.3f}")


def part_b(n_worlds: int, statics: int) -> None:
    print("B. bitstar agent, closed loop (dt 0.05 s)")
    print(f"{'scenario':>10} {'status':>8} {'T_goal':>7} {'T_ref':>7} {'bound':>7} {'goal/bd':>7} "
          f"{'ref/bd':>7} {'rms [m]':>9} {'max [m]':>9} {'kind':>12} {'clear':>6}")
    scs = [load_scenario(n).static_only() for n in ("paper-1", "paper-2", "paper-3")]
    scs += [dataclasses.replace(random_scenario(s, n_moving=1, n_static=statics).static_only(),
                                name=f"rand-{s}") for s in range(n_worlds)]
    worst = 0.0
    for i, sc in enumerate(scs):
        agent = make_agent("bitstar")
        r = simulate(sc, agent, seed=i)
        e = r.extra
        lb = e.get("time_lower_bound_s", math.nan)
        tg = r.time_to_goal_s if r.time_to_goal_s is not None else math.nan
        worst = max(worst, e["reference_duration_s"] / lb)
        print(f"{sc.name:>10} {r.status:>8} {tg:7.2f} {e['reference_duration_s']:7.2f} {lb:7.2f} "
              f"{tg / lb:7.3f} {e['reference_duration_s'] / lb:7.3f} {e['tracking_rms_m']:9.2e} "
              f"{e['tracking_max_m']:9.2e} {e['trajectory_kind']:>12} {r.min_clearance_m:6.3f}")
    print(f"worst reference duration / bound: {worst:.4f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worlds", type=int, default=10)
    ap.add_argument("--statics", type=int, default=12)
    ap.add_argument("--no-toppra", action="store_true")
    a = ap.parse_args()
    if not a.no_toppra:
        try:
            import toppra  # noqa: F401
        except ImportError:
            print("toppra not installed: part A skipped")
        else:
            part_a(a.worlds, a.statics)
    part_b(a.worlds, a.statics)


if __name__ == "__main__":
    main()
