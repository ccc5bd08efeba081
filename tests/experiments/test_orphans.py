"""Workers die with the bench: after a SIGKILL of the main process, no worker and no resource
tracker keeps running."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
SLOW_RUN = {"name": "crawl", "time_limit": 3600.0, "arena": {"width": 10.0, "height": 3.0},
            "robot": {"start": [0.5, 1.5, 0.0], "goal": [9.5, 1.5], "radius": 0.2, "v_max": 0.001,
                      "omega_max": 1.0, "a_max": 2.0, "alpha_max": 2.0}}


def _children(pid: int) -> list[int]:
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_and_resource_tracker_die_with_a_killed_bench(tmp_path):
    sc = tmp_path / "crawl.yaml"
    sc.write_text(yaml.safe_dump(SLOW_RUN))
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    p = subprocess.Popen([sys.executable, "-m", "anyplan", "bench", "--suite", str(sc), "--planners",
                          "straight", "--runs", "4", "--jobs", "2", "--no-progress", "--db",
                          str(tmp_path / "r.db")], env=env, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    kids: list[int] = []
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and len(kids) < 3:  # two workers + the resource tracker
            time.sleep(0.5)
            kids = _children(p.pid)
        assert len(kids) >= 2, f"the bench started {len(kids)} child processes"
        p.send_signal(signal.SIGKILL)
        p.wait(timeout=30)
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline and any(_alive(k) for k in kids):
            time.sleep(0.2)
        left = [k for k in kids if _alive(k)]
        assert not left, f"still running after the bench was killed: {left}"
    finally:  # leave nothing behind, whatever happened
        for k in set(kids) | (set(_children(p.pid)) if p.poll() is None else set()):
            if _alive(k):
                os.kill(k, signal.SIGKILL)
        if p.poll() is None:
            p.kill()
