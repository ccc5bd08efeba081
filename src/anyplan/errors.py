"""Exceptions raised by anyplan for bad input."""

from __future__ import annotations

__all__ = ["AnyplanError", "ScenarioError", "UnknownNameError"]


class AnyplanError(Exception):
    """Base class of anyplan's input errors; its message is one line, fit for a user."""


class ScenarioError(AnyplanError, ValueError):
    """A scenario file or dictionary is malformed.

    Attributes:
        source: The file (or "<dict>") the scenario came from.
        field: Dotted path of the offending field, e.g. ``robot.radius``.
    """

    def __init__(self, source: str, field: str, message: str) -> None:
        self.source = source
        self.field = field
        self.message = message
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {message}")


class UnknownNameError(AnyplanError, KeyError):
    """A name (planner, scenario, ...) is not registered."""

    def __init__(self, kind: str, name: str, known: list[str]) -> None:
        import difflib

        self.kind = kind
        self.name = name
        close = difflib.get_close_matches(name, known, n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        msg = f"unknown {kind} '{name}'{hint} (known: {', '.join(sorted(known))})"
        super().__init__(msg)

    def __str__(self) -> str:
        return str(self.args[0])
