"""Speed of ``plan_motion`` and ``Trajectory.sample`` against a pre-optimisation revision.

The trajectory package of a git revision (default ``d7f20d8``, the last one before the numba
spline kernels) is extracted with ``git show`` into a temporary directory and imported under
another name (``anyplan.trajectory`` in its sources renamed), so both implementations run in this
process on the same inputs: BIT* paths (fixed seeds and batch counts, so the set is the same on
every run) on paper-1..3 and random worlds, each with and without a virtual square across the
straight route, from four robot states (at rest aligned, at rest turned 0.6 rad, driving at
0.3 m/s while turning at 0.1 rad/s, and driving away from the path at 0.3 m/s turning at
0.2 rad/s, which takes a brake + turn + smooth motion), at grid steps 0.05 m (the seq-bitstar
agent's) and 0.02 m (plan_motion's default).

Reported per grid step: the median and 90th percentile over the paths of the per-call time
(best of ``--repeats``), old / new ratios, and the agreement of the two results (same kind,
feasibility and certification; largest differences of duration and of sampled states at 500
times). For ``Trajectory.sample``: a single time (the ``state`` call) and the five times of one
Kanayama control step, old / new. Finally the same for the calls the seq-bitstar agent itself
makes in closed loop (recorded from simulations, then replayed through both implementations).

Usage::

    python benchmarks/bench_plan_motion.py [--rev d7f20d8] [--repeats 5] [--random 6]
"""

from __future__ import annotations

import argparse
import importlib
import pathlib
import subprocess
import sys
import tempfile
import time
from functools import partial

import numpy as np

from anyplan.experiments.generate import random_scenario
from anyplan.geometry import square
from anyplan.planning import BITStar, Problem, batches
from anyplan.trajectory import plan_motion
from anyplan.world import RobotState, load_scenario

REPO = pathlib.Path(__file__).resolve().parents[1]


def load_baseline(rev: str, tmp: pathlib.Path):
    """``plan_motion`` of the trajectory package at git revision ``rev`` (imported from ``tmp``)."""
    pkg = "anyplan_trajectory_" + "".join(ch for ch in rev if ch.isalnum())
    names = subprocess.run(["git", "-C", str(REPO), "ls-tree", "--name-only", rev,
                            "src/anyplan/trajectory/"], check=True, capture_output=True,
                           text=True).stdout.split()
    out = tmp / pkg
    out.mkdir()
    for name in names:
        if not name.endswith(".py"):
            continue
        src = subprocess.run(["git", "-C", str(REPO), "show", f"{rev}:{name}"], check=True,
                             capture_output=True, text=True).stdout
        (out / pathlib.Path(name).name).write_text(src.replace("anyplan.trajectory", pkg))
    sys.path.insert(0, str(tmp))
    return importlib.import_module(pkg + ".motion").plan_motion


def make_cases(n_random: int) -> list[dict]:
    """Fixed BIT* paths and robot states (see the module docstring)."""
    cases = []
    scenarios = [load_scenario(n) for n in ("paper-1", "paper-2", "paper-3")]
    scenarios += [random_scenario(seed, n_moving=1) for seed in range(n_random)]
    for i, sc in enumerate(scenarios):
        spec = sc.robot
        base = sc.obstacle_set()
        start, goal = np.array(spec.start[:2]), np.array(spec.goal, dtype=float)
        for virtual in (False, True):
            obs = base
            if virtual:
                sq = square(start + 0.4 * (goal - start) + np.array([0.0, 0.2]), 1.2)
                obs = base.with_shapes([sq])
                if obs.clearance(start) < spec.radius + 0.05:
                    continue
            planner = BITStar(Problem.create(obs, start, goal, spec.radius + 0.03), rng=i,
                              samples_per_batch=100)
            planner.solve(batches(3))
            res = planner.result()
            if not res.status:
                continue
            th = spec.start[2]
            for state in (RobotState(start[0], start[1], th, 0.0, 0.0),
                          RobotState(start[0], start[1], th + 0.6, 0.0, 0.0),
                          RobotState(start[0], start[1], th + 0.2, 0.3, 0.1),
                          RobotState(start[0], start[1], th + 2.5, 0.3, 0.2)):
                cases.append({"name": f"{sc.name}-{i}{'+square' if virtual else ''}",
                              "path": res.path, "spec": spec, "state": state, "obstacles": obs})
    return cases


def agent_calls(n_random: int) -> list[tuple[tuple, dict]]:
    """The plan_motion calls (arguments) of the seq-bitstar agent in closed loop on paper-1..3
    and ``n_random`` random scenarios, seeds 0 and 1 (recorded by wrapping the function the
    agent's reference-motion builder, :mod:`anyplan.trajectory.reference`, imported; nothing is
    changed on disk)."""
    import anyplan.trajectory.reference as seq_agent
    from anyplan.agents import make_agent
    from anyplan.simulation import simulate

    calls: list[tuple[tuple, dict]] = []
    original = seq_agent.plan_motion

    def record(*a, **k):
        calls.append((a, k))
        return original(*a, **k)

    seq_agent.plan_motion = record
    try:
        scenarios = [load_scenario(n) for n in ("paper-1", "paper-2", "paper-3")]
        scenarios += [random_scenario(seed) for seed in range(n_random)]
        for sc in scenarios:
            for seed in (0, 1):
                simulate(sc, make_agent("seq-bitstar"), seed=seed)
    finally:
        seq_agent.plan_motion = original
    return calls


def best_time(fn, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def sample_many(tr, t: np.ndarray, n: int = 20) -> None:
    for _ in range(n):
        tr.sample(t)


def compare(tr_old, tr_new) -> tuple[bool, float, float]:
    """(same kind/flags, |duration difference| [s], max |sampled state difference|)."""
    same = (tr_old.kind == tr_new.kind and tr_old.feasible == tr_new.feasible
            and tr_old.certified_free == tr_new.certified_free)
    t = np.linspace(tr_old.t_start - 0.5, max(tr_old.t_end, tr_new.t_end) + 0.5, 500)
    a, b = np.array(tr_old.sample(t)), np.array(tr_new.sample(t))
    a[2], b[2] = np.unwrap(a[2]), np.unwrap(b[2])
    return same, abs(tr_old.duration - tr_new.duration), float(np.max(np.abs(a - b)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rev", default="d7f20d8", help="baseline git revision")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--random", type=int, default=6, help="number of random worlds")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        old_plan_motion = load_baseline(args.rev, pathlib.Path(tmp))
        cases = make_cases(args.random)
        print(f"{len(cases)} (path, state) cases; baseline {args.rev}; best of {args.repeats}")
        for gs in (0.05, 0.02):
            t_old, t_new, dur_d, st_d, n_same, s1, s5 = [], [], [], [], 0, [], []
            kinds: dict[str, int] = {}
            for c in cases:
                call_old = partial(old_plan_motion, c["path"], c["spec"], c["state"], c["obstacles"],
                                   0.0, margin=0.015, grid_step=gs)
                call_new = partial(plan_motion, c["path"], c["spec"], c["state"], c["obstacles"], 0.0,
                                   margin=0.015, grid_step=gs)
                tr_old, tr_new = call_old(), call_new()  # also warms up
                t_old.append(best_time(call_old, args.repeats))
                t_new.append(best_time(call_new, args.repeats))
                same, dd, sd = compare(tr_old, tr_new)
                n_same += same
                dur_d.append(dd)
                st_d.append(sd)
                # Trajectory.sample: one time, and one Kanayama control step (5 times over 0.05 s),
                # in the middle of the motion and at its start (braking or turning, if any)
                kinds[str(tr_new.kind)] = kinds.get(str(tr_new.kind), 0) + 1
                for t0 in (0.5 * tr_new.t_end, tr_new.t_start + 0.01):
                    t1 = np.array([t0])
                    t5 = t0 + 0.05 * np.linspace(0.0, 1.0, 5)
                    s1.append([best_time(partial(sample_many, tr, t1), 3) for tr in (tr_old, tr_new)])
                    s5.append([best_time(partial(sample_many, tr, t5), 3) for tr in (tr_old, tr_new)])
            to, tn = np.array(t_old) * 1e3, np.array(t_new) * 1e3
            print(f"\ngrid_step {gs} m: plan_motion per call [ms]; motions {kinds}")
            print(f"  old median {np.median(to):7.2f}  p90 {np.percentile(to, 90):7.2f}  "
                  f"max {to.max():7.2f}")
            print(f"  new median {np.median(tn):7.2f}  p90 {np.percentile(tn, 90):7.2f}  "
                  f"max {tn.max():7.2f}")
            r = to / tn
            worst = int(np.argmax(tn))
            print(f"  slowest new: {cases[worst]['name']} from {cases[worst]['state']} "
                  f"({tn[worst]:.2f} ms, old {to[worst]:.2f} ms)")
            print(f"  ratio old/new: of medians {np.median(to) / np.median(tn):5.2f}, per path "
                  f"median {np.median(r):5.2f} (min {r.min():5.2f}, max {r.max():5.2f})")
            print(f"  agreement: same kind/feasible/certified {n_same}/{len(cases)}, "
                  f"max |duration diff| {max(dur_d):.1e} s, max |state diff| {max(st_d):.1e}")
            a1, a5 = np.array(s1) / 20 * 1e3, np.array(s5) / 20 * 1e3
            print(f"  Trajectory.sample, 1 time [ms]: old {np.median(a1[:, 0]):.4f}  new "
                  f"{np.median(a1[:, 1]):.4f}  ratio {np.median(a1[:, 0] / a1[:, 1]):5.1f}")
            print(f"  Trajectory.sample, 5 times [ms]: old {np.median(a5[:, 0]):.4f}  new "
                  f"{np.median(a5[:, 1]):.4f}  ratio {np.median(a5[:, 0] / a5[:, 1]):5.1f}")

        # The calls Sequential BIT* really makes (states on the move, virtual squares, its grid).
        try:
            calls = agent_calls(args.random)
        except Exception as exc:  # the agent is developed concurrently: report, do not fail
            print(f"\nseq-bitstar calls: skipped ({type(exc).__name__}: {exc})")
            return
        t_old, t_new, n_same, dmax = [], [], 0, 0.0
        for a, k in calls:
            tr_old, tr_new = old_plan_motion(*a, **k), plan_motion(*a, **k)
            t_old.append(best_time(partial(old_plan_motion, *a, **k), args.repeats))
            t_new.append(best_time(partial(plan_motion, *a, **k), args.repeats))
            same, dd, sd = compare(tr_old, tr_new)
            n_same += same
            dmax = max(dmax, dd, sd)
        to, tn = np.array(t_old) * 1e3, np.array(t_new) * 1e3
        print(f"\nseq-bitstar's own plan_motion calls ({len(calls)}, closed loop on paper-1..3 and "
              f"{args.random} random scenarios, seeds 0-1) [ms]")
        print(f"  old median {np.median(to):7.2f}  p90 {np.percentile(to, 90):7.2f}  max {to.max():7.2f}")
        print(f"  new median {np.median(tn):7.2f}  p90 {np.percentile(tn, 90):7.2f}  max {tn.max():7.2f}")
        print(f"  ratio old/new: of medians {np.median(to) / np.median(tn):5.2f}, per call median "
              f"{np.median(to / tn):5.2f}; same kind/flags {n_same}/{len(calls)}, max difference {dmax:.1e}")


if __name__ == "__main__":
    main()
