"""Kernel warm-up: parts, and the compiling notice only when numba really compiles."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from anyplan.agents import make_agent
from anyplan.agents.warmup import PARTS, compiling_notifier, warm_up_kernels
from anyplan.cli.main import main


def test_notifier_fires_once_on_a_real_compilation_and_not_on_a_loaded_one():
    @njit
    def twice(a):
        return 2.0 * a

    calls = []
    with compiling_notifier(lambda: calls.append(1)) as note:
        assert twice(np.ones(3)).sum() == 6.0  # compiles (an inner function: no cache)
        assert twice(np.ones(2)).sum() == 4.0  # same signature, nothing new
    assert calls == [1] and note.compiled
    with compiling_notifier(lambda: calls.append(2)) as note:
        twice(np.ones(4))  # already compiled for this signature
    assert calls == [1] and not note.compiled
    twice(1.0)  # compiles outside any block: no callback
    assert calls == [1]


def test_unknown_part_is_refused():
    with pytest.raises(ValueError, match="unknown"):
        warm_up_kernels(["bitstar", "nope"])


def test_agents_declare_only_the_parts_they_use():
    assert make_agent("st-bitstar").kernel_parts == PARTS
    assert make_agent("seq-bitstar").kernel_parts == ("bitstar", "motion", "contacts", "sequential")
    assert make_agent("bitstar").kernel_parts == ("bitstar", "motion")
    assert not getattr(make_agent("dovs"), "kernel_parts", ())


def test_run_says_nothing_about_compiling_when_the_kernels_are_loaded(tmp_path, capsys):
    warm_up_kernels()  # everything loaded (or compiled) in this process before the command
    args = ["run", "paper-1", "--planner", "bitstar", "--out", str(tmp_path), "--no-plot"]
    assert main(args) in (0, 1)  # and what else the command compiles (the time lower bound's)
    capsys.readouterr()
    assert main(args) in (0, 1)
    err = capsys.readouterr().err
    assert "compiling" not in err and "minute" not in err


def test_notifier_times_and_counts_the_compilations():
    @njit
    def inner(a):
        return a + 1.0

    @njit
    def outer(a):
        return inner(a) * 3.0

    with compiling_notifier(None) as note:
        assert outer(1.0) == 6.0  # outer and, nested inside its compilation, inner
    assert note.count == 2 and note.seconds > 0.0
    with compiling_notifier(None) as again:
        outer(2.0)
    assert again.count == 0 and again.seconds == 0.0


def test_run_says_compiling_when_anything_in_the_command_compiles(tmp_path, capsys, monkeypatch):
    import anyplan.cli.cmd_run as cmd_run

    @njit
    def fresh(x):
        return x + 1

    def run_that_compiles(args):  # stands for a run on a cold cache, wherever it compiles
        return int(fresh(1)) - 2

    monkeypatch.setattr(cmd_run, "_run", run_that_compiles)
    monkeypatch.setenv("ANYPLAN_COMPILE_JOBS", "1")  # no second process for this stand-in
    assert main(["run", "paper-1", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "compiling kernels" in err and "compiled 1 function in" in err


@pytest.mark.slow
def test_first_run_on_a_fresh_cache_says_compiling_and_the_second_does_not(tmp_path):
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    cmd = [sys.executable, "-c", "from anyplan.cli.main import main; raise SystemExit(main())",
           "run", "paper-1", "--planner", "straight", "--no-plot", "--out", str(tmp_path / "out")]
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert first.returncode == second.returncode == 1  # straight collides on paper-1
    assert "compiling kernels" in first.stderr and "functions in" in first.stderr
    assert "compil" not in second.stderr


@pytest.fixture
def no_parts_loaded(monkeypatch):
    """This process has loaded no part and started no second process (restored afterwards)."""
    import anyplan.agents.warmup as wu

    monkeypatch.setattr(wu, "_DONE", set())
    monkeypatch.setattr(wu, "_PREFETCH", {})
    return wu


def test_second_process_takes_the_motion_part_only_when_another_part_stays_here(no_parts_loaded):
    wu = no_parts_loaded
    # in the order the second process compiles them: the clearance kernels come last
    assert wu.prefetch_parts(PARTS) == ("contacts", "motion")
    # the simulation's visibility graph first: this process checks feasibility before BIT*
    assert wu.prefetch_parts((wu.VISGRAPH, *PARTS)) == (wu.VISGRAPH, "contacts", "motion")
    assert wu.prefetch_parts((wu.VISGRAPH,)) == ()  # a planner without kernels: nothing to share
    assert wu.prefetch_parts(("bitstar", "motion")) == ("motion",)
    assert wu.prefetch_parts(("motion", "contacts")) == ()  # this process would only wait
    assert wu.prefetch_parts(("bitstar",)) == ()
    wu._DONE.update(("motion", "contacts"))
    assert wu.prefetch_parts(PARTS) == ()  # already loaded here


def test_one_compile_job_starts_no_second_process(no_parts_loaded, monkeypatch):
    wu = no_parts_loaded
    monkeypatch.setenv("ANYPLAN_COMPILE_JOBS", "1")
    assert wu.prefetch_kernels(PARTS) == ()
    assert wu._PREFETCH == {}


def test_a_failed_second_process_is_reported_as_such_and_counts_nothing(no_parts_loaded):
    job = no_parts_loaded._Prefetch(("nope",))  # its warm_up_kernels refuses the part
    job.finish(timeout_s=300)
    assert job.ok is False and job.count == 0 and job.seconds == 0.0
    job.finish()  # a second call waits no more
    assert job.ok is False


def test_run_counts_the_second_process_in_its_compile_message(tmp_path, capsys, monkeypatch):
    import anyplan.cli.cmd_run as cmd_run

    @njit
    def fresh2(x):
        return x + 2

    monkeypatch.setattr(cmd_run, "_run", lambda args: int(fresh2(1)) - 3)
    monkeypatch.setenv("ANYPLAN_COMPILE_JOBS", "1")
    import anyplan.agents.warmup as wu

    monkeypatch.setattr(wu, "prefetch_report", lambda: (40, 2.5))
    assert main(["run", "paper-1", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "compiled 41 functions in" in err and "40 of them in a second process" in err
    secs = float(err.split("compiled 41 functions in ")[1].split(" s")[0])
    assert secs >= 2.5  # the wait for the second process is compile time on this clock


@pytest.mark.slow
def test_second_process_fills_the_cache_that_this_process_then_loads(no_parts_loaded, tmp_path,
                                                                     monkeypatch):
    import os
    import subprocess
    import sys

    cache = tmp_path / "cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))
    monkeypatch.delenv("ANYPLAN_COMPILE_JOBS", raising=False)
    job = no_parts_loaded._Prefetch(("motion",))
    job.finish(timeout_s=600)
    assert job.ok and job.count > 10 and job.seconds > 0.0
    assert any(f.suffix == ".nbc" for f in cache.rglob("*"))
    probe = ("from anyplan.agents.warmup import compiling_notifier, warm_up_kernels\n"
             "with compiling_notifier(None) as n: warm_up_kernels(['motion'])\n"
             "print(n.count)")
    out = subprocess.run([sys.executable, "-c", probe], env=dict(os.environ), capture_output=True,
                         text=True, timeout=600, check=True)
    assert out.stdout.strip() == "0"  # everything loaded from the cache the second process wrote


def _kernel_modules_after(code: str) -> list[str]:
    """The modules of anyplan's compiled kernels that hold code (compiled or loaded) after
    ``code`` runs in a fresh process."""
    import subprocess
    import sys

    probe = (
        "import sys\n" + code +
        "from numba.core.registry import CPUDispatcher\n"
        "used = set()\n"
        "for name, mod in list(sys.modules.items()):\n"
        "    if name.startswith('anyplan.'):\n"
        "        for attr in vars(mod).values():\n"
        "            if isinstance(attr, CPUDispatcher) and attr.signatures:\n"
        "                used.add(attr.py_func.__module__)\n"
        "print(' '.join(sorted(used)))\n")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=600, check=True)
    return out.stdout.split()


def test_stmap_part_loads_no_kernel_of_the_motion_part():
    """The s-t map part runs while a second process compiles the motion part (the parts' order
    in PARTS puts it first): it must not need that part's kernels, or it would compile them again
    on this side."""
    used = _kernel_modules_after("from anyplan.agents.warmup import warm_up_kernels\n"
                                 "warm_up_kernels(['stmap'])\n")
    assert "anyplan.trajectory.spacetime.stmap" in used  # the probe sees what ran
    assert "anyplan.trajectory.spacetime._lattice_kernels" in used
    motion = [m for m in used if m.startswith(("anyplan.trajectory.spline", "anyplan.trajectory.profile",
                                               "anyplan.trajectory.brake", "anyplan.trajectory.turn",
                                               "anyplan.trajectory._path"))]
    assert motion == []
    assert PARTS.index("stmap") < PARTS.index("motion")


def test_motion_part_compiles_its_curve_kernels_before_any_clearance_kernel():
    """A second process compiling the motion part on a cold cache starts with the kernels that
    query no obstacle (``_curves``), so that it meets the clearance kernels only once this
    process, which compiles them first (scenario loading, BIT*), has put them in the cache."""
    used = _kernel_modules_after("import numpy as np\n"
                                 "import anyplan.agents.warmup as wu\n"
                                 "obs, spec = wu._scene()\n"
                                 "wu._curves(spec, np.array([[0.5, 0.5], [3.0, 1.2], [3.5, 3.5]]))\n")
    assert {"anyplan.trajectory.spline._fit", "anyplan.trajectory.profile",
            "anyplan.trajectory.spline._drive"} <= set(used)
    assert not [m for m in used if m.startswith("anyplan.geometry")]
