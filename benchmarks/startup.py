"""Benchmark: the README's first command's start, on a cold and on a warm numba cache (issue 11).

Runs ``anyplan run paper-3 --out DIR --no-plot`` (the README's first command; the default
planner, st-bitstar) in fresh processes:

* cold: with an empty ``NUMBA_CACHE_DIR`` (a fresh machine): the seconds numba compiles (wall
  and CPU, from numba's ``numba:compile`` events, nested compilations counted once), split by
  phase (loading the scenario, the agent's warm-up parts, the simulation) and the kernels that
  cost most (exclusive CPU, each specialisation listed);
* warm: the same command again ``--repeats`` times with that cache: seconds from the process's
  spawn to the agent's first planning call, and the phases before it.

On a cold cache the command hands the motion kernels to a second process
(``anyplan.agents.warmup.prefetch_kernels``); the phase tables count this process's compilations
only, and the command's own line ("compiled N functions in S s, M of them in a second process")
gives the whole. ``--serial`` adds one more cold run with ``ANYPLAN_COMPILE_JOBS=1`` (everything
compiled in one process), for the comparison.

The children run with Python's bytecode cache on (``PYTHONDONTWRITEBYTECODE`` removed from
their environment), as on a user's machine. CPU seconds are the process's own
(``time.process_time``; for the whole command, both processes, from ``getrusage``): on this
shared 2-core machine the wall clock is inflated by the load (printed), the CPU time much less. Usage::

    python benchmarks/startup.py                 # one cold run, 3 warm runs
    python benchmarks/startup.py --repeats 5 --top 30
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

#: Runs in the child: the CLI with numba's compile events recorded and phase marks.
CHILD = r"""
import json, sys, time
SPAWN = float(sys.argv[1]); OUT = sys.argv[2]
T0 = time.perf_counter(); C0 = time.process_time()
marks = [("interpreter", time.time() - SPAWN, 0.0)]
def mark(name):
    marks.append((name, time.time() - SPAWN, time.process_time() - C0))
from numba.core import event
rows, stack, phase = [], [], ["import"]
class L(event.Listener):
    def on_start(self, ev):
        stack.append([time.perf_counter(), time.process_time(), 0.0, 0.0])
    def on_end(self, ev):
        w0, c0, wc, cc = stack.pop()
        w = time.perf_counter() - w0; c = time.process_time() - c0
        if stack:
            stack[-1][2] += w; stack[-1][3] += c
        d = ev.data["dispatcher"]
        rows.append(dict(kernel=d.py_func.__module__ + "." + d.py_func.__qualname__,
                         sig=str(ev.data["args"]), cpu=c - cc, wall=w - wc, phase=phase[0],
                         top=not stack))
event.register("numba:compile", L())
import numpy
mark("numpy, numba imported")
import anyplan.cli.main as cm
import anyplan.cli.cmd_run as cr
import anyplan.agents.warmup as wu
import anyplan.agents.sequential as sa
mark("anyplan.cli imported")
def phased(name, f):
    def w(*a, **k):
        phase[0] = name
        try:
            return f(*a, **k)
        finally:
            mark(name)
            phase[0] = "simulation"
    return w
cr.load_scenario = phased("load scenario", cr.load_scenario)
for part, f in list(wu._RUN.items()):
    wu._RUN[part] = phased("warm-up " + part, f)
import anyplan.agents.spacetime as sta
firsts = {cls: cls.__dict__["_replan"] for cls in (sa.SequentialBITStarAgent,
                                                    sta.SpaceTimeBITStarAgent)}
def replan(self, *a, **k):
    for cls, f in firsts.items():
        cls._replan = f
    mark("first planning call")
    return type(self)._replan(self, *a, **k)
for cls in firsts:  # st-bitstar (the default) has its own _replan
    cls._replan = replan
code = cm.main(["run", "paper-3", "--out", OUT, "--no-plot"])
mark("end")
json.dump(dict(code=code, marks=marks, compiles=rows), open(OUT + "/startup.json", "w"))
"""


def run_once(cache: str, jobs: str | None = None) -> dict:
    """One ``anyplan run paper-3`` in a fresh process with numba's cache in ``cache`` (and
    ``ANYPLAN_COMPILE_JOBS=jobs`` if given); adds the command's compile line and wall time."""
    out = tempfile.mkdtemp(prefix="startup-")
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    # Python's own bytecode cache as a user has it (``pip install .`` writes the .pyc files, and
    # an editable install writes them on first import): without it every warm run would also
    # recompile anyplan's modules from source (about 0.2 s on this machine).
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if jobs is not None:
        env["ANYPLAN_COMPILE_JOBS"] = jobs
    spawn = time.time()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run([sys.executable, "-c", CHILD, repr(spawn), out], env=env, check=True,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.time() - spawn
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(os.path.join(out, "startup.json")) as f:
        res = json.load(f)
    res["line"] = next((ln for ln in proc.stderr.splitlines() if "compiled" in ln), "")
    res["wall"] = wall
    # the command and the second process it waited for (a waited-for grandchild counts too)
    res["cpu_all"] = r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime
    return res


def compile_report(res: dict, top: int) -> None:
    """Compile seconds: total, by phase, and the costliest kernels."""
    rows = res["compiles"]
    cpu = sum(r["cpu"] for r in rows)
    wall = sum(r["wall"] for r in rows)
    print(f"this process: {len(rows)} functions compiled, {cpu:.1f} s CPU, {wall:.1f} s wall")
    by_phase: dict[str, list[float]] = {}
    for r in rows:
        by_phase.setdefault(r["phase"], [0.0, 0.0, 0])
        by_phase[r["phase"]][0] += r["cpu"]
        by_phase[r["phase"]][1] += r["wall"]
        by_phase[r["phase"]][2] += 1
    print("\n| phase | functions | compile CPU [s] | compile wall [s] |\n|---|---|---|---|")
    for ph, (c, w, n) in by_phase.items():
        print(f"| {ph} | {n} | {c:.1f} | {w:.1f} |")
    by_kernel: dict[str, list] = {}
    for r in rows:
        by_kernel.setdefault(r["kernel"], []).append(r)
    ours = sum(r["cpu"] for r in rows if r["kernel"].startswith("anyplan"))
    print(f"\nanyplan's own kernels {ours:.1f} s CPU, numba's library functions {cpu - ours:.1f} s")
    print(f"\n| kernel (top {top} by exclusive compile CPU) | specialisations | CPU [s] |\n|---|---|---|")
    for k, rs in sorted(by_kernel.items(), key=lambda kv: -sum(r["cpu"] for r in kv[1]))[:top]:
        print(f"| `{k}` | {len(rs)} | {sum(r['cpu'] for r in rs):.2f} |")


def marks_table(results: list[dict]) -> None:
    """Seconds from the spawn to each mark (median over the runs), wall and CPU."""
    names = [m[0] for m in results[0]["marks"]]
    print("\n| warm run: seconds from spawn to | wall (median) | CPU (median) |\n|---|---|---|")
    for i, name in enumerate(names):
        w = sorted(r["marks"][i][1] for r in results)
        c = sorted(r["marks"][i][2] for r in results)
        print(f"| {name} | {w[len(w) // 2]:.2f} | {c[len(c) // 2]:.2f} |")


def main() -> None:
    """Parse arguments, run cold once and warm ``--repeats`` times, print the tables."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3, help="warm runs (default 3)")
    ap.add_argument("--top", type=int, default=20, help="kernels listed (default 20)")
    ap.add_argument("--serial", action="store_true",
                    help="also one cold run compiling in one process (ANYPLAN_COMPILE_JOBS=1)")
    args = ap.parse_args()
    print("load:", os.getloadavg())
    cache = tempfile.mkdtemp(prefix="numba-cache-")
    cold = run_once(cache)
    print(f"cold: {cold['line'] or 'nothing compiled'}; whole command {cold['wall']:.1f} s wall, "
          f"{cold['cpu_all']:.1f} s CPU (both processes)")
    if args.serial:
        serial = run_once(tempfile.mkdtemp(prefix="numba-cache-"), jobs="1")
        print(f"cold, ANYPLAN_COMPILE_JOBS=1: {serial['line']}; whole command "
              f"{serial['wall']:.1f} s wall, {serial['cpu_all']:.1f} s CPU")
    compile_report(cold, args.top)
    marks_table([cold])
    warm = [run_once(cache) for _ in range(args.repeats)]
    again = sum(len(r["compiles"]) for r in warm)
    print(f"\nwarm: {args.repeats} runs, {again} functions compiled")
    marks_table(warm)
    print("load:", os.getloadavg())


if __name__ == "__main__":
    main()
