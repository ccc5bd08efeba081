"""Fixtures of the experiments tests: a tiny scenario file and test-only agents."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

import anyplan_bench_test_agents as agents

agents.register_all()


@pytest.fixture
def tiny_file(tmp_path: Path) -> Path:
    p = tmp_path / "tiny.yaml"
    p.write_text(yaml.safe_dump(agents.TINY))
    return p
