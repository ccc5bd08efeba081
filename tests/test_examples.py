"""The examples run as documented."""

from __future__ import annotations

import runpy
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_custom_agent_example_compares_with_seq_bitstar(capsys):
    mod = runpy.run_path(str(EXAMPLES / "custom_agent.py"))
    mod["main"]()
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 6
    seq = [ln for ln in lines if "seq-bitstar" in ln]
    assert len(seq) == 3 and all(" reached " in ln for ln in seq)
    # The custom agent is a registered planner like any other.
    from anyplan.agents import AGENTS

    assert "cautious-straight" in AGENTS
