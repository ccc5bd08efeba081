"""Benchmark of the DOVS baseline (issue 6).

Part A, the model: time to decide which of the dynamic window's commands are forbidden, for
1-6 random moving obstacles, with the analytic per-ray model against a brute-force time
simulation of the same commands (what the model replaces; 10 ms steps over the horizon), both
measured in this process. Reported: the ratio brute force / analytic, and the agreement (the
analytic set must contain every command the brute force finds colliding).

Part B, closed loop: the ``dovs`` agent on paper-1..3: outcome, path length, time to goal and
per-period computation time (mean, median, max).

Usage::

    python benchmarks/bench_dovs.py [--scenes 40] [--no-closed-loop]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from anyplan.agents import make_agent
from anyplan.baselines.dovs import DOVSConfig, DOVSModel, DynamicWindow, ModelObstacle, arc_points
from anyplan.simulation import simulate
from anyplan.world import load_scenario


def random_obstacles(rng: np.random.Generator, n: int) -> list[ModelObstacle]:
    out = []
    for i in range(n):
        circular = rng.random() < 0.4
        v = float(rng.uniform(0.1, 0.5))
        w = math.copysign(v / rng.uniform(1.0, 3.0), rng.uniform(-1, 1)) if circular else 0.0
        x, y = rng.uniform(-4.0, 4.0, 2)
        out.append(ModelObstacle(f"o{i}", "circular" if circular else "linear", float(x), float(y),
                                 float(rng.uniform(-math.pi, math.pi)), v, w, 0.63))
    return out


def brute_force(obstacles: list[ModelObstacle], v: np.ndarray, w: np.ndarray, horizon: float,
                dt: float = 0.01) -> np.ndarray:
    t = np.arange(0.0, horizon + 1e-12, dt)
    moving = v > 1e-12
    kappa = np.where(moving, w / np.where(moving, v, 1.0), 0.0)
    px, py = arc_points(kappa[:, None], v[:, None] * t[None, :])
    hit = np.zeros(len(v), dtype=bool)
    for o in obstacles:
        if o.kind == "linear":
            ox, oy = o.x + o.v * t * math.cos(o.theta), o.y + o.v * t * math.sin(o.theta)
        else:
            r = o.v / o.omega
            th = o.theta + o.omega * t
            ox, oy = o.x + r * (np.sin(th) - math.sin(o.theta)), o.y - r * (np.cos(th) - math.cos(o.theta))
        hit |= np.any((px - ox) ** 2 + (py - oy) ** 2 < o.radius ** 2, axis=1)
    return hit


def part_a(n_scenes: int) -> None:
    cfg = DOVSConfig()
    rng = np.random.default_rng(0)
    print("Part A: forbidden-set test of the dynamic window's samples (analytic vs brute force)")
    print(f"{'obstacles':>9} {'samples':>8} {'analytic [ms]':>14} {'brute [ms]':>11} {'ratio':>7} "
          f"{'missed':>7}")
    for n in range(1, 7):
        ta = tb = 0.0
        samples = missed = 0
        for _ in range(n_scenes):
            obs = random_obstacles(rng, n)
            w0 = rng.uniform(-0.3, 0.3)
            v0 = rng.uniform(0.0, 1.0) * cfg.v_max * (1 - abs(w0) / cfg.omega_max)
            v, w = DynamicWindow.around(v0, w0, cfg).candidates(cfg)
            t0 = time.perf_counter()
            f = DOVSModel(obs, cfg).forbidden(v, w)
            t1 = time.perf_counter()
            hit = brute_force(obs, v, w, cfg.time_horizon_s)
            t2 = time.perf_counter()
            ta += t1 - t0
            tb += t2 - t1
            samples += len(v)
            missed += int(np.sum(hit & ~f))
        print(f"{n:>9} {samples / n_scenes:>8.0f} {1e3 * ta / n_scenes:>14.2f} {1e3 * tb / n_scenes:>11.2f} "
              f"{tb / ta:>7.1f} {missed:>7}")


def part_b() -> None:
    print("\nPart B: the dovs agent on the paper scenarios")
    print(f"{'scenario':>9} {'outcome':>9} {'path [m]':>9} {'to goal [s]':>12} {'periods':>8} "
          f"{'mean [ms]':>10} {'median [ms]':>12} {'max [ms]':>9}")
    for name in ("paper-1", "paper-2", "paper-3"):
        res = simulate(load_scenario(name), make_agent("dovs"), seed=0)
        pt = 1e3 * np.asarray(res.planning_times_s)
        ttg = f"{res.time_to_goal_s:.1f}" if res.time_to_goal_s is not None else "-"
        print(f"{name:>9} {res.status:>9} {res.path_length_m:>9.2f} {ttg:>12} {len(pt):>8} "
              f"{pt.mean():>10.2f} {np.median(pt):>12.2f} {pt.max():>9.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", type=int, default=40, help="random scenes per obstacle count")
    ap.add_argument("--no-closed-loop", action="store_true", help="skip part B")
    args = ap.parse_args()
    part_a(args.scenes)
    if not args.no_closed_loop:
        part_b()


if __name__ == "__main__":
    main()
