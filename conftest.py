"""Collection rules for the whole suite: doctests of modules whose optional extra is missing.

``python -m pytest`` collects ``tests/`` and the doctests of ``src/anyplan`` (see
``[tool.pytest.ini_options]`` in pyproject.toml). A module that imports an optional peer at its
top (``anyplan.gym`` needs Gymnasium) cannot be imported without its extra: its doctests are
then left out, and the summary names it, instead of failing the run. Any other import error
still fails the collection.
"""

from __future__ import annotations

import importlib
import os
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

_SRC = Path(__file__).parent / "src"
_left_out: list[str] = []


def _missing_peer(exc: BaseException) -> str | None:
    """The third-party module whose absence caused ``exc``, if that is the cause."""
    while exc is not None:
        if isinstance(exc, ModuleNotFoundError) and exc.name and exc.name.split(".")[0] != "anyplan":
            return exc.name
        exc = exc.__cause__ or exc.__context__
    return None


def pytest_ignore_collect(collection_path, config):
    """Leave out a source module that cannot be imported for want of an optional peer."""
    path = Path(collection_path)
    if path.suffix != ".py" or _SRC not in path.parents or path.name == "__main__.py":
        return None
    parts = list(path.relative_to(_SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    try:
        importlib.import_module(".".join(parts))
    except ImportError as exc:
        peer = _missing_peer(exc)
        if peer is None:
            raise
        _left_out.append(f"{'.'.join(parts)} (needs {peer})")
        return True
    return None


def pytest_terminal_summary(terminalreporter):
    """Name the modules whose doctests were left out."""
    if _left_out:
        terminalreporter.write_line("doctests left out, optional extra missing: " + ", ".join(_left_out))
