"""The matplotlib backend for programs that draw without a screen (the command line).

The library's drawing functions never select a backend: they draw on figures with an Agg canvas
of their own (:func:`anyplan.viz.style.new_figure`). A program that also uses pyplot, such as
``anyplan`` itself, calls :func:`pick_headless_backend` once at its start. matplotlib costs
about 0.3 s to import, and most commands never draw: if it is not imported yet, the choice is
made when something imports it, so importing this module or calling the function costs nothing.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import os
import sys
from typing import Any

__all__ = ["pick_headless_backend"]


def pick_headless_backend() -> None:
    """Select matplotlib's non-interactive Agg backend, unless the user chose a backend
    (``MPLBACKEND``, a matplotlibrc, or ``matplotlib.use`` before) or pyplot is already in use.

    If matplotlib is not imported yet, this happens right after its import, whenever that is."""
    if os.environ.get("MPLBACKEND"):
        return
    if "matplotlib" in sys.modules:
        _pick()
    elif not any(isinstance(f, _PickOnImport) for f in sys.meta_path):
        sys.meta_path.insert(0, _PickOnImport())


def _pick() -> None:
    import matplotlib

    chosen = getattr(matplotlib.rcParams, "_get_backend_or_none", lambda: None)()
    if chosen is None and "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")


class _PickOnImport(importlib.abc.MetaPathFinder):
    """Finds nothing itself: on the import of ``matplotlib`` it removes itself and has the
    module's loader call :func:`_pick` once the module is executed."""

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != "matplotlib":
            return None
        sys.meta_path.remove(self)
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if spec is not None and spec.loader is not None and hasattr(spec.loader, "exec_module"):
            exec_module = spec.loader.exec_module

            def exec_then_pick(module: Any) -> None:
                exec_module(module)
                _pick()

            spec.loader.exec_module = exec_then_pick  # type: ignore[method-assign]
        return spec
