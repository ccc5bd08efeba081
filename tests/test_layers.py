"""Import direction: each layer imports only earlier layers (CONTRIBUTING.md, "Layers").

Every ``import`` and ``from ... import`` in ``src/anyplan`` is read with :mod:`ast`, including
imports inside functions and under ``if TYPE_CHECKING:`` (a type is a dependency too).

* Layer order: geometry -> world -> planning, prediction -> trajectory -> control ->
  baselines -> agents -> simulation -> experiments -> viz, cli (and gym, an integration).
  Packages of one tier (planning and prediction; viz, cli and gym) may import each other only
  one way (no cycle). ``anyplan``, ``anyplan.errors`` and ``anyplan.registry`` sit below all.
* Only ``anyplan.viz`` imports matplotlib.
* No module imports another package's private module or name (``pkg._x``,
  ``from pkg.mod import _x``): a package's private parts are used only inside it.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "anyplan"

#: Tier of each top-level part of ``anyplan``; a module may import its own tier and lower ones.
TIERS: dict[str, int] = {
    "__init__": 0, "errors": 0, "config": 0, "registry": 0, "scenarios": 0,
    "geometry": 1,
    "world": 2,
    "planning": 3, "prediction": 3,
    "trajectory": 4,
    "control": 5,
    "baselines": 6,
    "agents": 7,
    "simulation": 8,
    "experiments": 9,
    "viz": 10, "cli": 10, "gym": 10,
    "__main__": 11,
}

#: The only part of anyplan that may import matplotlib.
MATPLOTLIB_USERS = {"viz"}

#: (importing module, imported name) pairs allowed to break a rule while a restructure is under
#: way (issue 13 emptied it); the test fails on any other break.
KNOWN: set[tuple[str, str]] = set()


def _module_name(path: Path) -> list[str]:
    parts = ["anyplan", *path.relative_to(SRC).with_suffix("").parts]
    return parts[:-1] if parts[-1] == "__init__" else parts


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, dotted name) of everything ``path`` imports; ``from a import b`` gives ``a.b``."""
    here = _module_name(path)
    package = here if path.name == "__init__.py" else here[:-1]
    out: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            out += [(node.lineno, f"{module}.{alias.name}") for alias in node.names if alias.name != "*"]
            out.append((node.lineno, module))
    return out


def _part(dotted: list[str]) -> str:
    """Top-level part of anyplan a dotted name belongs to (``anyplan`` alone is ``__init__``)."""
    return dotted[1] if len(dotted) > 1 else "__init__"


def _private_owner(dotted: list[str]) -> list[str] | None:
    """The package whose private part ``dotted`` names (``a.b._c.d`` -> ``a.b``), if any."""
    for i, name in enumerate(dotted):
        if name.startswith("_") and not name.startswith("__"):
            return dotted[:i]
    return None


def _source_files() -> list[Path]:
    return sorted(SRC.rglob("*.py"))


def _violations() -> list[tuple[str, str, str]]:
    """(importing module:line, imported name, rule broken) for every break of the rules."""
    found: list[tuple[str, str, str]] = []
    for path in _source_files():
        here = _module_name(path)
        mine = _part(here)
        where = ".".join(here)
        for line, name in _imports(path):
            dotted = name.split(".")
            if dotted[0] == "matplotlib" and mine not in MATPLOTLIB_USERS:
                found.append((f"{where}:{line}", name, "only viz imports matplotlib"))
            if dotted[0] != "anyplan":
                continue
            theirs = _part(dotted)
            if theirs in TIERS and mine in TIERS and TIERS[theirs] > TIERS[mine]:
                found.append((f"{where}:{line}", name, f"{mine} (tier {TIERS[mine]}) imports a "
                                                       f"later layer, {theirs} (tier {TIERS[theirs]})"))
            owner = _private_owner(dotted)
            # A package's private parts are open to the package's own top-level part only.
            if owner is not None and len(owner) >= 2 and _part(owner) != mine:
                found.append((f"{where}:{line}", name, f"private part of {'.'.join(owner)}"))
    return found


def test_every_part_of_anyplan_has_a_tier() -> None:
    parts = {_part(_module_name(p)) for p in _source_files()}
    parts |= {p.name for p in SRC.iterdir() if p.is_dir() and not p.name.startswith("__")}
    assert parts <= set(TIERS), f"give these a tier in tests/test_layers.py: {parts - set(TIERS)}"


def test_imports_follow_the_layers() -> None:
    new = [v for v in _violations() if (v[0].split(":")[0], v[1]) not in KNOWN]
    assert not new, "imports against the rules (CONTRIBUTING.md, 'Layers'):\n" + "\n".join(
        f"  {where}: {name}: {rule}" for where, name, rule in new)


def test_no_cycle_between_parts_of_one_tier() -> None:
    edges: dict[str, set[str]] = defaultdict(set)
    for path in _source_files():
        mine = _part(_module_name(path))
        for _, name in _imports(path):
            dotted = name.split(".")
            if dotted[0] == "anyplan" and _part(dotted) != mine:
                edges[mine].add(_part(dotted))
    cycles = sorted(f"{a} <-> {b}" for a in edges for b in edges[a] if a < b and a in edges.get(b, ()))
    assert not cycles, f"parts of anyplan that import each other: {cycles}"


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("import matplotlib.pyplot as plt\n", "only viz imports matplotlib"),
        ("def f():\n    from anyplan.viz import run\n", "imports a later layer"),
        ("from anyplan.trajectory import _kernels\n", "private part of anyplan.trajectory"),
        ("from anyplan.experiments.tables import _cells\n", "private part of anyplan.experiments.tables"),
        ("from ..trajectory._kernels import x\n", "private part of anyplan.trajectory"),
    ],
)
def test_the_checker_sees_a_break(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, source: str,
                                  expected: str) -> None:
    fake = tmp_path / "anyplan"
    (fake / "geometry").mkdir(parents=True)
    (fake / "geometry" / "bad.py").write_text(source, encoding="utf-8")
    monkeypatch.setattr(f"{__name__}.SRC", fake)
    rules = [rule for _, _, rule in _violations()]
    assert any(expected in rule for rule in rules), rules
