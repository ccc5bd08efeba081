"""The matplotlib backend for programs that draw without a screen (the command line).

The library's drawing functions never select a backend: they draw on figures with an Agg canvas
of their own (:func:`anyplan.viz.style.new_figure`). A program that also uses pyplot, such as
``anyplan`` itself, calls :func:`pick_headless_backend` once at its start. matplotlib is
imported only when the function runs, so importing this module costs nothing.
"""

from __future__ import annotations

import os
import sys

__all__ = ["pick_headless_backend"]


def pick_headless_backend() -> None:
    """Select matplotlib's non-interactive Agg backend, unless the user chose a backend
    (``MPLBACKEND``, a matplotlibrc, or ``matplotlib.use`` before) or pyplot is already in use."""
    if os.environ.get("MPLBACKEND"):
        return
    import matplotlib

    chosen = getattr(matplotlib.rcParams, "_get_backend_or_none", lambda: None)()
    if chosen is None and "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
