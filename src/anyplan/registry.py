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
from typing import Any, Generic, TypeVar

from anyplan.errors import AnyplanError, UnknownNameError

__all__ = ["Registry", "LoadError"]

T = TypeVar("T")


class LoadError(AnyplanError, ImportError):
    """A registered lazy entry (e.g. a plugin) cannot be imported; the message is one line."""


class Registry(Generic[T]):
    """A mapping of names to objects that rejects duplicates and suggests near misses."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._entries: dict[str, T | str] = {}
        self._origins: dict[str, str] = {}
        self._discover: Callable[[Registry[T]], None] | None = None

    def set_discovery(self, fn: Callable[[Registry[T]], None]) -> None:
        """Call ``fn(self)`` once, before the first look-up (e.g. to add plugins' entries)."""
        self._discover = fn

    def _discovered(self) -> None:
        fn, self._discover = self._discover, None
        if fn is not None:
            fn(self)

    def origin(self, name: str) -> str:
        """Where ``name`` comes from: ``"built-in"`` or what :meth:`register` was told."""
        self._discovered()
        return self._origins.get(name, "built-in")

    def register(self, name: str, obj: T | str, origin: str | None = None) -> None:
        """Register ``obj`` (or a lazy ``"module:attr"`` string) under ``name``; ``origin`` says
        where it comes from (default: built-in)."""
        if name in self._entries:
            raise ValueError(f"{self.kind} '{name}' is already registered")
        self._entries[name] = obj
        if origin is not None:
            self._origins[name] = origin

    def decorator(self, name: str) -> Callable[[T], T]:
        """Class decorator form of :meth:`register`."""
        def deco(obj: T) -> T:
            self.register(name, obj)
            return obj
        return deco

    def get(self, name: str) -> T:
        """The object registered under ``name``; :class:`UnknownNameError` otherwise, and
        :class:`LoadError` (one line) when a lazy entry cannot be imported."""
        self._discovered()
        if name not in self._entries:
            raise UnknownNameError(self.kind, name, list(self._entries))
        entry = self._entries[name]
        if isinstance(entry, str):
            mod, _, attr = entry.partition(":")
            try:
                obj: Any = importlib.import_module(mod)
                for part in attr.split(".") if attr else ():
                    obj = getattr(obj, part)
            except Exception as exc:  # noqa: BLE001 - any failure of third-party code at import
                where = self._origins.get(name, "built-in")
                first = (str(exc).splitlines() or [""])[0]
                raise LoadError(f"{self.kind} '{name}' ({where}: {entry}) cannot be loaded: "
                                f"{type(exc).__name__}: {first}") from None
            entry = obj
            self._entries[name] = entry
        return entry

    def names(self) -> list[str]:
        """Registered names, in registration order."""
        self._discovered()
        return list(self._entries)

    def __contains__(self, name: object) -> bool:
        self._discovered()
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        self._discovered()
        return iter(self._entries)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {self.names()!r})"


