"""The viz modules leave matplotlib's backend alone; only the command line picks Agg, and only
when the user chose none. Each case runs in a fresh interpreter."""

from __future__ import annotations

import os
import subprocess
import sys

IMPORT_ALL = """
import importlib, pkgutil, sys
import matplotlib
matplotlib.use("svg")
before = matplotlib.get_backend()
import anyplan.viz
names = [m.name for m in pkgutil.iter_modules(anyplan.viz.__path__, "anyplan.viz.")]
for name in names:
    importlib.import_module(name)
assert len(names) >= 6, names
print(before, matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
"""

CLI = """
import matplotlib
from anyplan.cli.main import main
main(["scenarios"])
print(matplotlib.get_backend().lower())
"""


CLI_LATE = """
import sys
from anyplan.cli.main import main
main(["scenarios"])
assert "matplotlib" not in sys.modules  # a command that does not draw never imports it
import matplotlib
print(matplotlib.get_backend().lower())
"""


def _run(code: str, **env: str) -> str:
    e = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    e.update(env)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=e,
                         timeout=300, check=True)
    return out.stdout.strip().splitlines()[-1]


def test_importing_every_viz_module_keeps_the_backend():
    assert _run(IMPORT_ALL) == "svg svg False"


def test_the_command_line_picks_agg_only_when_none_was_chosen():
    assert _run(CLI) == "agg"
    assert _run(CLI, MPLBACKEND="svg") == "svg"


def test_the_command_line_imports_matplotlib_only_to_draw_and_then_picks_agg():
    assert _run(CLI_LATE) == "agg"
    assert _run(CLI_LATE, MPLBACKEND="svg") == "svg"
