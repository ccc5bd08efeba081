"""An agent's settings: what ``--set KEY=VALUE`` and ``--deterministic`` may change.

The settings of an agent class are its ``__init__``'s scalar keywords (``float``, ``int``,
``bool``, ``str``, ``None``, unions of those, ``tuple[float, ...]``; read through ``**kwargs``
to the base classes, so plugins work too) plus the fields of its ``config_classes`` (a config
class, or a config instance whose values are the agent's defaults), listed with their range,
unit and description when declared with :func:`anyplan.config.setting`. Values are parsed as
YAML scalars and checked against the setting's type, an unknown key is refused with the nearest
known one, and range checks are the agent's own (turned into one-line errors by
:func:`build_agent_config`). ``deterministic_settings`` make a run depend only on the scenario,
the settings and the seed. Errors name ``setting`` / ``deterministic``; the command line tells
them as ``--set`` / ``--deterministic``.
"""

from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import yaml

from anyplan.config import Spec, describe, type_name
from anyplan.errors import AnyplanError, NumberRefused, UnknownNameError, finite_float, one_line, shorten

__all__ = ["Setting", "SettingsError", "agent_settings", "parse_set_options", "build_agent_config",
           "deterministic_settings"]

_SCALARS = (float, int, bool, str, type(None))


class SettingsError(AnyplanError, ValueError):
    """A bad ``--set`` option or ``--deterministic`` request (exit code 2 on the command line)."""


@dataclass(frozen=True)
class Setting:
    """One settable option: ``name``, its ``default``, its type ``hint`` (None: unannotated) and,
    for a field of a settings dataclass, its :class:`~anyplan.config.Spec` (range, unit, doc)."""

    name: str
    default: Any
    hint: Any
    spec: Spec = field(default_factory=Spec)

    @property
    def type_name(self) -> str:
        """The type in words, e.g. ``float or None``."""
        return _hint_name(self.hint)

    def line(self) -> str:
        """``name = default  (type, range, unit): doc``, one line of ``anyplan planners --settings``."""
        extra = ", ".join(x for x in (self.type_name, self.spec.range_text(), self.spec.unit) if x)
        doc = f": {self.spec.doc}" if self.spec.doc else ""
        return f"{self.name} = {self.default!r}  ({extra}){doc}"


def _hint_name(hint: Any) -> str:
    if hint is None or hint is inspect.Parameter.empty:
        return "any"
    return type_name(hint)


def _settable(hint: Any) -> bool:
    if hint is inspect.Parameter.empty:
        return True
    if hint in _SCALARS:
        return True
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        members = [a for a in typing.get_args(hint) if a is not type(None)]
        return bool(members) and all(_settable(a) for a in members)
    if origin is tuple:
        return all(a in (float, int, Ellipsis) for a in typing.get_args(hint))
    return origin is typing.Literal


def _hints(obj: Any) -> dict[str, Any]:
    try:
        return typing.get_type_hints(obj)
    except Exception:  # noqa: BLE001 - unresolvable annotations: treat as unannotated
        return {}


def agent_settings(cls: type) -> dict[str, Setting]:
    """The settings of agent class ``cls``, by name (constructor keywords, those of the base
    classes its ``**kwargs`` are passed on to, then config fields)."""
    out: dict[str, Setting] = {}
    # A constructor with **kwargs passes them on to its base class's: read that one too.
    for klass in cls.__mro__:
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        hints = _hints(init)
        forwards = False
        for p in list(inspect.signature(init).parameters.values())[1:]:
            if p.kind is p.VAR_KEYWORD:
                forwards = True
            if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) or p.name in out:
                continue
            hint = hints.get(p.name, inspect.Parameter.empty)
            if _settable(hint):
                out[p.name] = Setting(p.name, None if p.default is p.empty else p.default, hint)
        if not forwards:
            break
    # A config class, or a config instance whose values are the agent's defaults.
    for conf in getattr(cls, "config_classes", ()):
        fh = _hints(conf if isinstance(conf, type) else type(conf))
        for info in describe(conf):
            hint = fh.get(info.name, inspect.Parameter.empty)
            if info.name in out or not _settable(hint):
                continue
            out[info.name] = Setting(info.name, info.default, hint, info.spec)
    return out


def _coerce(hint: Any, value: Any) -> Any:
    """``value`` as type ``hint``; raises TypeError when it is not one, NumberRefused (kind
    ``"overflow"``) for an int beyond the float range where a float is expected."""
    if hint is inspect.Parameter.empty:
        return value
    if hint is type(None):
        if value is None:
            return None
        raise TypeError
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        members = typing.get_args(hint)
        # Exact type matches first, so that "measured" stays a str and 2 stays an int.
        def exact_first(a: Any) -> int:
            return 0 if isinstance(value, a if isinstance(a, type) else ()) else 1

        for a in sorted(members, key=exact_first):
            try:
                return _coerce(a, value)
            except TypeError:
                continue
        raise TypeError
    if origin is typing.Literal:
        if value in typing.get_args(hint):
            return value
        raise TypeError
    if origin is tuple:
        if not isinstance(value, list | tuple):
            value = [value]
        return tuple(_coerce(float, v) for v in value)
    if hint is bool:
        if isinstance(value, bool):
            return value
        raise TypeError
    if hint is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        raise TypeError
    if hint is float:
        if isinstance(value, float):
            return float(value)  # nan and inf too: the agent's own checks refuse them in its words
        if isinstance(value, int) and not isinstance(value, bool):
            return finite_float(value)  # an int of hundreds of digits: NumberRefused
        if isinstance(value, str):  # YAML 1.1 reads 1e-3 as a string
            try:
                return float(value)
            except ValueError:
                raise TypeError from None
        raise TypeError
    if hint is str:
        if isinstance(value, str):
            return value
        raise TypeError
    if isinstance(value, hint):
        return value
    raise TypeError


def parse_set_options(items: Sequence[str]) -> dict[str, Any]:
    """``["KEY=VALUE", ...]`` as a dictionary, each value parsed as a YAML scalar.

    Raises:
        SettingsError: an item without ``=``, an empty key, a key given twice, or bad YAML (or
            YAML Python cannot hold: an int of more than 4300 digits, a date like 2020-13-45).
    """
    out: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise SettingsError.about("setting", f": expected KEY=VALUE, got '{item}'")
        if key in out:
            raise SettingsError.about("setting", f": '{key}' is given twice")
        try:
            out[key] = yaml.safe_load(text) if text.strip() else ""
        # ValueError: an int of more than 4300 digits, a date like 2020-13-45; RecursionError: [[[...
        except (yaml.YAMLError, ValueError, RecursionError):
            raise SettingsError.about("setting", f" {key}: cannot read '{one_line(text, 60)}' as a YAML "
                                      "value") from None
    return out


def deterministic_settings(cls: type, planner: str) -> dict[str, Any]:
    """The settings that make ``planner``'s runs independent of the machine.

    Raises:
        SettingsError: the agent has no deterministic mode.
    """
    det = getattr(cls, "deterministic_settings", None)
    if det is None:
        raise SettingsError.about("deterministic", f": planner '{planner}' has no deterministic mode "
                            "(its class sets no deterministic_settings)")
    return dict(det)


def build_agent_config(cls: type, planner: str, options: dict[str, Any],
                       deterministic: bool = False) -> dict[str, Any]:
    """The keyword config for ``cls``: its deterministic settings (if asked), then ``options``
    checked against :func:`agent_settings`; the agent is built once to run its own checks.

    Raises:
        SettingsError: an unknown key (with the nearest known one), a value of the wrong type
            (or an int beyond the float range for a float), or a value the agent rejects.
    """
    known = agent_settings(cls)
    config = deterministic_settings(cls, planner) if deterministic else {}
    for key, value in options.items():
        if key not in known:
            err = UnknownNameError(f"setting of planner '{planner}'", key, list(known))
            raise SettingsError.about("setting", f": {err}")
        s = known[key]
        try:
            config[key] = _coerce(s.hint, value)
        except TypeError:
            raise SettingsError.about("setting", f" {key}={shorten(value)}: planner '{planner}' expects "
                                f"{s.type_name} (default {s.default!r})") from None
        except NumberRefused as exc:
            raise SettingsError.about("setting", f" {key}={shorten(value)}: {exc}") from None
    try:
        cls(**config)
    except (TypeError, ValueError) as exc:
        first = (str(exc).splitlines() or [""])[0]
        raise SettingsError.about("setting", f": planner '{planner}' rejects its settings: {first}") from None
    return config
