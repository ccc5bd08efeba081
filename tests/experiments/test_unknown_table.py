"""benchmarks/unknown.py's summary table: the success interval and the robot-caused collisions
with obstacles seen in time."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from anyplan.experiments.significance import wilson_interval

PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "unknown.py"


def _module():
    spec = importlib.util.spec_from_file_location("unknown_bench", PATH)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_table_counts_and_interval():
    def row(status, caused=False, late=None):
        return {"suite": "crowds", "mode": "tracked", "planner": "st-bitstar", "scenario": "w",
                "seed": 0, "status": status, "robot_caused": caused, "appeared_within_stop": late,
                "min_dist": 0.1, "discomfort": 0.0, "t_over_lb": 1.2, "times": [0.01]}

    rows = ([row("reached")] * 7 + [row("collision", True, True), row("collision", True, False),
                                     row("collision", False, None), row("timeout")])
    line = _module()._table(rows).splitlines()[2]
    lo, hi = wilson_interval(7, 11)
    # 11 runs, 7 reached; 3 collisions, 2 robot-caused, 1 of them with a person seen in time
    assert line.startswith(f"| crowds | tracked | st-bitstar | 7/11 ({lo:.2f}-{hi:.2f}) | 3 | 2 | 1 | ")
