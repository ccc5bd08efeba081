"""Agent options shared by ``anyplan run`` and ``anyplan bench``: ``--set`` and ``--deterministic``."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import Any

from anyplan.agents.base import AGENTS
from anyplan.agents.settings import SettingsError, agent_settings, build_agent_config, parse_set_options

__all__ = ["add_agent_options", "run_config", "bench_configs"]

SET_HELP = ("agent setting, e.g. --set planning_delay=0.1 (repeatable; VALUE is read as YAML: "
            "0.1, 2, true, null, measured; 'anyplan planners --settings' lists the keys)")
DET_HELP = ("same result for the same seed on any machine: for seq-bitstar a fixed planning delay "
            "(planning_delay=0.1), a batch budget (batches_per_plan=2) instead of a time budget and "
            "max_time_s=10, for st-bitstar also no search budgets (search_budget_s=null, "
            "improve_budget_s=null); --set "
            "overrides any of them")


def add_agent_options(p: argparse.ArgumentParser, bench: bool = False) -> None:
    """Add ``--set`` and ``--deterministic`` to parser ``p``."""
    extra = (" With several planners, PLANNER:KEY=VALUE sets one planner's; a plain KEY=VALUE "
             "goes to every listed planner that has that setting.") if bench else ""
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="set_options",
                   help=SET_HELP + extra)
    p.add_argument("--deterministic", action="store_true", help=DET_HELP)


def run_config(args: argparse.Namespace, planner: str) -> dict[str, Any]:
    """The keyword config of ``planner`` from ``--set`` and ``--deterministic``."""
    cls = AGENTS.get(planner)
    return build_agent_config(cls, planner, parse_set_options(args.set_options), args.deterministic)


def bench_configs(args: argparse.Namespace, planners: Sequence[str],
                  base: dict[str, dict[str, Any]] | None = None,
                  source: str = "--planners") -> dict[str, dict[str, Any]]:
    """Per-planner keyword configs from ``--set [PLANNER:]KEY=VALUE`` and ``--deterministic``,
    on top of ``base`` (e.g. ``--config``, checked by
    :func:`~anyplan.experiments.runner.check_planner_config`);
    ``source`` names where the planners come from in the error messages (a benchmark with a
    fixed list has no ``--planners``)."""
    base = base or {}
    per: dict[str, list[str]] = {p: [] for p in planners}
    for item in args.set_options:
        head, sep, _ = item.partition("=")
        name, colon, key = head.partition(":")
        if sep and colon:
            name = name.strip()
            if name not in per:
                raise SettingsError(f"--set {item}: planner '{name}' is not in {source} "
                                    f"({', '.join(planners)})")
            per[name].append(item.split(":", 1)[1])
            continue
        key = head.strip()
        takers = [p for p in planners if key in agent_settings(AGENTS.get(p))]
        if not takers:
            if len(planners) == 1:
                takers = list(planners)  # the unknown-key error, with its hint, comes below
            else:
                raise SettingsError(f"--set {item}: no planner in {source} ({', '.join(planners)}) "
                                    f"has a setting '{key}'")
        for p in takers:
            per[p].append(item)
    out = {}
    for p in planners:
        opts = parse_set_options(per[p])
        checked = build_agent_config(AGENTS.get(p), p, opts, args.deterministic) \
            if opts or args.deterministic else {}
        out[p] = {**base.get(p, {}), **checked}
    return out
