"""Scenario suites for ``anyplan bench``: named sets of scenarios.

``resolve_suite`` accepts:

* ``paper``: the built-in ``paper-1``, ``paper-2``, ``paper-3`` (1, 2 and 3 moving obstacles);
* ``random``: generated scenarios (:mod:`anyplan.experiments.generate`), ``per_count`` for each
  number of moving obstacles 1-6, from ``random_seed``;
* ``gaps``: 20 x ``per_count`` gap worlds (:mod:`anyplan.experiments.gaps`) from ``random_seed``;
* a folder: every ``*.yaml`` / ``*.yml`` file in it, sorted by name;
* a comma-separated list of scenario files or built-in names.

The named suites are entries of the registry :data:`SUITES`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from anyplan.errors import AnyplanError
from anyplan.experiments.generate import random_suite
from anyplan.registry import Registry
from anyplan.world.scenario import Scenario, load_scenario

__all__ = ["resolve_suite", "suite_size", "PAPER_SUITE", "SUITES", "GENERATED", "SuiteError"]

PAPER_SUITE = ("paper-1", "paper-2", "paper-3")


class SuiteError(AnyplanError):
    """A suite cannot be resolved to scenarios."""


def _paper(random_seed: int, per_count: int) -> list[Scenario]:
    return [load_scenario(n) for n in PAPER_SUITE]


def _random(random_seed: int, per_count: int) -> list[Scenario]:
    if per_count < 1:
        raise SuiteError.about("per_count", f" must be >= 1, got {per_count}")
    return random_suite(random_seed, per_count=per_count)


def _gaps(random_seed: int, per_count: int) -> list[Scenario]:
    from anyplan.experiments.gaps import gap_suite

    return gap_suite(random_seed, n=20 * per_count)


#: Named suites: name -> ``(random_seed, per_count) -> scenarios``.
SUITES: Registry[Callable[[int, int], list[Scenario]]] = Registry("suite")
SUITES.register("paper", _paper)
SUITES.register("random", _random)
SUITES.register("gaps", _gaps)
#: How many scenarios a named suite has for a ``per_count``, known before it is built.
_SIZES: dict[str, Callable[[int], int]] = {
    "paper": lambda per_count: len(PAPER_SUITE),
    "random": lambda per_count: 6 * per_count,  # numbers of moving obstacles 1-6
    "gaps": lambda per_count: 20 * per_count,
}
#: The named suites generated from ``random_seed`` and ``per_count``; every other suite reads neither.
GENERATED = ("random", "gaps")


def suite_size(suite: str, per_count: int = 1) -> int | None:
    """How many scenarios :func:`resolve_suite` returns for a named suite, computed without
    building it (to refuse a bench that is too large before generating it); None for a folder,
    a list or a suite whose size is not known in advance."""
    size = _SIZES.get(suite)
    return size(per_count) if size is not None and suite in SUITES else None


def resolve_suite(suite: str, random_seed: int = 0, per_count: int = 1) -> list[Scenario]:
    """The scenarios of ``suite`` (see the module docstring).

    Raises:
        SuiteError: an empty name, folder or list, or two scenarios with one name.
        ScenarioError, UnknownNameError: a file or name that does not load.
    """
    if not suite.strip():  # Path("") is the current folder: never read it by accident
        raise SuiteError.about("suite", ": empty (no suite name, folder, scenario names or files)")
    if suite in SUITES:
        scenarios = SUITES.get(suite)(random_seed, per_count)
    elif Path(suite).is_dir():
        files = sorted(p for p in Path(suite).iterdir() if p.suffix in (".yaml", ".yml"))
        if not files:
            raise SuiteError(f"suite folder '{suite}' holds no .yaml scenario files")
        scenarios = [load_scenario(p) for p in files]
    else:
        items = [s.strip() for s in suite.split(",") if s.strip()]
        if not items:
            raise SuiteError.about("suite", ": empty (no scenario names or files)")
        scenarios = [load_scenario(s) for s in items]
    seen: dict[str, str] = {}
    for sc in scenarios:
        h = sc.content_hash()
        if sc.name in seen and seen[sc.name] != h:
            raise SuiteError(f"two different scenarios are named '{sc.name}' ({sc.source})")
        seen[sc.name] = h
    # Drop exact duplicates (same name and content), keep order.
    out, keys = [], set()
    for sc in scenarios:
        k = (sc.name, sc.content_hash())
        if k not in keys:
            keys.add(k)
            out.append(sc)
    return out
