"""Name registries: planners and other components are selected by name.

Entries are either objects or lazy ``"module:attribute"`` strings, imported on first use so that
registering a heavy component costs nothing until it is asked for.

Examples:
    >>> reg = Registry("widget")
    >>> reg.register("a", "math:sqrt")
    >>> reg.get("a")(4.0)
    2.0
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator
from typing import Generic, TypeVar

from anyplan.errors import UnknownNameError

__all__ = ["Registry"]

T = TypeVar("T")


class Registry(Generic[T]):
    """A mapping of names to objects that rejects duplicates and suggests near misses."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._entries: dict[str, T | str] = {}

    def register(self, name: str, obj: T | str) -> None:
        """Register ``obj`` (or a lazy ``"module:attr"`` string) under ``name``."""
        if name in self._entries:
            raise ValueError(f"{self.kind} '{name}' is already registered")
        self._entries[name] = obj

    def decorator(self, name: str) -> Callable[[T], T]:
        """Class decorator form of :meth:`register`."""
        def deco(obj: T) -> T:
            self.register(name, obj)
            return obj
        return deco

    def get(self, name: str) -> T:
        """The object registered under ``name``; :class:`UnknownNameError` otherwise."""
        if name not in self._entries:
            raise UnknownNameError(self.kind, name, list(self._entries))
        entry = self._entries[name]
        if isinstance(entry, str):
            mod, _, attr = entry.partition(":")
            entry = getattr(importlib.import_module(mod), attr)
            self._entries[name] = entry
        return entry  # type: ignore[return-value]

    def names(self) -> list[str]:
        """Registered names, in registration order."""
        return list(self._entries)

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {self.names()!r})"


