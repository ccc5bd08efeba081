"""Settings dataclasses: one validation helper, driven by field metadata, that can also list them.

A settings field declares its range, choices, unit and description once, with :func:`setting`;
:func:`validate` (called from the dataclass's ``__post_init__``) checks every such field against
its annotated type and its metadata, and :func:`describe` lists them (``anyplan planners
--settings``). Errors are :class:`SettingError`: they name the settings class and the field,
never a command-line flag (the command line maps fields to its flags when it reports).
This module imports only :mod:`anyplan.errors`, so that every layer may use it.

Examples:
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Demo:
    ...     dt: float = setting(0.05, lo=0.001, hi=0.05, unit="s", doc="step")
    ...     def __post_init__(self) -> None:
    ...         validate(self)
    >>> try:
    ...     Demo(dt=1.0)
    ... except SettingError as exc:
    ...     print(exc)
    Demo.dt: must be in [0.001, 0.05] s, got 1.0
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from anyplan.errors import AnyplanError, NumberRefused, finite_float, shorten

__all__ = ["SettingError", "Spec", "FieldInfo", "setting", "spec_of", "validate", "describe",
           "type_name"]

_KEY = "anyplan.setting"


class SettingError(AnyplanError, ValueError):
    """A setting has a bad value.

    Attributes:
        owner: The settings class (e.g. ``SimConfig``; empty when the message has no owner).
        field: The field's name.
        problem: What is wrong, e.g. ``must be > 0, got -1``.
    """

    def __init__(self, owner: str, field: str, problem: str) -> None:
        self.owner = owner
        self.field = field
        self.problem = problem
        super().__init__(f"{owner}.{field}: {problem}" if owner else f"{field}: {problem}")


@dataclass(frozen=True)
class Spec:
    """What a field accepts: ``lo``/``hi`` bounds (open or closed), ``choices``, and its ``unit``
    and ``doc`` for listings. A bound of an ``int`` field is inclusive."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple[Any, ...] | None = None
    unit: str = ""
    doc: str = ""

    def range_text(self) -> str:
        """The range in words, e.g. ``> 0``, ``in [1, 1001]`` (empty without bounds)."""
        if self.lo is not None and self.hi is not None:
            left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
            return f"in {left}{self.lo:g}, {self.hi:g}{right}"
        if self.lo is not None:
            return f"{'>' if self.lo_open else '>='} {self.lo:g}"
        if self.hi is not None:
            return f"{'<' if self.hi_open else '<='} {self.hi:g}"
        if self.choices is not None:
            return "one of " + ", ".join(str(c) for c in self.choices)
        return ""


def setting(default: Any = dataclasses.MISSING, *, default_factory: Any = dataclasses.MISSING,
            lo: float | None = None, hi: float | None = None, lo_open: bool = False,
            hi_open: bool = False, choices: Sequence[Any] | None = None, unit: str = "",
            doc: str = "") -> Any:
    """A dataclass field with its :class:`Spec` in the metadata (see the module docstring)."""
    spec = Spec(lo, hi, lo_open, hi_open, None if choices is None else tuple(choices), unit, doc)
    if default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=default_factory, metadata={_KEY: spec})
    return dataclasses.field(default=default, metadata={_KEY: spec})


def spec_of(f: dataclasses.Field[Any]) -> Spec | None:
    """The :class:`Spec` of field ``f`` (None: declared without :func:`setting`)."""
    return f.metadata.get(_KEY)


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls: type) -> dict[str, Any]:
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


def _kinds(hint: Any) -> tuple[set[Any], bool]:
    """The scalar types a hint allows, and whether None is allowed."""
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
        kinds: set[Any] = set()
        for a in args:
            if a is not type(None):
                kinds |= _kinds(a)[0]
        return kinds, type(None) in args
    if typing.get_origin(hint) is tuple:
        return {tuple}, False
    return {hint}, False


def _check_value(spec: Spec, hint: Any, value: Any) -> str | None:
    """What is wrong with ``value`` (None: nothing)."""
    kinds, nullable = _kinds(hint)
    if value is None:
        return None if nullable else f"must not be None, got {value!r}"
    if spec.choices is not None:
        if value not in spec.choices:
            return f"must be one of {', '.join(str(c) for c in spec.choices)}, got {value!r}"
        return None
    if bool in kinds and isinstance(value, bool):
        return None
    if bool in kinds and not kinds - {bool}:
        return f"must be a bool, got {value!r}"
    if tuple in kinds and isinstance(value, tuple):
        for v in value:
            problem = _check_number(spec, v, False)
            if problem is not None:
                return f"every item {problem}"
        return None
    if int in kinds and float not in kinds:
        if isinstance(value, bool) or not isinstance(value, int):
            return f"must be an integer{_unit_range(spec)}, got {value!r}"
        return _check_number(spec, value, True)
    if float in kinds or int in kinds:
        return _check_number(spec, value, False)
    return None


def _unit_range(spec: Spec) -> str:
    r = spec.range_text()
    return f" {r}" if r else ""


def _check_number(spec: Spec, value: Any, integer: bool) -> str | None:
    lo, hi = spec.lo, spec.hi
    try:
        finite_float(value, -math.inf if lo is None else lo, math.inf if hi is None else hi,
                     lo_open=spec.lo_open, hi_open=spec.hi_open)
    except NumberRefused as exc:
        if exc.kind not in ("low", "high"):  # not a number, an int beyond the float range, nan, inf
            return f"must be a finite number, got {shorten(value)}"
        unit = f" {spec.unit}" if spec.unit and lo is not None and hi is not None else ""
        return f"must be {'an integer ' if integer and lo is not None and hi is not None else ''}" \
               f"{spec.range_text()}{unit}, got {shorten(value)}"
    return None


def validate(obj: Any, error: type[SettingError] = SettingError, owner: str | None = None) -> None:
    """Check every :func:`setting` field of dataclass instance ``obj``.

    Args:
        obj: The instance (call this from its ``__post_init__``).
        error: The :class:`SettingError` subclass to raise.
        owner: The name in messages (default: the class's name; ``""`` for none).

    Raises:
        SettingError: the first field whose value is of the wrong type or out of its range.
    """
    cls = type(obj)
    hints = _hints(cls)
    name = cls.__name__ if owner is None else owner
    for f in dataclasses.fields(obj):
        spec = spec_of(f)
        if spec is None:
            continue
        problem = _check_value(spec, hints.get(f.name, Any), getattr(obj, f.name))
        if problem is not None:
            raise error(name, f.name, problem)


@dataclass(frozen=True)
class FieldInfo:
    """One listed setting: ``name``, ``default``, ``type_name`` and its :class:`Spec`."""

    name: str
    default: Any
    type_name: str
    spec: Spec

    def line(self) -> str:
        """``name = default  (type, range, unit): doc``: one line of a listing."""
        extra = ", ".join(x for x in (self.type_name, self.spec.range_text(), self.spec.unit) if x)
        doc = f": {self.spec.doc}" if self.spec.doc else ""
        return f"{self.name} = {self.default!r}  ({extra}){doc}"


def describe(config: Any) -> list[FieldInfo]:
    """The fields of settings dataclass ``config`` (a class, or an instance whose values are
    then the defaults), with their specs (an empty spec for fields declared without one)."""
    cls = config if isinstance(config, type) else type(config)
    hints = _hints(cls)
    out = []
    for f in dataclasses.fields(cls):
        if isinstance(config, type):
            default = (f.default if f.default is not dataclasses.MISSING
                       else f.default_factory() if f.default_factory is not dataclasses.MISSING
                       else None)
        else:
            default = getattr(config, f.name)
        out.append(FieldInfo(f.name, default, type_name(hints.get(f.name, Any)), spec_of(f) or Spec()))
    return out


def type_name(hint: Any) -> str:
    """A type hint in words for listings, e.g. ``float or None``, ``list of float``."""
    if hint is type(None):
        return "None"
    args = typing.get_args(hint)
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        return " or ".join(type_name(a) for a in args)
    if typing.get_origin(hint) is tuple:
        return f"list of {type_name(args[0])}" if args else "list"
    if typing.get_origin(hint) is typing.Literal:
        return " or ".join(repr(a) for a in args)
    return getattr(hint, "__name__", str(hint))
