"""A bounded, strict YAML reader for scenario files.

``yaml.safe_load`` accepts documents that are valid YAML but hostile or ambiguous as input:

* a duplicate key silently keeps the last value (``radius: 0.9`` then ``radius: 5.0``);
* aliases may expand a kilobyte into gigabytes (the "billion laughs"): the loaded object is a
  small graph, but anything that walks it (a ``repr`` in an error message, JSON) explodes;
* deep nesting (``[[[[...]]]]``) overflows Python's recursion limit in the composer;
* ``1e6`` is text in YAML 1.1 (read here as the number it is meant to be);
* an integer literal of thousands of digits hits Python's int-string conversion limit.

:func:`load_yaml` refuses all of these with :class:`YamlLimitError` (line and column when known)
and keeps the limits below. They are far beyond any real scenario file.
"""

from __future__ import annotations

import re
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

__all__ = ["YamlLimitError", "load_yaml", "dump_yaml", "MAX_DOCUMENT_CHARS", "MAX_DEPTH", "MAX_NODES",
           "MAX_SCALAR_CHARS"]

#: Largest document [characters].
MAX_DOCUMENT_CHARS = 4_000_000
#: Deepest nesting of lists and mappings.
MAX_DEPTH = 50
#: Most nodes of the document with every alias expanded.
MAX_NODES = 1_000_000
#: Longest scalar (a number, a string) [characters].
MAX_SCALAR_CHARS = 10_000


class YamlLimitError(ValueError):
    """The document is malformed or exceeds a limit; ``where`` is e.g. ``"line 3, column 5"``."""

    def __init__(self, message: str, where: str = "", field: str = "") -> None:
        self.where = where
        self.message = message
        self.field = field  # dotted path of the offending value, when known
        text = f"{message} at {where}" if where else message
        self.text = text
        super().__init__(f"{field}: {text}" if field else text)


def _where(node_or_mark: Any) -> str:
    mark = getattr(node_or_mark, "start_mark", node_or_mark)
    if mark is None or not hasattr(mark, "line"):
        return ""
    return f"line {mark.line + 1}, column {mark.column + 1}"


class _StrictLoader(yaml.SafeLoader):
    """SafeLoader with a nesting limit while composing and duplicate-key refusal."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: Node | None, index: Any) -> Node | None:
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise YamlLimitError(f"nesting deeper than {MAX_DEPTH} levels",
                                     _where(self.peek_event()))
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node: Node, deep: bool = False) -> dict[Any, Any]:
        if isinstance(node, MappingNode):
            seen: set[Any] = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                if not isinstance(key_node, ScalarNode):
                    continue  # complex keys: the base class reports them (unhashable)
                key = self.construct_object(key_node, deep=True)
                try:
                    dup = key in seen
                except TypeError:
                    continue
                if dup:
                    raise YamlLimitError(f"duplicate key {str(key)[:40]!r}", _where(key_node))
                seen.add(key)
        return super().construct_mapping(node, deep)  # type: ignore[arg-type]


def _expanded_size(root: Node) -> int:
    """Number of nodes with aliases expanded (shared nodes counted at each use), capped; also
    refuses nesting deeper than MAX_DEPTH and scalars longer than MAX_SCALAR_CHARS."""
    sizes: dict[int, int] = {}
    depths: dict[int, int] = {}
    # Iterative post-order walk: aliases make the node graph a DAG (recursive ones are refused
    # by the composer), so memoised sizes are exact.
    stack: list[tuple[Node, bool, str]] = [(root, False, "")]
    while stack:
        node, expanded, path = stack.pop()
        nid = id(node)
        if nid in sizes:
            continue
        if isinstance(node, ScalarNode):
            if len(node.value) > MAX_SCALAR_CHARS:
                raise YamlLimitError(f"a value longer than {MAX_SCALAR_CHARS} characters",
                                     _where(node), path)
            sizes[nid] = 1
            depths[nid] = 0
            continue
        if isinstance(node, SequenceNode):
            children = list(node.value)
            paths = [f"{path}[{i}]" for i in range(len(children))]
        else:
            children = [c for kv in node.value for c in kv]
            paths = []
            for k, _ in node.value:
                key = k.value[:40] if isinstance(k, ScalarNode) else "?"
                paths += [path, f"{path}.{key}" if path else key]
        if not expanded:
            stack.append((node, True, path))
            stack.extend((c, False, p) for c, p in zip(children, paths, strict=True)
                         if id(c) not in sizes)
            continue
        total = 1 + sum(sizes[id(c)] for c in children)
        depth = 1 + max((depths[id(c)] for c in children), default=0)
        if depth > MAX_DEPTH:
            raise YamlLimitError(f"nesting deeper than {MAX_DEPTH} levels", _where(node), path)
        depths[nid] = depth
        if total > MAX_NODES:
            raise YamlLimitError(f"more than {MAX_NODES} values once its aliases are expanded "
                                 "(an alias bomb?)", _where(node), path)
        sizes[nid] = total
    return sizes[id(root)]


# YAML 1.1 reads ``1e6`` (no dot) as text; read it as a number, as YAML 1.2 and JSON do.
_EXP_FLOAT = re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")
_StrictLoader.add_implicit_resolver("tag:yaml.org,2002:float", _EXP_FLOAT, list("-+0123456789"))


class _Dumper(yaml.SafeDumper):
    """``yaml.SafeDumper`` that quotes the strings :func:`load_yaml` would read as numbers."""

    def choose_scalar_style(self) -> str:
        # PyYAML writes a NEL (U+0085) raw in a single-quoted scalar with allow_unicode, and
        # reads it back as a folded space; double quotes escape it (\N).
        if "\x85" in getattr(self.event, "value", ""):
            return '"'
        return str(super().choose_scalar_style())


# the dumper quotes a string when its own resolvers would read the plain scalar as another type
_Dumper.add_implicit_resolver("tag:yaml.org,2002:float", _EXP_FLOAT, list("-+0123456789"))


def dump_yaml(data: Any, **kwargs: Any) -> str:
    """``yaml.safe_dump(data, **kwargs)`` whose text :func:`load_yaml` reads back as ``data``:
    a string such as ``"1e5"``, which plain YAML 1.1 writes unquoted, is quoted."""
    return str(yaml.dump(data, Dumper=_Dumper, **kwargs))


_CComposer: type[yaml.CSafeLoader] | None = None
if getattr(yaml, "__with_libyaml__", False):
    class _CSafeComposer(yaml.CSafeLoader):
        """libyaml's scanner, parser and composer (fast) with our resolvers."""

    _CSafeComposer.yaml_implicit_resolvers = _StrictLoader.yaml_implicit_resolvers
    _CComposer = _CSafeComposer

# A bracket, a quoted string (skipped whole) or a comment.
_FLOW_TOKEN = re.compile(r"""[\[\]{}]|"(?:[^"\\]|\\.)*"|'(?:[^']|'')*'|#[^\n]*""")
# The indentation and the "- " / "? " indicators that open a line: a bound on block nesting.
_BLOCK_PREFIX = re.compile(r"(?m)^[ \t]*(?:[-?][ \t]+)*")


def _flow_depth(text: str) -> int:
    """Deepest nesting of flow brackets outside quoted strings and comments (linear time;
    PyYAML's scanner is quadratic in it)."""
    if text.count("[") + text.count("{") <= MAX_DEPTH:
        return 0
    depth = deepest = 0
    for m in _FLOW_TOKEN.finditer(text):
        ch = m.group()[0]
        if ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth = max(depth - 1, 0)
    return deepest


def _compose(text: str) -> tuple[Node | None, Any]:
    """The document's node graph and a constructor for it. libyaml composes when the text's
    block nesting is shallow (its composer recurses in C); otherwise the pure-Python composer,
    which counts the depth as it goes."""
    block = max((len(m.group()) for m in _BLOCK_PREFIX.finditer(text)), default=0)
    if _CComposer is not None and block <= 4 * MAX_DEPTH:
        composer = _CComposer(text)
        try:
            return composer.get_single_node(), _StrictLoader("")
        finally:
            composer.dispose()
    loader = _StrictLoader(text)
    return loader.get_single_node(), loader


def load_yaml(text: str) -> Any:
    """Parse one YAML document strictly (see the module docstring); None for an empty one.

    Raises:
        YamlLimitError: malformed YAML, a duplicate key, or a limit exceeded.
    """
    if len(text) > MAX_DOCUMENT_CHARS:
        raise YamlLimitError(f"the document is larger than {MAX_DOCUMENT_CHARS} characters")
    if _flow_depth(text) > MAX_DEPTH:
        raise YamlLimitError(f"nesting deeper than {MAX_DEPTH} levels")
    loader = None
    try:
        node, loader = _compose(text)
        if node is None:
            return None
        _expanded_size(node)
        return loader.construct_document(node)
    except YamlLimitError:
        raise
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or "malformed YAML"
        raise YamlLimitError(f"malformed YAML at {_where(mark) or 'unknown place'}: {problem}") \
            from None
    except ValueError as exc:  # e.g. an integer literal beyond the int-string conversion limit
        raise YamlLimitError(f"unreadable value ({str(exc)[:80]})") from None
    except RecursionError:
        raise YamlLimitError(f"nesting deeper than {MAX_DEPTH} levels") from None
    finally:
        if loader is not None:
            loader.dispose()
