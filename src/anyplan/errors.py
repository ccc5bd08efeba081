"""Exceptions raised by anyplan for bad input, and the check every layer makes of a number.

Library errors name fields and parameters (``runs``, ``SimConfig.dt``), not command-line flags;
the command line (:mod:`anyplan.cli.main`) maps them to its flags when it reports them.
:func:`finite_float` checks that a user's value is a finite number within bounds; its callers
(agent settings, scenario fields, worlds files, import options) tell its refusal with their own
error type and field name.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Literal, Self

__all__ = ["AnyplanError", "ScenarioError", "UnknownNameError", "UsageError", "one_line", "shorten",
           "MAX_MESSAGE_CHARS", "NumberRefused", "finite_float"]

#: Longest error line printed by the command line [characters].
MAX_MESSAGE_CHARS = 400


def one_line(text: object, limit: int = MAX_MESSAGE_CHARS) -> str:
    r"""``text`` as one bounded line: control characters (newlines, tabs, ...) escaped as
    ``\n``-style sequences, and the middle cut out (``...``) beyond ``limit`` characters."""
    s = str(text)
    if len(s) > 4 * limit:  # escape only what can be shown
        s = s[: 2 * limit] + s[-2 * limit:]
    s = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii")
                for ch in s)
    if len(s) > limit:
        keep = max(limit - 3, 2)
        s = s[: keep - keep // 3] + "..." + s[len(s) - keep // 3:]
    return s


def shorten(value: object, limit: int = 40) -> str:
    """A user's value quoted in an error message: its repr, one line, at most ``limit`` chars."""
    try:
        s = repr(value) if not isinstance(value, str) else repr(value[: 4 * limit])
    except Exception:  # noqa: BLE001 - a repr that fails is still reported
        s = f"<{type(value).__name__}>"
    return one_line(s, limit)


class NumberRefused(ValueError):
    """Why :func:`finite_float` refused a value; its caller raises its own error from it.

    Attributes:
        kind: ``"type"`` (not an int or float, or a bool), ``"overflow"`` (an int beyond the
            float range), ``"nonfinite"`` (nan or inf), ``"low"`` or ``"high"`` (out of bounds).
        shown: The value as a message shows it: ``f"{x:g}"`` of its float, else its
            :func:`shorten` (``"type"``, ``"overflow"``).

    Its message is the reason without a field name, e.g. ``must be > 0, got -1``.
    """

    def __init__(self, kind: Literal["type", "overflow", "nonfinite", "low", "high"], reason: str,
                 shown: str) -> None:
        super().__init__(reason)
        self.kind = kind
        self.shown = shown


def finite_float(value: object, lo: float = -math.inf, hi: float = math.inf, *,
                 lo_open: bool = False, hi_open: bool = False) -> float:
    """``value`` as a float when it is an int or float (not a bool), finite, >= ``lo`` (> ``lo``
    with ``lo_open``) and <= ``hi`` (< ``hi`` with ``hi_open``); the bounds are in the value's
    own unit.

    Raises:
        NumberRefused: anything else (its ``kind`` tells why, its message names no field).

    Examples:
        >>> finite_float(2, lo=0.0, lo_open=True)
        2.0
        >>> for bad in (True, "1", 10**400, math.nan, -math.inf, 0.0):
        ...     try:
        ...         finite_float(bad, lo=0.0, lo_open=True)
        ...     except NumberRefused as exc:
        ...         print(f"{exc.kind}: {exc}")
        type: expected a number, got True
        type: expected a number, got '1'
        overflow: number too large (beyond the floating-point range)
        nonfinite: must be finite, got nan
        nonfinite: must be finite, got -inf
        low: must be > 0, got 0
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        shown = shorten(value)
        raise NumberRefused("type", f"expected a number, got {shown}", shown)
    try:
        x = float(value)
    except OverflowError:  # an int of hundreds of digits
        raise NumberRefused("overflow", "number too large (beyond the floating-point range)",
                            shorten(value)) from None
    if not math.isfinite(x):
        raise NumberRefused("nonfinite", f"must be finite, got {x:g}", f"{x:g}")
    if x < lo or (lo_open and x == lo):
        raise NumberRefused("low", f"must be {'>' if lo_open else '>='} {lo:g}, got {x:g}", f"{x:g}")
    if x > hi or (hi_open and x == hi):
        raise NumberRefused("high", f"must be {'<' if hi_open else '<='} {hi:g}, got {x:g}", f"{x:g}")
    return x


class AnyplanError(Exception):
    """Base class of anyplan's input errors; its message is one line, fit for a user.

    An error made by :meth:`about` concerns one input, named by a field or parameter name
    (``subject``, e.g. ``runs``), never by a command-line flag: the message is ``subject`` then
    ``rest``. The command line tells it with its flag instead (:meth:`told_with`).
    """

    #: The field or parameter the message is about (None: not about one input).
    subject: str | None = None
    #: The message after the subject, e.g. ``" must be >= 1, got 0"`` or ``": not JSON"``.
    rest: str = ""
    #: Other inputs named in ``rest`` (as ``{name}``).
    also: tuple[str, ...] = ()

    @classmethod
    def about(cls, subject: str, rest: str, *also: str) -> Self:
        """An error about input ``subject``; ``rest`` starts with ``": "`` or ``" "``. Other
        inputs it names are listed in ``also`` and written ``{name}`` in ``rest``."""
        exc = cls(subject + (rest.format(**{a: a for a in also}) if also else rest))
        exc.subject, exc.rest, exc.also = subject, rest, also
        return exc

    def told_with(self, names: Mapping[str, str]) -> str:
        """The message, with its subject (and the inputs in ``also``) told by ``names[...]``
        (e.g. a command-line flag) where ``names`` has them."""
        if self.subject is None:
            return str(self)
        rest = self.rest.format(**{a: names.get(a, a) for a in self.also}) if self.also else self.rest
        return names.get(self.subject, self.subject) + rest


class UsageError(AnyplanError):
    """Bad command-line input detected after parsing (exit code 2)."""


class ScenarioError(AnyplanError, ValueError):
    """A scenario file or dictionary is malformed.

    Attributes:
        source: The file (or "<dict>") the scenario came from.
        field: Dotted path of the offending field, e.g. ``robot.radius``.
        obstacle: The name of the static obstacle the field's value runs into (a start inside
            one), or None.
    """

    def __init__(self, source: str, field: str, message: str, obstacle: str | None = None) -> None:
        self.source = source
        self.field = field
        self.message = message
        self.obstacle = obstacle
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
