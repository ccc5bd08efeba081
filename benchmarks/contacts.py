"""Benchmark: the collision prediction's first contacts, closed form against the certified search.

Records every collision prediction (``anyplan.prediction.collision``) that st-bitstar makes on a
few recorded-crowd windows (``tracked``: straight discs that grow with the horizon, up to 60
people in view in the dense overlays) and DynaBARN worlds (``twist``: straight discs, exact),
then replays each recorded call in this process through both ways of answering it:

* ``closed form``: what the library does (``_predict_uncached``): the discs on straight lines
  by the compiled closed form on the robot's samples, the others by the certified search;
* ``certified``: the certified search (``_certified_hits``: Lipschitz bounds on a grid, then a
  bisection to a time tolerance) for every disc, as before the closed form.

Printed per suite: calls, obstacles per call, the time of all calls (best of ``--repeats``
passes) and the median call for each way, their ratio, and the check that both find the same
obstacles, the closed form never earlier than the certified search (which reports the start of
the first interval it cannot certify free). Times are CPU-bound wall clock on this machine;
compare the ratio, not the milliseconds. Needs ``../shared/benchmarks`` (crowds, DynaBARN).

Usage::

    python benchmarks/contacts.py                # 3 sparse + 2 dense crowd windows, 4 worlds
    python benchmarks/contacts.py --windows 6 --worlds 8 --repeats 5
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import unknown


def _record(scenarios: list[Any], mode: str, limit: int) -> list[tuple[Any, ...]]:
    """The arguments of up to ``limit`` collision predictions of st-bitstar on ``scenarios``."""
    from anyplan.agents import make_agent
    from anyplan.agents.settings import deterministic_settings
    from anyplan.agents.spacetime import SpaceTimeBITStarAgent
    from anyplan.prediction import collision
    from anyplan.simulation import SimConfig, simulate
    from anyplan.simulation.perception import override_sensing
    from anyplan.world.scenario import scenario_from_dict

    calls: list[tuple[Any, ...]] = []
    inner = collision._predict_uncached

    def spy(*args: Any) -> Any:
        if len(calls) < limit and args[7] is not None:  # the sampled checks (all the planners')
            calls.append(args)
        return inner(*args)

    collision._predict_uncached = spy
    try:
        for data in scenarios:
            sc = override_sensing(scenario_from_dict(data, data["name"]), mode)
            agent = make_agent("st-bitstar", **deterministic_settings(SpaceTimeBITStarAgent,
                                                                      "st-bitstar"))
            simulate(sc, agent, seed=0, config=SimConfig())
    finally:
        collision._predict_uncached = inner
    return calls


def _replay(calls: list[tuple[Any, ...]], fn: Any, repeats: int) -> tuple[float, np.ndarray, list[Any]]:
    """Best total over ``repeats`` passes [s], the per-call times of that pass [s], the answers."""
    best, per, answers = np.inf, np.zeros(len(calls)), []
    for _ in range(repeats):
        times, out = np.empty(len(calls)), []
        t_all = time.perf_counter()
        for i, args in enumerate(calls):
            t0 = time.perf_counter()
            out.append(fn(*args))
            times[i] = time.perf_counter() - t0
        total = time.perf_counter() - t_all
        if total < best:
            best, per, answers = total, times, out
    return best, per, answers


def _agree(calls: list[tuple[Any, ...]], new: list[Any], old: list[Any]) -> tuple[int, int]:
    """Calls whose answers differ in the obstacles met (the first one only, for a first-contact
    call), or with a contact earlier than the certified one (both should be 0)."""
    differ = earlier = 0
    for args, a, b in zip(calls, new, old, strict=True):
        if args[8]:  # first contact only
            a, b = sorted(a, key=lambda h: h.t)[:1], sorted(b, key=lambda h: h.t)[:1]
        ta, tb = {h.obstacle: h.t for h in a}, {h.obstacle: h.t for h in b}
        if set(ta) != set(tb):
            differ += 1
        elif any(ta[k] < tb[k] - 1e-9 for k in ta):
            earlier += 1
    return differ, earlier


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--windows", type=int, default=3, help="sparse crowd windows (dense: 2/3 of it)")
    ap.add_argument("--worlds", type=int, default=4, help="DynaBARN worlds from 40 on")
    ap.add_argument("--calls", type=int, default=1500, help="recorded calls per suite at most")
    ap.add_argument("--repeats", type=int, default=3, help="replay passes (best is kept)")
    args = ap.parse_args()

    from anyplan.prediction import collision

    crowds = unknown._crowds(100)
    sparse = [d for tag, d in crowds if tag == "crowds"][: args.windows]
    dense = [d for tag, d in crowds if tag == "crowds-dense"][: max(1, 2 * args.windows // 3)]
    suites = {
        "crowds, tracked": (sparse, "tracked"),
        "dense crowds, tracked": (dense, "tracked"),
        "DynaBARN 40+, twist": (unknown._dynabarn(list(range(40, 40 + args.worlds))), "twist"),
    }
    print("| suite | calls | obstacles per call | closed form: all [s] / median call [ms] "
          "| certified: all [s] / median call [ms] | certified / closed form | differ | earlier |")
    print("|" + "---|" * 8)
    for name, (scs, mode) in suites.items():
        calls = _record(scs, mode, args.calls)
        if not calls:
            continue

        def certified(motion: Any, obs: Any, r: float, t0: float, t1: float, margin: float,
                      tol: float, sample_dt: float | None, first_only: bool) -> Any:
            return collision._certified_hits(motion, obs, r, t0, t1, margin, tol, sample_dt,
                                             first_only)

        a, pa, new = _replay(calls, collision._predict_uncached, args.repeats)
        b, pb, old = _replay(calls, certified, args.repeats)
        differ, earlier = _agree(calls, new, old)
        n_obs = np.median([len(c[1]) for c in calls])
        print(f"| {name} | {len(calls)} | {n_obs:.0f} | {a:.2f} / {1e3 * np.median(pa):.2f} | "
              f"{b:.2f} / {1e3 * np.median(pb):.2f} | {b / a:.1f} | {differ} | {earlier} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
