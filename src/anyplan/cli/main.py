"""``anyplan``: argument parsing only; every command calls library functions.

Each sub-command lives in its own module listed in :data:`COMMAND_MODULES`; a module provides
``register(subparsers)`` which adds its parser and sets ``func`` (``args -> int``) as default.

Bad input (an unknown scenario or planner, a malformed scenario file, a bad option value) ends
with exit code 2 and one line on stderr, ``anyplan: error: ...``, never a traceback. Library
errors name fields and parameters; :data:`FLAGS` tells them with the flags that set them.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
from collections.abc import Sequence

from anyplan import __version__
from anyplan.errors import AnyplanError, UsageError, one_line
from anyplan.viz.backend import pick_headless_backend

__all__ = ["main", "COMMAND_MODULES", "UsageError", "FLAGS"]

#: Library field and parameter names (:attr:`AnyplanError.subject`) -> the flags that set them.
FLAGS = {"runs": "--runs", "jobs": "--jobs", "planners": "--planners", "config": "--config",
         "scheduler": "--scheduler", "per_count": "--random-count", "suite": "--suite",
         "setting": "--set", "deterministic": "--deterministic", "budget_s": "--budget",
         "ompl": "--ompl", "mcap": "--mcap", "source": "--source", "worlds_file": "--worlds-file",
         "worlds": "--worlds", "window_s": "--window", "step_s": "--step", "margin_m": "--margin",
         "edge_m": "--edge", "sensing_range_m": "--sensing-range", "noise_m": "--sensor-noise",
         "rate_hz": "--sensor-rate", "copies": "--copies", "copy_shift_s": "--copy-shift",
         "name": "--name", **{f"robot_{k}": f"--robot-{k.replace('_', '-')}" for k in (
             "radius", "v_max", "omega_max", "a_max", "alpha_max", "goal_tolerance")}}

#: Modules that each register one or more sub-commands.
COMMAND_MODULES = [
    "anyplan.cli.cmd_run",
    "anyplan.cli.cmd_bench",
    "anyplan.cli.cmd_dynabarn",
    "anyplan.cli.cmd_barn",
    "anyplan.cli.cmd_crowd",
    "anyplan.cli.cmd_plan",
    "anyplan.cli.cmd_dovs",
    "anyplan.cli.cmd_planners",
]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit with code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(one_line(f"anyplan: error: {self.prog}: {message}") + "\n")
        sys.exit(2)


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser."""
    parser = _Parser(prog="anyplan", description="Motion planning among static and moving "
                     "obstacles: Sequential BIT*, BIT*, DOVS and friends.")
    parser.add_argument("--version", action="version", version=f"anyplan {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more log output (repeat for debug)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for mod in COMMAND_MODULES:
        importlib.import_module(mod).register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (0 success, 1 failure, 2 bad input, 130
    interrupted, 141 its output's reader gone: ``anyplan bench ... | head``)."""
    pick_headless_backend()  # Agg for the commands that draw, unless the user chose a backend
    # logging first: building the parser finds the plugins, whose refusals are warnings
    configured = not logging.getLogger().handlers
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    parser = build_parser()
    args = parser.parse_args(argv)
    if configured:  # an application that set up logging keeps its level
        logging.getLogger().setLevel(logging.WARNING - 10 * min(args.verbose, 2))
    try:
        code = int(args.func(args))
        sys.stdout.flush()  # a reader gone early (| head) is met here, not at the interpreter's exit
        return code
    except BrokenPipeError:
        # Stop quietly, as a command killed by SIGPIPE does (Python ignores the signal and
        # raises instead); what is still buffered goes nowhere, not to another error at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 128 + 13  # SIGPIPE
    except AnyplanError as exc:
        sys.stderr.write(one_line(f"anyplan: error: {exc.told_with(FLAGS)}") + "\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("anyplan: interrupted\n")
        return 130


if __name__ == "__main__":  # python -m anyplan.cli.main, as python -m anyplan
    sys.exit(main())
