"""Agents from other packages, found through the entry-point group ``anyplan.agents``.

A package makes its agent a planner like the built-in ones by declaring, in its
``pyproject.toml``::

    [project.entry-points."anyplan.agents"]
    my-planner = "my_package.agent:MyAgent"

Once that package is installed, ``my-planner`` is listed by ``anyplan planners`` and works with
``anyplan run --planner my-planner``, ``anyplan bench --planners my-planner,seq-bitstar``,
:func:`~anyplan.agents.make_agent` and the reports. The class must subclass
:class:`~anyplan.agents.Agent`. Entry points are read (with :mod:`importlib.metadata`) on the
first look-up of a planner name, but a plugin's module is imported only when that planner is
asked for; a module that fails to import is reported in one line naming the plugin and its
package (:class:`~anyplan.registry.LoadError`). A plugin may not take a built-in's name (it is
skipped, with a warning); when two packages declare the same name, the first found wins.
"""

from __future__ import annotations

import logging
from importlib import metadata
from typing import Any

__all__ = ["ENTRY_POINT_GROUP", "discover_plugins"]

#: The entry-point group that third-party agents register under.
ENTRY_POINT_GROUP = "anyplan.agents"

log = logging.getLogger(__name__)


def _entry_points() -> list[Any]:
    return list(metadata.entry_points(group=ENTRY_POINT_GROUP))


def discover_plugins(registry: Any) -> list[str]:
    """Register every ``anyplan.agents`` entry point in ``registry`` (lazily, by its
    ``module:attr`` value); returns the names added."""
    added = []
    for ep in _entry_points():
        dist = getattr(ep, "dist", None)
        where = f"plugin from {dist.name} {dist.version}" if dist is not None else "plugin"
        if ":" not in ep.value:
            log.warning("%s: entry point %s = %s ignored: expected 'module:Class'", where, ep.name,
                        ep.value)
            continue
        try:
            registry.register(ep.name, ep.value, origin=where)
        except ValueError:
            log.warning("%s: entry point %s = %s ignored: the name is taken", where, ep.name, ep.value)
            continue
        added.append(ep.name)
    return added
