"""``anyplan planners``: the planners available here, built-in and from plugins."""

from __future__ import annotations

import argparse

from anyplan.agents.base import AGENTS
from anyplan.agents.settings import agent_settings
from anyplan.registry import LoadError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``planners`` sub-command."""
    p = sub.add_parser("planners", help="list the planners (built-in and plugins) and their settings",
                       description="List every planner that --planner/--planners accept: the built-in "
                       "ones and those of installed plugins (entry-point group 'anyplan.agents').")
    p.add_argument("--settings", action="store_true",
                   help="also list each planner's settings (for --set KEY=VALUE) with defaults")
    p.set_defaults(func=cmd_planners)


def cmd_planners(args: argparse.Namespace) -> int:
    """Print the planners; exit code 1 when a plugin cannot be loaded."""
    broken = 0
    for name in AGENTS.names():
        try:
            cls = AGENTS.get(name)
        except LoadError as exc:
            print(f"{name:18s} BROKEN: {exc}")
            broken += 1
            continue
        doc = ((cls.__doc__ or "").strip().splitlines() or [""])[0]
        det = " [deterministic mode]" if getattr(cls, "deterministic_settings", None) is not None else ""
        print(f"{name:18s} {AGENTS.origin(name)}: {doc}{det}")
        if args.settings:
            for s in agent_settings(cls).values():
                print(f"    {s.line()}")
    return 1 if broken else 0
