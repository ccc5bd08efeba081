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
    assert make_agent("seq-bitstar").kernel_parts == PARTS
    assert make_agent("bitstar").kernel_parts == ("bitstar", "motion")
    assert not getattr(make_agent("dovs"), "kernel_parts", ())


def test_run_says_nothing_about_compiling_when_the_kernels_are_loaded(tmp_path, capsys):
    warm_up_kernels()  # everything loaded (or compiled) in this process before the command
    assert main(["run", "paper-1", "--planner", "bitstar", "--out", str(tmp_path), "--no-plot"]) in (0, 1)
    err = capsys.readouterr().err
    assert "compiling" not in err and "minute" not in err
